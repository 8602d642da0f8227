"""Pantograph-base kinematics and spectra (studies.pantograph).

Tolerances: exact synthetic data are recovered to 1e-12 relative; the
least-squares solve of a system with cond(A) ~ 3 loses at most a few ulps per
operation, so 1e-12 leaves three orders of margin above round-off (~1e-15)
while any modelling error (wrong sign, wrong lever arm) is O(1).
"""
import numpy as np
import pandas as pd
import pytest
from exudyn.rigidBodyUtilities import RotXYZ2RotationMatrix

from eroad.errors import EroadInputError
from studies.pantograph import (BANDS, QUANTITIES, amplitude_spectrum, band_energies,
                                base_motion_from_channels, check_points, kinematics_matrix,
                                motion_band_table, motion_spectra, point_displacements,
                                power_spectrum, rotation_xyz, solve_base_motion)

FS = 200.0
# DCDC top corners, 0.8 m long, 0.6 m wide, 0.1 m above the reference point
POINTS = np.array([[0.4, 0.3, 0.1], [0.4, -0.3, 0.1], [-0.4, 0.3, 0.1], [-0.4, -0.3, 0.1]])


def _motion(t, scale=1.0):
    """Noise-free sinusoids: Ty 31 Hz, Tz 7 Hz, Rx 22 Hz, Ry 0.3 Hz (+ yaw 2 Hz)."""
    return (scale * 1e-3 * np.sin(2 * np.pi * 31 * t),
            scale * 2e-3 * np.cos(2 * np.pi * 7 * t + 0.2),
            scale * 4e-3 * np.sin(2 * np.pi * 22 * t + 1.0),
            scale * 3e-3 * np.sin(2 * np.pi * 0.3 * t),
            scale * 1e-3 * np.sin(2 * np.pi * 2 * t))


def _relerr(est, true):
    return np.max(np.abs(est - true)) / np.max(np.abs(true))


@pytest.mark.parametrize("include_yaw", [False, True])
def test_linear_recovers_exact_synthetic_motion(include_yaw):
    t = np.arange(0, 10, 1 / FS)
    ty, tz, rx, ry, rz = _motion(t)
    rz = rz if include_yaw else 0.0
    dy, dz = point_displacements(POINTS, ty, tz, rx, ry, rz)
    m = solve_base_motion(POINTS, dy, dz, time=t, include_yaw=include_yaw)
    for est, true in ((m.Ty, ty), (m.Tz, tz), (m.Rx, rx), (m.Ry, ry)):
        assert _relerr(est, true) < 1e-12
    if include_yaw:
        assert _relerr(m.Rz, rz) < 1e-12
    else:
        assert m.Rz is None
    assert np.max(m.residual_rms) < 1e-12 * 4e-4
    assert m.Ty.shape == (t.size,) and m.cond == pytest.approx(check_points(POINTS))


def test_exact_method_recovers_finite_rotations_like_exudyn():
    """Displacements made with Exudyn's own rotation matrices (Tait-Bryan xyz)
    for angles up to 0.05 rad are recovered to 1e-12 by method='exact'; the
    linear method is off by O(angle^2) and its error drops 4x when the motion
    halves (small-angle law)."""
    t = np.arange(0, 2, 1 / FS)
    ty, tz, rx, ry, rz = _motion(t, scale=12.0)
    disp = np.empty((t.size, 4, 3))
    for i in range(t.size):
        a = RotXYZ2RotationMatrix([rx[i], ry[i], rz[i]])
        disp[i] = (a @ POINTS.T).T - POINTS
    dy = ty[:, None] + disp[..., 1]
    dz = tz[:, None] + disp[..., 2]
    m = solve_base_motion(POINTS, dy, dz, method="exact", include_yaw=True)
    for est, true in ((m.Ty, ty), (m.Tz, tz), (m.Rx, rx), (m.Ry, ry), (m.Rz, rz)):
        assert _relerr(est, true) < 1e-12
    assert np.max(m.residual_rms) < 1e-15

    errs = []
    for scale in (12.0, 6.0):
        mot = _motion(t, scale)
        dy, dz = point_displacements(POINTS, *mot, method="exact")
        lin = solve_base_motion(POINTS, dy, dz, include_yaw=True)
        errs.append(np.max(np.abs(lin.Ry - mot[3])))
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.05)


