"""Criterion 3 of decision.txt: the truth road under axle 3's own four tyres (y = +-0.76, +-1.10 m),
fitted one-slope over each true segment as benchmarks/bench_inverse.py's oracle fits (its
``_true_road_fit``), against the ISO truth: mean signed ln G(1 cycle/m).

    python tyre_oracle.py DATA_ROOT bilinear   # A's drives: the truck read the grid bilinearly
    python tyre_oracle.py DATA_ROOT exact      # B's drives: the truck read the road's own lines

Run with the code of the change (it reloads each truth road.npz; 'bilinear' drops the exact lines,
so the tracks are what the code before the change fed the truck)."""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
from bench_inverse import _true_road_fit  # noqa: E402
from drives.synth import read_truth  # noqa: E402
from roadlib.surface import RoadSurface  # noqa: E402

TYRES = (-1.10, -0.76, 0.76, 1.10)
LN10 = math.log(10.0)


def main(root, mode):
    errs = []
    for ds in sorted(Path(root).glob("null-*")):
        truth = read_truth(ds)
        road = RoadSurface.load(ds / "truth" / "road.npz")
        if mode == "bilinear":
            road.lines = None
        elif road.lines is None:
            raise SystemExit(f"{ds}: no exact lines")
        for s in truth["segments"]:
            if s["t_end"] - s["t_start"] < 3.0:
                continue
            fit = _true_road_fit(road, s["x_start"], s["x_end"], (s["nmin"], s["nmax"]), TYRES)
            if fit is None:
                continue
            errs.append(math.log(fit["Gq"] / s["Gq_n0"]) - (fit["w"] - s["w"]) * LN10)
    e = np.array(errs)
    print(f"{root} ({mode}): {e.size} segments >= 3 s, the true road under axle 3's tyres against ISO: "
          f"ln G(1 cycle/m) mean {e.mean():+.3f}, sd {e.std():.3f}, within 20 % {100 * np.mean(np.abs(e) <= math.log(1.2)):.0f} %")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
