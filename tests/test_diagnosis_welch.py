"""diagnosis.welch against scipy.signal.welch / csd (the convention every caller used).

Tolerance 1e-12 relative to the largest value: the two differ in summation order only."""
import numpy as np
import pytest
from scipy import signal

from diagnosis.welch import cross_spectra, segment_ffts, welch


def _close(a, b):
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.max(np.abs(b)))


@pytest.mark.parametrize("n, L", [(1500, 256), (1501, 255), (300, 512), (2000, 64)])
def test_welch_and_csd_equal_scipy(n, L):
    rng = np.random.default_rng(n + L)
    x = rng.standard_normal((3, n)) + 5.0           # an offset: the per-segment mean removal
    y = np.cumsum(rng.standard_normal(n)) * 0.1
    kw = dict(fs=200.0, window="hann", nperseg=min(L, n), noverlap=min(L, n) - min(L, n) // 2,
              detrend="constant")
    f_ref, p_ref = signal.welch(x, axis=-1, **kw)
    f, p = welch(x, 200.0, L)
    np.testing.assert_array_equal(f, f_ref)
    _close(p, p_ref)
    f, pxx, pyy, pxy = cross_spectra(x[0], y, 200.0, L)
    _close(pxx, p_ref[0])
    _close(pyy, signal.welch(y, **kw)[1])
    _close(pxy, signal.csd(x[0], y, **kw)[1])


def test_scipy_default_overlap_for_even_segments():
    """scipy's default noverlap L // 2 is the same hop as ours for even L (the noise-floor
    callers use it)."""
    x = np.random.default_rng(1).standard_normal(1000)
    _close(welch(x, 100.0, 256)[1], signal.welch(x, fs=100.0, nperseg=256)[1])


def test_segment_count_and_hop():
    f, X = segment_ffts(np.zeros(1000), 100.0, 200)
    assert X.shape == (9, 101) and f[1] == pytest.approx(0.5)
    assert segment_ffts(np.zeros(1000), 100.0, 200, hop=200)[1].shape == (5, 101)
