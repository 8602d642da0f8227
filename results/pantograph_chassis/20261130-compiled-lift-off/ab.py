"""A/B of vehicles.linear_sim.COMPILED_UNILATERAL on the chassis-stiffness study (stop 62).

    python results/pantograph_chassis/20261130-compiled-lift-off/ab.py ROAD OUT [--reps 2]

Runs the full study serially (n_workers=1, in this process, so the module flag reaches every case)
with the flag on and off, alternating, each on its own empty case cache; prints each wall, the ratio
measured in this run, the cases' own simulation walls (cases.csv ``sim_wall_s``), and whether the
study's numbers agree (cases.csv and band_energies.csv, every column but the timing)."""
import argparse
import shutil
import time
from pathlib import Path

import numpy as np
import pandas as pd


def compare(pa: Path, pb: Path, name: str) -> str:
    x, y = pd.read_csv(pa / "data" / name), pd.read_csv(pb / "data" / name)
    timing = [c for c in x.columns if c.endswith("wall_s")]
    num = [c for c in x.columns if c not in timing and pd.api.types.is_float_dtype(x[c])]
    other = [c for c in x.columns if c not in timing and c not in num]
    rel = float(np.nanmax(np.abs(x[num].to_numpy() - y[num].to_numpy())
                          / (np.abs(y[num].to_numpy()) + 1e-300))) if num else 0.0
    same = bool((x[other].astype(str) == y[other].astype(str)).all().all())
    return (f"{name}: {len(x)} rows; {len(num)} float columns, max relative difference {rel:.1e}; "
            f"{len(other)} other columns equal: {same} (timing columns {timing} not compared)")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("road")
    ap.add_argument("out")
    ap.add_argument("--reps", type=int, default=1)
    a = ap.parse_args()
    from studies import chassis_study as cs
    from vehicles import linear_sim

    out = Path(a.out)
    walls, sims, paths = {True: [], False: []}, {True: [], False: []}, {}
    for rep in range(a.reps):
        for flag in (True, False):
            linear_sim.COMPILED_UNILATERAL = flag
            tag = f"{'compiled' if flag else 'numpy'}-{rep}"
            shutil.rmtree(out / f"cache-{tag}", ignore_errors=True)
            t = time.perf_counter()
            s = cs.run_chassis_study(a.road, out / tag, cs.full_config(solver="linear"), n_workers=1,
                                     cache_dir=out / f"cache-{tag}", progress=False,
                                     command=["ab.py", a.road])
            walls[flag].append(time.perf_counter() - t)
            paths[flag] = Path(s["path"])
            sims[flag].append(float(pd.read_csv(paths[flag] / "data" / "cases.csv")["sim_wall_s"].sum()))
            print(f"{tag:11s} study {walls[flag][-1]:.1f} s wall ({s['n_cases']} cases; their "
                  f"simulations {sims[flag][-1]:.1f} s)", flush=True)
    print(f"numpy / compiled: study wall {np.median(walls[False]) / np.median(walls[True]):.2f} "
          f"(medians {np.median(walls[False]):.1f} / {np.median(walls[True]):.1f} s), the cases' "
          f"simulations {np.median(sims[False]) / np.median(sims[True]):.2f} "
          f"({np.median(sims[False]):.1f} / {np.median(sims[True]):.1f} s), {a.reps} rep(s)")
    for name in ("cases.csv", "band_energies.csv"):
        print(compare(paths[True], paths[False], name))


if __name__ == "__main__":
    main()
