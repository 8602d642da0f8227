"""Two-slope road PSD (roadlib.psd.two_slope_psd) through roadlib and the linear model."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from eroad.errors import EroadInputError
from roadlib.psd import N0, band_variance, iso_psd, local_waviness, road_psd, two_slope_psd
from roadlib.synthesis import SpectralParams, harmonic_field, synth_profile, synth_surface
from vehicles.linear import temporal_road_psd

GD0, W1, W2, NB = 256e-6, 3.2, 1.7, 0.25


def test_continuous_at_break_and_slopes():
    eps = 1e-9
    lo, at, hi = two_slope_psd([NB * (1 - eps), NB, NB * (1 + eps)], GD0, W1, W2, NB)
    # across the break the PSD moves by O(eps w) only: no jump
    assert lo == pytest.approx(at, rel=1e-7) and hi == pytest.approx(at, rel=1e-7)
    n = np.array([0.02, 0.05, 1.0, 3.0])
    g = two_slope_psd(n, GD0, W1, W2, NB)
    # local log-log slopes are -w1 below and -w2 above the break
    assert -math.log(g[1] / g[0]) / math.log(n[1] / n[0]) == pytest.approx(W1, rel=1e-12)
    assert -math.log(g[3] / g[2]) / math.log(n[3] / n[2]) == pytest.approx(W2, rel=1e-12)
    # below the break it is the ISO line through Gd(n0) = GD0
    assert two_slope_psd([N0], GD0, W1, W2, NB)[0] == pytest.approx(GD0, rel=1e-14)
    np.testing.assert_array_equal(local_waviness(n, W1, W2, NB), [W1, W1, W2, W2])


def test_one_slope_special_cases():
    n = np.geomspace(0.01, 5.0, 50)
    # road_psd without w2 is the ISO call itself, bit for bit
    np.testing.assert_array_equal(road_psd(n, GD0, 2.3), iso_psd(n, GD0, 2.3))
    # w2 = w1 is one slope whatever the break (round-off only)
    for nb in (0.03, 0.1, 1.7):
        np.testing.assert_allclose(two_slope_psd(n, GD0, 2.3, 2.3, nb), iso_psd(n, GD0, 2.3), rtol=1e-13)
    with pytest.raises(EroadInputError):
        road_psd(n, GD0, 2.0, w2=1.5)                     # n_break missing
    with pytest.raises(EroadInputError):
        two_slope_psd(n, GD0, 2.0, 1.5, -0.1)


@pytest.mark.parametrize("band", [(0.011, 2.83), (0.3, 2.0), (0.02, 0.2), (0.05, 1.0)])
def test_band_variance_closed_form(band):
    """The closed form against adaptive quadrature of the PSD (break inside, above and
    below the band; w = 1 takes the logarithm)."""
    a, b = band
    num = quad(lambda x: two_slope_psd(x, GD0, W1, W2, NB), a, b, points=[NB] if a < NB < b else None,
               epsrel=1e-12, limit=200)[0]
    assert band_variance(GD0, W1, a, b, W2, NB) == pytest.approx(num, rel=1e-9)
    num1 = quad(lambda x: iso_psd(x, GD0, 1.0), a, b, epsrel=1e-12)[0]
    assert band_variance(GD0, 1.0, a, b) == pytest.approx(num1, rel=1e-9)


def _period_power(z: np.ndarray, dx: float, a: float, b: float) -> float:
    """Variance of a profile over exactly one period held in the FFT bins of [a, b]."""
    X = np.fft.rfft(z) / z.size
    n = np.fft.rfftfreq(z.size, dx)
    p = 2.0 * np.abs(X) ** 2
    sel = (n >= a) & (n <= b)
    return float(p[sel].sum())


@pytest.mark.parametrize("sub", [(0.05, 0.2), (0.3, 1.5)])
def test_synthesis_band_variance_two_slope(sub):
    """A synthesised two-slope profile, taken over exactly one field period, holds in a
    sub-band the closed-form variance of that band.

    Tolerance 1 %: the synthesis samples the PSD at the bin centres n_k (bin width
    dn = 1 / 409.6 m = 0.0024 cycles/m), a midpoint rule on the piecewise power law;
    its relative error, dn^2 w (w+1) / (24 n^2) at the lowest bin, is 0.25 % at
    n = 0.05 and w = 3.2, and the band edges fall between bins (up to half a bin at
    each end: 0.6 % of (0.05, 0.2) at most). The phases do not enter: with deterministic
    amplitudes and exactly one period, the periodogram is the amplitude spectrum."""
    P = SpectralParams(Gq_n0=GD0, w=W1, w2=W2, n_break=NB, nmin=0.02, nmax=2.5, dx=0.1)
    field = harmonic_field(P, 400.0, seed=11)
    L = (field.n_fft - 1) * P.dx
    x, z = synth_profile(P, L, seed=11)
    assert z.size == field.n_fft
    a, b = sub
    dn = 1.0 / (field.n_fft * P.dx)
    got = _period_power(z, P.dx, a, b)
    # the bins whose centres are inside [a, b] cover [a', b'] exactly
    k = np.flatnonzero((field.n >= a) & (field.n <= b))
    a2, b2 = field.n[k[0]] - dn / 2, field.n[k[-1]] + dn / 2
    assert got == pytest.approx(band_variance(GD0, W1, a2, b2, W2, NB), rel=0.01)
    # the whole field: its expected variance is the band integral within 2 %: the bin
    # straddling nmin = 0.02 is weighted by its in-band share but evaluated at its centre,
    # where the w = 3.2 PSD differs by up to w dn / (2 nmin) = 20 % from the in-band
    # part's (measured +0.9 %)
    assert field.variance() == pytest.approx(band_variance(GD0, W1, 0.02, 2.5, W2, NB), rel=0.02)


def test_two_slope_equal_slopes_synthesises_the_one_slope_road():
    """w2 = w gives the one-slope road of the same seed (same phases, amplitudes to
    round-off), profile and surface."""
    base = dict(Gq_n0=GD0, w=2.4, nmin=0.03, nmax=3.0, dx=0.05, dy=0.1, lam=1.5)
    one = SpectralParams(**base)
    two = SpectralParams(**base, w2=2.4, n_break=0.4)
    np.testing.assert_allclose(synth_profile(two, 200.0, seed=4)[1], synth_profile(one, 200.0, seed=4)[1],
                               rtol=0, atol=1e-15)
    s1, s2 = synth_surface(one, 60.0, 2.0, seed=5), synth_surface(two, 60.0, 2.0, seed=5)
    np.testing.assert_allclose(s2.z, s1.z, rtol=0, atol=1e-15)
    assert "w2" not in one.to_dict() and two.to_dict()["n_break"] == 0.4
    with pytest.raises(EroadInputError):
        SpectralParams(Gq_n0=GD0, w2=1.5)                 # n_break missing


def test_two_slope_surface_tracks_keep_the_1d_psd():
    """Every harmonic's lateral weights sum to 1 above and below the break: each track
    has the 1D two-slope PSD (the expected variance of the surface field equals the
    profile's)."""
    P = SpectralParams(Gq_n0=GD0, w=W1, w2=W2, n_break=NB, nmin=0.05, nmax=2.0, dx=0.1, dy=0.1)
    f2 = harmonic_field(P, 100.0, width=3.0, seed=1)
    f1 = harmonic_field(P, 100.0, width=0.0, seed=1)
    np.testing.assert_allclose((np.abs(f2.coef) ** 2).sum(axis=1), (np.abs(f1.coef[:, 0]) ** 2), rtol=1e-12)


def test_temporal_road_psd_two_slope():
    v = 8.0
    f = np.geomspace(0.2, 30.0, 200)
    road = {"Gq_n0": GD0, "w": W1, "nmin": 0.05, "nmax": 3.0, "w2": W2, "n_break": NB}
    G = temporal_road_psd(road, v, f)
    n = f / v
    inside = (n >= 0.05) & (n <= 3.0)
    np.testing.assert_allclose(G[inside], two_slope_psd(n[inside], GD0, W1, W2, NB) / v, rtol=1e-14)
    assert np.all(G[~inside] == 0)
    # the same through SpectralParams, and the one-slope dict unchanged
    P = SpectralParams(Gq_n0=GD0, w=W1, nmin=0.05, nmax=3.0, w2=W2, n_break=NB, dx=0.1)
    np.testing.assert_array_equal(temporal_road_psd(P, v, f), G)
    one = {k: road[k] for k in ("Gq_n0", "w", "nmin", "nmax")}
    np.testing.assert_array_equal(temporal_road_psd(one, v, f)[inside], iso_psd(n[inside], GD0, W1) / v)
    # time-domain variance over the band = the spatial band variance
    ff = np.geomspace(0.05 * v, 3.0 * v, 200001)
    var_t = np.trapezoid(temporal_road_psd(road, v, ff), ff)
    assert var_t == pytest.approx(band_variance(GD0, W1, 0.05, 3.0, W2, NB), rel=1e-4)
    with pytest.raises(EroadInputError):
        temporal_road_psd({**one, "w2": 1.5}, v, f)
