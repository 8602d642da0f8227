"""Benchmark of the linear integrator (``simulate(solver="linear")``) against Exudyn's run.

The drives are the shape the gap diagnosis simulates by the hundred: the dump truck over
``--duration`` s (default 9.5: a 7.5 s window and its 2 s run-in) at 8 -> 12 m/s on a class C
road, ``--n`` road seeds.  Printed per variant (nominal truck; a payload, whose model is
linearised anew for each value as a calibration does; a flexible frame; the nonlinear effects,
whose suspension forces the linear integrator solves step by step): the wall time per
drive of each integrator, their ratio measured in this run, and the agreement, as in
``bench_vehicles.py``: ``rms_err`` = max over channels of |RMS(linear) / RMS(exudyn) - 1|
(the level the diagnosis compares) and ``wave_err`` = max over channels of
RMS(linear - exudyn) / RMS(exudyn).

Usage::

    python benchmarks/bench_linear_sim.py [--n 10] [--duration 9.5]

Timings are printed, never asserted.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10, help="road seeds per variant")
    ap.add_argument("--duration", type=float, default=9.5, help="drive length [s]")
    args = ap.parse_args(argv)

    from roadlib.segments import RoadSegment, segmented_surface
    from vehicles.simulate import SpeedProfile, simulate

    d = args.duration
    prof = SpeedProfile(np.array([0.0, d]), np.array([8.0, 12.0]))
    length = 12.0 * d + 20.0
    variants = [("nominal", lambda i: None),
                ("payload (new value each drive)", lambda i: {"payload": {"mass": 1000.0 + 500.0 * i}}),
                ("frame_flex", lambda i: {"frame_flex": {}}),
                # the nonlinear effects: local suspension forces solved per step
                # (vehicles/suspension_forces.py) against Exudyn's Newton run
                ("leaf_friction 2 kN", lambda i: {"leaf_friction": {"force": 2000.0}}),
                ("leaf_friction 12 kN, v0 5 mm/s", lambda i: {"leaf_friction": {"force": 12000.0,
                                                                                 "velocity": 0.005}}),
                ("damper_asymmetry 4", lambda i: {"damper_asymmetry": {"ratio": 4.0}}),
                ("bump_stop 10 mm", lambda i: {"bump_stop": {"gap": 0.01}})]
    print(f"dump truck, {d:g} s at 8 -> 12 m/s, class C, {args.n} road seeds per variant")
    print(f"{'variant':32s} {'exudyn s':>9s} {'linear s':>9s} {'ratio':>7s} {'rms_err':>9s} {'wave_err':>9s}")
    for name, eff in variants:
        te, tl, rms_err, wave_err = [], [], 0.0, 0.0
        for i in range(args.n):
            road = segmented_surface([RoadSegment(Gq_n0=256e-6, share=length, nmin=0.011, nmax=5.0)],
                                     length, 3.0, 0.05, 0.1, seed=100 + i)
            t = time.perf_counter()
            a = simulate("dump_truck_8x4", road, prof, d, effects=eff(i))
            te.append(time.perf_counter() - t)
            t = time.perf_counter()
            b = simulate("dump_truck_8x4", road, prof, d, effects=eff(i), solver="linear")
            tl.append(time.perf_counter() - t)
            if b.meta["solver"] != "linear":
                print(f"  seed {100 + i}: not linear ({b.meta['tyre_contact_run']} tyres), Exudyn ran")
            for c in a.channels:
                if c == "speed":
                    continue
                x, y = a.channels[c], b.channels[c]
                rms_err = max(rms_err, abs(np.std(y) / np.std(x) - 1.0))
                wave_err = max(wave_err, float(np.sqrt(np.mean((x - y) ** 2)) / np.std(x)))
        me, ml = float(np.median(te)), float(np.median(tl))
        print(f"{name:32s} {me:9.3f} {ml:9.3f} {me / ml:7.1f} {rms_err:9.2e} {wave_err:9.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
