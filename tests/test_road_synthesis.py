"""Harmonic synthesis (roadlib.synthesis): scale, waviness, anisotropy, seeds, fast path."""
import dataclasses

import numpy as np
import pytest

from eroad.errors import EroadInputError
from roadlib.metrics import fit_iso_psd, profile_psd
from roadlib.psd import class_gd0
from roadlib.synthesis import SpectralParams, harmonic_field, synth_profile, synth_surface

C = class_gd0("C")


def test_class_c_profile_level_pinned_by_welch():
    """Scale pin: the Welch level of a 4 km class C profile (dx = 0.1 m, 4096-sample
    segments: K = 18 half-overlapping Hann averages, ~1000 bins in 0.05-2.5 cycles/m) is
    256e-6 m^3 within 4 standard errors.  The standard error sqrt(2/dof * 1.5/M) (~0.9 %,
    1.5 = Hann bin correlation) is computed from the number of averages by fit_iso_psd;
    4 SE ~ 4 %.  The two known wrong scales (class upper bound = 2x, and 1/pi) are off by
    +100 % and -68 %, far outside."""
    p = SpectralParams.from_class("C")
    _, z = synth_profile(p, 4000.0, seed=11)
    est = profile_psd(z, p.dx, nperseg=4096)
    assert est.n_averages == 18
    fit = fit_iso_psd(est, band=(0.05, 2.5), w=2.0)
    assert fit.Gd_n0_rel_se < 0.011
    assert abs(fit.Gd_n0 / C - 1) < 4 * fit.Gd_n0_rel_se
    assert fit.iso_class == "C"
    # Parseval: variance = integral of the one-sided PSD over the band, within 3 %.  The
    # 1D amplitudes are deterministic and the 4 km record spans 98.8 % of the field's
    # period, so the harmonics are nearly orthogonal over it; the remaining differences
    # (Riemann sum of the n^-2 integral near nmin, partial period) are a few tenths of a %.
    expected = C * 0.1**2 * (1 / p.nmin - 1 / p.nmax)
    assert np.var(z) == pytest.approx(expected, rel=0.03)


@pytest.mark.parametrize("w", [2.0, 2.6])
def test_waviness_recovered_within_0_05(w):
    """w from the free (Gd0, w) Whittle fit within 0.05 (issue requirement).  The fit's
    statistical SE is ~0.011 for this record (K = 18 averages, 1000 bins), so 0.05 is > 4 SE."""
    p = SpectralParams(Gq_n0=C, w=w)
    _, z = synth_profile(p, 4000.0, seed=3)
    fit = fit_iso_psd(profile_psd(z, p.dx, nperseg=4096), band=(0.05, 2.5))
    assert fit.w_se < 0.0125
    assert abs(fit.w - w) < 0.05
    assert abs(fit.Gd_n0 / C - 1) < 4 * fit.Gd_n0_rel_se


def test_surface_track_has_the_1d_psd():
    """Any longitudinal track of a 3D surface has Gd(n) in expectation: a single track at
    y = 1.3 m of a 2 km x 4 m class C surface, level within 4 SE (SE ~1.3 %, 2048-sample
    segments, K = 18)."""
    p = SpectralParams.from_class("C")
    s = synth_surface(p, 2000.0, 4.0, seed=21)
    fit = fit_iso_psd(profile_psd(s.track(1.3), p.dx, nperseg=2048), band=(0.05, 2.5), w=2.0)
    assert abs(fit.Gd_n0 / C - 1) < 4 * fit.Gd_n0_rel_se


def _lateral_over_longitudinal(lam):
    from scipy import signal
    s = synth_surface(SpectralParams.from_class("C", lam=lam), 400.0, 4.0, seed=5)
    nl, gl = signal.welch(s.z, fs=10.0, window="hann", nperseg=41, axis=1, detrend="linear")
    est = profile_psd(s.z[:, ::5], 0.1, nperseg=1024)
    sel_l, sel_x = (nl >= 0.7) & (nl <= 1.5), (est.n >= 0.7) & (est.n <= 1.5)
    return gl.mean(axis=0)[sel_l].mean() / est.G[sel_x].mean()


