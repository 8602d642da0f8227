"""``eroad reproduce``: the main command, end to end.

The full quick run (dataset -> Figures 4-5 -> inversion -> Figure 11 -> chassis study ->
diagnosis) takes 2-4 minutes, so it is a ``slow`` test; it checks that every paper
item is on disk as a valid file (not only that the manifest says so), not the science
(each package's own tests do that).  The default run checks a partial run of the first
two steps (about 5 s): the same on-disk validation for Figures 4-5, and that the
manifest reports every item of the steps not run as missing.
"""
import json
import re
from pathlib import Path

import numpy as np
import pytest

from eroad.cli import main

#: paper item -> (file pattern relative to the run folder, kind of file); written out from
#: the paper's list (studies/reproduce.py module docstring, docs/studies.md) rather than
#: taken from studies.reproduce.MANIFEST, so that a manifest that drops or renames an
#: item fails here
PAPER_ITEMS = {
    "Figure 4": ("fig4_5/figure4_displacement.png", "png"),
    "Figure 5": ("fig4_5/figure5_spectrum.png", "png"),
    "Figure 6": ("invert/figures/figure6_segmentation.png", "png"),
    "Table 1": ("invert/tables/table1.md", "md"),
    "Figure 8": ("invert/figures/figure8_time_compare.png", "png"),
    # issue 17: measured against simulated on the reconstructed road (axle 2 held out)
    "Figure 8 on the road replica": ("replica/figures/replica_time.png", "png"),
    "Figure 9": ("invert/figures/figure9_amplitude_distributions.png", "png"),
    "Table 2": ("invert/tables/table2.md", "md"),
    "Global road (section 2.5)": ("invert/road.*", "road"),     # .npz and .crg, as the manifest lists
    "Table 1, nominal vs corrected model": ("invert/tables/table1_nominal_vs_corrected.md", "md"),
    "Figure 11": ("figure11/figures/figure11.png", "png"),
    "Findings of section 5 (true/false)": ("figure11/data/findings.md", "md"),
    "Chassis-stiffness study": ("chassis/figures/*.png", "png"),
    "Sim-to-real gap diagnosis": ("diagnose/report.md", "md"),
}
#: items made only under a condition: the corrected inversion (and so its comparison
#: table) is run only when the diagnosis names an effect with confidence "clear"
#: (diagnosis.closed_loop)
CONDITIONAL = {"Table 1, nominal vs corrected model"}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def check_file(path: Path, kind: str) -> None:
    """Assert that ``path`` is a non-empty, readable file of its kind.

    png: PNG signature, decodes to an image of at least 200 x 200 pixels that is not one
    flat colour (a figure with nothing drawn); md: UTF-8 text with a heading or a
    markdown table holding at least one data row; road: a road surface that loads, with
    finite heights that are not all equal, on an increasing x grid."""
    assert path.is_file(), path
    data = path.read_bytes()
    assert len(data) > 0, path
    if kind == "png":
        import matplotlib.image as mpimg

        assert data[:8] == PNG_MAGIC, path
        img = mpimg.imread(path)
        assert img.ndim == 3 and img.shape[0] >= 200 and img.shape[1] >= 200, (path, img.shape)
        assert float(np.std(img[..., :3])) > 0.01, f"{path}: a blank image"
    elif kind == "md":
        text = data.decode("utf-8")
        lines = [ln for ln in text.splitlines() if ln.strip()]
        sep = [i for i, ln in enumerate(lines) if ln.startswith("|") and set(ln.replace("|", "").strip()) <= set("-: ")]
        assert text.lstrip().startswith("#") or sep, f"{path}: neither a heading nor a table"
        for i in sep:   # every table has a data row under its separator
            assert i + 1 < len(lines) and lines[i + 1].startswith("|"), f"{path}: empty table"
    elif kind == "road":
        from roadlib.surface import RoadSurface

        road = RoadSurface.load(path)
        assert np.all(np.isfinite(road.z)) and np.ptp(road.z) > 0, path
        assert np.all(np.diff(road.x) > 0) and road.length > 0, path
    else:  # pragma: no cover - a typo in PAPER_ITEMS
        raise ValueError(kind)


