"""The gap scalar (diagnosis.gap.band_gap) and the shrink of the held-out gap
(diagnosis.which.Entry, diagnosis.pipeline.heldout_shrink), against numbers worked out
independently: scaled copies of a record (exact log band-power ratios), independent white
noise of known variance ratio, hand-made band spectra, and a stand-in simulator whose gaps
are known in closed form.
"""
import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy import special

from diagnosis.bandpower import BandSpectrum, band_powers, third_octave_bands
from diagnosis.gap import Reference, band_gap, reference
from diagnosis.signals import Signals

FS = 200.0


def _noise(rng, n, chans=("a", "b", "c"), sd=1.0, t0=0.0):
    return Signals(np.arange(n) / FS, {c: sd * rng.standard_normal(n) for c in chans},
                   meta={"t0": t0})


def _scaled(sig, factor):
    return Signals(sig.time, {c: factor * x for c, x in sig.channels.items()}, meta=dict(sig.meta))


def _weight(nu):
    """1 / (2 trigamma(nu / 2)): the inverse variance of a log band-power ratio of two
    independent estimates with nu degrees of freedom each (docs/diagnosis.md, "The gap
    scalar"), from SciPy's polygamma."""
    return 1.0 / (2.0 * special.polygamma(1, np.asarray(nu, float) / 2.0))


def test_band_gap_of_a_scaled_copy_is_exact():
    """Simulation = c x measurement (same samples), c = 1.5, two windows of 20 s and 12 s:
    every band power scales by c^2 exactly, so every estimable cell has ln(P_sim/P_meas) =
    +2 ln c (positive: the simulation is the stronger), the gap and every per-band gap are
    (2 ln c)^2, and the floor is n / sum w with w from the measured EDOF.  Tolerance 1e-10:
    floating-point rounding only."""
    rng = np.random.default_rng(1)
    meas = [_noise(rng, 4000), _noise(rng, 2400)]
    c = 1.5
    g = band_gap([_scaled(m, c) for m in meas], reference(meas))
    d = 2 * math.log(c)
    # the estimable cells and their weights, computed here from the measured band spectra
    nu = np.array([band_powers(np.vstack(list(m.channels.values())), FS).nu for m in meas])
    cell = nu >= 6.0
    w = np.where(cell, _weight(np.maximum(nu, 1e-9)), 0.0)
    assert g.n_cells == int(cell.sum()) and g.n_cells > 80
    np.testing.assert_allclose(g.log_ratio[cell], d, rtol=1e-10)
    assert np.all(np.isnan(g.log_ratio[~cell]))
    assert g.value == pytest.approx(d ** 2, rel=1e-10)
    assert g.floor == pytest.approx(cell.sum() / w.sum(), rel=1e-10)
    has = cell.any(axis=(0, 1))
    np.testing.assert_allclose(g.per_band[has], d ** 2, rtol=1e-10)
    assert np.all(np.isnan(g.per_band[~has])) and (~has).sum() >= 1    # 12 s loses 0.5 Hz
    np.testing.assert_allclose(g.per_band_floor[has],
                               cell.sum(axis=(0, 1))[has] / w.sum(axis=(0, 1))[has], rtol=1e-10)
    np.testing.assert_allclose(g.weight, w, rtol=1e-10)
    # the other direction: a weaker simulation gives the negative log ratio, same gap
    g2 = band_gap([_scaled(m, 1 / c) for m in meas], reference(meas))
    np.testing.assert_allclose(g2.log_ratio[cell], -d, rtol=1e-10)
    assert g2.value == pytest.approx(d ** 2, rel=1e-10)


def test_band_gap_of_independent_noise_with_known_variance_ratio():
    """Measurement: white noise of variance 1; simulation: INDEPENDENT white noise of variance
    4 (60 s, 4 channels).  The true log band-power ratio is ln 4 in every band, so the
    weighted mean of the cell log ratios estimates +ln 4 and the gap estimates
    (ln 4)^2 + sum w var_i / sum w, var_i = trigamma(nu_sim/2) + trigamma(nu_meas/2) the
    sampling variance of cell i (both sides random).  Tolerance 4 standard deviations of
    each estimate, computed from the same cell variances (cells treated as independent:
    white noise, disjoint bands): sd of the mean sqrt(sum w^2 var_i) / sum w, sd of the gap
    sqrt(sum w^2 (4 mu^2 var_i + 2 var_i^2)) / sum w (a normal d_i)."""
    rng = np.random.default_rng(2)
    meas, sim = _noise(rng, 12000, "abcd"), _noise(rng, 12000, "abcd", sd=2.0)
    g = band_gap([sim], reference([meas]))
    ps = band_powers(np.vstack(list(sim.channels.values())), FS)
    pm = band_powers(np.vstack(list(meas.channels.values())), FS)
    cell = (pm.nu >= 6) & (ps.nu >= 6)
    var = special.polygamma(1, ps.nu[cell] / 2) + special.polygamma(1, pm.nu[cell] / 2)
    w = _weight(pm.nu[cell])
    mu = math.log(4.0)
    d = g.log_ratio[0][cell]
    mean = float(np.sum(w * d) / w.sum())
    assert mean == pytest.approx(mu, abs=4 * math.sqrt(np.sum(w ** 2 * var)) / w.sum())
    expect = mu ** 2 + float(np.sum(w * var) / w.sum())
    sd_gap = math.sqrt(np.sum(w ** 2 * (4 * mu ** 2 * var + 2 * var ** 2))) / w.sum()
    assert g.value == pytest.approx(expect, abs=4 * sd_gap)


