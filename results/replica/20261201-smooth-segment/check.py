"""The embedded drive's replica against its truth road, per segment and wavelength band (stop 71).

    python check.py REPRODUCE_RUN TRUTH_DATASET      # e.g. out/reproduce ~/.cache/eroad/datasets/luliang-seed0-*

REPRODUCE_RUN: an `eroad reproduce` output (its replica/tracks.csv and invert/summary.json); TRUTH_DATASET:
the embedded drive's folder with truth/road.npz (`eroad synth --scenario luliang --seed 0` rebuilds it).  The
replica's x origin is found by the band-passed (0.5-20 m) correlation of its left track with the truth's
(scanned over 740-760 m, the drive's road start); then per inversion segment and side: the correlation, the
replica's band-passed variance over the truth's, and ln(replica PSD / truth PSD) in wavelength bands."""
import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.signal import butter, filtfilt, welch

from roadlib.surface import RoadSurface


def main(run, ds):
    run, ds = Path(run), Path(ds)
    tr = pd.read_csv(run / "replica" / "tracks.csv")
    x = tr["x_m"].to_numpy()
    dx = float(np.median(np.diff(x)))
    road = RoadSurface.load(ds / "truth" / "road.npz")
    b, a = butter(2, [2 * dx / 20.0, 2 * dx / 0.5], "band")
    rep = {s: tr[f"z_{s}_m"].to_numpy() for s in ("left", "right")}
    y = {"left": 1.02, "right": -1.02}        # the front tyres' lines (axle 1 drives the replica's x)
    zl = filtfilt(b, a, rep["left"])
    offs = np.arange(740.0, 760.0, 0.05)
    cs = [np.corrcoef(zl, filtfilt(b, a, road.track(y["left"], o + x)))[0, 1] for o in offs]
    off = float(offs[int(np.argmax(cs))])
    print(f"replica x origin at truth x = {off:.2f} m (band-passed correlation {max(cs):.3f} over the drive)")
    inv = json.loads((run / "invert" / "summary.json").read_text())
    rep_seg = json.loads((run / "replica" / "summary.json").read_text()).get("against_inversion", {})
    bands = ((20.0, 5.0), (5.0, 2.0), (2.0, 1.0), (1.0, 0.5))
    print("| segment | truth class | side | corr (0.5-20 m) | var replica / truth | "
          + " | ".join(f"ln PSD ratio {l:g}-{s:g} m" for l, s in bands) + " | replica vs inversion (its figure) |")
    print("|---" * (6 + len(bands)) + "|")
    truth = json.loads((ds / "truth" / "summary.json").read_text())["segments"]
    for k, s in enumerate(rep_seg.get("segments", [])):
        sel = (x >= s["x_start"] + 5) & (x <= s["x_end"] - 5)
        t_mid = 0.5 * (s["t_start"] + s["t_end"])
        tcls = next((t["label"] for t in truth if t["t_start"] <= t_mid <= t["t_end"]), "?")
        for side in ("left", "right"):
            zr = rep[side]
            zt = road.track(y[side], off + x)
            fr, pr = welch(zr[sel] - zr[sel].mean(), fs=1 / dx, nperseg=min(1024, sel.sum() // 2))
            _, pt = welch(zt[sel] - zt[sel].mean(), fs=1 / dx, nperseg=min(1024, sel.sum() // 2))
            lr = []
            for l, sh in bands:
                m = (fr >= 1 / l) & (fr < 1 / sh)
                lr.append(f"{np.log(pr[m].mean() / pt[m].mean()):+.2f}")
            br, bt = filtfilt(b, a, zr)[sel], filtfilt(b, a, zt)[sel]
            print(f"| {s['segment']} | {tcls} | {side} | {np.corrcoef(br, bt)[0, 1]:.3f} | {br.var() / bt.var():.2f} | "
                  + " | ".join(lr) + f" | {s['ln_ratio']:+.2f} |")
    print("inversion classes:", " ".join(g["class"] for g in inv["segments"]))




def segment_velocity_rms(ds, run):
    """The leaf-spring stations' suspension-velocity RMS per inversion segment, as
    inverse.replica.replica_linear_model computes it for the whole drive (derivative of susp_disp,
    low-passed at 25 Hz), and the equivalent damping F sqrt(2/pi)/s it would give there."""
    from scipy.signal import sosfiltfilt

    from drives.format import read_drive
    from inverse.replica import VELOCITY_LOWPASS_HZ

    from vehicles.params import load_vehicle

    d = read_drive(ds)
    fs = 1.0 / float(np.median(np.diff(d.time)))
    sos = butter(4, min(VELOCITY_LOWPASS_HZ, 0.4 * fs), fs=fs, output="sos")
    vp = load_vehicle(d.vehicle)
    leaf = {str(i + 1) for i, a in enumerate(vp.axles) if getattr(a, "spring_type", "") == "leaf"}
    chans = [c for c in d.channels.columns if c.startswith("susp_disp_") and c[10] in leaf]
    y = {c: d.channels[c].to_numpy(float) for c in chans}
    vel = {c: np.gradient(sosfiltfilt(sos, v - v.mean())) * fs for c, v in y.items()}
    rep = json.loads((Path(run) / "replica" / "summary.json").read_text())
    force = rep["closed_loop"].get("effects", {}).get("leaf_friction", {}).get("force") if rep.get("closed_loop") else None
    t = d.time
    rows = [("whole drive", t[0], t[-1] + 1)] + [(f"segment {s['segment']}", s["t_start"], s["t_end"])
                                                 for s in rep["against_inversion"]["segments"]]
    for name, a, b in rows:
        m = (t >= a) & (t < b)
        s = float(np.sqrt(np.mean([np.mean(v[m] ** 2) for v in vel.values()])))
        c = f", c_eq {force * np.sqrt(2 / np.pi) / s:.0f} N s/m" if force else ""
        print(f"{name} ({a:.1f}-{b:.1f} s; leaf-spring axles {', '.join(sorted(leaf))}): suspension velocity RMS {1e3 * s:.0f} mm/s{c}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
    segment_velocity_rms(sys.argv[2], sys.argv[1])