def files_on_disk(run: Path, pattern: str) -> list[str]:
    return sorted(str(p.relative_to(run)) for p in run.glob(pattern))


def check_manifest_matches_disk(run: Path, manifest: dict) -> None:
    """Every manifest row names only existing, non-empty files and is ``present`` exactly
    when it names some; the paper's items are all listed (items the manifest adds beyond
    PAPER_ITEMS are held to the same truthfulness)."""
    missing = set(PAPER_ITEMS) - set(manifest)
    assert not missing, f"paper items not in the manifest: {sorted(missing)}"
    for item, row in manifest.items():
        for f in row["files"]:
            assert (run / f).is_file() and (run / f).stat().st_size > 0, (item, f)
        assert row["present"] is bool(row["files"]), item


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


@pytest.fixture(scope="module")
def partial_run(tmp_path_factory):
    """``eroad reproduce --steps dataset,fig4_5`` (about 5 s)."""
    out = tmp_path_factory.mktemp("reproduce") / "run"
    assert main(["reproduce", "--out", str(out), "--steps", "dataset,fig4_5", "--json"]) == 0
    return out


def test_partial_reproduce_files_and_manifest(partial_run):
    """The steps run produce Figures 4-5 as valid PNGs on disk; the manifest lists exactly
    those files for them, marks them present, and marks every item of the steps not run
    missing, with no file on disk (the manifest neither drops nor invents an item)."""
    out = partial_run
    manifest = {row["item"]: row for row in json.loads((out / "manifest.json").read_text())}
    check_manifest_matches_disk(out, manifest)
    for item, (pattern, kind) in PAPER_ITEMS.items():
        on_disk = files_on_disk(out, pattern)
        assert manifest[item]["files"] == on_disk, item
        if item in ("Figure 4", "Figure 5"):
            assert len(on_disk) == 1 and manifest[item]["present"] is True, item
            check_file(out / on_disk[0], kind)
        else:
            assert on_disk == [] and manifest[item]["present"] is False, item
    others = [r for item, r in manifest.items() if item not in ("Figure 4", "Figure 5")]
    assert not any(r["present"] for r in others)
    md = (out / "manifest.md").read_text()
    assert md.count("**missing**") == len(manifest) - 2
    rj = json.loads((out / "run.json").read_text())
    assert rj["status"] == "complete"
    # the archive's fields, so `eroad runs show` prints no None for this run
    assert rj["start_utc"] and rj["end_utc"] and rj["host"]["hostname"] and rj["seed"] is not None


def test_recorded_paths_point_into_the_final_folder(partial_run):
    """Steps record the dataset path they were given; after the temporary run folder is
    renamed into place, those records name the dataset relative to the run (so they hold
    when the run is moved or committed), never the vanished temporary folder."""
    out = partial_run
    texts = {p: p.read_text() for p in out.rglob("*.json") if p.name != "run.json"}
    assert not any(".run.tmp-" in t for t in texts.values())
    assert not any(str(out.resolve()) in t for t in texts.values())
    rel = [(p, m) for p, t in texts.items() for m in re.findall(r'"(\.{1,2}/dataset)"', t)]
    assert rel, "no record of the dataset path"
    for p, m in rel:    # relative to the run folder (the nearest folder up holding run.json)
        run = next(d for d in p.parents if (d / "run.json").is_file())
        assert (run / m / "channels.csv").is_file(), (p, m)


