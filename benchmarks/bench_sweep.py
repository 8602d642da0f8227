"""Parallel efficiency of :func:`studies.sweep.run_cases` on local dask workers.

Runs the same CPU-bound cases (``studies.sweep.mass_spring_case``: an Exudyn
mass-spring model with a Python user function, built inside the worker, about
1-2 s each) once serially in this process and once on a LocalCluster, each
into a fresh cache, and prints::

    efficiency = T_serial / (n_workers * T_parallel)        target >= 0.85

The cluster is started and the workers warmed up (Exudyn imported, one tiny
case run) before timing; the start-up time is reported separately.  Results
of the serial and parallel runs are checked to be bitwise identical.

Usage (keep the machine otherwise quiet; ``nice`` is polite on shared hosts)::

    nice /work/venv/bin/python benchmarks/bench_sweep.py [--cases 10] [--steps 700000]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

from studies.sweep import dask_client, mass_spring_case, run_cases

FUNC = "studies.sweep:mass_spring_case"


def _warm_up() -> bool:
    """Import Exudyn and run a tiny case (executed on each worker)."""
    mass_spring_case({"steps": 10, "t_end": 0.01})
    return True


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=10, help="number of cases (default 10)")
    ap.add_argument("--steps", type=int, default=700_000,
                    help="time steps per case, ~1.7 us each (default 700000, ~1.2 s)")
    ap.add_argument("--workers", type=int, default=2, help="local workers (default 2)")
    ap.add_argument("--target", type=float, default=0.85, help="efficiency target (0.85)")
    args = ap.parse_args(argv)

    cases = [{"stiffness": 1e4 * (1.0 + 0.1 * i), "z0": 0.01 + 0.001 * i,
              "steps": args.steps, "t_end": 2.0} for i in range(args.cases)]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"cases: {args.cases} x mass_spring_case ({args.steps} steps), "
          f"workers: {args.workers}, cpus: {os.cpu_count()}, load(1 min) before: {load:.2f}")

    _warm_up()
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        t0 = time.perf_counter()
        with dask_client(n_workers=args.workers) as client:
            client.run(_warm_up)
            t_startup = time.perf_counter() - t0

            t0 = time.perf_counter()
            serial = run_cases(FUNC, cases, os.path.join(tmp, "serial"), n_workers=0,
                               progress=False)
            t_serial = time.perf_counter() - t0

            t0 = time.perf_counter()
            parallel = run_cases(FUNC, cases, os.path.join(tmp, "parallel"), scheduler=client,
                                 progress=False)
            t_parallel = time.perf_counter() - t0
        t_close = time.perf_counter() - t0 - t_parallel

    same = all(np.array_equal(a["z"], b["z"]) and a["z_final"] == b["z_final"]
               for a, b in zip(serial.results, parallel.results))
    eff = t_serial / (args.workers * t_parallel)
    print(f"cluster startup + warm-up: {t_startup:6.2f} s (not timed below); "
          f"shutdown {t_close:.2f} s")
    for label, res in (("serial", serial), ("parallel", parallel)):
        w = np.array(res.case_wall_s, dtype=float)
        print(f"per case ({label + '):':<10} mean {w.mean():.2f} s, min {w.min():.2f} s, "
              f"max {w.max():.2f} s, sum {w.sum():.2f} s")
    print(f"T_serial          : {t_serial:6.2f} s")
    print(f"T_parallel        : {t_parallel:6.2f} s  ({args.workers} workers)")
    print(f"speed-up          : {t_serial / t_parallel:6.2f}")
    print(f"efficiency        : {eff:6.1%}  (target >= {args.target:.0%}: "
          f"{'met' if eff >= args.target else 'NOT met'})")
    print("  (parallel per-case time above serial = CPU contention, e.g. other load or "
          "shared cores; T_parallel above sum/workers = scheduling overhead)")
    print(f"serial == parallel results (bitwise): {same}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
