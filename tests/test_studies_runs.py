"""Archived runs (studies.runs): folder layout, atomic rename, failure handling,
collision safety, listing and lookup."""
import json
import math
import subprocess
import tomllib

import numpy as np
import pytest

import studies.runs as runs
from eroad.errors import EroadInputError
from studies.runs import (RunArchive, find_run, git_state, list_runs, load_run,
                          write_json_atomic)


def _only_hidden_left(study_dir):
    return [p.name for p in study_dir.iterdir() if p.name.startswith(".")]


def test_complete_run_layout(tmp_path):
    """A finished run has config.toml, run.json, data/, figures/, summary.json,
    status complete, and no temporary folder is left behind."""
    config = {"frame": {"k_factor": np.float64(2.0), "segments": 4}, "seeds": (1, 2),
              "optional": None, "path": tmp_path / "x"}
    with RunArchive("chassis", config, root=tmp_path, seed=42,
                    command=["eroad", "study", "chassis"], overrides=["frame.k=2"]) as run:
        assert run.path.name.startswith(".tmp-")
        np.save(run.data_dir / "a.npy", np.arange(3))
        (run.figures_dir / "f.png").write_bytes(b"png")
        run.write_summary({"peak_hz": np.float32(7.5), "n": np.int64(3)})
    assert run.status == "complete"
    assert run.path == tmp_path / "chassis" / run.run_id
    assert sorted(p.name for p in run.path.iterdir()) == [
        "config.toml", "data", "figures", "run.json", "summary.json"]
    assert _only_hidden_left(run.path.parent) == []

    cfg = tomllib.loads((run.path / "config.toml").read_text())
    assert cfg == {"frame": {"k_factor": 2.0, "segments": 4}, "seeds": [1, 2],
                   "path": str(tmp_path / "x")}          # None dropped: TOML has no null
    info = json.loads((run.path / "run.json").read_text())
    assert info["status"] == "complete" and info["run_id"] == run.run_id
    assert info["seed"] == 42 and info["overrides"] == ["frame.k=2"]
    assert info["command"] == "eroad study chassis"
    assert info["versions"]["numpy"] == np.__version__
    assert set(info["versions"]) >= {"python", "exudyn", "casadi", "numpy", "scipy", "pandas"}
    assert info["wall_s"] >= 0 and info["end_utc"] >= info["start_utc"]
    assert set(info["git"]) == {"commit", "dirty"}
    assert info["host"]["hostname"]
    summary = json.loads((run.path / "summary.json").read_text())
    assert summary == {"peak_hz": 7.5, "n": 3}
    assert (run.path / "data" / "a.npy").is_file()


def test_failed_run_is_kept_with_status_failed(tmp_path):
    """An exception inside the block propagates; the folder is still renamed
    into place with status failed, the traceback and the partial data kept."""
    with pytest.raises(ZeroDivisionError):
        with RunArchive("chassis", {"a": 1}, root=tmp_path) as run:
            (run.data_dir / "partial.csv").write_text("x\n1\n")
            1 / 0
    assert run.status == "failed"
    rec = load_run(run.path)
    assert rec.status == "failed"
    assert rec.info["error"]["type"] == "ZeroDivisionError"
    assert "1 / 0" in (run.path / "error.txt").read_text()
    assert (run.path / "data" / "partial.csv").read_text() == "x\n1\n"
    assert _only_hidden_left(run.path.parent) == []


def test_never_overwrites_another_run(tmp_path, monkeypatch):
    """If the final name is taken (here forced by a fixed run-id), the run gets
    a fresh id and the existing folder is untouched."""
    taken = tmp_path / "s" / "20260101T000000Z-deadbeef"
    taken.mkdir(parents=True)
    (taken / "keep.txt").write_text("mine")
    ids = iter(["20260101T000000Z-deadbeef", "20260101T000000Z-deadbeef"])
    real = runs.new_run_id
    monkeypatch.setattr(runs, "new_run_id", lambda when=None: next(ids, None) or real(when))
    with RunArchive("s", {}, root=tmp_path) as run:
        pass
    assert run.run_id != taken.name
    assert (taken / "keep.txt").read_text() == "mine"
    assert sorted(p.name for p in taken.iterdir()) == ["keep.txt"]
    assert load_run(run.path).info["run_id"] == run.run_id   # run.json follows the new id