def test_band_gap_on_hand_made_spectra():
    """Band spectra written by hand (2 channels x 3 bands, one window): measured power Pm and
    EDOF nu_m, simulated power Pm exp(D) and EDOF nu_s.  Cells enter where both EDOFs are
    >= 6: (0, 1) is out by its simulated EDOF 5, (1, 0) by its measured EDOF 4.  Weights
    come from the MEASURED EDOF only (the same for every model compared on these data):
    gap = sum w D^2 / sum w, floor = 4 / sum w, per band the same sums over the band's
    cells."""
    bands = third_octave_bands(1.0, 1.6)
    assert bands.shape == (3, 3)
    L = np.array([256, 256, 256])
    Pm = np.array([[1.0, 2.0, 4.0], [1.0, 1.0, 1.0]])
    nu_m = np.array([[10.0, 20.0, 40.0], [4.0, 30.0, 12.0]])
    D = np.array([[0.5, -0.25, 1.0], [2.0, 0.1, -0.3]])
    nu_s = np.array([[8.0, 5.0, 100.0], [50.0, 30.0, 12.0]])

    def spec(P, nu):
        return BandSpectrum(bands, P, nu, np.full(3, 8), L, np.full(3, 5))

    ref = Reference(["x", "y"], bands, [spec(Pm, nu_m)], [2048], 6.0)
    g = band_gap(None, ref, spectra=[spec(Pm * np.exp(D), nu_s)])
    cells = [(0, 0), (0, 2), (1, 1), (1, 2)]
    w = {c: float(_weight(nu_m[c])) for c in cells}
    sw = sum(w.values())
    assert g.n_cells == 4
    assert g.value == pytest.approx(sum(w[c] * D[c] ** 2 for c in cells) / sw, rel=1e-12)
    assert g.floor == pytest.approx(4 / sw, rel=1e-12)
    np.testing.assert_allclose(g.per_band, [
        D[0, 0] ** 2, D[1, 1] ** 2,
        (w[(0, 2)] * D[0, 2] ** 2 + w[(1, 2)] * D[1, 2] ** 2) / (w[(0, 2)] + w[(1, 2)])], rtol=1e-12)
    np.testing.assert_allclose(g.per_band_floor, [1 / w[(0, 0)], 1 / w[(1, 1)],
                                                  2 / (w[(0, 2)] + w[(1, 2)])], rtol=1e-12)
    expect = np.full((2, 3), np.nan)
    for c in cells:
        expect[c] = D[c]
    np.testing.assert_allclose(g.log_ratio[0], expect, rtol=1e-12)   # NaN where not a cell


def test_entry_shrink_against_the_nominal_held_out_gap():
    """:class:`diagnosis.which.Entry`: before = [2, 4], after = [1.5, 1.5] per seed, noise floor
    1: shrink fraction 1 - 1.5/3 = 0.5 (against the nominal model's HELD-OUT gap, not the
    calibration gap, 10 here), per-seed shrink [0.25, 0.625] with spread (ddof 1)
    0.375 / sqrt(2), shrink of the part above the floor 1 - 0.5/2 = 0.75, improvement 1.5."""
    from diagnosis.which import Entry

    e = Entry("x", {"x": {"p": 1.0}}, 1, 10.0, np.array([2.0, 4.0]), np.array([1.5, 1.5]),
              np.zeros(3), np.zeros(3), 100, 13, floor=1.0)
    assert e.shrink_fraction == pytest.approx(0.5, abs=1e-15)
    np.testing.assert_allclose(e.shrink_per_seed, [0.25, 0.625], rtol=1e-15)
    assert e.shrink_spread == pytest.approx(0.375 / math.sqrt(2), rel=1e-12)
    assert e.shrink_excess == pytest.approx(0.75, abs=1e-15)
    assert e.improvement == pytest.approx(1.5, abs=1e-15)
    rec = e.record()
    assert rec["shrink_fraction"] == pytest.approx(0.5) and rec["shrink_min"] == 0.25


