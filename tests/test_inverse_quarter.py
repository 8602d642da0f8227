"""The quarter-truck reference simulator of the inverse fit (inverse.quarter).

Reference values come from outside ``inverse.quarter``: ``tests/_ref_quarter.py``
assembles the 2-DOF quarter car from its parameters (mass, damping and stiffness
matrices, road input through the tyre spring and damper) and answers by a matrix
solve per frequency, by time integration (``scipy.signal.lsim``) and by hand
formulas (natural frequencies, low- and high-frequency limits); plus the physical
laws of a linear model (response proportional to road amplitude, i.e. to
sqrt(Gq_n0)).
"""
import math

import numpy as np
import pytest
from scipy.signal import welch

from _ref_quarter import (QUANTITIES, complex_amplitude, frf_matrix, natural_frequencies,
                          simulate_ode)
from eroad.errors import EroadInputError
from inverse.quarter import (QuarterTruck, QuarterTruckParams, QuarterTruckSimulator, harmonic_profile,
                             travelled_distance)

FS = 200.0


def _sim(duration=60.0, speed=10.0, x_bounds=(0.0, 1e9)):
    t = np.arange(int(duration * FS)) / FS
    return t, QuarterTruckSimulator(t, speed, np.asarray(x_bounds))


def _gd(n, gq, w, nmin, nmax):
    """ISO 8608 one-sided road PSD [m^3] inside the band, 0 outside (n0 = 0.1 cycles/m)."""
    n = np.asarray(n, float)
    return np.where((n >= nmin) & (n <= nmax), gq * (n / 0.1) ** (-w), 0.0)


def test_response_psd_matches_independent_closed_form():
    """Welch PSD of the simulated responses sits on |H_ref|^2 Gd(f/v)/v, with H_ref from the
    matrix solve of tests/_ref_quarter.py (not QuarterTruck.frf).

    Tolerance: mean ln ratio over ~600 bins (2 sides) between 0.5 and 60 Hz.  Each
    bin of a 1024-sample Welch estimate over 60 s has ~44 degrees of freedom
    (sd of ln about 0.21, bias about -1/44 = -0.023); neighbouring Hann bins are
    correlated, so the mean has sd about 0.02.  0.08 is bias + 3 sd.
    """
    t, sim = _sim()
    P = np.array([[256e-6, 2.0, 0.01, 8.0]])
    out = sim(P, seed=1)
    for q in QUANTITIES:
        logs = []
        for side in "LR":
            f, p = welch(out[f"{q}_3{side}"], FS, nperseg=1024)
            sel = (f > 0.5) & (f < 60)
            ref = np.abs(frf_matrix(QuarterTruckParams(), f[sel])[q]) ** 2 * _gd(f[sel] / 10.0, *P[0]) / 10.0
            logs.append(np.log(p[sel] / ref))
        assert abs(np.mean(logs)) < 0.08, q


def test_response_psd_formula_against_matrix_frf():
    """QuarterTruck.response_psd = |H_ref|^2 Gd(f/v) / v exactly (deterministic: 1e-9
    relative, round-off of the 2 x 2 solve), zero outside [nmin v, nmax v]; checked on a
    non-default vehicle and speed so that no default hides a wrong parameter."""
    p = QuarterTruckParams(ms=3000.0, mu=600.0, ks=8e5, cs=2e4, kt=2.5e6, ct=2e3)
    f = np.geomspace(0.05, 80.0, 300)
    v, gq, w, nmin, nmax = 12.5, 256e-6, 1.7, 0.02, 4.0
    for q in QUANTITIES:
        got = QuarterTruck(p).response_psd(f, q, gq, w, v, nmin, nmax)
        ref = np.abs(frf_matrix(p, f)[q]) ** 2 * _gd(f / v, gq, w, nmin, nmax) / v
        np.testing.assert_allclose(got, ref, rtol=1e-9, atol=0.0)
        assert np.all(got[f > nmax * v] == 0.0) and np.any(got > 0)


#: lightly damped and a non-default vehicle for the FRF checks (every parameter differs
#: from the defaults, so a parameter swapped for another one inside ``frf`` shows)
VEHICLES = {"nominal": QuarterTruckParams(),
            "other": QuarterTruckParams(ms=3000.0, mu=600.0, ks=8e5, cs=2e4, kt=2.5e6, ct=2e3)}


