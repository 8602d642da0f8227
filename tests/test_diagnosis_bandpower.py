"""Band powers and their equivalent degrees of freedom (diagnosis.bandpower)."""
import numpy as np
import pytest
from scipy import signal

from diagnosis.bandpower import band_powers, third_octave_bands, var_log_power, welch_edof


def test_third_octave_bands_iec_base10():
    """IEC 61260-1 base-10 third octaves: 21 centres 0.5-50 Hz, edges fc * 10**(+-1/20)."""
    b = third_octave_bands(0.5, 50.0)
    assert b.shape == (21, 3)
    assert np.isclose(b[3, 1], 1.0) and np.isclose(b[13, 1], 10.0)
    np.testing.assert_allclose(b[:, 2] / b[:, 0], 10 ** 0.1)
    np.testing.assert_allclose(b[1:, 0], b[:-1, 2])          # contiguous


def test_edof_single_bin_matches_welch_1967():
    """One bin, K Hann segments at 50 % overlap: nu = 2K / (1 + 2 rho^2), rho(Hann, 50 %) = 0.167
    (Welch 1967; Harris 1978 table); exact formula vs the textbook value within 1 %."""
    for K in (4, 10, 40):
        nu = float(welch_edof(np.ones(1), np.array([20]), 512, K))
        ref = 2 * K / (1 + 2 * 0.1667 ** 2 * (K - 1) / K)
        assert abs(nu / ref - 1) < 0.01


def test_edof_predicts_variance_of_log_band_power():
    """Band-pass noise (2nd-order Butterworth 5-20 Hz, a steep, coloured spectrum), 30 s at
    200 Hz, 300 replicates: the predicted var(ln P) = trigamma(nu/2) agrees with the
    replicate variance.  Tolerance: the sample variance of 300 values has a relative standard
    error sqrt(2/299) = 8 %; we allow 30 % (4 sd), and the prediction may be up to 35 % high
    (conservative) because the EDOF weights use the noisy PSD estimate."""
    rng = np.random.default_rng(1)
    b, a = signal.butter(2, [5 / 100, 20 / 100], "band")
    x = signal.lfilter(b, a, rng.standard_normal((300, 6000)), axis=1)
    bs = band_powers(x, 200.0)
    for j in range(0, 21, 2):
        emp = np.var(np.log(bs.power[:, j]))
        pred = np.median(var_log_power(bs.nu[:, j]))
        assert 0.7 < pred / emp < 1.35, (bs.bands[j, 1], pred, emp)


def test_band_power_sums_to_variance():
    """White noise: the band powers sum to the variance share of 0.447-56.2 Hz (Parseval),
    within 5 % (about 10 independent estimates per band at this length)."""
    rng = np.random.default_rng(2)
    x = rng.standard_normal(60000)
    bs = band_powers(x, 200.0)
    share = (56.23 - 0.447) / 100.0
    assert abs(np.nansum(bs.power) / share - 1) < 0.05


def test_edof_is_scale_free_down_to_underflow():
    """EDOF depends on the shape of the PSD in a band, not its scale: 1 and 1e-200 give the
    same value (before, s^2 underflowed to 0 and 0/0 gave NaN with a RuntimeWarning); a band
    with no power gets the flat-spectrum EDOF."""
    import warnings

    from diagnosis.bandpower import welch_edof

    bins = np.arange(10, 18)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        flat = welch_edof(np.ones(8), bins, 256, 7)
        assert welch_edof(np.full(8, 1e-200), bins, 256, 7) == pytest.approx(flat, rel=1e-12)
        assert welch_edof(np.zeros(8), bins, 256, 7) == pytest.approx(flat, rel=1e-12)
        assert welch_edof(np.r_[1.0, np.zeros(7)], bins, 256, 7) < flat / 3