@pytest.mark.slow
def test_quick_reproduce_produces_every_paper_item(tmp_path):
    """Every paper item is on disk after the quick run, as a valid file of its kind
    (:func:`check_file`), independently of the manifest's ``present`` flag; the
    conditional comparison table exactly when the run's diagnosis names an effect the closed
    loop takes (clear or identified);
    and the manifest agrees with the disk."""
    out = tmp_path / "run"
    assert main(["reproduce", "--quick", "--out", str(out), "--json"]) == 0
    manifest = {row["item"]: row for row in json.loads((out / "manifest.json").read_text())}
    check_manifest_matches_disk(out, manifest)
    diag = json.loads((out / "diagnose" / "summary.json").read_text())
    # corrected when the closed loop takes the verdict's effect: 'clear', or identified
    # (diagnosis.closed_loop.effects_from_diagnosis, the rule the run itself applies)
    from diagnosis.closed_loop import effects_from_diagnosis
    corrected = bool(effects_from_diagnosis(diag)[0])
    for item, (pattern, kind) in PAPER_ITEMS.items():
        on_disk = files_on_disk(out, pattern)
        assert manifest[item]["files"] == on_disk, item
        if item in CONDITIONAL and not corrected:
            assert on_disk == [] and manifest[item]["present"] is False, item
            continue
        assert on_disk, f"{item}: no {pattern} in the run"
        for f in on_disk:
            check_file(out / f, kind)
        assert manifest[item]["present"] is True, item
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "complete"
    # nothing of the synthetic truth is copied into the run
    assert not (out / "dataset" / "truth").exists()


def test_figures_4_5_show_the_window_in_its_record(partial_run):
    """Figures 4-5 are drawn from the whole record (dataset/record/, minutes long) with the
    460-490 s window marked; the dataset the inversion reads is the window alone."""
    from drives.format import read_drive

    s = json.loads((partial_run / "summary.json").read_text())["steps"]["fig4_5"]
    assert s["window_s"] == [460.0, 490.0]
    assert s["welch_averages"]["record"] > 3 * s["welch_averages"]["window"]
    assert s["rms_record"] != s["rms_window"]
    win = read_drive(partial_run / "dataset")
    rec = read_drive(partial_run / "dataset" / "record")
    assert (win.time[0], win.duration_s) == (460.0, 30.0)
    assert rec.duration_s >= 120.0 and rec.time[0] < 460.0 and rec.time[-1] >= 490.0


def test_copied_diagnosis_records_the_dataset_relative_to_its_new_folder(tmp_path):
    """reproduce copies invert/diagnose to diagnose/: the dataset path it records must
    point at RUN/dataset from the new folder (it was one level off)."""
    import json

    from studies.reproduce import rebase_diagnosis

    run = tmp_path / "run"
    src = run / "invert" / "diagnose"
    src.mkdir(parents=True)
    (run / "dataset").mkdir()
    (src / "summary.json").write_text(json.dumps({"meta": {"dataset": "../../dataset"}}))
    (src / "report.md").write_text("# x\n- dataset: `../../dataset`\n")
    import shutil

    dst = run / "diagnose"
    shutil.copytree(src, dst)
    rebase_diagnosis(dst, src, run / "dataset")
    assert json.loads((dst / "summary.json").read_text())["meta"]["dataset"] == "../dataset"
    assert "- dataset: `../dataset`" in (dst / "report.md").read_text()
    assert (dst / json.loads((dst / "summary.json").read_text())["meta"]["dataset"]).resolve() \
        == (run / "dataset").resolve()


def test_the_manifest_carries_the_replicas_warnings(tmp_path):
    """A warning of the replica's linear model (a friction damper too soft for a quiet stretch) is
    put at the top of the manifest, where a user of `eroad reproduce` starts (stop 71)."""
    from studies.reproduce import _manifest_md, _replica_warnings

    assert _replica_warnings(tmp_path) == []
    (tmp_path / "replica").mkdir()
    notes = ["leaf_friction 2221 N statistically linearised: ...",
             "WARNING: one friction damper serves the whole drive, but on 460-465 s ..."]
    (tmp_path / "replica" / "summary.json").write_text(json.dumps({"linear_model": {"notes": notes}}))
    ws = _replica_warnings(tmp_path)
    assert ws == ["one friction damper serves the whole drive, but on 460-465 s ..."]
    md = _manifest_md([], {}, None, None, ws)
    assert "**Road replica:** one friction damper serves the whole drive" in md
    assert md.index("Road replica:") < md.index("| paper item |")
    assert "Road replica:" not in _manifest_md([], {}, None, None)
