"""Contact statistics (catenary.stats) on closed-form signals.

A sine of amplitude A over whole periods has population sd A / sqrt(2) exactly and its
mean is the offset; sampled finely the discrete sums equal these to round-off, so the
tolerance is 1e-9 relative.  A force F0 + A sin(wt) with A > F0 is <= 0 for the share
1/2 - arcsin(F0/A)/pi of a period; with N samples per period the sampled share is within
1/N of that (tolerance 1.5/N).
"""
import math

import numpy as np
import pytest

from catenary.stats import contact_statistics, lateral_statistics, lowpass
from eroad.errors import EroadInputError

FS = 1000.0


def sine(mean, amp, f=2.0, periods=10):
    t = np.arange(int(periods * FS / f)) / FS
    return t, mean + amp * np.sin(2 * math.pi * f * t)


def test_sine_mean_sd_and_3sd():
    t, F = sine(120.0, 30.0)
    s = contact_statistics(F, fs=FS, lowpass_hz=None)
    assert s.mean == pytest.approx(120.0, rel=1e-9)
    assert s.sd == pytest.approx(30.0 / math.sqrt(2.0), rel=1e-9)
    assert s.stat_max == pytest.approx(120.0 + 3 * 30.0 / math.sqrt(2.0), rel=1e-9)
    assert s.stat_min == pytest.approx(120.0 - 3 * 30.0 / math.sqrt(2.0), rel=1e-9)
    assert s.actual_max == pytest.approx(150.0, rel=1e-6)
    assert s.actual_min == pytest.approx(90.0, rel=1e-6)
    assert s.loss_percent == 0.0


@pytest.mark.parametrize("ratio", [0.0, 0.3, 0.8])
def test_loss_fraction_of_a_dipping_force(ratio):
    """F0 + A sin with F0 = ratio * A: loss share 1/2 - arcsin(ratio)/pi."""
    A = 100.0
    t, F = sine(ratio * A, A, f=1.0, periods=4)
    s = contact_statistics(F, fs=FS, lowpass_hz=None)
    ref = 0.5 - math.asin(ratio) / math.pi
    n_per_period = FS / 1.0
    assert s.loss_percent / 100.0 == pytest.approx(ref, abs=1.5 / n_per_period)


def test_physical_force_clipped_at_zero_counts_loss():
    """A penalty force is max(0, .): the clipped samples are the loss samples."""
    t, F = sine(20.0, 100.0, f=1.0, periods=4)
    Fc = np.maximum(F, 0.0)
    s = contact_statistics(Fc, fs=FS, lowpass_hz=None)
    ref = 0.5 - math.asin(0.2) / math.pi
    assert s.loss_percent / 100.0 == pytest.approx(ref, abs=1.5e-3)
    assert s.actual_min == 0.0


def test_lowpass_removes_high_frequency_and_keeps_low():
    """20 Hz zero-phase Butterworth: a 2 Hz sine passes (gain 1 within 1e-3, 4th order
    gives (2/20)^8 attenuation), a 100 Hz sine is cut (gain (20/100)^8 ~ 3e-6 each
    pass); sd of the sum is then the 2 Hz sine's alone within 1 %."""
    t = np.arange(20000) / FS
    F = 100 + 10 * np.sin(2 * math.pi * 2 * t) + 10 * np.sin(2 * math.pi * 100 * t)
    s = contact_statistics(F, fs=FS, lowpass_hz=20.0, t_range=(2.0, 18.0), time=t)
    assert s.sd == pytest.approx(10 / math.sqrt(2), rel=0.01)
    unf = contact_statistics(F, fs=FS, lowpass_hz=None)
    assert unf.sd == pytest.approx(10.0, rel=0.01)  # both sines: sqrt(50 + 50)
    assert lowpass(F, FS, 20.0).shape == F.shape


def test_window_by_position():
    x = np.linspace(0, 100, 1001)
    F = np.where(x < 50, 0.0, 100.0)
    s = contact_statistics(F, x=x, x_range=(60.0, 100.0), lowpass_hz=None)
    assert s.mean == 100.0 and s.loss_percent == 0.0
    s_all = contact_statistics(F, lowpass_hz=None)
    assert s_all.loss_percent == pytest.approx(50.0, abs=0.1)


def test_lateral_margin():
    o = 0.3 * np.sin(np.linspace(0, 2 * math.pi, 1001))
    s = lateral_statistics(o, half_width=0.5)
    assert s.max_abs_offset == pytest.approx(0.3, rel=1e-6)
    assert s.rms_offset == pytest.approx(0.3 / math.sqrt(2), rel=1e-3)
    assert s.margin == pytest.approx(0.2, rel=1e-5)
    assert s.beyond_percent == 0.0
    s2 = lateral_statistics(o, half_width=0.15)
    assert s2.margin < 0 and 0 < s2.beyond_percent < 100


def test_bad_input_one_clear_error():
    with pytest.raises(EroadInputError, match="not finite"):
        contact_statistics([1.0, float("nan"), 2.0], lowpass_hz=None)
    with pytest.raises(EroadInputError, match="sample rate"):
        contact_statistics([1.0, 2.0, 3.0])
    with pytest.raises(EroadInputError, match="half-width"):
        lateral_statistics([0.0, 0.1], half_width=0.0)
