"""Benchmark: a 1 km x 4 m ISO 8608 surface at dx = dy = 0.1 m with the full harmonic set.

What it measures (one core: BLAS/FFT threads pinned to 1 before numpy loads):

1. ``synth_surface`` -- the fast grid path (harmonics on the FFT grid, one small
   matrix product across y and an inverse real FFT along x), including drawing
   the phases.  Target <= 0.2 s.
2. the plain harmonic sum  z = sum_kl a_kl cos(2 pi (n_k x + m_l y) + phi_kl)  of
   the very same harmonics, evaluated directly.  It is far too slow for the whole
   grid, so it is timed on a random subset of grid points and extrapolated
   linearly in the number of points (each point costs the same); the printout
   says so.
3. ``HarmonicField.evaluate`` (the library's exact point evaluation, a complex
   matrix product), on a subset, extrapolated the same way.

It also checks that the plain sum and the grid path agree on the subset.
Timings are printed as ratios against the plain sum measured in the same run;
no pass/fail.  Run:  nice python benchmarks/bench_road.py
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import time  # noqa: E402

import numpy as np  # noqa: E402

from roadlib.synthesis import SpectralParams, harmonic_field, synth_surface  # noqa: E402

LENGTH, WIDTH, DX, DY = 1000.0, 4.0, 0.1, 0.1
PARAMS = SpectralParams.from_class("C", nmin=0.011, nmax=1 / (2 * DX), dx=DX, dy=DY, lam=1.0)
SEED = 2024


def best_of(fn, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def plain_sum(field, x, y):
    """Direct cosine sum over every harmonic, one point at a time (vectorised over harmonics)."""
    nk = np.repeat(field.n, field.m.size)
    ml = np.tile(field.m, field.n.size)
    c = field.coef.ravel()
    a, phi = np.abs(c), np.angle(c)
    out = np.empty(x.size)
    for i in range(x.size):
        out[i] = np.sum(a * np.cos(2 * np.pi * (nk * x[i] + ml * y[i]) + phi))
    return out


def main():
    t_fast, surf = best_of(lambda: synth_surface(PARAMS, LENGTH, WIDTH, seed=SEED), 5)
    nx, ny = surf.z.shape
    field = harmonic_field(PARAMS, LENGTH, WIDTH, seed=SEED)
    n_points = nx * ny
    rng = np.random.default_rng(0)
    sub = 60
    i, j = rng.integers(0, nx, sub), rng.integers(0, ny, sub)
    t_plain_sub, z_plain = best_of(lambda: plain_sum(field, surf.x[i], surf.y[j]), 1)
    t_plain = t_plain_sub / sub * n_points
    sub_e = 2000
    ie, je = rng.integers(0, nx, sub_e), rng.integers(0, ny, sub_e)
    t_eval_sub, _ = best_of(lambda: field.evaluate(surf.x[ie], surf.y[je]), 2)
    t_eval = t_eval_sub / sub_e * n_points
    err = np.max(np.abs(z_plain - surf.z[i, j]))

    print(f"surface: {LENGTH:g} m x {WIDTH:g} m, dx = dy = {DX} m, grid {nx} x {ny} = {n_points} points")
    print(f"harmonics: {field.n.size} longitudinal (n = {field.n[0]:.4f}..{field.n[-1]:.4f} cycles/m) x "
          f"{field.m.size} lateral = {field.coef.size} (all with non-zero amplitude: {field.n_harmonics})")
    print(f"fast grid path (synth_surface, best of 5):         {t_fast:9.3f} s   target <= 0.2 s "
          f"-> {'met' if t_fast <= 0.2 else 'NOT met'}")
    print(f"plain harmonic sum, measured on {sub} points:       {t_plain_sub:9.3f} s")
    print(f"plain harmonic sum, extrapolated to the grid:      {t_plain:9.1f} s   (linear in points)")
    print(f"exact evaluate(), measured on {sub_e} points:       {t_eval_sub:9.3f} s")
    print(f"exact evaluate(), extrapolated to the grid:        {t_eval:9.2f} s")
    print(f"ratio plain sum / fast path:                       {t_plain / t_fast:9.0f} x")
    print(f"ratio evaluate() / fast path:                      {t_eval / t_fast:9.1f} x")
    print(f"max |plain sum - grid| on the subset: {err:.2e} m (z rms {np.std(surf.z) * 1000:.2f} mm)")


if __name__ == "__main__":
    main()