def test_lambda_changes_lateral_against_longitudinal_spectrum():
    """eq (5) predicts lateral/longitudinal PSD ratio lam^(1-w) at equal n: 1 (lam = 1),
    0.25 (lam = 4), 2 (lam = 0.5).  The lateral estimate uses 41-point lines (4 m, Hann),
    with 0.24 cycles/m resolution and leakage from the steeper low band, so only a factor 2
    around the predicted ratios is claimed; the effect tested is 4x and 2x.  For lam = 0.5 the
    lower end is raised to 1.4: a factor 2 below the predicted 2 is 1.0, the value with no
    effect at all, which a lam ignored by the synthesis could reach (measured 2.03, seed 5)."""
    r1, r4, r05 = (_lateral_over_longitudinal(lam) for lam in (1.0, 4.0, 0.5))
    assert 0.5 < r1 < 2.0
    assert 0.125 < r4 / r1 < 0.5
    assert 1.4 < r05 / r1 < 4.0


def test_fast_grid_path_equals_exact_sum():
    """FFT grid path = explicit cosine sum of the same harmonics to round-off (1e-12 of the
    RMS), 1D and 3D, at random grid points."""
    rng = np.random.default_rng(0)
    for width in (0.0, 3.0):
        p = SpectralParams.from_class("D", dx=0.1, dy=0.25, lam=1.5)
        f = harmonic_field(p, 300.0, width, seed=4)
        y = np.arange(0, width + 1e-9, p.dy) - width / 2 if width else np.zeros(1)
        zg = f.grid(5.0, 3001, y)
        i = rng.integers(0, 3001, 200)
        j = rng.integers(0, y.size, 200)
        ze = f.evaluate(5.0 + i * p.dx, y[j])
        assert np.max(np.abs(ze - zg[i, j])) < 1e-12 * np.std(zg)
        # the one-position path (junction heights) is the same sum
        assert np.max(np.abs(f.row(7.3, y) - f.evaluate(np.full(y.size, 7.3), y))) < 1e-12 * np.std(zg)
    # and the profile generator is that grid path
    x, z = synth_profile(p, 300.0, seed=4, x0=5.0)
    assert np.array_equal(z, harmonic_field(p, 300.0, 0.0, seed=4).grid(5.0, x.size)[:, 0])


def test_same_seed_same_bytes_other_seed_differs():
    p = SpectralParams.from_class("C", lam=2.0)
    a = synth_surface(p, 200.0, 2.0, seed=7)
    b = synth_surface(p, 200.0, 2.0, seed=7)
    c = synth_surface(p, 200.0, 2.0, seed=8)
    assert a.z.tobytes() == b.z.tobytes()
    assert a.meta == b.meta
    assert not np.array_equal(a.z, c.z)
    assert np.array_equal(synth_profile(p, 50, seed=np.random.SeedSequence(3))[1],
                          synth_profile(p, 50, seed=3)[1])


def test_surface_grid_convention():
    """y centred on 0, x from x0, shape (nx, ny)."""
    s = synth_surface(SpectralParams.from_class("B"), 10.0, 2.0, seed=0, x0=3.0)
    assert s.z.shape == (101, 21)
    assert s.x[0] == 3.0 and s.x[-1] == pytest.approx(13.0)
    assert s.y[0] == pytest.approx(-1.0) and s.y[-1] == pytest.approx(1.0)


