"""Multiple testing of the diagnosis (diagnosis.fdr): Benjamini-Hochberg flags against SciPy's
implementation, and the false-coverage-rate promise of the adjusted intervals by simulation.

References the code did not make: ``scipy.stats.false_discovery_control`` (BH adjusted
p-values), a step-up example worked by hand, the level formula of Benjamini and Yekutieli
(2005), and Monte Carlo repetitions with a known truth.
"""
import numpy as np
import pytest
from scipy import stats

from diagnosis.fdr import benjamini_hochberg, fcr_level


def _scipy_bh(p, q):
    """BH flags from SciPy's adjusted p-values: reject where p_adj <= q."""
    return stats.false_discovery_control(p, method="bh") <= q


@pytest.mark.parametrize("m", [1, 2, 7, 60, 757])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bh_flags_match_scipy(m, seed):
    """Random p-values (a mixture of uniform nulls and small p-values from Beta(0.1, 1), so
    that BH flags a real share of them at most sizes): the flags equal SciPy's at q = 0.05
    and q = 0.2.  The comparison is exact: continuous random p-values have no ties with
    the thresholds ``q k / m`` (a tie would be a floating-point coincidence)."""
    rng = np.random.default_rng(seed)
    p = np.where(rng.uniform(size=m) < 0.3, rng.beta(0.1, 1.0, size=m), rng.uniform(size=m))
    for q in (0.05, 0.2):
        np.testing.assert_array_equal(benjamini_hochberg(p, q), _scipy_bh(p, q))
    if m == 757:         # the size of the toy's table: the case must not be vacuous
        assert 0 < benjamini_hochberg(p, 0.05).sum() < m


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_bh_ignores_nan_cells(seed):
    """The documented NaN rule: NaN entries (untestable cells) are never flagged and do not
    count in the family size ``m``.  So the flags on a table with NaNs equal SciPy's flags on
    the finite entries alone, NaN positions False, shape kept (a 2-D table)."""
    rng = np.random.default_rng(seed)
    p = np.where(rng.uniform(size=(6, 40)) < 0.3, rng.beta(0.1, 1.0, size=(6, 40)),
                 rng.uniform(size=(6, 40)))
    p[rng.uniform(size=p.shape) < 0.25] = np.nan
    ok = np.isfinite(p)
    for q in (0.05, 0.2):
        got = benjamini_hochberg(p, q)
        assert got.shape == p.shape and got.dtype == bool
        assert not got[~ok].any()
        np.testing.assert_array_equal(got[ok], _scipy_bh(p[ok], q))
        assert got.sum() > 0
    # NaN must not count in m: with the NaNs counted as tests the thresholds q k / m would be
    # lower; a case where this changes the answer: 2 finite p-values, 8 NaNs
    p2 = np.array([0.02, 0.04] + [np.nan] * 8)
    np.testing.assert_array_equal(benjamini_hochberg(p2, 0.05), [True, True] + [False] * 8)
    assert not benjamini_hochberg(np.full(5, np.nan), 0.05).any()


def test_bh_step_up_by_hand():
    """m = 4, q = 0.05: thresholds 0.0125, 0.025, 0.0375, 0.05.  Sorted p = 0.001, 0.03,
    0.036, 0.2: the largest k with p_(k) <= q k / m is k = 3, so the step-up procedure flags
    the three smallest, 0.03 included although it misses its own threshold 0.025 (a
    step-down procedure would stop at k = 1; Bonferroni, p <= q / m, flags only 0.001)."""
    p = np.array([0.036, 0.001, 0.2, 0.03])
    np.testing.assert_array_equal(benjamini_hochberg(p, 0.05), [True, True, False, True])
    # the same with 0.036 -> 0.04 (> 0.0375): now only k = 1 qualifies
    np.testing.assert_array_equal(benjamini_hochberg(np.array([0.04, 0.001, 0.2, 0.03]), 0.05),
                                  [False, True, False, False])


def test_fcr_level_formula():
    """Benjamini and Yekutieli (2005): level ``1 - q R / m`` for R selected of m; with no
    selection ``1 - q / m`` (the Bonferroni level)."""
    assert fcr_level(5, 100, 0.05) == pytest.approx(1 - 0.05 * 5 / 100, abs=1e-15)
    assert fcr_level(0, 100, 0.05) == pytest.approx(1 - 0.05 / 100, abs=1e-15)
    assert fcr_level(1, 100, 0.05) == fcr_level(0, 100, 0.05)
    assert fcr_level(40, 40, 0.1) == pytest.approx(0.9, abs=1e-15)
    assert fcr_level(3, 757, 0.05) == pytest.approx(1 - 0.15 / 757, abs=1e-15)


def _fcr_sim(theta, n_rep, q, seed, level_fn):
    """Monte Carlo of selected-parameter intervals: X ~ N(theta, 1) independent, two-sided
    p-values, BH selection, intervals X +- z at ``level_fn(R, m)``.  Returns per-repetition
    false coverage proportions V / max(R, 1) and whether every repetition's selection is
    exactly the set of intervals that exclude 0."""
    rng = np.random.default_rng(seed)
    m = theta.size
    fcp = np.empty(n_rep)
    consistent = True
    for k in range(n_rep):
        x = theta + rng.standard_normal(m)
        p = 2 * stats.norm.sf(np.abs(x))
        sel = benjamini_hochberg(p, q)
        r = int(sel.sum())
        h = stats.norm.isf((1 - level_fn(r, m)) / 2)
        fcp[k] = np.sum(sel & (np.abs(x - theta) > h)) / max(r, 1)
        consistent &= bool(np.array_equal(sel, np.abs(x) > h))
    return fcp, consistent


@pytest.mark.parametrize("theta", [np.r_[np.zeros(10), np.full(10, 2.0)], np.full(20, 1.5)],
                         ids=["half_null", "no_null"])
def test_fcr_of_selected_intervals_is_at_most_q(theta):
    """The FCR promise (Benjamini and Yekutieli 2005, Theorem 1, independent estimates): the
    expected share of BH-selected parameters whose interval at level ``fcr_level(R, m, q)``
    misses the TRUE value is at most q = 0.05.  4000 repetitions of 20 normal estimates with
    a known truth (half null and half at 2 sd, or all at 1.5 sd: the selection is then biased
    away from the truth, which is what the adjustment is for).

    Tolerance: each repetition's proportion lies in [0, 1], so with mean FCR <= q its
    variance is at most q (1 - q) (the Bernoulli bound); the mean of 4000 has sd at most
    sqrt(0.05 * 0.95 / 4000) = 0.0034 and we allow 3 sd: FCR <= 0.0603 (about 0.1 % chance
    of a false failure if the FCR were exactly q; measured 0.036 and 0.025).

    Power of the check: the same simulation with unadjusted marginal (1 - q) intervals must
    exceed that bound (measured 0.107 and 0.173), so a level that ignores the selection fails.
    And the flags are exactly the cells whose adjusted interval excludes 0 (as the
    localisation table promises), in every repetition."""
    q, n_rep = 0.05, 4000
    bound = q + 3 * np.sqrt(q * (1 - q) / n_rep)
    fcp, consistent = _fcr_sim(theta, n_rep, q, 11, lambda r, m: fcr_level(r, m, q))
    assert fcp.mean() <= bound, fcp.mean()
    assert consistent
    raw, _ = _fcr_sim(theta, n_rep, q, 11, lambda r, m: 1 - q)
    assert raw.mean() > bound, raw.mean()
