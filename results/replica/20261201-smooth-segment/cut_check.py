"""The smooth segment alone, replicas with three friction dampers, against the truth road (stop 71).

    python cut_check.py TRUTH_DATASET REPLICA_RUN [REPLICA_RUN ...]

Each REPLICA_RUN an `eroad replica` of the embedded drive cut to 460-472.6 s (`eroad data cut --window`).
Per run and side: the band-passed (0.5-20 m) correlation with the truth road (x origin found as in check.py),
the variance ratio and ln(replica PSD / truth PSD) per wavelength band, 5 m trimmed at each end."""
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import butter, filtfilt, welch

from roadlib.surface import RoadSurface


def main(ds, runs):
    road = RoadSurface.load(Path(ds) / "truth" / "road.npz")
    bands = ((20.0, 5.0), (5.0, 2.0), (2.0, 1.0), (1.0, 0.5))
    print("| replica run | side | corr (0.5-20 m) | var replica / truth | "
          + " | ".join(f"ln PSD {l:g}-{s:g} m" for l, s in bands) + " |")
    print("|---" * (4 + len(bands)) + "|")
    for run in runs:
        tr = pd.read_csv(Path(run) / "tracks.csv")
        x = tr["x_m"].to_numpy()
        dx = float(np.median(np.diff(x)))
        b, a = butter(2, [2 * dx / 20.0, 2 * dx / 0.5], "band")
        y = {"left": 1.02, "right": -1.02}
        zl = filtfilt(b, a, tr["z_left_m"].to_numpy())
        offs = np.arange(740.0, 760.0, 0.05)
        off = float(offs[int(np.argmax([np.corrcoef(zl, filtfilt(b, a, road.track(y["left"], o + x)))[0, 1]
                                         for o in offs]))])
        sel = (x >= x[0] + 5) & (x <= x[-1] - 5)
        for side in ("left", "right"):
            zr = tr[f"z_{side}_m"].to_numpy()
            zt = road.track(y[side], off + x)
            nps = min(1024, int(sel.sum()) // 2)
            fr, pr = welch(zr[sel] - zr[sel].mean(), fs=1 / dx, nperseg=nps)
            _, pt = welch(zt[sel] - zt[sel].mean(), fs=1 / dx, nperseg=nps)
            lr = [f"{np.log(pr[(fr >= 1 / l) & (fr < 1 / s)].mean() / pt[(fr >= 1 / l) & (fr < 1 / s)].mean()):+.2f}"
                  for l, s in bands]
            br, bt = filtfilt(b, a, zr)[sel], filtfilt(b, a, zt)[sel]
            print(f"| {Path(run).name} | {side} | {np.corrcoef(br, bt)[0, 1]:.3f} | {br.var() / bt.var():.2f} | "
                  + " | ".join(lr) + " |")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
