"""A/B of vehicles.linear_sim.COMPILED_UNILATERAL on one diagnosis (stop 62).

    python results/pantograph_chassis/20261130-compiled-lift-off/ab_diagnose.py DATASET OUT

``eroad diagnose`` (diagnosis.pipeline.diagnose, 2 workers, forked after the flag is set) with the flag on,
off, on, off; prints each wall and whether the verdict and the ranking's numbers are the same."""
import json
import sys
import time
from pathlib import Path

from diagnosis.pipeline import diagnose
from vehicles import linear_sim


def main():
    ds, out = sys.argv[1], Path(sys.argv[2])
    walls, res = {True: [], False: []}, {}
    for rep in range(2):
        for flag in (True, False):
            linear_sim.COMPILED_UNILATERAL = flag
            o = out / f"{'compiled' if flag else 'numpy'}-{rep}"
            t = time.perf_counter()
            diagnose(ds, o, workers=2)
            walls[flag].append(time.perf_counter() - t)
            s = json.loads((o / "summary.json").read_text())
            res[flag] = (s["verdict"], [(e["effect"], round(e["heldout_gap_after"], 9)) for e in s["ranking"]])
            print(f"{o.name:11s} {walls[flag][-1]:.1f} s  verdict {s['verdict']}", flush=True)
    print(f"numpy / compiled: {min(walls[False]) / min(walls[True]):.2f} (best of 2: "
          f"{min(walls[False]):.1f} / {min(walls[True]):.1f} s); verdict and ranking gaps the same: "
          f"{res[True] == res[False]}")


if __name__ == "__main__":
    main()
