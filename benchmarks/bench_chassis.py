"""Benchmark of the chassis-stiffness study on the linear integrator against the same study in Exudyn.

The study (``studies.chassis_study.run_chassis_study``: frame x DCDC-mount stiffness factors over the
road file and its equivalent realisations) is run twice in this process, each with its own empty case
cache: with ``solver="linear"`` (the default since stop 61: ``vehicles.linear_sim`` with the DCDC body)
and with ``solver="exudyn"``. Printed: the wall time of each run and their ratio measured in this run,
and the agreement of what the study reports -- the Figure-11 findings per case (equal or not), the band
energies of the base motion (max and median |ln(linear / Exudyn)| over cases x quantities x bands),
the RMS of the base motion per case (max relative difference), and the summary's conclusions (which
bands depend on the frame and on the mounts).

Usage::

    python benchmarks/bench_chassis.py [--road FILE] [--quick] [--workers 2] [--out DIR]

``--road``: a road file (.npz / .crg; default: the development road of ``studies.figure11``, 95 m).
Timings are printed, never asserted.
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd


def run(road: Path, out: Path, quick: bool, workers: int) -> dict:
    """Both studies on ``road`` into ``out/<solver>``; their walls and paths."""
    from studies import chassis_study as cs

    res = {}
    for solver in ("linear", "exudyn"):
        cfg = (cs.quick_config if quick else cs.full_config)(solver=solver)
        t = time.perf_counter()
        s = cs.run_chassis_study(road, out / solver, cfg, n_workers=workers, cache_dir=out / f"cache-{solver}",
                                 progress=False, command=["benchmarks/bench_chassis.py"])
        res[solver] = {"wall_s": time.perf_counter() - t, "path": s["path"], "summary": s}
        print(f"{solver:7s} study: {res[solver]['wall_s']:.1f} s wall ({s['n_cases']} cases)", flush=True)
    return res


def agreement(lin: dict, exu: dict) -> dict:
    """What the two studies report, compared."""
    dl, de = Path(lin["path"]) / "data", Path(exu["path"]) / "data"
    bl, be = pd.read_csv(dl / "band_energies.csv"), pd.read_csv(de / "band_energies.csv")
    key = ["frame", "mount", "road_index", "quantity", "band"]
    m = be.merge(bl, on=key, suffixes=("_exu", "_lin"))
    r = np.abs(np.log(m["energy_lin"] / m["energy_exu"]))
    cl, ce = pd.read_csv(dl / "cases.csv"), pd.read_csv(de / "cases.csv")
    cm = ce.merge(cl, on=["frame", "mount", "road_index"], suffixes=("_exu", "_lin"))
    findings = [c[:-4] for c in cm.columns if c.startswith("finding_") and c.endswith("_exu")]
    same = int(np.all([cm[f"{f}_exu"] == cm[f"{f}_lin"] for f in findings], axis=0).sum())
    rms = max(float(np.max(np.abs(cm[f"rms_{q}_lin"] / cm[f"rms_{q}_exu"] - 1.0))) for q in ("Ty", "Tz", "Rx", "Ry"))
    sl, se = lin["summary"], exu["summary"]
    concl = {k: sl.get(k) == se.get(k) for k in ("findings", "bands_depending_on_frame", "bands_depending_on_mount")}
    return {"n_cases": len(cm), "cases_with_every_finding_equal": same, "n_band_energies": int(len(m)),
            "band_energy_abs_ln_ratio_max": float(r.max()), "band_energy_abs_ln_ratio_median": float(r.median()),
            "rms_rel_diff_max": rms, "conclusions_equal": concl}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--road", type=Path, default=None)
    ap.add_argument("--quick", action="store_true", help="the quick study (8 cases, 8 s drives)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None, help="work folder (default: a temporary one)")
    a = ap.parse_args(argv)
    out = a.out or Path(tempfile.mkdtemp(prefix="bench_chassis-"))
    road = a.road
    if road is None:
        from studies.figure11 import development_road
        road = out / "development_road.npz"
        out.mkdir(parents=True, exist_ok=True)
        development_road(length=95.0, seed=5).save(road)
    print(f"road: {road}")
    res = run(Path(road), out, a.quick, a.workers)
    ag = agreement(res["linear"], res["exudyn"])
    ratio = res["exudyn"]["wall_s"] / res["linear"]["wall_s"]
    print(f"ratio Exudyn / linear (same run): {ratio:.2f}x")
    print(f"cases with every finding equal: {ag['cases_with_every_finding_equal']} of {ag['n_cases']}")
    print(f"band energies ({ag['n_band_energies']}): |ln(linear / Exudyn)| max {ag['band_energy_abs_ln_ratio_max']:.4f}, "
          f"median {ag['band_energy_abs_ln_ratio_median']:.4f}")
    print(f"RMS of the base motion (Ty, Tz, Rx, Ry): max relative difference {ag['rms_rel_diff_max']:.4f}")
    print(f"conclusions equal: {ag['conclusions_equal']}")
    print(json.dumps({"wall_s": {k: v["wall_s"] for k, v in res.items()}, "ratio": ratio, **ag}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
