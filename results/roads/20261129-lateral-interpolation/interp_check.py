"""Is the road a tyre sees between two grid tracks the road the surface's parameters describe?

roadlib surfaces are grids (dx along, dy across); vehicles.simulate.road_under_tyres and
drives.independent_truck read a tyre's track by bilinear interpolation.  A tyre between two grid
lines gets a weighted mean of two tracks that are only partly coherent at short waves, so its
input has less power there than either grid track.  Measured here on the scenarios' own grid
(class C, w = 2, nmin 0.1, nmax 5, dx 0.025 m, dy 0.1 m, width 3 m, lam = 1; six 1000 m surfaces):
Welch PSD of the track at y = 1.02 m (where the 8x4 truck's front tyres run) and 1.05 m (half-way)
against the grid track at y = 1.00 m, and of the grid track against the parameters.
Run from the repository root: python results/roads/20261129-lateral-interpolation/interp_check.py
"""
import sys

import numpy as np

sys.path.insert(0, ".")
from roadlib.metrics import profile_psd                      # noqa: E402
from roadlib.synthesis import SpectralParams, synth_surface  # noqa: E402

p = SpectralParams.from_class("C", w=2.0, nmin=0.1, nmax=5.0, dx=0.025, dy=0.1, lam=1.0)
acc = {}
for seed in range(6):
    s = synth_surface(p, 1000.0, 3.0, seed=seed)
    for y in (1.0, 1.02, 1.05):
        ps = profile_psd(s.track(y), s.dx, nperseg=4096)
        acc.setdefault(y, []).append(ps.G)
n = ps.n
G0 = np.mean(acc[1.0], axis=0)
NS = (0.2, 0.5, 1, 2, 3, 4)


def band_mean(r, nn):
    return float(np.mean(r[(n > nn / 1.2) & (n < nn * 1.2)]))


print("PSD ratio in bands n/1.2 .. 1.2 n [cycles/m]:")
for y in (1.02, 1.05):
    r = np.mean(acc[y], axis=0) / G0
    print(f"  track at y = {y} m / grid track at 1.00 m: " + "  ".join(f"n={nn:g}: {band_mean(r, nn):.2f}" for nn in NS))
with np.errstate(divide="ignore"):
    ref = p.Gq_n0 * (n / 0.1) ** -p.w
print("  grid track / the parameters' G(n):          " + "  ".join(f"n={nn:g}: {band_mean(G0 / ref, nn):.2f}" for nn in NS))
