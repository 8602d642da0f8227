"""Timing of the pantograph-contact drive (issue 18 target: a 30 s tractor drive with
pantograph and 4 spans of contact line in <= 60 s wall on 2 cores), against the
tractor alone measured in the same run.

The contact simulation's cost grows with the number of line DOFs and the number of
steps.  A drive of ``--duration`` seconds at ``--speed-kmh`` covers more than 4 spans at
road speeds, so two contact cases are timed:

* ``4 spans``: the truck line cut to 4 spans (plus lead-in), the pantograph base driven
  by the first ``4 spans / v`` seconds of the drive, run repeatedly (``--repeat`` laps,
  each from the static start) to fill the drive's duration;
* ``full``: the line as long as the drive (what ``eroad pantograph-contact`` builds).

Prints wall times and the ratios to the tractor-alone simulation, and the full line once
more with frame friction in the pantograph (``--frame-friction``, default 20 N; the base
driven by the same random walk), against the run without.  Timings are for looking at,
never a pass/fail test.

Usage::

    nice python benchmarks/bench_pantograph_contact.py --road ROAD.npz [--speed-kmh 80]
        [--duration 30] [--dt 1e-3] [--frame-friction 20]
"""
from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--road", required=True)
    ap.add_argument("--speed-kmh", type=float, default=80.0)
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--frame-friction", type=float, default=20.0)
    args = ap.parse_args()

    from catenary.contact import simulate_contact
    from catenary.line import ContactLine, load_line
    from roadlib.surface import RoadSurface
    from studies.figure11 import DEFAULT_VEHICLE, max_duration, simulate_tractor, tractor_variant
    from vehicles.pantograph_model import collector, load_pantograph

    road = RoadSurface.load(args.road)
    v = args.speed_kmh / 3.6
    vp = tractor_variant(DEFAULT_VEHICLE)
    dur = float(math.floor(min(args.duration, max_duration(road, vp, v) - 0.5)))
    t0 = time.perf_counter()
    simulate_tractor(vp, road, speed=v, duration=dur)
    w_tractor = time.perf_counter() - t0
    print(f"tractor alone: {dur:.0f} s drive at {args.speed_kmh:g} km/h: {w_tractor:.1f} s wall")

    pp = load_pantograph("truck")
    col = collector(pp)
    lp = load_line("truck_ohl")
    rng = np.random.default_rng(0)
    # 4 spans + lead-in/out, repeated laps to cover the drive's duration
    line4 = ContactLine(replace(lp, n_spans=6))
    lap = 4 * lp.span / v
    laps = int(math.ceil(args.duration / lap))
    t0 = time.perf_counter()
    for _ in range(laps):
        n = int(math.floor(4 * lp.span / v / args.dt + 1e-9)) + 1
        zb = 1e-3 * np.cumsum(rng.standard_normal(n)) * math.sqrt(args.dt)
        simulate_contact(line4, col, speed=v, x_start=lp.span, x_end=5 * lp.span,
                         dt=args.dt, base_z=zb, base_zdot=np.gradient(zb, args.dt))
    w4 = time.perf_counter() - t0
    print(f"contact, 4 spans ({line4.n_dof} DOFs), {laps} laps = {laps * lap:.1f} s "
          f"simulated: {w4:.1f} s wall; ratio to tractor alone {w4 / w_tractor:.2f}; "
          f"tractor + contact {w_tractor + w4:.1f} s for a {args.duration:g} s drive")
    travel = v * args.duration
    nsp = int(math.ceil(travel / lp.span)) + 2
    linef = ContactLine(replace(lp, n_spans=nsp))
    n = int(math.floor(travel / v / args.dt + 1e-9)) + 1
    zb = 1e-3 * np.cumsum(rng.standard_normal(n)) * math.sqrt(args.dt)
    kw = dict(speed=v, x_start=lp.span, x_end=lp.span + travel, dt=args.dt, base_z=zb,
              base_zdot=np.gradient(zb, args.dt))
    t0 = time.perf_counter()
    simulate_contact(linef, col, **kw)
    wf = time.perf_counter() - t0
    print(f"contact, full line {nsp} spans ({linef.n_dof} DOFs), {args.duration:g} s: "
          f"{wf:.1f} s wall; ratio to tractor alone {wf / w_tractor:.2f}")
    if args.frame_friction > 0:
        t0 = time.perf_counter()
        simulate_contact(linef, replace(col, friction=args.frame_friction), **kw)
        wfr = time.perf_counter() - t0
        print(f"the same with {args.frame_friction:g} N frame friction: {wfr:.1f} s wall; "
              f"ratio to without {wfr / wf:.2f}")


if __name__ == "__main__":
    main()