def test_signs_match_rigid_rotation():
    """Right-handed x fwd, y left, z up: positive pitch lowers the front,
    positive roll lifts the left side and moves the top to the right, positive
    yaw moves the front to the left; linear model = exact map to O(angle^2)."""
    eps = 1e-6
    front_left_top = np.array([[1.0, 1.0, 1.0], [-1.0, -1.0, 0.0]])
    _, dz = point_displacements(front_left_top, 0, 0, 0, eps)
    assert dz[0, 0] == pytest.approx(-eps)
    dy, dz = point_displacements(front_left_top, 0, 0, eps, 0)
    assert dz[0, 0] == pytest.approx(eps) and dy[0, 0] == pytest.approx(-eps)
    dy, _ = point_displacements(front_left_top, 0, 0, 0, 0, eps)
    assert dy[0, 0] == pytest.approx(eps)
    for angles in ([eps, 0, 0], [0, eps, 0], [0, 0, eps], [eps, -eps, 2 * eps]):
        lin = np.hstack(point_displacements(POINTS, 0, 0, *angles))
        exact = np.hstack(point_displacements(POINTS, 0, 0, *angles, method="exact"))
        assert np.max(np.abs(lin - exact)) < 10 * eps ** 2
    assert np.allclose(rotation_xyz(0.1, -0.2, 0.3), RotXYZ2RotationMatrix([0.1, -0.2, 0.3]),
                       rtol=0, atol=1e-15)


def test_condition_number_of_rectangle_closed_form():
    """Points (+-a, +-b, h): A^T A = 4 blockdiag([[1, -h], [-h, h^2+b^2]], 1, a^2)
    (Tz decoupled), so the singular values are 2, 2a and 2 sqrt(lambda) of the
    2x2 block; with h = 0: cond = max(1, a, b) / min(1, a, b)."""
    for a, b, h in ((0.4, 0.3, 0.1), (0.4, 0.3, 0.0), (2.0, 0.5, 0.0), (0.25, 0.6, -0.2)):
        pts = np.array([[a, b, h], [a, -b, h], [-a, b, h], [-a, -b, h]])
        tr, det = 1 + h * h + b * b, b * b
        lam = np.array([(tr + np.sqrt(tr * tr - 4 * det)) / 2,
                        (tr - np.sqrt(tr * tr - 4 * det)) / 2])
        s = np.concatenate([[2.0, 2 * a], 2 * np.sqrt(lam)])
        assert check_points(pts) == pytest.approx(s.max() / s.min(), rel=1e-12)
        if h == 0:
            assert check_points(pts) == pytest.approx(max(1, a, b) / min(1, a, b), rel=1e-12)
    assert check_points(POINTS) == pytest.approx(3.36992, rel=1e-5)


@pytest.mark.parametrize("pts, why", [
    ([[0.4, 0.3, 0], [0.1, 0.3, 0], [-0.2, 0.3, 0], [-0.4, 0.3, 0]], "rank"),   # line along x
    ([[0.4, 0.3, 0], [0.4, 0.1, 0], [0.4, -0.2, 0], [0.4, -0.3, 0]], "rank"),   # line along y
    ([[0.4, 0.3, 0.1]] * 4, "rank"),                                              # coincident
    ([[0.4, 0.3, 0], [0.1, 0.3 + 1e-5, 0], [-0.4, 0.3, 0]], "condition"),       # near line
    ([[1e-5, 0.3, 0], [0, -0.3, 0.2]], "condition"),                              # 2 pts, tiny x
    ([[0.4, 0.3, 0], [-0.4, -0.3, 0]], "rank"),                          # 2 pts, same height
])
def test_degenerate_point_sets_refused(pts, why):
    with pytest.raises(EroadInputError, match=why):
        check_points(pts)
    with pytest.raises(EroadInputError, match=why):
        solve_base_motion(pts, np.zeros((3, len(pts))), np.zeros((3, len(pts))))


