"""drives.rate: a record above 400 Hz is brought to 200 Hz before the road methods see it.

References: sines of known frequency (what lies below 60 Hz must come through unchanged,
what lies above the new Nyquist frequency must not alias into the record), and the road
methods' own answer at the logger's 200 Hz: the same drive logged at 1 kHz must give it too.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drives.format import read_drive, write_drive
from drives.rate import TARGET_HZ, for_road_methods
from eroad.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _drive(tmp_path, fs, f_keep=10.0, f_alias=310.0):
    t = 5.0 + np.arange(int(8 * fs)) / fs
    df = pd.DataFrame({"time": t,
                       "axle_acc_3L": np.sin(2 * np.pi * f_keep * t) + 0.5 * np.sin(2 * np.pi * f_alias * t) + 3.0,
                       "speed": 9.0 + 0.1 * t})
    return read_drive(write_drive(tmp_path / f"d{fs:g}", df, {"vehicle": "dump_truck_8x4"}))


def test_fast_record_is_resampled_without_aliasing(tmp_path):
    """1 kHz -> 200 Hz: the 10 Hz sine within 0.5 % in amplitude and phase (away from the ends,
    where the FIR has its transient), the 310 Hz sine (it would alias to 110 -> 90 Hz) below
    1 % of its amplitude, the mean kept, speed interpolated, record time kept."""
    d = _drive(tmp_path, 1000.0)
    r, note = for_road_methods(d)
    assert note["from_hz"] == pytest.approx(1000.0) and r.sample_rate_hz == TARGET_HZ
    assert r.time[0] == d.time[0] and np.allclose(np.diff(r.time), 1 / TARGET_HZ)
    x = r.channels["axle_acc_3L"].to_numpy()
    mid = slice(100, -100)
    ref = np.sin(2 * np.pi * 10.0 * r.time) + 3.0
    assert np.max(np.abs(x[mid] - ref[mid])) < 0.01          # 10 Hz through, 310 Hz gone
    assert np.allclose(r.speed, 9.0 + 0.1 * r.time)


def test_slow_record_is_left_alone(tmp_path):
    d = _drive(tmp_path, 200.0, f_alias=60.0)
    r, note = for_road_methods(d)
    assert note is None and r is d


def test_invert_on_a_1khz_logger_gives_the_200hz_answer(tmp_path, capsys):
    """The README's worked example imported at the logger's 200 Hz and at 1 kHz (cubic, from the
    same logger file): the inversion ran into 'dt exceeds the output period' at 1 kHz before
    2026-11-26; now both give the same segmentation and classes."""
    classes = {}
    for rate in (200, 1000):
        ds = tmp_path / f"r{rate}"
        assert main(["data", "import", str(ROOT / "examples" / "logger_drive.csv"), "--map",
                     str(ROOT / "examples" / "logger_map.toml"), "--out", str(ds), "--rate", str(rate)]) == 0
        out = tmp_path / f"inv{rate}"
        assert main(["invert", str(ds), "--out", str(out), "--quick", "--quiet"]) == 0
        s = json.loads((out / "summary.json").read_text())
        classes[rate] = [g["class"] for g in s["segments"]]
        assert (s["dataset"]["resampled"] or {}).get("from_hz") == (1000.0 if rate == 1000 else None)
    capsys.readouterr()
    assert classes[1000] == classes[200], classes