@pytest.mark.parametrize("kw, msg", [
    ({"nmax": 5.0, "dx": 0.2}, r"nmax = 5 cycles/m exceeds the Nyquist frequency 1/\(2 dx\) = 2.5"),
    ({"nmin": 3.0, "nmax": 2.0}, "nmin = 3.0 must be below nmax"),
    ({"dx": -0.1}, "dx must be positive"),
    ({"dy": 0.0}, "dy must be positive"),
    ({"lam": float("nan")}, "lam must be positive and finite"),
    ({"w": 7.0}, "w = 7.0 is outside"),
    ({"w": "abc"}, "w must be a number"),
])
def test_bad_spectral_parameters_refused(kw, msg):
    with pytest.raises(EroadInputError, match=msg):
        SpectralParams(Gq_n0=C, **kw)


def test_bad_level_and_sizes_refused():
    with pytest.raises(EroadInputError, match="implausible"):
        SpectralParams(Gq_n0=256.0)
    with pytest.raises(EroadInputError, match="Gq_n0 must be positive"):
        SpectralParams(Gq_n0=-1e-6)
    p = SpectralParams.from_class("C")
    with pytest.raises(EroadInputError, match="shorter than one dx"):
        synth_profile(p, 0.05)
    with pytest.raises(EroadInputError, match="road width"):
        synth_surface(p, 10.0, -1.0)
    with pytest.raises(EroadInputError, match="no harmonic"):
        synth_profile(SpectralParams(Gq_n0=C, nmin=0.0101, nmax=0.0102), 10.0)


def test_paper_table1_case():
    """Paper Table 1: nmax = 5 cycles/m with dx = 0.2 m is refused; the project uses
    dx = 0.1 m (Nyquist = 5 cycles/m) to keep the paper's band (docs/roadlib.md)."""
    with pytest.raises(EroadInputError, match="use dx <= 0.1 m or nmax <= 2.5"):
        SpectralParams(Gq_n0=C, nmin=0.011, nmax=5.0, dx=0.2)
    p = SpectralParams(Gq_n0=C, nmin=0.011, nmax=5.0, dx=0.1)
    _, z = synth_profile(p, 100.0, seed=0)
    assert np.all(np.isfinite(z))


def test_nyquist_harmonic_consistent():
    """nmax = Nyquist with an even FFT length puts a harmonic on the Nyquist bin; the grid
    path still equals the exact sum (round-off 1e-12 of the RMS)."""
    p = SpectralParams.from_class("C", nmax=5.0, dx=0.1)
    f = harmonic_field(p, 100.0, 1.0, seed=1, n_fft=2000)
    assert f.k[-1] == f.n_fft // 2
    y = np.array([-0.5, 0.0, 0.5])
    zg = f.grid(0.3, 1001, y)
    ze = f.evaluate((0.3 + np.arange(1001) * 0.1)[:, None], y[None, :])
    assert np.max(np.abs(ze - zg)) < 1e-12 * np.std(zg)


@pytest.mark.parametrize("width, nmin, nmax", [(0.0, 0.1, 5.0), (3.0, 0.1, 5.0), (3.0, 0.011, 2.0)])
def test_phases_are_those_of_the_whole_grid(width, nmin, nmax):
    """The phases jump to the band's first bin in the PCG64 stream (a speed-up): they must
    be those of drawing one phase per bin of the whole grid and lateral harmonic (the
    documented rule that makes roads of one seed comparable across bands).  Tolerance
    1e-12 relative: |a e^(i phi)| and a differ by rounding only; a phase from another
    place in the stream is off by O(1)."""
    p = dataclasses.replace(SpectralParams.from_class("C"), nmin=nmin, nmax=nmax)
    ss = np.random.SeedSequence(7, spawn_key=(3,))
    f = harmonic_field(p, 200.0, width, ss)
    n_bins = f.n_fft // 2 + 1
    phi = np.random.default_rng(ss).uniform(0.0, 2.0 * np.pi, size=(n_bins, f.m.size))[f.k]
    assert f.k[0] > 0 and f.m.size == (1 if width == 0 else f.m.size)
    np.testing.assert_allclose(f.coef, np.abs(f.coef) * np.exp(1j * phi), rtol=1e-12, atol=0)