def test_yaw_needs_spread_in_x_and_threshold_is_a_parameter():
    same_x = [[0.4, 0.3, 0.0], [0.4, -0.3, 0.0], [0.4, 0.0, 0.5]]
    check_points(same_x[:2] + [[-0.4, 0.0, 0.0]])
    with pytest.raises(EroadInputError, match="rank"):
        check_points(same_x, include_yaw=True)
    with pytest.raises(EroadInputError, match="condition"):
        check_points(POINTS, max_cond=3.0)
    assert kinematics_matrix(POINTS, include_yaw=True).shape == (8, 5)


def test_bad_inputs_name_point_and_row():
    dy = np.zeros((5, 4))
    bad = dy.copy()
    bad[3, 2] = np.nan
    with pytest.raises(EroadInputError, match="P3 at row 3"):
        solve_base_motion(POINTS, bad, dy)
    with pytest.raises(EroadInputError, match=r"\(N, 4\)"):
        solve_base_motion(POINTS, np.zeros((5, 3)), np.zeros((5, 3)))
    with pytest.raises(EroadInputError, match=r"\(n, 3\)"):
        check_points(np.zeros((4, 2)))
    with pytest.raises(EroadInputError, match="time"):
        solve_base_motion(POINTS, dy, dy, time=np.arange(4))
    one = solve_base_motion(POINTS, np.full(4, 1e-3), np.zeros(4))   # one time step
    assert one.Ty.shape == (1,) and one.Ty[0] == pytest.approx(1e-3, rel=1e-12)
    assert abs(one.Rx[0]) < 1e-15 and abs(one.Ry[0]) < 1e-15


def test_from_channels():
    t = np.arange(0, 1, 1 / FS)
    mot = _motion(t)[:4]
    dy, dz = point_displacements(POINTS, *mot)
    frame = pd.DataFrame({"time": t, **{f"dcdc_y_P{k + 1}": dy[:, k] for k in range(4)},
                          **{f"dcdc_z_P{k + 1}": dz[:, k] for k in range(4)}})
    m = base_motion_from_channels(frame, POINTS)
    assert _relerr(m.Rx, mot[2]) < 1e-12 and np.array_equal(m.time, t)
    assert list(m.to_dataframe().columns) == ["time", "Ty", "Tz", "Rx", "Ry", "residual_rms"]
    with pytest.raises(EroadInputError, match="missing channel dcdc_z_P3"):
        base_motion_from_channels(frame.drop(columns="dcdc_z_P3"), POINTS)


# --- spectra ------------------------------------------------------------------
def test_amplitude_of_bin_centred_sinusoid_and_derivatives():
    """Hann, periodic window: a sinusoid on bin k reads its amplitude exactly
    (the Hann DFT has only bins 0, +-1); derivatives scale by (2 pi f)^n."""
    n, f0, a = 4000, 7.0, 2.5e-3                # df = 0.05 Hz, 7 Hz is bin 140
    t = np.arange(n) / FS
    x = a * np.sin(2 * np.pi * f0 * t + 0.4)
    f, amp = amplitude_spectrum(x, FS)
    k = int(np.argmax(amp))
    assert f[k] == f0 and amp[k] == pytest.approx(a, rel=1e-12)
    for order in (1, 2):
        _, d = amplitude_spectrum(x, FS, order=order)
        assert d[k] == pytest.approx(a * (2 * np.pi * f0) ** order, rel=1e-12)
    _, boxcar = amplitude_spectrum(x, FS, window="boxcar")
    assert boxcar[k] == pytest.approx(a, rel=1e-12)
    assert np.max(np.delete(boxcar, k)) < 1e-12 * a      # no leakage on bin


def test_parseval():
    """Boxcar: sum of the power spectrum = mean square exactly; and
    A_k^2 / 2 (A_0^2 at DC and Nyquist) = P_k.  Hann: sum = sum(w^2 x^2) /
    sum(w^2) exactly."""
    rng = np.random.default_rng(np.random.SeedSequence(11))
    from scipy.signal import get_window
    for n in (1000, 1001):
        x = rng.standard_normal(n) + 0.3
        _, p = power_spectrum(x, FS, window="boxcar", detrend=None)
        assert p.sum() == pytest.approx(np.mean(x ** 2), rel=1e-12)
        _, amp = amplitude_spectrum(x, FS, window="boxcar", detrend=None)
        expect = amp ** 2 / 2
        expect[0] = amp[0] ** 2
        if n % 2 == 0:
            expect[-1] = amp[-1] ** 2
        assert np.allclose(p, expect, rtol=1e-12, atol=0)
        w = get_window("hann", n, fftbins=True)
        xd = x - np.sum(w * x) / np.sum(w)         # detrend="mean" is window-weighted
        _, ph = power_spectrum(x, FS)
        assert ph.sum() == pytest.approx(np.sum(w ** 2 * xd ** 2) / np.sum(w ** 2), rel=1e-12)