def test_two_runs_same_second_distinct(tmp_path):
    with RunArchive("s", {}, root=tmp_path) as a:
        pass
    with RunArchive("s", {}, root=tmp_path) as b:
        pass
    assert a.run_id != b.run_id and a.path.is_dir() and b.path.is_dir()


def test_write_outside_block_and_bad_names(tmp_path):
    run = RunArchive("s", {}, root=tmp_path)
    with pytest.raises(RuntimeError):
        run.write_summary({})
    with run:
        pass
    with pytest.raises(RuntimeError):
        run.write_summary({})
    for bad in ("", ".hidden", "a/b", "x y"):
        with pytest.raises(EroadInputError):
            RunArchive(bad, {}, root=tmp_path)


def test_list_find_and_load(tmp_path):
    with RunArchive("alpha", {}, root=tmp_path) as a:
        a.write_summary({"x": 1})
    with pytest.raises(KeyError):
        with RunArchive("beta", {}, root=tmp_path) as b:
            raise KeyError("boom")
    (tmp_path / "beta" / ".tmp-20990101T000000Z-00000000").mkdir()   # abandoned temp run
    (tmp_path / "beta" / "not-a-run").mkdir()
    recs = list_runs(tmp_path)
    assert [(r.study, r.status) for r in recs] == [("alpha", "complete"), ("beta", "failed")]
    assert [r.run_id for r in list_runs(tmp_path, study="beta")] == [b.run_id]
    assert list_runs(tmp_path / "missing") == []
    assert find_run(a.run_id, root=tmp_path).path == a.path
    assert find_run(a.path).summary == {"x": 1}
    assert find_run(f"beta/{b.run_id}", root=tmp_path).status == "failed"
    assert find_run(b.run_id[:-2], root=tmp_path).path == b.path  # unique prefix
    with pytest.raises(EroadInputError, match="ambiguous"):
        find_run("20", root=tmp_path)
    with pytest.raises(EroadInputError, match="no run"):
        find_run("nope", root=tmp_path)
    with pytest.raises(EroadInputError, match="not a run folder"):
        load_run(tmp_path / "beta" / "not-a-run")
    (a.path / "summary.json").write_text("{broken")
    with pytest.raises(EroadInputError, match="cannot read JSON"):
        load_run(a.path)
    assert [r.status for r in list_runs(tmp_path)][0] == "unreadable"


def test_write_json_atomic(tmp_path):
    """NaN/inf become null (standard JSON), numpy types convert; a value that
    cannot be written leaves the previous file intact and no temp file."""
    path = tmp_path / "s.json"
    write_json_atomic(path, {"a": np.float64("nan"), "b": np.arange(2), "c": math.inf})
    assert json.loads(path.read_text()) == {"a": None, "b": [0, 1], "c": None}
    with pytest.raises(TypeError):
        write_json_atomic(path, {"bad": object()})
    assert json.loads(path.read_text())["b"] == [0, 1]
    assert [p.name for p in tmp_path.iterdir()] == ["s.json"]


def test_git_state_tolerates_missing_git(tmp_path, monkeypatch):
    assert git_state(tmp_path) == {"commit": None, "dirty": None}   # not a repository

    def no_git(*a, **k):
        raise FileNotFoundError("git")
    monkeypatch.setattr(subprocess, "run", no_git)
    assert git_state() == {"commit": None, "dirty": None}
    with RunArchive("s", {}, root=tmp_path) as run:
        pass
    assert load_run(run.path).info["git"] == {"commit": None, "dirty": None}


def test_git_state_of_this_repository():
    """In the source checkout the commit is a 40-hex string (skipped when the
    package is installed without its repository)."""
    state = git_state()
    if state["commit"] is None:
        pytest.skip("package not in a git work tree")
    assert len(state["commit"]) == 40 and isinstance(state["dirty"], bool)
