"""`eroad runs list` and `eroad runs show`."""
import json

from eroad.cli import main
from studies.runs import RunArchive


def _make_runs(root):
    with RunArchive("chassis", {"k": 1.0}, root=root, seed=3,
                    command=["eroad", "study", "chassis"]) as ok:
        ok.write_summary({"n_cases": 12, "bands": {"<0.5": 1e-3, "5-15": 2e-3},
                          "series": list(range(50))})
    try:
        with RunArchive("fig11", {}, root=root) as bad:
            raise ValueError("road missing")
    except ValueError:
        pass
    return ok, bad


def test_runs_list_table_and_json(tmp_path, capsys):
    ok, bad = _make_runs(tmp_path)
    assert main(["runs", "list", "--root", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split() == ["STUDY", "RUN-ID", "STATUS", "START", "(UTC)", "WALL"]
    assert lines[1].split()[:3] == ["chassis", ok.run_id, "complete"]
    assert lines[2].split()[:3] == ["fig11", bad.run_id, "failed"]
    assert main(["runs", "list", "--root", str(tmp_path), "--json", "--study", "fig11"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["run_id"] for r in rows] == [bad.run_id]
    assert main(["runs", "list", "--root", str(tmp_path / "none")]) == 0
    assert "no runs" in capsys.readouterr().out
    # the root may also be given as the positional argument a user tries first; two
    # different roots are refused in one line; a root that does not exist is said to
    assert main(["runs", "list", str(tmp_path), "--study", "fig11", "--json"]) == 0
    assert [r["run_id"] for r in json.loads(capsys.readouterr().out)] == [bad.run_id]
    assert main(["runs", "list", str(tmp_path / "none")]) == 0
    assert capsys.readouterr().out.strip().endswith("(no such folder)")
    assert main(["runs", "list", str(tmp_path), "--root", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "two results roots given" in err


def test_runs_show(tmp_path, capsys):
    ok, bad = _make_runs(tmp_path)
    assert main(["runs", "show", ok.run_id, "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "status" in out and "complete" in out and "eroad study chassis" in out
    assert "n_cases" in out and "bands.<0.5" in out and "[50 items]" in out
    assert main(["runs", "show", str(bad.path)]) == 0
    out = capsys.readouterr().out
    assert "ValueError: road missing" in out and "no summary.json" in out
    assert main(["runs", "show", ok.run_id, "--root", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["run"]["seed"] == 3 and data["summary"]["n_cases"] == 12


def test_runs_errors_are_one_line(tmp_path, capsys):
    assert main(["runs", "show", "nope", "--root", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("eroad: error: run 'nope'")
    assert main(["runs"]) == 2          # no action: usage
    assert "list" in capsys.readouterr().out
