"""The run archive (eroad.archive): one run.json schema, every run folder under results/
listed and shown without None fields, manifests that list only files the run holds."""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from eroad.archive import (RUN_SCHEMA, RunArchive, finish_run_info, list_runs, load_run,
                           manifest_problems, manifest_rows, normalize_info, run_info,
                           write_run_json)
from eroad.cli import main

RESULTS = Path(__file__).resolve().parents[1] / "results"

#: the fields every run.json has (eroad.archive.run_info)
SCHEMA_KEYS = {"schema", "study", "run_id", "status", "command", "argv", "overrides", "cwd", "git",
               "host", "versions", "seed", "start_utc", "end_utc", "wall_s", "error", "extra"}


def _tracked() -> set[str] | None:
    """Files under results/ that git tracks (None without git): the committed runs."""
    import subprocess
    try:
        r = subprocess.run(["git", "-C", str(RESULTS.parent), "ls-files", "results"],
                           capture_output=True, text=True, timeout=30, check=True)
    except (OSError, subprocess.SubprocessError):
        return None
    return set(r.stdout.split())


def _committed_run_folders() -> set[Path]:
    """Committed run folders under results/, found without the archive's code: each
    folder two levels down, or a study folder that holds files only (a folder some
    other work is still writing, with nothing committed, is left out)."""
    tracked = _tracked()
    return {p for p in _run_folders()
            if tracked is None or any(t.startswith(p.relative_to(RESULTS.parent).as_posix() + "/")
                                      for t in tracked)}


def _run_folders() -> set[Path]:
    out = set()
    for study in RESULTS.iterdir():
        if not study.is_dir() or study.name.startswith("."):
            continue
        subs = [d for d in study.iterdir() if d.is_dir() and not d.name.startswith(".")]
        out.update(subs if subs else [study])
    return out


def test_runs_list_json_lists_every_run_folder_under_results(capsys, monkeypatch):
    monkeypatch.chdir(RESULTS.parent)
    assert main(["runs", "list", "--json"]) == 0
    listed = {Path(r["path"]).resolve() for r in json.loads(capsys.readouterr().out)}
    assert len(_committed_run_folders()) >= 15   # 8 diagnosis_blind, 4 inverse_blind, 2 reproduce, effect_ranges
    assert listed == {p.resolve() for p in _run_folders()}


@pytest.mark.parametrize("run", sorted(p.name for p in _committed_run_folders()))
def test_runs_show_has_no_none_field_on_a_committed_run(run, capsys, monkeypatch):
    monkeypatch.chdir(RESULTS.parent)
    path = next(p for p in _committed_run_folders() if p.name == run)
    assert main(["runs", "show", str(path.relative_to(RESULTS.parent))]) == 0
    head = capsys.readouterr().out.split("\nsummary")[0]
    assert not re.search(r"\bNone\b|\snull$", head, flags=re.M), head
    info = json.loads((path / "run.json").read_text())
    assert set(info) == SCHEMA_KEYS and info["schema"] == RUN_SCHEMA


def test_committed_nested_run_json_files_share_the_schema():
    tracked = _tracked()
    files = [f for f in RESULTS.rglob("run.json")
             if tracked is None or f.relative_to(RESULTS.parent).as_posix() in tracked]
    assert files
    for f in files:
        assert set(json.loads(f.read_text())) == SCHEMA_KEYS, f


@pytest.mark.parametrize("run", sorted(str(p.parent.relative_to(RESULTS))
                                       for p in RESULTS.rglob("manifest.json")))
def test_committed_manifests_list_only_files_the_run_holds(run):
    assert manifest_problems(RESULTS / run) == []


