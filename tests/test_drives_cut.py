"""``eroad data cut``: a dataset cut to a window or to its moving stretches (drives.cut).

Reference: a drive written here with a known speed profile (rest, a 2 s crawl, a 6 s
stretch, a stop, a 2.5 s stretch, a stop, an 8 s stretch), so every piece's time span is
known exactly; the pieces must hold the source's rows unchanged, and the source must be
left as it was.
"""
from __future__ import annotations

import hashlib

import numpy as np
import pandas as pd
import pytest

from drives.cut import cut_dataset, runs_above, slow_stretches
from drives.format import read_drive, write_drive
from eroad.cli import main
from eroad.errors import EroadInputError

FS = 100.0


def _tree_hash(folder):
    h = hashlib.sha256()
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


@pytest.fixture()
def stop_drive(tmp_path):
    """30 s at 100 Hz from t = 100 s: speed 0 (0-1 s), 0.3 (1-3 s: a crawl), 9 (3-9 s), 0
    (9-12 s), 8 (12-14.5 s: too short), 0 (14.5-16 s), 10 (16-24 s), 0 after."""
    t = 100.0 + np.arange(3000) / FS
    r = t - 100.0
    v = np.select([r < 1, r < 3, r < 9, r < 12, r < 14.5, r < 16, r < 24], [0.0, 0.3, 9.0, 0.0, 8.0, 0.0, 10.0], 0.0)
    rng = np.random.default_rng(0)
    df = pd.DataFrame({"time": t, "susp_disp_3L": 0.01 * rng.standard_normal(t.size),
                       "axle_acc_3L": rng.standard_normal(t.size), "speed": v})
    src = write_drive(tmp_path / "src", df, {"vehicle": "dump_truck_8x4", "start_time_s": 100.0})
    return src


def test_runs_and_slow_stretches():
    v = np.array([0, 1, 1, 0, 0, 2, 2, 2, 0.5])
    assert runs_above(v, 0.5) == [(1, 3), (5, 8)]
    t = np.arange(v.size) * 0.5
    assert slow_stretches(t, v) == "0.00-0.00 s, 1.50-2.00 s, 4.00-4.00 s"


def test_moving_writes_each_stretch_with_the_source_rows(stop_drive, tmp_path):
    before = _tree_hash(stop_drive)
    s = cut_dataset(stop_drive, tmp_path / "moving", moving=True)
    assert _tree_hash(stop_drive) == before                      # the source is only read
    spans = [(p["t_start_s"], p["t_end_s"]) for p in s["pieces"]]
    assert spans == [(103.0, 108.99), (116.0, 123.99)]           # the crawl and the 2.5 s stretch go
    assert [(d["t_start_s"], d["t_end_s"]) for d in s["dropped"]] == [(112.0, 114.49)]
    assert s["slow_s"] == pytest.approx(30.0 - (6.0 + 2.5 + 8.0), abs=1e-9)  # the crawl is slow, the 2.5 s stretch not
    src = read_drive(stop_drive)
    for k, (t0, t1) in enumerate(spans, start=1):
        part = read_drive(tmp_path / "moving" / f"part{k:02d}")
        sel = (src.time >= t0 - 1e-9) & (src.time <= t1 + 1e-9)
        assert np.array_equal(part.time, src.time[sel]) and np.array_equal(part.speed, src.speed[sel])
        assert np.array_equal(part.channels.to_numpy(), src.channels.loc[sel].to_numpy())
        assert part.meta["start_time_s"] == t0 and part.meta["cut_window_s"] == [t0, t1]
        assert part.vehicle == "dump_truck_8x4" and np.min(part.speed) > 0.5


def test_window_and_moving_together_and_a_window_alone(stop_drive, tmp_path):
    s = cut_dataset(stop_drive, tmp_path / "w", window=(105.0, 120.0), moving=True)
    assert [(p["t_start_s"], p["t_end_s"]) for p in s["pieces"]] == [(105.0, 108.99), (116.0, 120.0)]
    one = cut_dataset(stop_drive, tmp_path / "one", window=(104.0, 106.0))
    d = read_drive(tmp_path / "one")
    assert one["pieces"][0]["folder"] == str(tmp_path / "one") and d.time[0] == 104.0 and d.time[-1] == 106.0


