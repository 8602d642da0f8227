"""Make a logger-style CSV from a measurement dataset (how examples/logger_drive.csv was made).

The file looks like what a data logger writes: semicolon-delimited, its own column names,
time in milliseconds, suspension displacements in mm, accelerations in g with gravity on
the body accelerations (+1 g at rest), speed in km/h, an unused temperature column, and
each sample taken at a time jittered by up to 0.1 % of the step (the value there is the
dataset's not-a-knot cubic spline at that time). ``eroad data import`` with
``examples/logger_map.toml`` turns it back into a dataset.

Usage::

    eroad synth --scenario luliang --seed 0 --duration 10 --out luliang-10s
    python examples/make_logger_example.py luliang-10s examples/logger_drive.csv --digits 6

``--digits`` rounds the values to that many significant digits (a logger's resolution;
the committed example uses 6 to stay small); left out, every digit is kept and the
import reproduces the dataset within 1e-6 of each channel's peak.
"""
from __future__ import annotations

import argparse

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from drives.format import read_drive

G = 9.80665
#: contract channel -> (logger column, factor, offset): logger value = SI value x factor + offset
COLUMNS = {
    "susp_disp_3L": ("Weg_HA3_li", 1000.0, 0.0),
    "susp_disp_3R": ("Weg_HA3_re", 1000.0, 0.0),
    "axle_acc_3L": ("aAchse_HA3_li", 1.0 / G, 0.0),
    "axle_acc_3R": ("aAchse_HA3_re", 1.0 / G, 0.0),
    "body_acc_3L": ("aRahmen_HA3_li", 1.0 / G, 1.0),
    "body_acc_3R": ("aRahmen_HA3_re", 1.0 / G, 1.0),
    "speed": ("v_kmh", 3.6, 0.0),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("dataset")
    ap.add_argument("out")
    ap.add_argument("--jitter", type=float, default=1e-3, help="relative time jitter (0.001)")
    ap.add_argument("--digits", type=int, default=None, help="significant digits of the values")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    d = read_drive(a.dataset)
    frame = d.to_dataframe()
    if "speed" not in frame:
        frame["speed"] = d.speed
    t = d.time
    e = np.random.default_rng(a.seed).uniform(-a.jitter, a.jitter, t.size) * d.dt
    e[0] = 0.0                                  # the logger's clock starts on its first sample
    tj = t + e
    out = {"Zeit_ms": tj * 1000.0}
    for name, (col, k, off) in COLUMNS.items():
        out[col] = CubicSpline(t, frame[name].to_numpy())(tj) * k + off
    out["Temp_C"] = np.round(21.0 + 0.1 * np.arange(t.size) / t.size, 2)
    df = pd.DataFrame(out)
    if a.digits is not None:                    # the values rounded; time kept to 0.1 us
        df["Zeit_ms"] = df["Zeit_ms"].map(lambda v: f"{v:.4f}")
        for c in df.columns[1:]:
            df[c] = df[c].map(lambda v: f"{v:.{a.digits}g}")
    df.to_csv(a.out, sep=";", index=False)


if __name__ == "__main__":
    main()