def test_manifest_rows_and_problems(tmp_path):
    """Rows hold only existing files, relative to the run; a listed file that is missing,
    a wrong 'present' flag, a path outside the run and a dead markdown link are caught."""
    run = tmp_path / "run"
    (run / "invert").mkdir(parents=True)
    (run / "invert" / "road.npz").write_bytes(b"x")
    rows = manifest_rows(run, [("road", "invert/road.*", "inverse.run.run_inversion"),
                               ("figure", "invert/figures/*.png", "inverse.report")])
    assert rows == [{"item": "road", "files": ["invert/road.npz"], "code": "inverse.run.run_inversion",
                     "present": True},
                    {"item": "figure", "files": [], "code": "inverse.report", "present": False}]
    (run / "manifest.json").write_text(json.dumps(rows))
    (run / "manifest.md").write_text("[road](invert/road.npz)\n")
    assert manifest_problems(run) == []
    bad = rows + [{"item": "crg", "files": ["invert/road.crg"], "present": True},
                  {"item": "abs", "files": [str(tmp_path / "x")], "present": True},
                  {"item": "flag", "files": [], "present": True}]
    (run / "manifest.json").write_text(json.dumps(bad))
    (run / "manifest.md").write_text("[road](invert/road.npz) [gone](invert/road.crg)\n")
    problems = manifest_problems(run)
    assert len(problems) == 4
    assert any("invert/road.crg is listed but missing" in p for p in problems)
    assert any("not a path inside the run" in p for p in problems)
    assert any("present=True with 0 file(s)" in p for p in problems)
    assert any("link invert/road.crg" in p for p in problems)


def test_old_run_json_names_are_read_into_the_schema(tmp_path):
    """invert wrote started/finished and a host string, reproduce start and a command list."""
    inv = normalize_info({"command": ["eroad", "invert", "d"], "study": "invert", "host": "vm",
                          "started": "2026-11-23T20:55:39.155072+00:00",
                          "finished": "2026-11-23T20:58:07.619008+00:00", "status": "complete",
                          "wall_s": 148.4}, tmp_path / "r")
    assert set(inv) == SCHEMA_KEYS
    assert inv["start_utc"] == "2026-11-23T20:55:39.155Z" and inv["end_utc"] == "2026-11-23T20:58:07.619Z"
    assert inv["host"] == {"hostname": "vm"} and inv["command"] == "eroad invert d"
    rep = normalize_info({"command": ["eroad", "reproduce"], "start": "2026-11-23T20:51:52Z",
                          "quick": False, "timings_s": {"a": 1.0}}, tmp_path / "x" / "r")
    assert rep["start_utc"] == "2026-11-23T20:51:52.000Z"
    assert rep["extra"] == {"quick": False, "timings_s": {"a": 1.0}}
    assert rep["study"] == "x" and rep["run_id"] == "r"


def test_every_writer_uses_one_schema(tmp_path):
    """The archive's own runs and the records commands write with run_info agree."""
    with RunArchive("alpha", {"k": 1}, root=tmp_path, seed=3) as a:
        pass
    archived = json.loads((a.path / "run.json").read_text())
    rec = finish_run_info(run_info("invert", command=["eroad", "invert"], seed=0), wall_s=1.5)
    write_run_json(tmp_path / "inv", rec) if (tmp_path / "inv").mkdir() is None else None
    written = json.loads((tmp_path / "inv" / "run.json").read_text())
    assert set(archived) == set(written) == SCHEMA_KEYS
    assert written["run_id"] == "inv" and written["status"] == "complete" and written["wall_s"] == 1.5
    assert archived["seed"] == 3 and archived["status"] == "complete"


def test_a_folder_without_run_json_is_listed_as_not_recorded(tmp_path):
    (tmp_path / "bench" / "old-run").mkdir(parents=True)
    (tmp_path / "bench" / "old-run" / "table.txt").write_text("x")
    (tmp_path / "sweep").mkdir()
    (tmp_path / "sweep" / "sweep.json").write_text("{}")
    recs = list_runs(tmp_path)
    assert sorted((r.study, r.run_id, r.status) for r in recs) == [
        ("bench", "old-run", "not recorded"), ("sweep", "sweep", "not recorded")]
    assert load_run(tmp_path / "bench" / "old-run").info["command"] == "not recorded"