@pytest.mark.parametrize("name", sorted(VEHICLES))
def test_frf_against_matrix_solve(name):
    """QuarterTruck.frf equals the FRF of M q'' + C q' + K q = Kr zr + Cr zr' solved as
    (K + i w C - w^2 M) X = Kr + i w Cr at 400 frequencies 0.01 Hz - 1 kHz.  Two
    algebraically equal closed forms: only round-off separates them; 1e-8 relative is
    far above it (measured 3e-11 for susp_disp at 0.01 Hz, where zu - zs cancels to
    1e-5 of zu)."""
    p = VEHICLES[name]
    f = np.geomspace(0.01, 1000.0, 400)
    ref = frf_matrix(p, f)
    for q in QUANTITIES:
        np.testing.assert_allclose(QuarterTruck(p).frf(f, q), ref[q], rtol=1e-8, atol=0.0, err_msg=q)


@pytest.mark.parametrize("freq", [0.7, 2.0, 12.4, 30.0])
def test_frf_against_time_integration(freq):
    """A sine road zr = sin(2 pi f t) through the state-space ODE (scipy lsim, from rest,
    100 samples per period and at least 1 kHz, 12 s): the steady-state complex amplitude
    of every output (least squares over the last 2 s) equals frf(f) times the road's
    complex amplitude -i.  Frequencies: below, at and between the body (2.0 Hz) and axle
    (12.4 Hz) modes and above.

    Tolerance 2e-3 (relative complex error): lsim holds the input linear between
    samples, an error of about (2 pi / 100)^2 / 12 = 3.3e-4 at 100 samples per period
    (measured 2e-6 - 4e-4); the start-up transient decays with the slowest pole's rate
    1.36 1/s to e^-13.6 = 1e-6 by t = 10 s."""
    p = QuarterTruckParams()
    fs_i = max(1000.0, 100.0 * freq)
    t = np.arange(int(12.0 * fs_i)) / fs_i
    w = 2.0 * math.pi * freq
    y = simulate_ode(p, t, np.sin(w * t), w * np.cos(w * t))
    keep = t >= 10.0
    for q in QUANTITIES:
        Y = complex_amplitude(t[keep], y[q][keep], freq)
        H = complex(QuarterTruck(p).frf(freq, q)) * (-1j)  # sin(wt) = Re(-i e^{iwt})
        assert abs(Y / H - 1.0) < 2e-3, (q, Y, H)


def test_frf_static_limit():
    """f -> 0: body and axle follow the road (displacement FRF = acceleration FRF / -(2 pi f)^2
    -> 1, accelerations vanish like (2 pi f)^2), and the suspension is compressed only by
    the body's inertia: ks (zu - zs) = ms zs'' gives susp_disp / zr -> -ms (2 pi f)^2 / ks.
    At f = 1e-3 Hz the next terms are of relative size 2 pi f cs / ks = 1.6e-4 (nominal;
    1.6e-4 for the other vehicle too) and (2 pi f)^2 ms / ks = 1.6e-7, so 1e-3 is 6x the
    largest; at 1e-2 Hz the same holds with 10x larger corrections (1e-2 tolerance)."""
    for p in VEHICLES.values():
        m = QuarterTruck(p)
        for f, tol in ((1e-3, 1e-3), (1e-2, 1e-2)):
            w2 = (2.0 * math.pi * f) ** 2
            assert abs(m.frf(f, "body_acc") / -w2 - 1.0) < tol
            assert abs(m.frf(f, "axle_acc") / -w2 - 1.0) < tol
            assert abs(m.frf(f, "susp_disp") / (-p.ms * w2 / p.ks) - 1.0) < tol


def test_frf_high_frequency_limit():
    """f -> infinity: the tyre damper drives the axle, mu zu'' = ct zr', so zu = ct zr / (mu s)
    (s = i 2 pi f): axle_acc / s -> ct / mu, susp_disp s -> ct / mu (the body stays behind),
    and the suspension damper drives the body, ms zs'' = cs zu': body_acc -> cs ct / (ms mu).
    Without tyre damping the tyre spring drives the axle: axle_acc -> kt / mu, susp_disp
    s^2 -> kt / mu, body_acc s -> cs kt / (ms mu).  At f = 1e7 Hz the next terms are of
    relative size kt / (ct 2 pi f) = 3.2e-5 and (cs + ct) / (mu 2 pi f) = 8e-7, so 1e-3
    bounds them with a wide margin (and is far below any parameter error)."""
    f = 1e7
    s = 2j * math.pi * f
    for p in VEHICLES.values():
        m = QuarterTruck(p)
        assert abs(m.frf(f, "axle_acc") / s / (p.ct / p.mu) - 1.0) < 1e-3
        assert abs(m.frf(f, "susp_disp") * s / (p.ct / p.mu) - 1.0) < 1e-3
        assert abs(m.frf(f, "body_acc") / (p.cs * p.ct / (p.ms * p.mu)) - 1.0) < 1e-3
        p0 = QuarterTruckParams(ms=p.ms, mu=p.mu, ks=p.ks, cs=p.cs, kt=p.kt, ct=0.0)
        m0 = QuarterTruck(p0)
        assert abs(m0.frf(f, "axle_acc") / (p.kt / p.mu) - 1.0) < 1e-3
        assert abs(m0.frf(f, "susp_disp") * s ** 2 / (p.kt / p.mu) - 1.0) < 1e-3
        assert abs(m0.frf(f, "body_acc") * s / (p.cs * p.kt / (p.ms * p.mu)) - 1.0) < 1e-3


