"""Is the replica short of the truth at short waves, or is the comparison? (stop 74)

    python check_lines.py REPRODUCE_RUN TRUTH_DATASET

Stop 71's check (`../20261201-smooth-segment/check.py`) scores the replica's SIDE track (tracks.csv
`z_left_m`: the mean of the road under that side's six tyres, `inverse.replica.side_tracks`) against the
truth's road on ONE line (the front tyres', |y| = 1.02 m).  Where a side's tyre lines are little coherent
(below about 1 m of wavelength) a mean of lines has less power than any one of them, so that comparison
reads a shortfall even for a perfect replica.  Here, per inversion segment and side, in wavelength bands:

  * `line`: each of the replica's own tyre lines (columns `z_<side>_y<|y|>_m`) against the truth on that
    line (the like-for-like comparison of the estimate);
  * `side`: the replica's side track against the truth's side track made the same way (every tyre of the
    side counted once, so a dual pair weighs twice);
  * `stop 71`: the replica's side track against the truth's front line (what check.py reported).

The x origin is found as check.py finds it (band-passed correlation of the left front line).
"""
import json
import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import butter, filtfilt, welch

from roadlib.surface import RoadSurface
from vehicles.linear import linear_model

BANDS = ((20.0, 5.0), (5.0, 2.0), (2.0, 1.0), (1.0, 0.5))


def ln_ratios(zr, zt, dx, nper):
    fr, pr = welch(zr - zr.mean(), fs=1 / dx, nperseg=nper)
    _, pt = welch(zt - zt.mean(), fs=1 / dx, nperseg=nper)
    out = []
    for lo, sh in BANDS:
        m = (fr >= 1 / lo) & (fr < 1 / sh)
        out.append(float(np.log(pr[m].mean() / pt[m].mean())))
    return out


def main(run, ds):
    run, ds = Path(run), Path(ds)
    tr = pd.read_csv(run / "replica" / "tracks.csv")
    x = tr["x_m"].to_numpy()
    dx = float(np.median(np.diff(x)))
    road = RoadSurface.load(ds / "truth" / "road.npz")
    lines = {}
    for c in tr.columns:
        m = re.fullmatch(r"z_(L|R)_y([0-9.]+)_m", c)
        if m:
            lines.setdefault({"L": "left", "R": "right"}[m.group(1)], []).append((float(m.group(2)), c))
    b, a = butter(2, [2 * dx / 20.0, 2 * dx / 0.5], "band")
    sign = {"left": 1.0, "right": -1.0}
    front = dict(lines["left"])
    y_front = min(front, key=lambda y: abs(y - 1.02))
    zl = filtfilt(b, a, tr[front[y_front]].to_numpy())
    offs = np.arange(740.0, 760.0, 0.05)
    cs = [np.corrcoef(zl, filtfilt(b, a, road.track(y_front, o + x)))[0, 1] for o in offs]
    off = float(offs[int(np.argmax(cs))])
    print(f"x origin at truth x = {off:.2f} m (corr {max(cs):.3f}); tyre lines: "
          + ", ".join(f"{s} {y:g} m" for s in lines for y, _ in lines[s]))
    # every tyre of the truck once: the side track's weights (a dual pair counts twice)
    from drives.format import read_drive

    lm = linear_model(read_drive(ds).vehicle)
    tyres = {"left": [abs(c["y"]) for c in lm.contacts if c["side"] == "L"],
             "right": [abs(c["y"]) for c in lm.contacts if c["side"] == "R"]}
    rep_seg = json.loads((run / "replica" / "summary.json").read_text()).get("against_inversion", {})
    print("| segment | side | comparison | " + " | ".join(f"ln PSD {lo:g}-{sh:g} m" for lo, sh in BANDS) + " |")
    print("|---" * (3 + len(BANDS)) + "|")
    rows = []
    for s in rep_seg.get("segments", []):
        sel = (x >= s["x_start"] + 5) & (x <= s["x_end"] - 5)
        nper = min(1024, sel.sum() // 2)
        for side in ("left", "right"):
            truth_line = {y: road.track(sign[side] * y, off + x)[sel] for y, _ in lines[side]}
            for y, col in lines[side]:
                r = ln_ratios(tr[col].to_numpy()[sel], truth_line[y], dx, nper)
                rows.append(("line", r))
                print(f"| {s['segment']} | {side} | line y {y:g} m | " + " | ".join(f"{v:+.2f}" for v in r) + " |")
            ts = np.mean([truth_line[min(truth_line, key=lambda yy: abs(yy - t))] for t in tyres[side]], axis=0)
            zs = tr[f"z_{side}_m"].to_numpy()[sel]
            r = ln_ratios(zs, ts, dx, nper)
            rows.append(("side", r))
            print(f"| {s['segment']} | {side} | side track vs truth side track | " + " | ".join(f"{v:+.2f}" for v in r) + " |")
            r = ln_ratios(zs, road.track(sign[side] * 1.02, off + x)[sel], dx, nper)
            rows.append(("stop71", r))
            print(f"| {s['segment']} | {side} | side track vs truth front line (stop 71) | "
                  + " | ".join(f"{v:+.2f}" for v in r) + " |")
    # the replica against the inversion's fitted PSD (summary.json against_inversion averages every line's
    # periodogram): the same computation on each line position alone, both sides' periodograms averaged
    from roadlib.metrics import profile_psd
    from inverse.replica import inversion_segment_psd

    inv = json.loads((run / "invert" / "summary.json").read_text())["segments"]
    print("\nreplica / inversion fit, mean ln ratio over the segment's band within 0.5-20 m (as against_inversion):")
    print("| segment | every line (summary.json) | " + " | ".join(f"lines at {y:g} m" for y, _ in lines["left"]) + " |")
    print("|---" * (2 + len(lines["left"])) + "|")
    for k, s in enumerate(rep_seg.get("segments", [])):
        seg = inv[s["segment"] - 1]
        sel = (x >= s["x_start"]) & (x <= s["x_end"])
        nper = int(2 ** np.floor(np.log2(max(32, sel.sum() // 4))))
        lo, hi = max(1 / 20.0, seg.get("nmin", 0.0)), min(1 / 0.5, seg.get("nmax", np.inf))
        out = []
        for y, _ in lines["left"]:
            cols = [c for side in ("left", "right") for yy, c in lines[side] if abs(yy - y) < 1e-6]
            est = profile_psd(np.stack([tr[c].to_numpy()[sel] for c in cols], axis=1), dx, nperseg=nper)
            n, G = est.n[1:], est.G[1:]
            m = (n >= lo) & (n <= hi)
            out.append(float(np.mean(np.log(G[m] / inversion_segment_psd(seg, n)[m]))))
        print(f"| {s['segment']} | {s['ln_ratio']:+.2f} | " + " | ".join(f"{v:+.2f}" for v in out) + " |")
    print("\nmedian over segments and sides / lines:")
    for kind in ("line", "side", "stop71"):
        R = np.array([r for k, r in rows if k == kind])
        print(f"  {kind:7s} " + "  ".join(f"{lo:g}-{sh:g} m: {v:+.2f}" for (lo, sh), v in zip(BANDS, np.median(R, axis=0))))


if __name__ == "__main__":
    main(*sys.argv[1:3])