def test_heldout_shrink_closed_form(monkeypatch):
    """:func:`diagnosis.pipeline.heldout_shrink` with the truck replaced by a stand-in (the
    dataset reader, road fit and callables patched; the scoring, seeds and null are the
    function's own).  Held-out windows: 15 s of white noise, 3 channels.  The stand-in
    simulates a window as ``factor x window``: ``a = 2`` for the nominal model, ``b =
    a^(1/sqrt 2)`` with the candidate effect, and the nominal model on the surrogate seeds
    (stream (2, k, j) of the documented seed scheme) ``a s_k``.  Every cell's log ratio is
    then 2 ln(ratio of factors) exactly, so: before = (2 ln a)^2, after = (2 ln b)^2 =
    before / 2, shrink 0.5 (the candidate removes exactly half the gap); against surrogate
    k the nominal model scores (2 ln s_k)^2 and the candidate (2 ln(b / (a s_k)))^2, whose
    difference over k gives the paired null's mean and sd (ddof 1) and paired_z.
    Tolerance 1e-9 relative: rounding only."""
    import diagnosis.pipeline as pl

    rng = np.random.default_rng(4)
    n = 3000
    wins = [_noise(rng, n, t0=15.0 * i) for i in range(4)]
    ctx = SimpleNamespace(model="stand-in", calib=wins[0::2], held=wins[1::2])
    monkeypatch.setattr(pl, "load_measured", lambda ds: (SimpleNamespace(vehicle="v"), None))
    monkeypatch.setattr(pl, "prepare", lambda sig, veh, seed=0, n_windows=4: ctx)

    seed, n_seeds, n_null = 7, 3, 5
    a = 2.0
    b = a ** (1 / math.sqrt(2))
    s = np.array([1.16, 0.75, 1.5, 0.9, 1.3])         # surrogate k's amplitude
    sur_seed = {int(np.random.SeedSequence(seed, spawn_key=(2, k, j)).generate_state(1)[0]): s[k]
                for k in range(n_null) for j in range(2)}

    class Fit:
        def __init__(self, model):
            pass

        def __call__(self, effects, data):
            return dict(effects or {})

    class Simulate:
        def __init__(self, model):
            pass

        def __call__(self, state, window, sd):
            f = (b if state else a) * sur_seed.get(int(sd), 1.0)
            return _scaled(window, f)

    monkeypatch.setattr(pl, "Fit", Fit)
    monkeypatch.setattr(pl, "Simulate", Simulate)
    out = pl.heldout_shrink("ds", {"x": {"p": 1.0}}, seed=seed, n_seeds=n_seeds, n_null=n_null,
                            delay=False)
    before, after = (2 * math.log(a)) ** 2, (2 * math.log(b)) ** 2
    null = (2 * np.log(s)) ** 2 - (2 * np.log(b / (a * s))) ** 2
    mu, sd = float(null.mean()), float(null.std(ddof=1))
    assert out["before"] == pytest.approx(before, rel=1e-9)
    assert out["after"] == pytest.approx(after, rel=1e-9)
    assert out["shrink_fraction"] == pytest.approx(0.5, rel=1e-9)
    assert out["improvement"] == pytest.approx(before - after, rel=1e-9)
    assert out["null_improvement_mean"] == pytest.approx(mu, rel=1e-9)
    assert out["null_improvement_sd"] == pytest.approx(sd, rel=1e-9)
    assert out["paired_z"] == pytest.approx((before - after - mu) / sd, rel=1e-9)


def test_a_channel_the_simulation_leaves_empty_is_a_huge_gap():
    """A simulation that reproduces channels a and c exactly but outputs zeros on b: b's cells
    count as a 12-decade deficit (ln 1e-12 = -27.6) instead of dropping out. Two thirds of
    the weight sits on exact cells, so the gap is about (ln 1e-12)^2 / 3 = 254 (between 100
    and 400 whatever the per-channel weights), where dropping the cells gave about 0."""
    rng = np.random.default_rng(3)
    meas = [_noise(rng, 4000)]
    sim = [Signals(meas[0].time, {c: (np.zeros_like(x) if c == "b" else x.copy())
                                  for c, x in meas[0].channels.items()}, meta=dict(meas[0].meta))]
    g = band_gap(sim, reference(meas))
    assert 100.0 < g.value < 400.0
    assert np.nanmin(g.log_ratio) == pytest.approx(math.log(1e-12))