def test_refusals_are_one_line_and_write_nothing(stop_drive, tmp_path, capsys):
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "keep.txt").write_text("mine")
    with pytest.raises(EroadInputError, match="exists and is not empty"):
        cut_dataset(stop_drive, tmp_path / "busy", moving=True)
    assert (tmp_path / "busy" / "keep.txt").read_text() == "mine"
    with pytest.raises(EroadInputError, match=r"no stretch of at least 3 s .* in 100-102.5 s"):
        cut_dataset(stop_drive, tmp_path / "none", window=(100.0, 102.5), moving=True)
    assert not (tmp_path / "none").exists()
    with pytest.raises(EroadInputError, match="outside the source"):
        cut_dataset(stop_drive, stop_drive / "parts", moving=True)
    assert main(["data", "cut", str(stop_drive), "--out", str(tmp_path / "x")]) == 2
    assert main(["data", "cut", str(stop_drive), "--moving", "--min-speed", "0", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "give --window T0 T1, --moving, or both" in err and "Traceback" not in err
    assert not (tmp_path / "x").exists()


def test_road_methods_on_a_drive_with_stops_name_them_and_the_cut(stop_drive, tmp_path, capsys):
    """invert, diagnose and replica refuse a drive with stops in one line naming the slow
    stretches and the command that cuts it."""
    df = pd.read_csv(stop_drive / "channels.csv")
    df["susp_disp_3R"], df["axle_acc_3R"] = df["susp_disp_3L"], df["axle_acc_3L"]
    src = write_drive(tmp_path / "both", df, {"vehicle": "dump_truck_8x4"})
    assert main(["invert", str(src), "--out", str(tmp_path / "run"), "--quick"]) == 2
    err = capsys.readouterr().err
    assert "needs a moving vehicle" in err and "100.00-102.99 s, 109.00-111.99 s" in err
    assert f"eroad data cut {src} --moving --out DIR" in err and not (tmp_path / "run").exists()
    for cmd in ("diagnose", "replica"):
        assert main([cmd, str(src), "--out", str(tmp_path / cmd)]) == 2
        err = capsys.readouterr().err
        assert f"eroad {cmd} needs a moving vehicle" in err and "eroad data cut" in err, err


def test_road_methods_refuse_a_record_too_short_in_one_line(tmp_path, capsys):
    """A moving record shorter than ``MIN_DURATION`` (3 s, the shortest stretch ``eroad data
    cut`` keeps): invert, diagnose and replica each say so in one line, exit 2 and write no run
    folder (a 0.25 s record used to stop in the segmentation with a traceback).  A record of
    exactly 3 s passes this check (it inverts and diagnoses, measured on a blind drive cut to
    3 s)."""
    from drives.cut import MIN_DURATION, require_road_record

    t = np.arange(25) / FS                       # 0.24 s
    rng = np.random.default_rng(1)
    df = pd.DataFrame({"time": t, "susp_disp_3L": 0.01 * rng.standard_normal(t.size),
                       "susp_disp_3R": 0.01 * rng.standard_normal(t.size),
                       "axle_acc_3L": rng.standard_normal(t.size),
                       "axle_acc_3R": rng.standard_normal(t.size), "speed": np.full(t.size, 10.0)})
    src = write_drive(tmp_path / "short", df, {"vehicle": "dump_truck_8x4"})
    for cmd in ("invert", "diagnose", "replica"):
        assert main([cmd, str(src), "--out", str(tmp_path / cmd)]) == 2
        err = capsys.readouterr().err
        assert f"eroad {cmd} needs at least 3 s of record; this one holds 0.24 s (25 samples)" in err
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / cmd).exists()
    t3 = np.arange(int(MIN_DURATION * FS) + 1) / FS
    df3 = pd.DataFrame({"time": t3, "axle_acc_3L": np.zeros(t3.size), "speed": np.full(t3.size, 10.0)})
    require_road_record(read_drive(write_drive(tmp_path / "three", df3, {"vehicle": "dump_truck_8x4"})),
                        "eroad invert")
