"""A drive logged on another axle than axle 3 (a logger on the front axle is the usual case):
``eroad invert`` fits that axle, ``eroad replica`` runs without a held-out axle, and a record
without one axle's two suspension displacements is refused with one line.

Before 2026-11-27 both commands stopped: "eroad invert needs column(s) susp_disp_3L,
susp_disp_3R" and, for the replica, "--holdout 2: the drive has no channels of axle 2" after
the whole reconstruction.

The truth is the independently written truck (``drives/independent_truck.py``), so the check
that axle 1 and axle 3 find the same road is made on data our Exudyn model did not make.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from eroad.cli import main


def _keep_axles(src: Path, dst: Path, axles, sides="LR") -> Path:
    """A copy of dataset ``src`` with only the wheel-station channels of ``axles`` (and speed)."""
    if dst.exists():
        return dst
    dst.mkdir(parents=True)
    df = pd.read_csv(src / "channels.csv")
    keep = ["time"] + [c for c in df.columns if c[-1] in sides and c[-2:-1].isdigit()
                       and int(c[-2]) in axles] + ["speed"]
    df[keep].to_csv(dst / "channels.csv", index=False)
    (dst / "meta.toml").write_text((src / "meta.toml").read_text())
    return dst


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    root = tmp_path_factory.mktemp("other-axle")
    full = root / "full"
    assert main(["synth", "--scenario", "second", "--seed", "3", "--duration", "20", "--out", str(full)]) == 0
    return root, full


def _invert(ds: Path, out: Path, channels: str | None = None) -> dict:
    extra = ["--channels", channels] if channels else []
    assert main(["invert", str(ds), "--out", str(out), "--quick", "--segments", "1"] + extra) == 0
    return json.loads((out / "summary.json").read_text())


def test_front_axle_drive_is_inverted_on_axle_1_and_finds_axle_3s_road(drive, capsys):
    root, full = drive
    s1 = _invert(_keep_axles(full, root / "axle1", [1]), root / "inv1")
    s3 = _invert(_keep_axles(full, root / "axle3", [3]), root / "inv3")
    out = capsys.readouterr().out
    assert "axle_acc_1L RMS err" in out
    assert s1["fit"]["reference_axle"] == 1 and s1["fit"]["channel_set"] == "axle1"
    # axle 1's intervals are the axle-3 constants, checked on blind drives fitted on axle 1
    assert s1["fit"]["uncertainty_calibration"] == "linear/axle1" and s1["fit"]["uncertainty_calibrated_for_channels"]
    assert [r["channel"] for r in s1["table2"]][0] == "axle_acc_1L"
    note = (root / "inv1" / "tables" / "table1.md").read_text()
    assert "axle 1" in note and "calibrated for them" in note
    assert "not comparable" in (root / "inv1" / "tables" / "table2.md").read_text()
    assert s3["fit"]["reference_axle"] == 3 and s3["fit"]["uncertainty_calibrated_for_channels"]
    # The two axles drove the same road 5 m apart, and their models differ (axle 1 steered, lighter
    # unsprung mass and wheel load): one level for the whole 20 s drive from each must agree.
    # Tolerance 0.3 in ln G (35 %) at the pair's common best-seen frequency: about 6x the
    # noise-only Laplace sd of the difference (0.037 per fit), well inside the reported 90 %
    # intervals (sd 0.7-0.9 here: one segment over a road of five carries a large misfit and the
    # open model-form term, so they would not catch a wrong axle model); measured difference 0.06.
    a, b = s1["segments"][0], s3["segments"][0]
    n = math.sqrt(a["n_best"] * b["n_best"])

    def lnG(seg):
        return math.log(seg["Gq_n0"] * (n / 0.1) ** (-seg["w"]))
    assert abs(lnG(a) - lnG(b)) <= 0.3, (lnG(a), lnG(b))


def test_an_unchecked_channel_list_says_its_intervals_were_not_checked(drive):
    # axles 1, 2 and 4 alone were checked on blind drives (results/inverse_blind/
    # 20261127-axle1-logger/, .../20261127-axles-2-4-logger/); a hand-made list was not
    root, full = drive
    s2 = _invert(_keep_axles(full, root / "axle2", [2]), root / "inv2")
    assert s2["fit"]["channel_set"] == "axle2" and s2["fit"]["uncertainty_calibrated_for_channels"]
    assert s2["fit"]["uncertainty_calibration"] == "linear/axle2"
    sc = _invert(root / "axle2", root / "invc", channels="susp_disp_2L,susp_disp_2R,axle_acc_2L")
    assert sc["fit"]["channel_set"] == "custom" and not sc["fit"]["uncertainty_calibrated_for_channels"]
    assert "not checked on blind drives" in (root / "invc" / "tables" / "table1.md").read_text()


def test_one_side_only_is_refused_with_one_line(drive, capsys):
    root, full = drive
    ds = _keep_axles(full, root / "left", [1, 3], sides="L")
    assert main(["invert", str(ds), "--out", str(root / "invL"), "--quick"]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "both sides of one axle" in err[0] and "channels.csv" in err[0]
    assert "Traceback" not in err[0] and not (root / "invL").exists()


def test_replica_of_a_one_axle_drive_says_nothing_was_held_out(drive, capsys):
    root, full = drive
    ds = _keep_axles(full, root / "axle1", [1])
    assert main(["replica", str(ds), "--out", str(root / "rep1")]) == 0
    s = json.loads((root / "rep1" / "summary.json").read_text())
    assert s["holdout"]["axle"] is None and "logs one axle" in s["holdout"]["note"]
    assert "no axle held out" in capsys.readouterr().out
    # an axle asked for that is not there: refused at once, nothing written
    assert main(["replica", str(ds), "--out", str(root / "rep2"), "--holdout", "2"]) != 0
    assert "axles logged: 1" in capsys.readouterr().err and not (root / "rep2").exists()


def test_axle_1_and_axle_3_put_a_road_change_at_one_place(drive):
    """Two segments from each axle: axle 1 meets the road change about 5 m / v earlier (0.45 s
    here), and both fits place it at the same distance along the road (measured 0.57 m apart;
    tolerance 2 m, about two boundary blocks at this speed; a fit laid out as if axle 3 had
    made axle 1's times puts it 5 m off)."""
    root, full = drive
    out = {}
    for a in (1, 3):
        ds = _keep_axles(full, root / f"axle{a}", [a])
        assert main(["invert", str(ds), "--out", str(root / f"seg2-{a}"), "--quick", "--segments", "2"]) == 0
        out[a] = json.loads((root / f"seg2-{a}" / "summary.json").read_text())
    t1, t3 = out[1]["segments"][0]["t_end"], out[3]["segments"][0]["t_end"]
    assert 0.2 < t3 - t1 < 0.8
    x1, x3 = out[1]["road"]["seg_lengths_m"][0], out[3]["road"]["seg_lengths_m"][0]
    assert abs(x1 - x3) < 2.0, (x1, x3)
