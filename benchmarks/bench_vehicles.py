"""Benchmark of the vehicle simulator: speed (real-time factor) and accuracy.

Issue 3, item 9: the rigid dump truck over 30 s of road at >= 100x real time and the
flexible-chassis truck at >= 50x, on one core, with outputs within 1 % RMS of a run
at a 4x smaller step.  This script measures, on this machine:

* the real-time factor (simulated seconds per wall-clock second of the whole
  ``simulate`` call: build, static solves, road input, solve, outputs), best of
  ``--repeat`` runs, and the same per CPU second of this process (robust against
  other processes on a shared machine), pinned to one core;
* the accuracy against the same run at a 4x smaller step, per channel group:
  ``rms_err`` = max over channels of |RMS(x) / RMS(x_ref) - 1| (the quantity the
  inverse fit and the diagnosis use), and ``wave_err`` = max over channels of
  RMS(x - x_ref) / RMS(x_ref) (time-history agreement, stricter);
* ratios against references measured in the same run: the 4x-smaller-step run
  (cost of the step size) and the rigid truck (cost of the flexible frame), plus
  informative runs of the tractor and of a nonlinear effect.

Road: ISO 8608 class C (Gd(n0) = 256e-6 m^3), w = 2, 0.011-5 cycles/m, 3D surface
(``roadlib.synthesis``), speed 10 m/s, seed 1.

Usage::

    python benchmarks/bench_vehicles.py [--quick] [--repeat 3] [--json out.json]

Timings are printed, never asserted (docs/design.md: timings live in benchmarks).
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

GROUPS = ("susp_disp", "axle_acc", "body_acc", "dcdc_y", "dcdc_z")


def make_road(length: float, seed: int = 1):
    """Class-C road surface [m] covering ``length`` metres."""
    from roadlib.synthesis import SpectralParams, synth_surface

    p = SpectralParams.from_class("C", w=2.0, nmin=0.011, nmax=5.0, dx=0.05, dy=0.1)
    return synth_surface(p, length, 3.0, seed=seed)


def accuracy(res, ref) -> dict:
    """Per channel group: max RMS-level error and max waveform error [-]."""
    out = {}
    for name in res.channels:
        g = name.rsplit("_", 1)[0]
        if g not in GROUPS:
            continue
        a, b = res[name], ref[name]
        rb = np.sqrt(np.mean(b ** 2))
        rms_err = abs(np.sqrt(np.mean(a ** 2)) / rb - 1)
        wave_err = np.sqrt(np.mean((a - b) ** 2)) / rb
        o = out.setdefault(g, {"rms_err": 0.0, "wave_err": 0.0, "worst": ""})
        if rms_err > o["rms_err"]:
            o["rms_err"], o["worst"] = float(rms_err), name
        o["wave_err"] = max(o["wave_err"], float(wave_err))
    return out


def timed(fn, repeat: int):
    """Best wall and CPU real-time factors over ``repeat`` runs, and the last result."""
    best_wall, best_cpu, res = 0.0, 0.0, None
    for _ in range(repeat):
        res = fn()
        best_wall = max(best_wall, res.meta["realtime_factor"])
        best_cpu = max(best_cpu, res.meta["cpu_realtime_factor"])
    return best_wall, best_cpu, res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="10 s instead of 30 s, one repeat")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--json", default=None, help="write the results to this JSON file")
    ap.add_argument("--no-fast", action="store_true",
                    help="skip the informative run with Exudyn's fast module (EXUDYN_MODULE=fast)")
    args = ap.parse_args(argv)
    duration = 10.0 if args.quick else args.duration
    repeat = 1 if args.quick else args.repeat
    try:
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
        pinned = sorted(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        pinned = None

    import exudyn

    from vehicles.simulate import simulate

    speed = 10.0
    road = make_road(duration * speed + 20.0)
    results = {"machine": {"python": platform.python_version(), "exudyn": exudyn.__version__,
                           "cpu_pinned": pinned, "loadavg_start": os.getloadavg()},
               "road": {"class": "C", "speed_mps": speed, "duration_s": duration}, "cases": {}}
    print(f"eroad vehicle benchmark: {duration:g} s at {speed:g} m/s on an ISO class C road; "
          f"Exudyn {exudyn.__version__}; pinned to CPU {pinned}; load average "
          f"{results['machine']['loadavg_start'][0]:.2f}")
    cases = [("dump_truck_8x4", "rigid", None, 100.0), ("dump_truck_8x4", "flexible", None, 50.0),
             ("e_tractor", "rigid", None, None), ("e_tractor", "flexible", None, None),
             ("dump_truck_8x4", "rigid", {"leaf_friction": 2000.0}, None)]
    rigid_cpu = None
    for vid, chassis, eff, target in cases:
        label = f"{vid}/{chassis}" + (f"+{','.join(eff)}" if eff else "")
        simulate(vid, road, speed, 2.0, chassis=chassis, effects=eff)      # warm-up (imports)
        t0 = time.perf_counter()
        wall, cpu, res = timed(lambda: simulate(vid, road, speed, duration, chassis=chassis,
                                                effects=eff), repeat)
        dt = res.meta["dt"]
        ref = simulate(vid, road, speed, duration, chassis=chassis, effects=eff, dt=dt / 4)
        acc = accuracy(res, ref)
        case = {"dt": dt, "steps": res.meta["steps"], "n_dof": res.meta["n_dof"],
                "realtime_factor": wall, "cpu_realtime_factor": cpu,
                "wall_s": duration / wall, "target": target,
                "ref_dt": dt / 4, "ref_realtime_factor": ref.meta["realtime_factor"],
                "ref_cpu_realtime_factor": ref.meta["cpu_realtime_factor"],
                "speedup_vs_4x_smaller_step": cpu / ref.meta["cpu_realtime_factor"],
                "accuracy": acc, "newton": res.meta["newton"],
                "bench_wall_s": time.perf_counter() - t0}
        if chassis == "rigid" and not eff and vid == "dump_truck_8x4":
            rigid_cpu = cpu
        if rigid_cpu and vid == "dump_truck_8x4" and chassis == "flexible" and not eff:
            case["cost_vs_rigid"] = rigid_cpu / cpu
        results["cases"][label] = case
        worst = max(v["rms_err"] for v in acc.values())
        wave = max(v["wave_err"] for v in acc.values())
        tgt = f" (target >= {target:g}x)" if target else ""
        print(f"\n{label}: dt {dt * 1e3:g} ms, {res.meta['steps']} steps, {res.meta['n_dof']} DOF, "
              f"newton {res.meta['newton']}")
        print(f"  real-time factor {wall:7.1f}x wall, {cpu:7.1f}x CPU{tgt}; "
              f"{case['speedup_vs_4x_smaller_step']:.2f}x faster than dt/4")
        print(f"  accuracy vs dt/4: max RMS error {100 * worst:.2f} %, max waveform error "
              f"{100 * wave:.2f} %")
        for g, v in acc.items():
            print(f"    {g:10s} rms {100 * v['rms_err']:6.3f} %  wave {100 * v['wave_err']:6.3f} %  "
                  f"(worst {v['worst']})")
    if not args.no_fast and os.environ.get("EXUDYN_MODULE", "") != "fast":
        # informative: Exudyn's build without range checks (opt-in through the
        # environment, exudyn/__init__.py); same code, separate process
        import subprocess
        import sys

        env = dict(os.environ, EXUDYN_MODULE="fast")
        cmd = [sys.executable, "-c",
               "import json, os, sys\n"
               "sys.path.insert(0, os.getcwd())\n"
               "from vehicles.simulate import simulate\n"
               f"sys.path.insert(0, {os.path.dirname(os.path.abspath(__file__))!r})\n"
               "from bench_vehicles import make_road\n"
               f"road = make_road({duration * speed + 20.0})\n"
               "out = {}\n"
               "for ch in ('rigid', 'flexible'):\n"
               "    simulate('dump_truck_8x4', road, 10.0, 2.0, chassis=ch)\n"
               f"    r = [simulate('dump_truck_8x4', road, 10.0, {duration}, chassis=ch) for _ in range({repeat})]\n"
               "    out[ch] = [max(x.meta['realtime_factor'] for x in r), max(x.meta['cpu_realtime_factor'] for x in r)]\n"
               "print(json.dumps(out))\n"]
        try:
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600,
                                  cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
            fast = json.loads(proc.stdout.strip().splitlines()[-1])
            results["exudyn_fast_module"] = fast
            print("\nwith EXUDYN_MODULE=fast (Exudyn without range checks, opt-in):")
            for ch, (w, c) in fast.items():
                print(f"  dump_truck_8x4/{ch}: {w:7.1f}x wall, {c:7.1f}x CPU")
        except (subprocess.SubprocessError, ValueError, IndexError) as exc:  # pragma: no cover
            print(f"\n(fast-module run skipped: {exc})")
    results["machine"]["loadavg_end"] = os.getloadavg()
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(results, fh, indent=2, default=float)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
