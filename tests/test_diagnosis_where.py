"""Localisation of the gap (diagnosis.where) on the toy tandem quarter-car (no Exudyn)."""
import numpy as np
import pytest

from diagnosis import toy
from diagnosis.signals import Signals
from diagnosis.where import localize

SEGS = [("S1", 0, 20), ("S2", 20, 40), ("S3", 40, 60)]


def _drive(state, seed, duration=60.0):
    return toy.simulate_drive(state, duration, 10.0, seed)


def test_null_flags_nothing_beyond_fdr():
    """Nominal vs nominal with other road phases: under the global null Benjamini-Hochberg
    flags anything with probability <= q = 0.05 per comparison.  Over 20 independent pairs
    the number of pairs with any flag is Binomial(20, <= 0.05); P(X >= 4) = 0.016, so we
    require <= 3."""
    st = toy.make_state()
    n_any = 0
    for i in range(20):
        loc = localize(_drive(st, 100 + i), _drive(st, 200 + i), segments=SEGS)
        assert loc.n_tested > 300
        n_any += loc.n_flagged > 0
    assert n_any <= 3


def test_interval_coverage_at_stated_rate():
    """Marginal 95 % intervals cover the true log ratio at 95 %.  Truth: the measured record is
    the nominal response times a gain g = 1.3 (all channels, noise included), so the true
    ratio is -2 ln g in every band.  80 replicates x 6 channels x 11 non-adjacent bands of the
    whole record; cells of one replicate are correlated (same road), so the binomial spread
    is computed with 80 x 11 = 880 effective trials: sd = sqrt(0.95 0.05 / 880) = 0.0073;
    tolerance 3 sd = 0.022."""
    st = toy.make_state()
    g = 1.3
    cover, n = 0, 0
    for i in range(80):
        a = _drive(st, 300 + i, 40.0)
        b = _drive(st, 400 + i, 40.0)
        meas = Signals(b.time, {k: g * v for k, v in b.channels.items()}, speed=b.speed)
        loc = localize(meas, a)
        sel = loc.estimable[0][:, ::2]
        lo, hi = loc.ci95_lo[0][:, ::2][sel], loc.ci95_hi[0][:, ::2][sel]
        truth = -2 * np.log(g)
        cover += np.sum((lo <= truth) & (truth <= hi))
        n += sel.sum()
    rate = cover / n
    assert abs(rate - 0.95) < 0.022, rate


def test_sensor_lowpass_is_localised_where_it_acts():
    """Measured data pass a 2nd-order Butterworth low-pass at 12 Hz (sensor dynamics); the
    simulation has the same road PSD (no road fit, so the true ratio is known analytically:
    ln of the band power ratio from the toy's frequency response).  Every flagged cell of
    the whole-record row must lie where the true |ratio| > 0.05 (FDR false flags allowed:
    at most 5 % of flags + 1), and every band with true ratio > 0.5 must be flagged on
    every channel."""
    nom = toy.make_state()
    sen = toy.make_state({"sensor": {"cutoff_hz": 12.0}})
    loc = localize(_drive(sen, 7, 60.0), _drive(nom, 8, 60.0), segments=SEGS)
    P0 = toy.expected_band_powers(nom, loc.bands, 10.0)
    P1 = toy.expected_band_powers(sen, loc.bands, 10.0)
    true = np.log(P0 / P1)                                   # (6 channels, nb), sim / meas
    flagged = loc.significant[0]
    false = flagged & (np.abs(true) <= 0.05)
    assert false.sum() <= 0.05 * flagged.sum() + 1
    must = loc.estimable[0] & (true > 0.5)
    assert must.sum() >= 20
    assert np.all(flagged[must])
    fl = loc.flagged_bands()
    assert min(min(v) for v in fl.values() if v) > 6.0       # nothing flagged at low frequency


def test_records_and_errors():
    """Records carry the summary fields; a missing channel is refused with one line."""
    st = toy.make_state()
    a, b = _drive(st, 1, 30.0), _drive(st, 2, 30.0)
    loc = localize(a, b, segments=[("A", 0, 15), ("B", 15, 30)], channels=["body_acc_1L"])
    rec = loc.records()
    assert len(rec) == 3 * 21
    assert {"channel", "band_hz", "segment", "log_psd_ratio", "significant", "ci_lo", "ci_hi"} <= set(rec[0])
    assert any(r["log_psd_ratio"] is None for r in rec if r["segment"] == "A")  # 0.5 Hz in 15 s
    from eroad.errors import EroadInputError
    with pytest.raises(EroadInputError, match="lack channel"):
        localize(a, b, channels=["body_acc_2R"])


def test_p_values_are_uniform_under_the_null():
    """The p-values of the localisation (two-sided F test of ``log_ratio_interval``, with the
    EDOF of ``bandpower``) are uniform when simulation and measurement are independent
    records of the same process.  30 pairs of 20 s of white noise at 200 Hz, 6 independent
    channels, whole record, every second third-octave band (neighbouring bands share window
    leakage; channels and alternate bands are then close to independent, as the KS test
    assumes): 1800 p-values, Kolmogorov-Smirnov against U(0, 1) at alpha = 0.01.

    Size of the check: the EDOF is slightly conservative (documented; on 36 000 such
    p-values the KS distance to U(0, 1) was 0.017, p-values a little too large), while the
    KS critical distance at n = 1800 and alpha = 0.01 is 1.63 / sqrt(1800) = 0.038, so this
    known bias passes and a gross error (one-sided p doubled or halved, wrong degrees of
    freedom) does not.  The share below 0.05 is also checked, 0.05 +- 3 binomial sd
    (sqrt(0.05 * 0.95 / 1800) = 0.0051): [0.035, 0.065]."""
    from scipy import stats

    rng = np.random.default_rng(0)
    fs, n = 200.0, 4000

    def rec():
        x = rng.standard_normal((6, n))
        return Signals(np.arange(n) / fs, {f"c{i}": x[i] for i in range(6)})

    ps = []
    for _ in range(30):
        loc = localize(rec(), rec())
        p = loc.p_value[0][:, ::2]
        ps.append(p[np.isfinite(p)])
    ps = np.concatenate(ps)
    assert ps.size >= 1700
    assert stats.kstest(ps, "uniform").pvalue > 0.01
    assert 0.035 <= np.mean(ps < 0.05) <= 0.065
