"""The road power each tyre of the 8x4 truck loses on the inversion's simulator grid (inverse.truck
SIM_WIDTH 3 m, SIM_DY 0.1 m): a tyre between two grid lines reads a*z1 + b*z2, whose PSD is
(a^2 + b^2 + 2 a b gamma(n, dy)) G(n) with gamma the surface coherence (w = 2, lam = 1).  The
inversion's linear features model exactly this (inverse.linear_features._tyre_lines), so the road
it reports is the one whose GRID reproduces the response.  Run from the repository root."""
import sys

import numpy as np

sys.path.insert(0, ".")
from inverse.linear_features import _tyre_lines, road_grid_lines   # noqa: E402
from inverse.truck import SIM_DY, SIM_WIDTH                         # noqa: E402
from vehicles.linear import linear_model, surface_coherence         # noqa: E402

lm = linear_model("dump_truck_8x4")
gy = road_grid_lines(SIM_WIDTH, SIM_DY)
NS = (0.5, 1, 2, 3, 4)
print(f"grid lines every {SIM_DY} m over {SIM_WIDTH} m; power factor of the tyre's input at n [cycles/m]:")
for c in lm.contacts:
    lines = _tyre_lines(c["y"], gy)
    if len(lines) == 1:
        f = [1.0] * len(NS)
    else:
        (y1, a), (y2, b) = lines
        f = [a * a + b * b + 2 * a * b * float(surface_coherence(np.array([n]), np.array([abs(y2 - y1)]), 2.0, 1.0)[0])
             for n in NS]
    print(f"  axle {c['axle']} {c['side']} y = {c['y']:+.3f} m: " + "  ".join(f"n={n:g}: {v:.2f}" for n, v in zip(NS, f)))
