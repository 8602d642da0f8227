"""``eroad invert DIR1 DIR2 ... --out ROOT`` on Dask (inverse/batch.py): one archived run per
drive, one line per drive, a failing drive reported without stopping the others."""
import json

import pytest

from drives.synth import synth_command
from eroad.cli import main
from eroad.errors import EroadInputError
from inverse.batch import invert_many, one_line, run_folder_names


@pytest.fixture(scope="module")
def drives(tmp_path_factory):
    root = tmp_path_factory.mktemp("batch")
    for s in (1, 2):
        synth_command(scenario="null", seed=s, duration=6.0, out=root / f"d{s}")
    (root / "bad").mkdir()     # not a dataset: no meta.toml
    return root


def test_many_drives_on_a_local_cluster(drives, capsys):
    """Two tiny null drives and a broken one on a 2-worker LocalCluster: exit 1 (one failed),
    one line per drive plus a total, each good drive's run folder complete with its run.json,
    the broken one's run.json 'failed' with the reader's one-line error, batch.json listing all."""
    root = drives / "ROOT"
    code = main(["invert", str(drives / "d1"), str(drives / "d2"), str(drives / "bad"), "--out", str(root),
                 "--quick", "--fit", "linear", "--candidates", "1", "--max-iter", "1", "--segments", "2",
                 "--workers", "2"])
    out = capsys.readouterr().out.strip().splitlines()
    assert code == 1
    assert len(out) == 4, out
    assert sum("FAILED" in ln for ln in out) == 1 and any(ln.startswith(str(drives / "bad")) and "meta.toml" in ln
                                                          for ln in out)
    assert sum(": wrote " in ln for ln in out) == 2
    assert out[-1].startswith("2 of 3 drives inverted") and "1 failed" in out[-1]
    for n in ("d1", "d2"):
        rj = json.loads((root / n / "run.json").read_text())
        assert rj["status"] == "complete" and rj["study"] == "invert" and rj["run_id"] == n
        s = json.loads((root / n / "summary.json").read_text())
        assert len(s["segments"]) == 2 and s["timing"]["workers"] == 1
        assert (root / n / "figures" / "figure8_time_compare.png").is_file()
    bad = json.loads((root / "bad" / "run.json").read_text())
    assert bad["status"] == "failed" and "meta.toml" in bad["error"]["message"]
    b = json.loads((root / "batch.json").read_text())
    assert (b["n_complete"], b["n_failed"]) == (2, 1)
    assert [r["run"] for r in b["runs"]] == ["d1", "d2", "bad"]
    assert [r["status"] for r in b["runs"]] == ["complete", "complete", "failed"]


def test_batch_bad_input_is_one_line(drives, tmp_path, capsys):
    """Two datasets with one folder name, an unreachable scheduler, --json with several: exit 2,
    one line, no traceback."""
    (tmp_path / "x").mkdir()
    twin = tmp_path / "x" / "d1"
    twin.symlink_to(drives / "d2", target_is_directory=True)
    code = main(["invert", str(drives / "d1"), str(twin), "--out", str(tmp_path / "R1")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "collide" in err[0], err
    # an unreachable scheduler: one line (the CLI waits the sweeps' 20 s; 1 s here), nothing written
    with pytest.raises(EroadInputError, match="cannot connect"):
        invert_many([drives / "d1"], tmp_path / "R2", scheduler="tcp://127.0.0.1:9", connect_timeout=1.0)
    assert not (tmp_path / "R2").exists()
    # --json: the error as JSON on stdout (eroad.cli's convention)
    code = main(["invert", str(drives / "d1"), str(drives / "d2"), "--out", str(tmp_path / "R3"), "--json"])
    cap = capsys.readouterr()
    assert code == 2 and "batch.json" in cap.out and "Traceback" not in cap.out + cap.err
    assert not (tmp_path / "R1").exists() and not (tmp_path / "R3").exists()
    with pytest.raises(EroadInputError, match="collide"):
        run_folder_names(["a/d", "b/d"])
    with pytest.raises(EroadInputError, match="no dataset"):
        invert_many([], tmp_path / "R4")
    # --workers 0 or 1: serial, no Dask (the sweeps' convention); the broken drive is reported
    res = invert_many([drives / "bad"], tmp_path / "R5", n_workers=1)
    assert res[0]["status"] == "failed" and "meta.toml" in res[0]["error"]
    assert json.loads((tmp_path / "R5" / "batch.json").read_text())["scheduler"] == "serial (no Dask)"


def test_one_line():
    assert one_line(EroadInputError("x: bad\n  detail")) == "x: bad detail"
    assert one_line(ValueError("boom")) == "ValueError: boom"