@pytest.mark.parametrize("f0, band", [(0.33, "<0.5"), (2.17, "0.5-5"), (8.03, "5-15"),
                                      (14.83, "5-15"), (27.43, "15-40")])
def test_band_energy_of_sinusoid(f0, band):
    """A sinusoid a sin(2 pi f0 t) between bins (20 s, df = 0.05 Hz) puts all
    but 1e-4 of its energy in its band.  Hann side lobes decay as
    (f - f0)^-6 in power; 0.33 and 14.83 Hz sit 3.4 bins from a band edge,
    where the leakage is 6e-5 (the worst case here).  The total is a^2/2
    within 1e-4: it is the Hann^2-weighted mean square, whose error term is
    the leakage of the w^2 window at 2 f0 >= 13 bins (measured < 2e-5)."""
    a = 1e-3
    t = np.arange(0, 20, 1 / FS)
    x = a * np.sin(2 * np.pi * f0 * t + 0.3)
    e = band_energies(x, FS)
    assert list(e) == ["<0.5", "0.5-5", "5-15", "15-40"]
    total = sum(e.values())
    assert e[band] / total > 1 - 1e-4
    assert total == pytest.approx(a * a / 2, rel=1e-4)
    # acceleration: each bin weighted by (2 pi f)^4; over the Hann main lobe
    # (f0 +- 2 df) that is (2 pi f0)^4 (1 + 6 <(f - f0)^2> / f0^2), and
    # <(f - f0)^2> < df^2, hence the tolerance 6 (df / f0)^2
    df = FS / t.size
    e2 = band_energies(x, FS, order=2)
    assert e2[band] == pytest.approx(e[band] * (2 * np.pi * f0) ** 4,
                                     rel=6 * (df / f0) ** 2 + 1e-9)


def test_motion_spectra_and_band_table():
    t = np.arange(0, 20, 1 / FS)
    ty, tz, rx, ry, _ = _motion(t)
    dy, dz = point_displacements(POINTS, ty, tz, rx, ry)
    m = solve_base_motion(POINTS, dy, dz, time=t)
    spec = motion_spectra(m)
    assert set(spec) == {"f"} | set(QUANTITIES)
    f = spec["f"]
    assert f[np.argmax(spec["Ry"])] == pytest.approx(0.3)
    assert f[np.argmax(spec["Rx_acc"])] == pytest.approx(22.0)
    assert f[np.argmax(spec["Tz_vel"])] == pytest.approx(7.0)
    table = motion_band_table(m)
    assert list(table.columns) == ["<0.5", "0.5-5", "5-15", "15-40", "unit"]
    dominant = table.drop(columns="unit").astype(float).idxmax(axis=1)
    assert dominant["Ry"] == "<0.5" and dominant["Tz_acc"] == "5-15"
    assert dominant["Rx_vel"] == "15-40" and dominant["Ty"] == "15-40"
    assert table.loc["Ty_acc", "unit"] == "(m/s^2)^2"
    with pytest.raises(EroadInputError, match="fs"):
        motion_spectra(solve_base_motion(POINTS, dy, dz))
    assert BANDS[0] == (0.0, 0.5)


def test_exact_refinement_reports_non_convergence():
    """With one Gauss-Newton iteration allowed, finite angles (0.05 rad) cannot
    reach round-off: a SimulationError names the iterations, not a silent
    inaccurate answer."""
    from eroad.errors import SimulationError
    t = np.arange(0, 1, 1 / FS)
    dy, dz = point_displacements(POINTS, *_motion(t, 12.0), method="exact")
    with pytest.raises(SimulationError, match="1 iterations"):
        solve_base_motion(POINTS, dy, dz, include_yaw=True, method="exact", max_iter=1)
    with pytest.raises(EroadInputError, match="method"):
        solve_base_motion(POINTS, dy, dz, method="quadratic")
