"""Random ISO-like test roads for the vehicle tests (and a check of the helper itself).

The vehicle tests build their own roads with numpy so they do not depend on
``roadlib.synthesis`` (developed in parallel): every longitudinal track has the
one-sided displacement PSD ``Gd(n) = gd0 (n / 0.1)^-w`` on ``[nmin, nmax]``
(ISO 8608 form, n0 = 0.1 cycles/m); tracks at different y share a common part with
correlation ``corr``.  Phases come from ``numpy.random.default_rng(seed)``: the
same seed gives the same phases whatever ``gd0``, so roads of two classes differ
by exactly the amplitude factor sqrt(gd0_D / gd0_C) (used by the linearity test).
"""
import numpy as np

from roadlib.surface import RoadSurface

#: ISO 8608 class levels Gd(n0) [m^3] (geometric means, ISO 8608:2016 table)
GD0 = {"A": 16e-6, "B": 64e-6, "C": 256e-6, "D": 1024e-6, "E": 4096e-6}


def random_road(length=150.0, width=4.0, dx=0.05, dy=0.25, gd0=GD0["B"], w=2.0, seed=0,
                nmin=0.02, nmax=5.0, corr=0.7, x0=0.0):
    """Random road surface [m] by inverse FFT (periodic over 2 x length).

    Parameters
    ----------
    length, width, dx, dy : float
        Extent and grid [m].
    gd0 : float
        Gd(n0) [m^3].
    w : float
        Waviness [-].
    seed : int
    nmin, nmax : float
        Band [cycles/m].
    corr : float
        Correlation between tracks [-].

    Returns
    -------
    RoadSurface
    """
    rng = np.random.default_rng(seed)
    nx = int(round(length / dx)) + 1
    n_fft = 2 * nx
    x = x0 + np.arange(nx) * dx
    y = np.arange(-width / 2, width / 2 + dy / 2, dy)
    n = np.fft.rfftfreq(n_fft, dx)
    band = (n >= nmin) & (n <= nmax)
    G = np.where(band, gd0 * (np.maximum(n, 1e-12) / 0.1) ** (-w), 0.0)
    amp = np.sqrt(2.0 * G / (n_fft * dx))          # cosine amplitude per harmonic

    def track():
        ph = rng.uniform(0.0, 2 * np.pi, n.size)
        return np.fft.irfft(amp * np.exp(1j * ph) * n_fft / 2, n_fft)[:nx]

    common = track()
    z = np.empty((nx, y.size))
    for j in range(y.size):
        z[:, j] = corr * common + np.sqrt(1 - corr ** 2) * track()
    return RoadSurface(x, y, z, {"generator": "tests.random_road", "gd0": gd0, "w": w, "seed": seed})


def flat_road(length=150.0, width=4.0, dx=0.1):
    """A flat road [m]."""
    x = np.arange(0.0, length + dx / 2, dx)
    y = np.array([-width / 2, width / 2])
    return RoadSurface(x, y, np.zeros((x.size, y.size)))


def test_random_road_variance_matches_psd():
    """The road's height variance equals the integral of its PSD over the band.

    Tolerance 15 %: every harmonic carries exactly its expected amplitude and only
    the phases are random, but the road is half of the FFT period, so its variance
    fluctuates with the phases of the few long waves (w = 2 puts most variance near
    nmin = 0.1 cycles/m, 40 such waves in 400 m: a few per cent typical).
    """
    gd0, w, nmin, nmax = GD0["C"], 2.0, 0.1, 5.0
    r = random_road(length=400.0, gd0=gd0, w=w, nmin=nmin, nmax=nmax, corr=1.0)
    n = np.linspace(nmin, nmax, 200001)
    var_psd = np.trapezoid(gd0 * (n / 0.1) ** (-w), n)
    assert abs(np.var(r.z[:, 0]) / var_psd - 1) < 0.15


def test_random_road_scales_with_class():
    """Same seed, 4x the PSD level -> exactly 2x the heights (linearity test premise)."""
    a = random_road(length=50.0, gd0=GD0["C"], seed=3)
    b = random_road(length=50.0, gd0=GD0["D"], seed=3)
    np.testing.assert_allclose(b.z, 2.0 * a.z, rtol=1e-12, atol=1e-15)
