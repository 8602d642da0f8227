"""``eroad reproduce``: the main command, end to end in its quick mode.

The quick run is the CI smoke test of the whole chain (dataset -> Figures 4-5 ->
inversion -> Figure 11 -> chassis study -> diagnosis); it checks that every paper
item of the manifest is produced, not the science (each package's own tests do
that).
"""
import json

import pytest

from eroad.cli import main


def test_unknown_step_refused(tmp_path, capsys):
    assert main(["reproduce", "--out", str(tmp_path / "r"), "--steps", "dataset,nope"]) == 2
    err = capsys.readouterr().err
    assert "unknown step(s) nope" in err
    assert not (tmp_path / "r").exists()


def test_existing_output_is_not_touched(tmp_path, capsys):
    out = tmp_path / "r"
    out.mkdir()
    (out / "precious.txt").write_text("keep me")
    assert main(["reproduce", "--out", str(out), "--steps", "dataset"]) == 2
    assert "exists and is not empty" in capsys.readouterr().err
    assert (out / "precious.txt").read_text() == "keep me"


def test_quick_reproduce_produces_every_paper_item(tmp_path):
    out = tmp_path / "run"
    assert main(["reproduce", "--quick", "--out", str(out), "--json"]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    missing = [row["item"] for row in manifest if not row["present"]]
    assert missing == []
    for row in manifest:
        for f in row["files"]:
            assert (out / f).stat().st_size > 0, f
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "complete"
    # nothing of the synthetic truth is copied into the run
    assert not (out / "dataset" / "truth").exists()


def test_recorded_paths_point_into_the_final_folder(tmp_path):
    """Steps record the dataset path they were given; after the temporary run folder is
    renamed into place, those records must name the final folder, not the vanished one."""
    out = tmp_path / "run"
    assert main(["reproduce", "--out", str(out), "--steps", "dataset,fig4_5", "--json"]) == 0
    texts = [p.read_text() for p in out.rglob("*.json")]
    assert not any(".run.tmp-" in t for t in texts)
    assert any(str(out.resolve()) in t for t in texts)
