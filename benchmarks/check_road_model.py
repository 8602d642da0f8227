"""Check of the per-segment road model (inverse.road_model) on inverted drives.

Usage::

    python benchmarks/check_road_model.py DATASET:RUN [DATASET:RUN ...] [--json OUT.json]

For every pair (a synthesised dataset with its truth/ and an ``eroad invert`` run of it)
prints one row per fitted segment: the run's one-slope fit (Gq_n0, w), the road model it
chose (w_low, w_high, n_break, ic_delta) and, for drives on the measured profile
(scenario ``second_measured``), the two-slope and one-slope Whittle fits
(:func:`inverse.road_model.fit_two_slope_psd`) of the profile actually driven under
that segment: the reference axle's two wheel tracks of ``truth/road.npz`` over the
segment's road window (``benchmarks.bench_inverse.reference_axle_x``/``window_psd``), in
the band [max(nmin, 3 / window length), min(nmax, 2 cycles/m)] (the profile is sampled
every 0.25 m: nothing of it lies above 2 cycles/m).  Also the whole profile's own fits
(``drives/data/profile_1.txt``, Welch 512-point segments, 0.05-2 cycles/m).  For ``null``
drives (one-slope truth) it counts the segments reported two-slope: the false rate.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def profile_own_fit(band=(0.05, 2.0)) -> dict:
    """The measured profile's own one- and two-slope fits (whole profile)."""
    from scipy.signal import welch

    from drives.synth import read_profile
    from inverse.road_model import fit_two_slope_psd

    x, z = read_profile("profile_1")
    dx = float(np.mean(np.diff(x)))
    n, g = welch(z, fs=1.0 / dx, nperseg=512, detrend="linear")
    return fit_two_slope_psd(n, g, band)


def rows_of(dataset: Path, run: Path) -> list:
    from bench_inverse import reference_axle_x, window_psd

    from inverse.road_model import fit_two_slope_psd
    from roadlib.surface import RoadSurface

    summary = json.loads((run / "summary.json").read_text())
    truth = json.loads((dataset / "truth" / "truth.json").read_text())
    scen = truth["scenario"]
    road = RoadSurface.load(dataset / "truth" / "road.npz") if scen == "second_measured" else None
    out = []
    for i, s in enumerate(summary["segments"]):
        r = {"dataset": dataset.name, "scenario": scen, "segment": i + 1, "t_start": s["t_start"],
             "t_end": s["t_end"], "Gq_n0": s["Gq_n0"], "w": s["w"], "nmin": s["nmin"], "nmax": s["nmax"],
             "fit_quality": s.get("fit_quality", {}).get("status"),
             **{k: s.get(k) for k in ("road_model", "w_low", "w_high", "n_break", "ic_delta")},
             "two_slope_candidate": (s.get("road_model_fit") or {}).get("two_slope"),
             "dispersion": (s.get("road_model_fit") or {}).get("dispersion"),
             "n_eff": (s.get("road_model_fit") or {}).get("n_eff")}
        if road is not None:
            x0, x1 = reference_axle_x(truth, [s["t_start"], s["t_end"]])
            est = window_psd(road, x0, x1)
            band = (max(s["nmin"], 3.0 / (x1 - x0)), min(s["nmax"], 2.0))
            r.update(x_start=float(x0), x_end=float(x1), profile_band=band)
            if est is not None and band[1] / band[0] > 4:
                try:
                    r["profile_fit"] = fit_two_slope_psd(est.n, est.G, band, n_starts=8)
                except Exception as exc:     # too few bins on a very short window
                    r["profile_fit_error"] = str(exc)
        out.append(r)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pairs", nargs="+", help="DATASET:RUN")
    ap.add_argument("--json", default=None, help="write all rows here")
    a = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    rows = []
    for p in a.pairs:
        ds, _, run = p.partition(":")
        rows += rows_of(Path(ds), Path(run))
    own = profile_own_fit()
    print("measured profile (whole, 0.05-2 cycles/m): two slopes Gd(n0) {:.3g} m^3, w_low {:.2f}, "
          "w_high {:.2f}, n_break {:.3f} cycles/m; one slope Gq_n0 {:.3g} m^3, w {:.2f}".format(
              own["Gd_n0"], own["w_low"], own["w_high"], own["n_break"], own["one_slope"]["Gq_n0"],
              own["one_slope"]["w"]))
    hdr = ("dataset", "seg", "t [s]", "Gq_n0 1e-6", "w", "model", "w_low", "w_high", "n_break", "ic_delta",
           "| prof Gd(n0)", "w_low", "w_high", "n_break", "prof 1-slope Gq", "w")
    print(" ".join(f"{h:>12}" for h in hdr))
    for r in rows:
        nb = r["n_break"]
        pf = r.get("profile_fit")
        cells = [r["dataset"], r["segment"], f"{r['t_start']:.1f}-{r['t_end']:.1f}", f"{1e6 * r['Gq_n0']:.1f}",
                 f"{r['w']:.2f}", r["road_model"], f"{r['w_low']:.2f}", f"{r['w_high']:.2f}",
                 "-" if nb is None else f"{nb:.3f}", "-" if r["ic_delta"] is None else f"{r['ic_delta']:+.1f}"]
        if pf:
            cells += [f"{1e6 * pf['Gd_n0']:.1f}", f"{pf['w_low']:.2f}", f"{pf['w_high']:.2f}", f"{pf['n_break']:.3f}",
                      f"{1e6 * pf['one_slope']['Gq_n0']:.1f}", f"{pf['one_slope']['w']:.2f}"]
        print(" ".join(f"{str(c):>12}" for c in cells))
    for scen in sorted({r["scenario"] for r in rows}):
        rs = [r for r in rows if r["scenario"] == scen]
        n2 = sum(r["road_model"] == "two_slope" for r in rs)
        long_ = [r for r in rs if r["t_end"] - r["t_start"] >= 3.0]
        n2l = sum(r["road_model"] == "two_slope" for r in long_)
        print(f"{scen}: {n2} of {len(rs)} segments two-slope ({n2l} of {len(long_)} segments >= 3 s)")
    if a.json:
        Path(a.json).write_text(json.dumps({"profile_own_fit": own, "rows": rows}, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