def test_frf_peaks_at_the_undamped_natural_frequencies():
    """With light damping (cs = 250, ct = 10 N s/m: damping ratios 2e-3 and 3e-3) every
    |frf| peaks at the undamped natural frequencies of the hand formula (roots of
    ms mu w^4 - (ms (ks + kt) + mu ks) w^2 + ks kt = 0): 2.040 Hz (body) and 12.416 Hz
    (axle) for the nominal masses and springs.  Grid of relative step 1e-5; the damped
    peaks move by about the damping ratio squared (< 1e-5), so 1e-4 bounds both."""
    for base in VEHICLES.values():
        p = QuarterTruckParams(ms=base.ms, mu=base.mu, ks=base.ks, cs=250.0, kt=base.kt, ct=10.0)
        f_body, f_axle = natural_frequencies(p)
        m = QuarterTruck(p)
        for f_n in (f_body, f_axle):
            f = np.geomspace(0.8 * f_n, 1.25 * f_n, int(math.log(1.25 / 0.8) / 1e-5))
            for q in QUANTITIES:
                peak = f[np.argmax(np.abs(m.frf(f, q)))]
                assert abs(peak / f_n - 1.0) < 1e-4, (q, peak, f_n)
    assert natural_frequencies(QuarterTruckParams()) == pytest.approx((2.0402, 12.4158), rel=1e-4)


def test_simulator_against_time_integration():
    """The FFT simulator's record equals the ODE's response to the simulator's own road
    heights (``road_heights``, on its internal grid at 4 x 200 Hz; the record is the last
    N of its samples, decimated by 4), integrated from rest with lsim: two segments, a
    speed varying 7-11 m/s, both sides.

    Tolerance: rms difference < 0.5 % of the channel's rms (measured 1.6e-4 susp_disp,
    3.4e-4 body_acc, 1.2e-3 axle_acc): lsim holds the input linear between the 800 Hz
    samples (attenuation (pi f / 800)^2 / 3 = 0.6 % at nmax v = 33 Hz, the top of the
    road band, where little power lies) and zr' is a central difference (error
    (2 pi f / 800)^2 / 6, on the tyre damper term ct zr' only).  The start-up from rest is
    > 10 s before the record (lead-in).  The last 0.25 s are left out: there the FFT's
    circular wrap (the road jumps from the record's end to the lead-in's start) rings
    into axle_acc (measured up to 0.2 of its sd at the last sample)."""
    t = np.arange(int(10 * FS)) / FS
    speed = 9 + 2 * np.sin(2 * np.pi * t / 10)
    x = travelled_distance(t, speed)
    sim = QuarterTruckSimulator(t, speed, np.array([0.0, x[1000], 1e9]))
    P = np.array([[64e-6, 2.0, 0.05, 3.0], [512e-6, 1.8, 0.1, 3.0]])
    out = sim(P, seed=3)
    zr = sim.road_heights(P, 3)
    m = sim.oversample
    fs_i = FS * m
    ti = np.arange(zr.shape[1]) / fs_i
    first = zr.shape[1] - t.size * m  # the record is the end of the internal grid
    keep = slice(0, t.size - int(0.25 * FS))
    for j, side in enumerate("LR"):
        y = simulate_ode(sim.vehicle, ti, zr[j], np.gradient(zr[j], 1.0 / fs_i))
        for q in QUANTITIES:
            ref = y[q][first::m][keep]
            got = out[f"{q}_3{side}"][keep]
            assert np.std(got - ref) < 5e-3 * np.std(ref), (q, side, np.std(got - ref) / np.std(ref))


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
