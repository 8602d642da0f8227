"""Sweep of every effect parameter over its advertised range, for both built-in vehicles.

Issue 15, item 4: each effect's advertised range must be one in which the vehicle stays
physical and the solver runs.  This script simulates, per vehicle and per effect
parameter (the others at their defaults), the range ends and three points inside
(the default and the midpoints between the ends and the default, geometric when the
range spans a factor >= 10), plus the worst corner of the effects whose parameters
interact in the solver (leaf friction: largest force with the smallest smoothing
velocity; bump stops: smallest gap and smoothing with the largest stiffness; damper
asymmetry: both ratio ends with the smallest smoothing velocity).  Vehicle-dependent
ranges (payload mass) come from ``Effect.vehicle_ranges``.

Drive: the ``null`` scenario of ``eroad synth`` (random road of classes A-E and speed
6-14 m/s drawn from the seed, nominal rigid chassis, the vehicle's own time step),
seed 1, 8 s record plus the scenario's 2 s run-in, built with the same functions as
``eroad synth`` (no sensor noise added: only the simulation is exercised).

Columns: ``ok`` (simulated without error), ``dt/2^k`` (time-step halvings the
simulator needed, ``vehicles.simulate.MAX_DT_HALVINGS``), ``wall`` [s] (whole
``simulate`` call), ``body_rms`` (largest RMS body acceleration over the channels,
m/s^2), ``axle_pk`` (largest |axle acceleration|, m/s^2), ``susp_sd`` (largest
standard deviation of suspension travel, mm), ``lift`` (fraction of samples with a
tyre off the ground), ``note`` (error message or the effect's own notes).

Usage::

    python benchmarks/effect_ranges.py [--vehicles dump_truck_8x4 e_tractor] [--seed 1]
        [--duration 8] [--effects NAME ...] [--out results/effect_ranges]

One simulation at a time (no pools).  Timings are printed, never asserted.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import shlex  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

VEHICLES = ("dump_truck_8x4", "e_tractor")
#: parameter combinations that stress the solver most (see the module docstring)
CORNERS = {
    "leaf_friction": [{"force": "hi", "velocity": "lo"}],
    "bump_stop": [{"gap": "lo", "stiffness": "hi", "smoothing": "lo"}],
    "damper_asymmetry": [{"ratio": "hi", "velocity": "lo"}, {"ratio": "lo", "velocity": "lo"}],
}


def drive(vehicle: str, seed: int, duration: float) -> dict:
    """Road, speed profile and start of the ``null`` scenario (as ``eroad synth``)."""
    from drives.synth import build_road, load_scenario, plan_drive, resolve_scenario
    from vehicles.params import load_vehicle
    from vehicles.simulate import SpeedProfile

    cfg, _ = load_scenario("null")
    sc = resolve_scenario(cfg, seed, vehicle=vehicle, duration=duration)
    vp = load_vehicle(vehicle)
    plan = plan_drive(sc, [a.x for a in vp.axles])
    fs = float(sc["scenario"]["sample_rate_hz"])
    return {"road": build_road(sc, plan), "speed": SpeedProfile(plan["t_sim"], plan["v_sim"]),
            "duration": (plan["n_runin"] + plan["n_record"]) / fs, "fs": fs,
            "x_start": plan["x_front0"],
            "classes": [s.get("label", "") for s in sc["road"]["segments"]]}


def points(lo: float, default: float, hi: float) -> list:
    """Range ends, default and the midpoints between them (geometric for wide ranges)."""
    geo = lo > 0 and hi / lo >= 10

    def mid(a, b):
        return math.sqrt(a * b) if geo and a > 0 else 0.5 * (a + b)
    default = min(max(default, lo), hi)
    pts = [lo, mid(lo, default), default, mid(default, hi), hi]
    out = []
    for p in pts:
        if not any(abs(p - q) <= 1e-12 * max(1.0, abs(q)) for q in out):
            out.append(float(p))
    return out


def cases(vehicle, names=None) -> list:
    """(effect, {param: value}, label) for one vehicle."""
    from vehicles.effects import EFFECTS
    from vehicles.params import load_vehicle

    vp = load_vehicle(vehicle)
    out = []
    for name, eff in EFFECTS.items():
        if names and name not in names:
            continue
        rng = {k: v[:2] for k, v in eff.vehicle_ranges(vp).items()}
        for p in eff.parameters:
            lo, hi = rng[p.name]
            for v in points(lo, p.default, hi):
                tag = "lo" if v == lo else "hi" if v == hi else "in"
                out.append((name, {p.name: v}, f"{p.name}={v:g} ({tag})"))
        for corner in CORNERS.get(name, []):
            vals = {k: rng[k][0 if e == "lo" else 1] for k, e in corner.items()}
            out.append((name, vals, "corner " + " ".join(f"{k}={v:g}" for k, v in vals.items())))
    return out


def run_case(vehicle, d, name, values, seed) -> dict:
    from eroad.errors import EroadInputError, SimulationError
    from vehicles.simulate import simulate

    t0 = time.perf_counter()
    row = {"vehicle": vehicle, "effect": name, "values": values}
    try:
        res = simulate(vehicle, d["road"], d["speed"], d["duration"], fs_out=d["fs"],
                       x_start=d["x_start"], effects={name: values}, seed=seed)
    except (EroadInputError, SimulationError) as exc:
        row.update(ok=False, wall=time.perf_counter() - t0, note=str(exc).splitlines()[0])
        return row
    ch = res.channels

    def grp(prefix):
        return [np.asarray(ch[c]) for c in ch if c.startswith(prefix)]
    notes = {k: v for k, v in res.meta.get("effect_notes", {}).items()}
    row.update(ok=True, wall=time.perf_counter() - t0, dt=res.meta["dt"],
               halvings=int(res.meta.get("dt_halvings", 0)),
               body_rms=max(float(np.sqrt(np.mean(x ** 2))) for x in grp("body_acc_")),
               axle_pk=max(float(np.max(np.abs(x))) for x in grp("axle_acc_")),
               susp_sd=1e3 * max(float(np.std(x)) for x in grp("susp_disp_")),
               lift=float(res.meta["tyre_lift_off_fraction"]),
               note="; ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                              for k, v in notes.items()))
    return row


def fmt_row(r) -> str:
    vals = " ".join(f"{k}={v:g}" for k, v in r["values"].items())
    head = f"{r['vehicle']:<15} {r['effect']:<17} {vals:<44}"
    if not r["ok"]:
        return f"{head} FAIL  {'':>5} {r['wall']:6.1f} {'':>8} {'':>8} {'':>7} {'':>5}  {r['note']}"
    return (f"{head} ok    {r['halvings']:>5d} {r['wall']:6.1f} {r['body_rms']:8.3f} "
            f"{r['axle_pk']:8.1f} {r['susp_sd']:7.2f} {r['lift']:5.3f}  {r['note']}")


HEADER = (f"{'vehicle':<15} {'effect':<17} {'values':<44} {'ok':<5} {'dt/2^k':>5} {'wall':>6} "
          f"{'body_rms':>8} {'axle_pk':>8} {'susp_sd':>7} {'lift':>5}  note")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--vehicles", nargs="+", default=list(VEHICLES))
    ap.add_argument("--effects", nargs="+", default=None)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration", type=float, default=8.0)
    ap.add_argument("--out", default=None, help="folder for sweep.txt and sweep.json")
    args = ap.parse_args(argv)
    t_all = time.perf_counter()
    rows, lines = [], []

    def say(s=""):
        print(s, flush=True)
        lines.append(s)
    cmd = "python " + " ".join(shlex.quote(a) for a in [sys.argv[0]] + list(argv or sys.argv[1:]))
    say(f"# {cmd}")
    say(f"# host {platform.node()}, python {platform.python_version()}, "
        f"{time.strftime('%Y-%m-%d %H:%M:%S')}")
    for vehicle in args.vehicles:
        d = drive(vehicle, args.seed, args.duration)
        t_ref = time.perf_counter()
        from vehicles.simulate import simulate
        simulate(vehicle, d["road"], d["speed"], d["duration"], fs_out=d["fs"],
                 x_start=d["x_start"])
        say(f"# {vehicle}: null scenario seed {args.seed}, {d['duration']:g} s simulated, road "
            f"segments {', '.join(d['classes'])}; nominal run {time.perf_counter() - t_ref:.1f} s")
        from vehicles.effects import EFFECTS
        from vehicles.params import load_vehicle
        vp = load_vehicle(vehicle)
        for name, eff in EFFECTS.items():
            if args.effects and name not in args.effects:
                continue
            rngs = ", ".join(f"{k} [{v[0]:g}, {v[1]:g}]" for k, v in eff.vehicle_ranges(vp).items())
            say(f"#   {name}: {rngs}")
        say(HEADER)
        for name, values, _ in cases(vehicle, args.effects):
            r = run_case(vehicle, d, name, values, args.seed)
            rows.append(r)
            say(fmt_row(r))
    n_fail = sum(not r["ok"] for r in rows)
    say(f"# {len(rows)} runs, {n_fail} failed, {sum(r.get('halvings', 0) > 0 for r in rows)} "
        f"needed a smaller step; {time.perf_counter() - t_all:.0f} s")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "sweep.txt").write_text("\n".join(lines) + "\n")
        (out / "sweep.json").write_text(json.dumps({"command": cmd, "rows": rows}, indent=1))
    return 1 if n_fail else 0


if __name__ == "__main__":
    sys.exit(main())
