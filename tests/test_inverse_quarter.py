"""The quarter-truck reference simulator of the inverse fit (inverse.quarter).

Reference values: closed-form frequency responses of the linear 2-DOF quarter
car (the simulator must agree with them in PSD), and the physical laws of a
linear model (response proportional to road amplitude, i.e. to sqrt(Gq_n0)).
"""
import numpy as np
import pytest
from scipy.signal import welch

from eroad.errors import EroadInputError
from inverse.quarter import QuarterTruck, QuarterTruckSimulator, harmonic_profile, travelled_distance

FS = 200.0


def _sim(duration=60.0, speed=10.0, x_bounds=(0.0, 1e9)):
    t = np.arange(int(duration * FS)) / FS
    return t, QuarterTruckSimulator(t, speed, np.asarray(x_bounds))


def test_response_psd_matches_closed_form():
    """Welch PSD of the simulated responses sits on |H|^2 Gd(f/v)/v.

    Tolerance: mean ln ratio over ~600 bins (2 sides) between 0.5 and 60 Hz.  Each
    bin of a 1024-sample Welch estimate over 60 s has ~44 degrees of freedom
    (sd of ln about 0.21, bias about -1/44 = -0.023); neighbouring Hann bins are
    correlated, so the mean has sd about 0.02.  0.08 is bias + 3 sd.
    """
    t, sim = _sim()
    P = np.array([[256e-6, 2.0, 0.01, 8.0]])
    out = sim(P, seed=1)
    model = QuarterTruck()
    for q in ("susp_disp", "axle_acc", "body_acc"):
        logs = []
        for side in "LR":
            f, p = welch(out[f"{q}_3{side}"], FS, nperseg=1024)
            sel = (f > 0.5) & (f < 60)
            logs.append(np.log(p[sel] / model.response_psd(f[sel], q, *P[0, :2], 10.0, *P[0, 2:])))
        assert abs(np.mean(logs)) < 0.08, q


def test_linear_in_road_amplitude():
    """Same seed, Gq_n0 times 4: every output exactly twice as large (linear model)."""
    t, sim = _sim(20.0)
    a = sim(np.array([[64e-6, 2.0, 0.05, 5.0]]), seed=3)
    b = sim(np.array([[256e-6, 2.0, 0.05, 5.0]]), seed=3)
    for c in a:
        np.testing.assert_allclose(b[c], 2.0 * a[c], rtol=1e-9, atol=1e-15)


def test_common_random_numbers():
    """Same seed, same bytes; phases do not depend on the parameters: moving nmax
    from 5 to 4 cycles/m (40-50 Hz at 10 m/s) leaves the displacement below
    20 Hz unchanged to 1e-6 of its RMS."""
    t, sim = _sim(20.0)
    P = np.array([[256e-6, 2.0, 0.05, 5.0]])
    a, b = sim(P, seed=5), sim(P, seed=5)
    assert all(np.array_equal(a[c], b[c]) for c in a)
    P2 = P.copy()
    P2[0, 3] = 4.0
    c = sim(P2, seed=5)
    from scipy.signal import butter, sosfiltfilt
    sos = butter(6, 20.0, fs=FS, output="sos")
    da = sosfiltfilt(sos, a["susp_disp_3L"])
    dc = sosfiltfilt(sos, c["susp_disp_3L"])
    assert np.sqrt(np.mean((da - dc) ** 2)) < 1e-3 * np.std(da)
    assert not np.array_equal(a["axle_acc_3L"], c["axle_acc_3L"])


def test_predict_rms_scales_with_sqrt_gq():
    m = QuarterTruck()
    r1 = m.predict_rms(64e-6, 2.0, 10.0)
    r2 = m.predict_rms(256e-6, 2.0, 10.0)
    assert r2 == pytest.approx(2.0 * r1, rel=1e-12)


def test_harmonic_profile_variance():
    """Variance of a synthesised profile = integral of Gd over [nmin, nmax]
    (deterministic amplitudes: exact up to the soft band edges, 1e-3)."""
    n, dx = 1 << 16, 0.01
    ph = np.random.default_rng(0).uniform(0, 2 * np.pi, n // 2 + 1)
    z = harmonic_profile(n, dx, 256e-6, 2.0, 0.05, 5.0, ph)
    expected = 256e-6 * 0.1 ** 2 * (1 / 0.05 - 1 / 5.0)  # int Gq (n/n0)^-2 dn
    assert np.var(z) == pytest.approx(expected, rel=1e-3)


def test_segments_change_level_at_the_boundary():
    """A quiet and a rough segment: the response RMS differs by the sqrt of the
    level ratio (4x Gq -> 2x RMS, within 25% for 15 s windows)."""
    t = np.arange(int(30 * FS)) / FS
    x = travelled_distance(t, 10.0)
    sim = QuarterTruckSimulator(t, 10.0, [0.0, x[t.size // 2], 1e9])
    out = sim(np.array([[64e-6, 2.0, 0.05, 5.0], [1024e-6, 2.0, 0.05, 5.0]]), seed=2)
    s = out["susp_disp_3L"]
    ratio = np.std(s[t.size // 2 + 200:]) / np.std(s[: t.size // 2 - 200])
    assert ratio == pytest.approx(4.0, rel=0.25)


def test_bad_input_refused():
    t, sim = _sim(5.0)
    with pytest.raises(EroadInputError):
        sim(np.array([[256e-6, 2.0, 0.05, 60.0]]), seed=0)  # nmax above the grid Nyquist
    with pytest.raises(EroadInputError):
        sim(np.ones((2, 4)), seed=0)  # two segments for a one-segment layout
    with pytest.raises(EroadInputError):
        QuarterTruckSimulator(t, -1.0, [0.0, 1e9])
