"""Figure 11: pantograph-base excitation of the e-tractor, and the kinematics check.

What it is for:

* the **kinematics check** (issue 6, item 1): the four DCDC top points of a simulated
  drive are reduced to the base motion with :mod:`studies.pantograph` and compared
  with the rigid-body motion of the DCDC block read from Exudyn
  (``SimResult.extra["dcdc_ref"]``): the exact method agrees to the precision of
  Exudyn's rigid-body state, the paper's linear method to first order in the angles;
* **Figure 11**: amplitude spectra of roll Rx and pitch Ry (angle, angular velocity,
  angular acceleration) and of the lateral and vertical translations Ty, Tz
  (displacement, velocity, acceleration) of the pantograph base for the tractor driven
  over a road: :func:`compute_figure11` simulates and saves numbers
  (:func:`save_figure11`), :func:`plot_figure11` draws them from the saved files only;
* the **findings table**: the paper's five statements on Figure 11, each judged true or
  false for our model by an explicit quantitative criterion (:data:`CRITERIA`,
  :func:`evaluate_findings`), every peak explained by the nearest mode of
  :mod:`vehicles.modal` and by the resonant mode of an exact modal decomposition of the
  linearised response (:func:`mode_table`, :func:`dominant_mode`).

It also holds the helpers that the chassis-stiffness study (:mod:`studies.chassis_study`)
shares: the tractor variant (:func:`tractor_variant`), one drive with the base motion
(:func:`drive_base_motion`).

What it is not: the kinematics and spectra themselves (:mod:`studies.pantograph`), the
vehicle model (:mod:`vehicles`), the command line (:mod:`studies.cli_pantograph`).
See ``docs/pantograph.md`` for the method, the criteria and the results.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from eroad.errors import EroadInputError, SimulationError
from roadlib.metrics import SHORT_WAVE_ROAD_HINT, road_input_band
from studies.pantograph import (QUANTITIES, amplitude_spectrum, check_points,
                                point_displacements, power_spectrum, solve_base_motion)

__all__ = [
    "DEFAULT_VEHICLE",
    "FIG11_ROWS",
    "CRITERIA",
    "SMOOTH_HZ",
    "PEAK_PROMINENCE",
    "F_MAX",
    "Figure11Data",
    "Finding",
    "development_road",
    "dcdc_points",
    "tractor_variant",
    "max_duration",
    "simulate_tractor",
    "static_dcdc_rotation",
    "reference_motion",
    "kinematics_check",
    "drive_base_motion",
    "mode_table",
    "nearest_mode",
    "dominant_mode",
    "compute_figure11",
    "save_figure11",
    "load_figure11",
    "plot_figure11",
    "smoothing_kernel",
    "smoothed_power",
    "evaluate_findings",
    "findings_markdown",
    "write_findings",
    "run_figure11",
]

#: the vehicle of the pantograph studies
DEFAULT_VEHICLE = "e_tractor"
#: rows of Figure 11: motion component -> the three quantities (order 0, 1, 2)
FIG11_ROWS = {"Rx": ("Rx", "Rx_vel", "Rx_acc"), "Ry": ("Ry", "Ry_vel", "Ry_acc"),
              "Ty": ("Ty", "Ty_vel", "Ty_acc"), "Tz": ("Tz", "Tz_vel", "Tz_acc")}
#: motion components saved as time series
COMPONENTS = ("Ty", "Tz", "Rx", "Ry")
#: order of the characteristic points P1..P4 (sign of x, sign of y), as in
#: ``vehicles.simulate.output_points``
POINT_SIGNS = ((1, 1), (1, -1), (-1, -1), (-1, 1))


# ---------------------------------------------------------------------------
# roads, vehicle variants, one drive
# ---------------------------------------------------------------------------
def development_road(length: float = 320.0, width: float = 3.0, classes: str = "BCD",
                     seed: int = 1, dx: float = 0.05, dy: float = 0.1, nmax: float = 5.0):
    """Segmented ISO 8608 road for development (classes B, C, D in equal shares).

    The synthesis band reaches ``nmax`` = 5 cycles/m (ISO 8608's band ends at 2.83), so
    that at 10 m/s the road excites up to 50 Hz and covers the study's 15-40 Hz band
    (with 2.83 cycles/m every spectrum drops by two decades at 28.3 Hz).

    Parameters
    ----------
    length : float, optional
        Road length [m] (default 320 m: 30 s at 10 m/s plus the tractor's wheelbase).
    width : float, optional
        Road width [m], centred on the vehicle (default 3 m covers the dual tyres).
    classes : str, optional
        ISO class letters of the consecutive segments (default ``"BCD"``).
    seed : int, optional
        Root seed (segment s uses ``SeedSequence(seed, spawn_key=(s,))``).
    dx, dy : float, optional
        Grid spacing [m].
    nmax : float, optional
        Upper spatial frequency of the synthesis [cycles/m] (<= 1 / (2 dx)).

    Returns
    -------
    roadlib.surface.RoadSurface
    """
    from roadlib.segments import RoadSegment, segmented_surface

    segs = [RoadSegment.from_class(c, nmax=float(nmax)) for c in classes]
    return segmented_surface(segs, length=length, width=width, dx=dx, dy=dy, seed=int(seed))


def dcdc_points(vp) -> np.ndarray:
    """Characteristic points P1..P4 of the DCDC top from the vehicle parameters.

    Parameters
    ----------
    vp : vehicles.params.VehicleParams
        Vehicle with a DCDC block (``dcdc.point_x``, ``dcdc.point_y``).

    Returns
    -------
    numpy.ndarray, shape (4, 3)
        ``(x, y, z)`` [m] relative to the centre of the top face (the pantograph base),
        vehicle axes, in channel order P1 (front left), P2 (front right), P3 (rear
        right), P4 (rear left); z = 0 (the points lie on the top face).

    Raises
    ------
    eroad.errors.EroadInputError
        If the vehicle has no DCDC block.
    """
    d = vp.dcdc
    if d is None:
        raise EroadInputError(f"vehicle {vp.id}: no [dcdc] table, so no pantograph base")
    return np.array([[sx * d.point_x, sy * d.point_y, 0.0] for sx, sy in POINT_SIGNS])


def tractor_variant(vehicle: Any = DEFAULT_VEHICLE, mount_factor: float = 1.0,
                    joint_translational_stiffness: float | None = None):
    """The tractor with a scaled DCDC mount stiffness (and optional joint stiffness).

    Parameters
    ----------
    vehicle : str or Path or VehicleParams, optional
        Built-in id, TOML file or parameters (default ``"e_tractor"``).
    mount_factor : float, optional
        Multiplies the vehicle's ``dcdc.mount_stiffness_factor`` [-] (all four mounts,
        all directions; the mount damping keeps its ratio).
    joint_translational_stiffness : float, optional
        Frame-joint translation stiffness [N/m]; default: the vehicle's.

    Returns
    -------
    vehicles.params.VehicleParams
    """
    from vehicles.params import load_vehicle

    vp = load_vehicle(vehicle)
    if vp.dcdc is None:
        raise EroadInputError(f"vehicle {vp.id}: no [dcdc] table, so no pantograph base")
    mount_factor = float(mount_factor)
    if not (math.isfinite(mount_factor) and mount_factor > 0):
        raise EroadInputError(f"DCDC mount stiffness factor must be positive, "
                              f"got {mount_factor!r}")
    vp = replace(vp, dcdc=replace(vp.dcdc, mount_stiffness_factor=vp.dcdc.mount_stiffness_factor
                                  * mount_factor))
    if joint_translational_stiffness is not None:
        vp = replace(vp, frame=replace(vp.frame, joint_translational_stiffness=float(
            joint_translational_stiffness)))
    return vp


def max_duration(road, vp, speed: float) -> float:
    """Longest drive [s] at constant ``speed`` [m/s] that the road covers.

    The first axle starts with the last axle at the road's start and must stay on
    the road (``vehicles.simulate`` refuses shorter roads).

    Parameters
    ----------
    road : roadlib.surface.RoadSurface
    vp : vehicles.params.VehicleParams
    speed : float
        [m/s]

    Returns
    -------
    float
        Duration [s] (a hair below the exact limit).
    """
    usable = road.length - vp.wheelbase_extent - 1e-6
    return max(0.0, usable / float(speed) * (1 - 1e-9))


def simulate_tractor(vp, road, *, speed: float, duration: float, chassis: str = "flexible",
                     frame_factor: float = 1.0, fs_out: float = 200.0, solver: str = "exudyn"):
    """Simulate the tractor (flexible frame scaled by ``frame_factor``, or rigid).

    Parameters
    ----------
    vp : vehicles.params.VehicleParams
    road : roadlib.surface.RoadSurface
    speed : float
        Constant speed [m/s].
    duration : float
        [s]
    chassis : {"flexible", "rigid"}
    frame_factor : float, optional
        Frame stiffness factor [-] (flexible chassis, ``frame_flex`` effect).
    fs_out : float, optional
        Output sample rate [Hz].
    solver : {"exudyn", "linear"}, optional
        Integrator (``vehicles.simulate.simulate``): Exudyn, or the linear model stepped with
        Exudyn's scheme (``vehicles.linear_sim``; the DCDC body and the flexible frame
        included, tyre lift-off corrected), 4-6x faster per drive (measured 2026-11-30, second
        of two runs at 10 m/s: 0.19 -> 0.034 s for 10 s on a class C road; 1.38 -> 0.35 s for
        30 s on a class E road where the tyres are off in 40 % of the samples).

    Returns
    -------
    SimResult

    Raises
    ------
    eroad.errors.SimulationError
        If the solve fails.
    """
    from vehicles.simulate import simulate

    if chassis not in ("flexible", "rigid"):
        raise EroadInputError(f"chassis must be 'flexible' or 'rigid', got {chassis!r}")
    effects = {"frame_flex": {"stiffness_factor": float(frame_factor)}} \
        if chassis == "flexible" else None
    return simulate(vp, road, speed=speed, duration=duration, chassis=chassis, effects=effects,
                    fs_out=fs_out, solver=solver)


def static_dcdc_rotation(vp, chassis: str = "flexible", frame_factor: float = 1.0) -> np.ndarray:
    """Rotation matrix of the DCDC block at static equilibrium on a flat road.

    This is the reference orientation of the outputs of ``vehicles.simulate``
    (the static state of ``vehicles.builder.build_model``).

    Parameters
    ----------
    vp : vehicles.params.VehicleParams
    chassis : {"flexible", "rigid"}
    frame_factor : float, optional
        Frame stiffness factor [-].

    Returns
    -------
    numpy.ndarray, shape (3, 3)
    """
    from vehicles.builder import build_model

    model = build_model(vp, chassis=chassis,
                        stiffness_factor=float(frame_factor) if chassis == "flexible" else 1.0)
    return np.array(model.static["dcdc"][1], dtype=float)


def reference_motion(result) -> dict[str, np.ndarray]:
    """The DCDC top's rigid-body motion read from Exudyn, as Tait-Bryan angles.

    ``SimResult.extra["dcdc_ref"]`` holds the translation of the top-face centre and
    the axial vector ``v = sin(theta) n`` of the rotation from the static pose,
    ``dR = R(t) R0^T`` (the skew part of dR).  dR is rebuilt exactly,
    ``dR = I + [v]x + [v]x^2 / (1 + cos theta)`` with ``cos theta = sqrt(1 - |v|^2)``
    (theta < 90 deg), and decomposed as ``A_x(Rx) A_y(Ry) A_z(Rz)`` (Exudyn's xyz
    Tait-Bryan convention, as :func:`studies.pantograph.rotation_xyz`).

    Parameters
    ----------
    result : vehicles.result.SimResult
        Simulation of a vehicle with a DCDC block.

    Returns
    -------
    dict
        ``Ty, Tz`` [m], ``Rx, Ry, Rz`` [rad] (Tait-Bryan), ``rotvec`` (N, 3) [rad]
        (the axial vector as stored).
    """
    ref = np.asarray(result.extra["dcdc_ref"], dtype=float)
    v = ref[:, 3:6]
    s2 = np.sum(v * v, axis=1)
    if np.any(s2 >= 1.0):
        raise SimulationError("DCDC reference rotation of 90 deg or more: not a small motion")
    c = np.sqrt(1.0 - s2)
    k = np.zeros((v.shape[0], 3, 3))
    k[:, 0, 1], k[:, 0, 2] = -v[:, 2], v[:, 1]
    k[:, 1, 0], k[:, 1, 2] = v[:, 2], -v[:, 0]
    k[:, 2, 0], k[:, 2, 1] = -v[:, 1], v[:, 0]
    d_r = np.eye(3) + k + (k @ k) / (1.0 + c)[:, None, None]
    return {"Ty": ref[:, 1].copy(), "Tz": ref[:, 2].copy(),
            "Rx": np.arctan2(-d_r[:, 1, 2], d_r[:, 2, 2]),
            "Ry": np.arcsin(np.clip(d_r[:, 0, 2], -1.0, 1.0)),
            "Rz": np.arctan2(-d_r[:, 0, 1], d_r[:, 0, 0]),
            "rotvec": v.copy()}


def _point_channels(result, n: int = 4) -> tuple[np.ndarray, np.ndarray]:
    ch = result.channels
    dy = np.column_stack([ch[f"dcdc_y_P{k}"] for k in range(1, n + 1)])
    dz = np.column_stack([ch[f"dcdc_z_P{k}"] for k in range(1, n + 1)])
    return dy, dz


def _solve_exact_with_yaw(points: np.ndarray, dy: np.ndarray, dz: np.ndarray):
    """``solve_base_motion(method="exact", include_yaw=True)``, robust to a small yaw.

    The exact refinement stops when every update is below 1e-13 of its own
    component's largest value; a yaw that is ~15 times smaller than roll and pitch
    has a round-off floor above that (~1.4e-13), so the call raises
    ``SimulationError`` although it has converged.  Then one exact rigid-body pose
    with 0.05 rad about every axis (made with the forward model) is appended as a
    scale anchor and removed from the result; the time steps are solved
    independently, so the other samples are unchanged.

    Returns
    -------
    (BaseMotion, bool)
        The motion (N samples) and whether the anchor was needed.
    """
    try:
        return solve_base_motion(points, dy, dz, method="exact", include_yaw=True), False
    except SimulationError:
        pass
    ay, az = point_displacements(points, 0.0, 0.0, 0.05, 0.05, 0.05, method="exact")
    m = solve_base_motion(points, np.vstack([dy, ay]), np.vstack([dz, az]), method="exact",
                          include_yaw=True)
    cut = slice(0, dy.shape[0])
    return replace(m, Ty=m.Ty[cut], Tz=m.Tz[cut], Rx=m.Rx[cut], Ry=m.Ry[cut], Rz=m.Rz[cut],
                   residual_rms=m.residual_rms[cut]), True


def kinematics_check(result, vp, chassis: str = "flexible", frame_factor: float = 1.0,
                     rotation0: np.ndarray | None = None) -> dict:
    """Compare the base motion from the four DCDC points with Exudyn's rigid-body motion.

    Three comparisons, all against :func:`reference_motion`:

    * ``forward``: the exact rigid-body map of :func:`studies.pantograph.point_displacements`
      applied to the reference motion reproduces the point channels;
    * ``exact``: :func:`studies.pantograph.solve_base_motion` with ``method="exact"`` and
      yaw, points in their static pose ``R0 p_k`` (R0 = static rotation of the block);
    * ``linear``: the paper's method (eq. 9-11): ``method="linear"``, unknowns
      (Ty, Tz, Rx, Ry), points as designed (top face level).

    Parameters
    ----------
    result : vehicles.result.SimResult
        Drive of ``vp`` (with ``chassis`` and ``frame_factor``).
    vp : vehicles.params.VehicleParams
        The parameters actually simulated.
    chassis : {"flexible", "rigid"}
    frame_factor : float, optional
    rotation0 : numpy.ndarray, optional
        Static rotation of the block (default: :func:`static_dcdc_rotation`).

    Returns
    -------
    dict
        ``cond`` (A of the design points, paper unknowns), ``cond_exact`` (static points,
        with yaw), ``points`` [m], ``static_tilt_rad`` (rotation angle of R0),
        ``amplitude`` (max |reference| per component), and for ``exact`` and
        ``linear``: ``max_abs_error`` and ``rel_error`` (max error / max |reference|)
        per component [m, rad, -]; ``forward_max_abs_error`` [m]; ``exact_anchor``
        (see :func:`_solve_exact_with_yaw`).
    """
    pts = dcdc_points(vp)
    r0 = static_dcdc_rotation(vp, chassis, frame_factor) if rotation0 is None else rotation0
    pts_static = pts @ r0.T
    dy, dz = _point_channels(result, pts.shape[0])
    ref = reference_motion(result)
    fy, fz = point_displacements(pts_static, ref["Ty"], ref["Tz"], ref["Rx"], ref["Ry"],
                                 ref["Rz"], method="exact")
    exact, anchored = _solve_exact_with_yaw(pts_static, dy, dz)
    linear = solve_base_motion(pts, dy, dz, method="linear")
    comps = ("Ty", "Tz", "Rx", "Ry")
    amp = {c: float(np.max(np.abs(ref[c]))) for c in comps + ("Rz",)}

    def errors(m, names):
        out_abs = {c: float(np.max(np.abs(getattr(m, c) - ref[c]))) for c in names}
        out_rel = {c: out_abs[c] / amp[c] if amp[c] > 0 else float("nan") for c in names}
        rms = {c: float(np.sqrt(np.mean((getattr(m, c) - ref[c]) ** 2))
                        / np.sqrt(np.mean(ref[c] ** 2))) for c in names}
        return {"max_abs_error": out_abs, "rel_error": out_rel, "rms_rel_error": rms}

    tilt = float(np.arccos(np.clip((np.trace(r0) - 1.0) / 2.0, -1.0, 1.0)))
    return {
        "points": pts.tolist(),
        "cond": check_points(pts),
        "cond_exact": check_points(pts_static, include_yaw=True),
        "static_tilt_rad": tilt,
        "amplitude": amp,
        "forward_max_abs_error": float(max(np.max(np.abs(fy - dy)), np.max(np.abs(fz - dz)))),
        "exact": errors(exact, comps + ("Rz",)),
        "exact_residual_rms_max": float(np.max(exact.residual_rms)),
        "exact_anchor": anchored,
        "linear": errors(linear, comps),
        "linear_residual_rms_max": float(np.max(linear.residual_rms)),
        "max_angle_rad": float(max(amp["Rx"], amp["Ry"], amp["Rz"])),
    }


def drive_base_motion(vp, road, *, speed: float, duration: float, chassis: str = "flexible",
                      frame_factor: float = 1.0, t_skip: float = 1.0, method: str = "linear",
                      check: bool = False, solver: str = "exudyn") -> dict:
    """One drive: simulate, solve the base motion from the DCDC points (paper method).

    Parameters
    ----------
    vp : vehicles.params.VehicleParams
    road : roadlib.surface.RoadSurface
    speed : float
        [m/s]
    duration : float
        Simulated time [s] (``t_skip`` included).
    chassis : {"flexible", "rigid"}
    frame_factor : float, optional
        Frame stiffness factor [-] (flexible).
    t_skip : float, optional
        Leading time [s] left out of the analysis (start-up from rest; default 1 s).
    method : {"linear", "exact"}, optional
        Kinematics method (default the paper's ``"linear"``).
    check : bool, optional
        Also run :func:`kinematics_check` on the drive.
    solver : {"exudyn", "linear"}, optional
        Integrator of the drive (:func:`simulate_tractor`).

    Returns
    -------
    dict
        ``motion`` (:class:`studies.pantograph.BaseMotion`, time from ``t_skip``),
        ``fs`` [Hz], ``meta`` (JSON-able part of ``SimResult.meta``), ``check`` (dict
        or None).
    """
    res = simulate_tractor(vp, road, speed=speed, duration=duration, chassis=chassis,
                           frame_factor=frame_factor, solver=solver)
    pts = dcdc_points(vp)
    dy, dz = _point_channels(res, pts.shape[0])
    keep = res.time >= t_skip - 1e-9
    motion = solve_base_motion(pts, dy[keep], dz[keep], time=res.time[keep] - res.time[keep][0],
                               method=method)
    chk = kinematics_check(res, vp, chassis, frame_factor) if check else None
    meta = {k: v for k, v in res.meta.items() if isinstance(v, (int, float, str, bool))}
    return {"motion": motion, "fs": float(res.sample_rate_hz), "meta": meta, "check": chk}


# ---------------------------------------------------------------------------
# modes
# ---------------------------------------------------------------------------
def mode_table(vp, chassis: str = "flexible", frame_factor: float = 1.0,
               f_max: float = 100.0, speed: float | None = None,
               freqs: np.ndarray | None = None) -> tuple[list[dict], dict | None]:
    """Labelled modes of the configuration (``vehicles.modal``) and their contributions.

    The modal contributions decompose the linear response of each base motion
    component (Ty, Tz, Rx, Ry of the DCDC top-face centre: the linear model's
    ``dcdc_<c>`` outputs) to road input exactly into modes.  With the undamped,
    mass-normalised modes ``Phi`` (all of them, so the transformation is exact) the
    linearised system in modal coordinates is
    ``Phi^T (K + j w D - w^2 M) Phi eta = Phi^T B(w) u`` and the response is
    ``y = sum_j y_j``, ``y_j = (C phi_j) eta_j``.  The road input ``u`` is the left
    and right track, taken as independent with equal spectra (an isotropic road:
    tracks 1.9 m apart are incoherent above ~5 Hz at 10 m/s); every tyre sees its
    track delayed by its distance behind the first axle (``B(w)`` sums
    ``(Bk + j w Bc) exp(j w x_c / v)`` per side).  Tabulated is the size of each mode's
    own contribution relative to the response::

        ratio_j = sqrt(sum_tracks |y_j|^2 / sum_tracks |y|^2)

    A mode resonating at a response peak has a ratio of order 1 there; far from
    their resonances, the quasi-static parts of the low modes can be large and
    cancel each other (ratios above 1), which is why :func:`dominant_mode` looks only
    at modes near the peak.

    Parameters
    ----------
    vp : vehicles.params.VehicleParams
    chassis : {"flexible", "rigid"}
    frame_factor : float, optional
    f_max : float, optional
        Highest natural frequency listed [Hz].
    speed : float, optional
        Vehicle speed [m/s] for the contributions (default: no contributions).
    freqs : numpy.ndarray, optional
        Frequencies of the contributions [Hz] (default 0.1 to 40 Hz every 0.1 Hz).

    Returns
    -------
    (list of dict, dict or None)
        Modes ``{label, freq_hz, damping, freq_damped_hz, freq_undamped_hz}``,
        ascending; contributions ``{"f": (nf,), "ratio": (nf, n_modes, 4),
        "components": ["Ty", "Tz", "Rx", "Ry"], "labels": [...], "freq_hz": [...]}``
        with modes above ``f_max`` (quasi-rigid joints, guides) pooled into one entry
        ``"stiff modes (> f_max)"``; None without ``speed``.
    """
    import scipy.linalg

    from vehicles.modal import modal_analysis

    res = modal_analysis(vp, chassis=chassis,
                         stiffness_factor=float(frame_factor) if chassis == "flexible" else 1.0,
                         f_max=f_max)
    table = res.table()
    if speed is None:
        return table, None
    lm = res.linear
    w2, phi = scipy.linalg.eigh(0.5 * (lm.K + lm.K.T), lm.M)
    f_und = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
    # label every undamped mode by the labelled mode that matched it (freq_undamped_hz)
    labels = [f"stiff modes (> {f_max:g} Hz)"] * len(f_und)
    freq_of = [float("nan")] * len(f_und)
    for m in res.modes:
        j = int(np.argmin(np.abs(f_und - m.freq_undamped_hz)))
        labels[j], freq_of[j] = m.label, float(m.freq_hz)
    groups = sorted(set(labels), key=lambda g: (g.startswith("stiff"), labels.index(g)))
    gidx = np.array([groups.index(g) for g in labels])
    f = np.arange(1, 401) * 0.1 if freqs is None else np.asarray(freqs, float)
    c_phi = np.array([lm.output(f"dcdc_{c}").row for c in COMPONENTS]) @ phi     # (4, n)
    k_m, d_m, m_m = phi.T @ lm.K @ phi, phi.T @ lm.D @ phi, phi.T @ lm.M @ phi
    xs = np.array([c["x"] for c in lm.contacts])
    left = np.array([c["side"] == "L" for c in lm.contacts])
    power = np.zeros((f.size, len(groups), len(COMPONENTS)))
    for i, fi in enumerate(f):
        w = 2 * np.pi * fi
        bw = (lm.Bk + 1j * w * lm.Bc) * np.exp(1j * w * xs / float(speed))[None, :]
        bt = np.column_stack([bw[:, left].sum(axis=1), bw[:, ~left].sum(axis=1)])   # (n, 2)
        eta = np.linalg.solve(k_m + 1j * w * d_m - w * w * m_m, phi.T @ bt)         # (n, 2)
        yj = c_phi[:, :, None] * eta[None, :, :]                                   # (4, n, 2)
        yg = np.zeros((len(COMPONENTS), len(groups), 2), complex)
        np.add.at(yg, (slice(None), gidx), yj)        # modes of one group (stiff) add up
        den = np.sum(np.abs(yj.sum(axis=1)) ** 2, axis=1)                          # (4,)
        power[i] = (np.sum(np.abs(yg) ** 2, axis=2) / np.where(den > 0, den, np.inf)[:, None]).T
    gfreq = [next((freq_of[j] for j in range(len(labels)) if labels[j] == g), float("nan"))
             for g in groups]
    return table, {"f": f, "ratio": np.sqrt(power), "components": list(COMPONENTS),
                   "labels": groups, "freq_hz": gfreq, "speed_mps": float(speed)}


def nearest_mode(freq: float, modes: list[dict]) -> dict | None:
    """The mode whose natural frequency is nearest to ``freq``.

    Parameters
    ----------
    freq : float
        [Hz]
    modes : list of dict
        From :func:`mode_table`.

    Returns
    -------
    dict or None
        ``{label, freq_hz, damping, delta_hz}`` (``delta_hz`` = freq - mode freq), or
        None without modes.
    """
    if not modes or not np.isfinite(freq):
        return None
    m = min(modes, key=lambda m: abs(m["freq_hz"] - freq))
    return {"label": m["label"], "freq_hz": m["freq_hz"], "damping": m["damping"],
            "delta_hz": round(float(freq - m["freq_hz"]), 4)}


def dominant_mode(freq: float, component: str, contributions: dict | None,
                  window: float = 0.25, min_ratio: float = 0.25) -> dict | None:
    """The resonant mode that makes a response peak of a base motion component.

    Among the modes whose natural frequency lies within ``window`` (relative, at
    least 0.5 Hz) of ``freq``, the one with the largest own contribution
    ``ratio_j`` (:func:`mode_table`) at ``freq``, if that is at least ``min_ratio``.

    Parameters
    ----------
    freq : float
        Peak frequency [Hz].
    component : {"Ty", "Tz", "Rx", "Ry"}
    contributions : dict or None
        From :func:`mode_table` (the nearest tabulated frequency is used).
    window : float, optional
        Relative half-width of the search (default 0.25).
    min_ratio : float, optional
        Smallest ratio that counts as making the peak (default 0.25).

    Returns
    -------
    dict or None
        ``{label, freq_hz, ratio}`` (ratio = |own contribution| / |response|); label
        None without a mode near ``freq`` that reaches ``min_ratio`` (the peak is then
        not a resonance:
        quasi-static response, or the road's and the wheelbase's spectral shape); None
        without contributions.
    """
    if not contributions or not np.isfinite(freq):
        return None
    f = np.asarray(contributions["f"])
    i = int(np.argmin(np.abs(f - freq)))
    c = list(contributions["components"]).index(component)
    r = np.asarray(contributions["ratio"])[i, :, c]
    fm = np.asarray(contributions["freq_hz"], float)
    half = max(window * freq, 0.5)
    near = np.isfinite(fm) & (np.abs(fm - freq) <= half)
    j = int(np.flatnonzero(near)[np.argmax(r[near])]) if near.any() else -1
    if j < 0 or r[j] < min_ratio:
        return {"label": None, "freq_hz": float("nan"), "ratio": float("nan")}
    return {"label": str(contributions["labels"][j]), "freq_hz": float(fm[j]),
            "ratio": round(float(r[j]), 4)}


# ---------------------------------------------------------------------------
# Figure 11: compute, save, load, plot
# ---------------------------------------------------------------------------
@dataclass
class Figure11Data:
    """Numbers behind Figure 11 (what is saved and what the plot reads).

    Attributes
    ----------
    time : numpy.ndarray, shape (N,)
        [s] from the start of the analysed record.
    motion : dict
        ``Ty, Tz`` [m], ``Rx, Ry`` [rad], shape (N,) each (paper method, eq. 11).
    fs : float
        Sample rate [Hz].
    f : numpy.ndarray
        Frequencies of the spectra [Hz].
    spectra : dict
        Amplitude spectrum of every :data:`studies.pantograph.QUANTITIES` name
        [rad, rad/s, rad/s^2, m, m/s, m/s^2] (Hann, peak-reading).
    modes : list of dict
        Mode table of the configuration (:func:`mode_table`).
    contributions : dict or None
        Modal contributions to Ty, Tz, Rx, Ry over frequency (:func:`mode_table`).
    check : dict or None
        :func:`kinematics_check` of the same drive.
    meta : dict
        Configuration, road, simulation metadata, notes.
    """

    time: np.ndarray
    motion: dict
    fs: float
    f: np.ndarray
    spectra: dict
    modes: list = field(default_factory=list)
    contributions: dict | None = None
    check: dict | None = None
    meta: dict = field(default_factory=dict)


def compute_figure11(road, *, vehicle: Any = DEFAULT_VEHICLE, speed: float = 10.0,
                     duration: float | None = 30.0, chassis: str = "flexible",
                     frame_factor: float = 1.0, mount_factor: float = 1.0,
                     t_skip: float = 1.0, check: bool = True) -> Figure11Data:
    """Simulate the tractor on a road and compute the Figure-11 spectra.

    Parameters
    ----------
    road : roadlib.surface.RoadSurface
    vehicle : str or Path or VehicleParams, optional
        Default ``"e_tractor"``.
    speed : float, optional
        Constant speed [m/s] (default 10).
    duration : float or None, optional
        Simulated time [s] (default 30; shortened to what the road covers; None: as
        long as the road allows).
    chassis : {"flexible", "rigid"}, optional
    frame_factor, mount_factor : float, optional
        Frame and DCDC mount stiffness factors [-].
    t_skip : float, optional
        Leading time left out [s].
    check : bool, optional
        Run the kinematics check on the drive (default True).

    Returns
    -------
    Figure11Data

    Raises
    ------
    eroad.errors.EroadInputError
        If the road is too short for a drive of at least 5 s after ``t_skip``.
    """
    vp = tractor_variant(vehicle, mount_factor)
    t_max = max_duration(road, vp, speed)
    dur = t_max if duration is None else min(float(duration), t_max)
    if dur - t_skip < 5.0:
        raise EroadInputError(f"road too short: {road.length:.1f} m allow {t_max:.1f} s at "
                              f"{speed:g} m/s, need at least {t_skip + 5.0:g} s")
    d = drive_base_motion(vp, road, speed=speed, duration=dur, chassis=chassis,
                          frame_factor=frame_factor, t_skip=t_skip, check=check)
    m = d["motion"]
    spectra = {}
    f = None
    for name, (comp, order, _, _) in QUANTITIES.items():
        f, spectra[name] = amplitude_spectrum(getattr(m, comp), d["fs"], order=order)
    modes, contrib = mode_table(vp, chassis, frame_factor, speed=speed)
    meta = {"vehicle": vp.id, "chassis": chassis, "frame_factor": float(frame_factor),
            "mount_factor": float(mount_factor), "speed_mps": float(speed),
            "duration_s": float(dur), "t_skip_s": float(t_skip), "fs_hz": d["fs"],
            "method": "linear (paper eq. 9-11)", "points": dcdc_points(vp).tolist(),
            "cond": float(m.cond), "simulation": d["meta"],
            "frame_joint_translational_stiffness": vp.frame.joint_translational_stiffness,
            "road": {k: v for k, v in (road.meta or {}).items()
                     if isinstance(v, (int, float, str, bool))},
            "road_length_m": float(road.length)}
    meta.update(road_input_band(road, speed))
    return Figure11Data(time=m.time, motion={c: getattr(m, c) for c in COMPONENTS},
                        fs=d["fs"], f=f, spectra=spectra, modes=modes, contributions=contrib,
                        check=d["check"], meta=meta)


def save_figure11(data: Figure11Data, folder: str | Path) -> dict[str, Path]:
    """Write the numbers of Figure 11 into ``folder``.

    Files: ``figure11_spectra.npz`` (f, every spectrum, time, motion, fs),
    ``figure11_spectra.csv`` (f and the 12 spectra, unit in each header),
    ``base_motion.csv`` (time, Ty, Tz, Rx, Ry), ``modes.json``,
    ``modal_contributions.npz``, ``figure11_meta.json`` and ``kinematics_check.json``
    (if checked).

    Parameters
    ----------
    data : Figure11Data
    folder : str or Path
        Existing folder (e.g. ``RunArchive.data_dir``).

    Returns
    -------
    dict
        Name -> path of every file written.
    """
    import pandas as pd

    from studies.runs import write_json_atomic

    folder = Path(folder)
    out = {}
    arrays = {"f": data.f, "time": data.time, "fs": np.array(data.fs)}
    arrays.update({f"spec_{k}": v for k, v in data.spectra.items()})
    arrays.update({f"motion_{k}": v for k, v in data.motion.items()})
    out["npz"] = folder / "figure11_spectra.npz"
    np.savez(out["npz"], **arrays)
    cols = {"f [Hz]": data.f}
    for name, (_, _, unit, _) in QUANTITIES.items():
        cols[f"{name} [{unit}]"] = data.spectra[name]
    out["csv"] = folder / "figure11_spectra.csv"
    pd.DataFrame(cols).to_csv(out["csv"], index=False, float_format="%.6e")
    motion = {"time [s]": data.time, "Ty [m]": data.motion["Ty"], "Tz [m]": data.motion["Tz"],
              "Rx [rad]": data.motion["Rx"], "Ry [rad]": data.motion["Ry"]}
    out["motion"] = folder / "base_motion.csv"
    pd.DataFrame(motion).to_csv(out["motion"], index=False, float_format="%.9e")
    out["modes"] = write_json_atomic(folder / "modes.json", data.modes)
    if data.contributions is not None:
        c = data.contributions
        out["contributions"] = folder / "modal_contributions.npz"
        np.savez(out["contributions"], f=c["f"], ratio=np.asarray(c["ratio"], np.float32),
                 components=np.array(c["components"]), labels=np.array(c["labels"]),
                 freq_hz=np.array(c["freq_hz"]), speed_mps=np.array(c["speed_mps"]))
    out["meta"] = write_json_atomic(folder / "figure11_meta.json", data.meta)
    if data.check is not None:
        out["check"] = write_json_atomic(folder / "kinematics_check.json", data.check)
    return out


def load_figure11(folder: str | Path) -> Figure11Data:
    """Read what :func:`save_figure11` wrote.

    Parameters
    ----------
    folder : str or Path

    Returns
    -------
    Figure11Data

    Raises
    ------
    eroad.errors.EroadInputError
        If ``figure11_spectra.npz`` is missing.
    """
    folder = Path(folder)
    path = folder / "figure11_spectra.npz"
    if not path.is_file():
        raise EroadInputError(f"{path}: no Figure-11 data here (run `eroad study pantograph`)")
    with np.load(path, allow_pickle=False) as z:
        spectra = {k[5:]: z[k] for k in z.files if k.startswith("spec_")}
        motion = {k[7:]: z[k] for k in z.files if k.startswith("motion_")}
        data = Figure11Data(time=z["time"], motion=motion, fs=float(z["fs"]), f=z["f"],
                            spectra=spectra)

    def read(name):
        p = folder / name
        return json.loads(p.read_text()) if p.is_file() else None

    data.modes = read("modes.json") or []
    pc = folder / "modal_contributions.npz"
    if pc.is_file():
        with np.load(pc, allow_pickle=False) as z:
            data.contributions = {"f": z["f"], "ratio": z["ratio"].astype(float),
                                  "components": [str(x) for x in z["components"]],
                                  "labels": [str(x) for x in z["labels"]],
                                  "freq_hz": [float(x) for x in z["freq_hz"]],
                                  "speed_mps": float(z["speed_mps"])}
    data.check = read("kinematics_check.json")
    data.meta = read("figure11_meta.json") or {}
    return data


#: modes marked in Figure 11 (label prefixes)
_MARKED_MODES = ("body pitch", "frame torsion", "frame bending", "DCDC")


def plot_figure11(data: Figure11Data | str | Path, path: str | Path, *, f_max: float = 40.0,
                  pdf: bool = True) -> list[Path]:
    """Draw Figure 11 from saved numbers (never simulates).

    Four rows (Rx, Ry, Ty, Tz) by three columns (angle/displacement, velocity,
    acceleration) of amplitude spectra, logarithmic amplitude over 0..``f_max`` Hz, the
    bands of the findings shaded (6-10 Hz, 15-35 Hz) and the frame and DCDC modes
    marked.

    Parameters
    ----------
    data : Figure11Data or str or Path
        Data, or the folder written by :func:`save_figure11`.
    path : str or Path
        PNG file to write (a PDF next to it when ``pdf``).
    f_max : float, optional
        Upper frequency of the plot [Hz].
    pdf : bool, optional
        Also write a PDF.

    Returns
    -------
    list of Path
        Files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not isinstance(data, Figure11Data):
        data = load_figure11(data)
    f = data.f
    sel = (f > 0) & (f <= f_max)
    # smoothed amplitude: the root of the amplitude^2 smoothed like the findings' power
    kernel = smoothing_kernel(f[1] - f[0])
    smooth = {k: np.sqrt(np.convolve(a ** 2, kernel, mode="same"))
              for k, a in data.spectra.items()}
    col_titles = ("angle / displacement", "velocity", "acceleration")
    fig, axes = plt.subplots(4, 3, figsize=(13, 11), sharex=True)
    marks = [m for m in data.modes if m["freq_hz"] <= f_max
             and any(m["label"].startswith(p) for p in _MARKED_MODES)]
    for i, (row, names) in enumerate(FIG11_ROWS.items()):
        for j, name in enumerate(names):
            ax = axes[i, j]
            _, _, unit, label = QUANTITIES[name]
            ax.axvspan(6, 10, color="tab:orange", alpha=0.12, lw=0)
            ax.axvspan(15, 35, color="tab:green", alpha=0.08, lw=0)
            ax.semilogy(f[sel], data.spectra[name][sel], color="tab:blue", lw=0.6, alpha=0.6)
            ax.semilogy(f[sel], smooth[name][sel], color="navy", lw=1.2)
            for m in marks:
                ax.axvline(m["freq_hz"], color="0.4", lw=0.6, ls=":")
            ax.set_ylabel(f"{row}: {label}\n[{unit}]", fontsize=8)
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(labelsize=8)
            if i == 0:
                ax.set_title(col_titles[j], fontsize=10)
            if i == 3:
                ax.set_xlabel("frequency [Hz]")
    axes[0, 0].set_xlim(0, f_max)
    meta = data.meta or {}
    f_top = meta.get("road_input_top_hz")
    if f_top is not None and float(f_top) < f_max:
        for ax in axes.flat:
            ax.axvspan(float(f_top), f_max, color="0.5", alpha=0.15, lw=0, hatch="//")
    from matplotlib.patches import Patch
    from matplotlib.lines import Line2D

    handles = [Line2D([], [], color="tab:blue", lw=0.6, alpha=0.6,
                      label="amplitude spectrum (Hann, peak-reading)"),
               Line2D([], [], color="navy", lw=1.2, label=f"smoothed over {SMOOTH_HZ:g} Hz"),
               Patch(color="tab:orange", alpha=0.3, label="6-10 Hz (findings b, d)"),
               Patch(color="tab:green", alpha=0.2, label="15-35 Hz (finding c)"),
               Line2D([], [], color="0.4", lw=0.6, ls=":", label="modes (below)")]
    if f_top is not None and float(f_top) < f_max:
        handles.append(Patch(facecolor="0.5", alpha=0.3, hatch="//",
                             label=f"no road input (above {float(f_top):.1f} Hz)"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False,
               bbox_to_anchor=(0.5, 0.022))
    fig.text(0.5, 0.004, "modes: " + ", ".join(f"{m['label']} {m['freq_hz']:.1f} Hz"
                                               for m in marks),
             ha="center", va="bottom", fontsize=7, color="0.3", wrap=True)
    fig.suptitle(f"Figure 11: pantograph-base spectra, {meta.get('vehicle', '')} "
                 f"({meta.get('chassis', '')} chassis, frame x{meta.get('frame_factor', 1):g}, "
                 f"mounts x{meta.get('mount_factor', 1):g}), "
                 f"{meta.get('speed_mps', float('nan')):g} m/s, "
                 f"{len(data.time) / data.fs:.0f} s", fontsize=11, y=0.995)
    fig.tight_layout(rect=(0, 0.045, 1, 0.975))
    path = Path(path)
    fig.savefig(path, dpi=110)
    out = [path]
    if pdf:
        fig.savefig(path.with_suffix(".pdf"))
        out.append(path.with_suffix(".pdf"))
    plt.close(fig)
    return out


# ---------------------------------------------------------------------------
# findings
# ---------------------------------------------------------------------------
#: the paper's findings and the criterion each is judged by (P = power spectrum, mean
#: square per bin; P_s = P smoothed over SMOOTH_HZ; f_peak(q) = frequency of the largest
#: P_s of quantity q in (0, F_MAX]; E_q(band) = sum of P over the band).  See
#: docs/pantograph.md for why each threshold has its value.
CRITERIA = {
    "a": ("pitch Ry dominates below 0.5 Hz",
          "E_Ry(<0.5 Hz) / E_Rx(<0.5 Hz) > 1 (pitch angle holds more mean square than roll "
          "angle below 0.5 Hz)"),
    "b": ("angular velocity and acceleration peak in 6-10 Hz (first pitch mode)",
          "6 <= f_peak(Ry_vel) <= 10 Hz and 6 <= f_peak(Ry_acc) <= 10 Hz"),
    "c": ("roll Rx angular acceleration has several peaks in 15-35 Hz",
          ">= 2 local maxima of log10 P_s(Rx_acc) in 15-35 Hz, at least 1 Hz apart, each with "
          "a prominence >= PEAK_PROMINENCE decades (power >= 3.2 x the higher neighbouring "
          "minimum)"),
    "d": ("Tz velocity and acceleration peak in 6-10 Hz together with pitch",
          "6 <= f_peak(Tz_vel), f_peak(Tz_acc) <= 10 Hz and |f_peak(Tz_x) - f_peak(Ry_x)| "
          "<= 1 Hz for x = vel, acc"),
    "e": ("Ty energy lies above 20 Hz",
          "E_Ty_acc(20 Hz-F_MAX) / E_Ty_acc(0-F_MAX) >= 0.5 (lateral acceleration; the "
          "shares of displacement and velocity are reported too)"),
}
#: equivalent smoothing width of the peak search [Hz] (Hann-weighted average of the
#: power, :func:`smoothing_kernel`).  Over a 29 s record it averages ~29 bins: ~58
#: degrees of freedom, a standard deviation of 0.08 in log10 P_s for a random-road response
SMOOTH_HZ = 1.0
#: prominence of a peak in log10 P_s [decades] for finding (c): 0.5 is ~4.5 standard
#: deviations of the difference of two smoothed log values (random peaks are rare)
PEAK_PROMINENCE = 0.5
#: upper frequency of the findings' analysis [Hz] (Figure 11's range, the study bands)
F_MAX = 40.0
#: the frequency band [Hz] each finding's claim is about (what the road must excite for the
#: finding to be judged on a response to the road)
FINDING_BANDS_HZ = {"a": (0.0, 0.5), "b": (6.0, 10.0), "c": (15.0, 35.0), "d": (6.0, 10.0),
                    "e": (20.0, F_MAX)}


def findings_beyond_input(meta: Mapping | None) -> list[str]:
    """The findings whose claimed band (:data:`FINDING_BANDS_HZ`) reaches above the road's
    input (``meta["road_input_top_hz"]``, :func:`road_input_band`); [] where it is not known."""
    top = (meta or {}).get("road_input_top_hz")
    if top is None:
        return []
    return [k for k, (_, hi) in FINDING_BANDS_HZ.items() if hi > float(top)]


def input_band_note(meta: Mapping | None) -> str | None:
    """One sentence for the findings' readers where the road's input ends inside a finding's
    band (None otherwise)."""
    ids = findings_beyond_input(meta)
    if not ids:
        return None
    top, n_top = float(meta["road_input_top_hz"]), float(meta["road_content_top_cpm"])
    bands = ", ".join(f"({k}) {FINDING_BANDS_HZ[k][0]:g}-{FINDING_BANDS_HZ[k][1]:g} Hz" for k in ids)
    return (f"The road holds no wavelength shorter than {1.0 / n_top:.2f} m (content up to "
            f"{n_top:.2f} cycles/m), so at {float(meta.get('speed_mps', float('nan'))):g} m/s its "
            f"input ends at {top:.1f} Hz: above that the spectra are not a response to the road. "
            f"Judged on bands reaching beyond it: {bands} -- read these on a road with shorter "
            f"waves (e.g. `{SHORT_WAVE_ROAD_HINT}`) before drawing a conclusion.")


@dataclass
class Finding:
    """One paper finding judged for our model.

    Attributes
    ----------
    id : str
        ``"a"`` .. ``"e"``.
    claim : str
        The paper's statement.
    criterion : str
        The quantitative criterion (see :data:`CRITERIA`).
    holds : bool
        True if the criterion is met.
    values : dict
        The numbers the criterion was evaluated on.
    peaks : list of dict
        Peaks involved: ``{quantity, freq_hz, mode, dominant}``: the nearest mode
        ``{label, freq_hz, damping, delta_hz}`` (:func:`nearest_mode`) and the
        resonant mode making the peak ``{label, freq_hz, ratio}``
        (:func:`dominant_mode`, None if no mode is near).
    explanation : str
        One-line physical reading.
    """

    id: str
    claim: str
    criterion: str
    holds: bool
    values: dict
    peaks: list = field(default_factory=list)
    explanation: str = ""

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"id": self.id, "claim": self.claim, "criterion": self.criterion,
                "holds": bool(self.holds), "values": self.values, "peaks": self.peaks,
                "explanation": self.explanation}


def smoothing_kernel(df: float, smooth_hz: float = SMOOTH_HZ) -> np.ndarray:
    """Hann-shaped frequency smoothing kernel of equivalent width ``smooth_hz``.

    A Hann kernel of n points averages ``(sum w)^2 / sum w^2 = n / 1.5`` bins
    effectively, so ``n = 1.5 smooth_hz / df`` (odd) gives the variance reduction of a
    ``smooth_hz`` wide moving average, with a single maximum on a spectral line (a
    boxcar would leave a flat top ``smooth_hz`` wide and an uncertain peak frequency).

    Parameters
    ----------
    df : float
        Bin spacing [Hz].
    smooth_hz : float, optional
        Equivalent width [Hz].

    Returns
    -------
    numpy.ndarray
        Kernel weights (sum 1), odd length >= 1.
    """
    n = max(1, int(round(1.5 * smooth_hz / df)))
    n += 1 - n % 2
    w = np.hanning(n + 2)[1:-1]
    return w / w.sum()


def smoothed_power(x: np.ndarray, fs: float, order: int = 0,
                   smooth_hz: float = SMOOTH_HZ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Power spectrum and its smoothed version (for the peak search of the findings).

    Parameters
    ----------
    x : numpy.ndarray, shape (N,)
        Signal (unit U).
    fs : float
        [Hz]
    order : int, optional
        Time-derivative order.
    smooth_hz : float, optional
        Equivalent width of the smoothing [Hz] (:func:`smoothing_kernel`).

    Returns
    -------
    (f, P, P_s)
        Frequencies [Hz], mean square per bin (:func:`studies.pantograph.power_spectrum`)
        and its smoothed version [U^2 / s^(2 order)].
    """
    f, p = power_spectrum(x, fs, order=order)
    ps = np.convolve(p, smoothing_kernel(f[1] - f[0], smooth_hz), mode="same")
    return f, p, ps


def _peak(f, ps, lo=0.0, hi=F_MAX) -> float:
    sel = (f > lo) & (f <= hi)
    return float(f[sel][np.argmax(ps[sel])])


def _band(f, p, lo, hi) -> float:
    return float(np.sum(p[(f >= lo) & (f < hi)]))


def evaluate_findings(motion: Mapping[str, np.ndarray], fs: float, modes: list[dict] | None = None,
                      contributions: dict | None = None, f_max: float = F_MAX,
                      smooth_hz: float = SMOOTH_HZ,
                      prominence: float = PEAK_PROMINENCE) -> list[Finding]:
    """Judge the paper's five Figure-11 findings for a base motion.

    Parameters
    ----------
    motion : Mapping
        ``Ty, Tz`` [m] and ``Rx, Ry`` [rad] time series sampled at ``fs``.
    fs : float
        Sample rate [Hz].
    modes : list of dict, optional
        Mode table (:func:`mode_table`) for the peak explanations (nearest mode).
    contributions : dict, optional
        Modal contributions (:func:`mode_table`) for the dominant mode at each peak.
    f_max : float, optional
        Upper analysis frequency [Hz] (default 40).
    smooth_hz : float, optional
        Smoothing of the peak search [Hz] (default :data:`SMOOTH_HZ`).
    prominence : float, optional
        Peak prominence of finding (c) in decades of power (default
        :data:`PEAK_PROMINENCE`).

    Returns
    -------
    list of Finding
        a..e with the criteria of :data:`CRITERIA` (F_MAX = ``f_max``).
    """
    modes = modes or []
    spec = {}
    for name, (comp, order, _, _) in QUANTITIES.items():
        spec[name] = smoothed_power(np.asarray(motion[comp], float), fs, order, smooth_hz)
    f = spec["Rx"][0]
    df = f[1] - f[0]

    def pk(name, lo=0.0, hi=f_max):
        return _peak(f, spec[name][2], lo, hi)

    def peak_entry(name, freq):
        return {"quantity": name, "freq_hz": round(freq, 4), "mode": nearest_mode(freq, modes),
                "dominant": dominant_mode(freq, QUANTITIES[name][0], contributions)}

    out = []
    # (a) pitch dominates below 0.5 Hz
    e_ry = _band(f, spec["Ry"][1], 0.0, 0.5)
    e_rx = _band(f, spec["Rx"][1], 0.0, 0.5)
    ratio = e_ry / e_rx if e_rx > 0 else float("inf")
    share_ry = e_ry / _band(f, spec["Ry"][1], 0.0, f_max)
    lowest = min((m["freq_hz"] for m in modes), default=float("nan"))
    out.append(Finding(
        "a", CRITERIA["a"][0], CRITERIA["a"][1], bool(ratio > 1.0),
        {"E_Ry_below_0.5Hz_rad2": e_ry, "E_Rx_below_0.5Hz_rad2": e_rx, "ratio": ratio,
         "Ry_share_below_0.5Hz": share_ry, "f_peak_Ry_hz": pk("Ry"), "f_peak_Rx_hz": pk("Rx"),
         "lowest_mode_hz": lowest},
        [peak_entry("Ry", pk("Ry"))],
        "below the lowest mode the body follows long road waves quasi-statically; pitch "
        "follows the wheelbase-filtered road slope, roll the left-right difference"))
    # (b) angular velocity and acceleration of pitch peak in 6-10 Hz
    def in_band_ratio(name, lo=6.0, hi=10.0):
        ps_ = spec[name][2]
        sel = (f > 0) & (f <= f_max)
        return float(np.max(ps_[(f >= lo) & (f <= hi)]) / np.max(ps_[sel]))

    fb = {n: pk(n) for n in ("Ry_vel", "Ry_acc")}
    info = {f"f_peak_{n}_hz": v for n, v in fb.items()}
    info.update({f"{n}_max_6_10Hz_over_max": in_band_ratio(n) for n in fb})
    info.update({f"f_peak_{n}_hz": pk(n) for n in ("Rx_vel", "Rx_acc")})
    out.append(Finding(
        "b", CRITERIA["b"][0], CRITERIA["b"][1], all(6.0 <= v <= 10.0 for v in fb.values()),
        info, [peak_entry(n, v) for n, v in fb.items()],
        "the peak frequency is the nearest lightly damped mode that moves the DCDC in pitch"))
    # (c) several roll-acceleration peaks in 15-35 Hz
    from scipy.signal import find_peaks

    ps = spec["Rx_acc"][2]
    band = (f >= 15.0) & (f <= 35.0)
    idx0 = int(np.argmax(band))
    seg = np.log10(np.maximum(ps[band], np.finfo(float).tiny))
    found, props = find_peaks(seg, prominence=prominence, distance=max(1, int(round(1.0 / df))))
    freqs = [float(f[idx0 + i]) for i in found]
    cand, cprops = find_peaks(seg, prominence=0.1, distance=max(1, int(round(1.0 / df))))
    out.append(Finding(
        "c", CRITERIA["c"][0], CRITERIA["c"][1], len(freqs) >= 2,
        {"n_peaks": len(freqs), "peak_freqs_hz": freqs,
         "prominence_decades": [round(float(p), 3) for p in props.get("prominences", [])],
         "candidates_prominence_0.1_hz": [round(float(f[idx0 + i]), 2) for i in cand],
         "candidates_prominence_decades": [round(float(p), 3)
                                           for p in cprops.get("prominences", [])],
         "share_15_35Hz": _band(f, spec["Rx_acc"][1], 15.0, 35.0)
         / _band(f, spec["Rx_acc"][1], 0.0, f_max)},
        [peak_entry("Rx_acc", v) for v in freqs],
        "each peak is a mode with DCDC roll/lateral or axle tramp/lateral motion"))
    # (d) Tz velocity and acceleration peak in 6-10 Hz together with pitch
    fd = {n: pk(n) for n in ("Tz_vel", "Tz_acc")}
    together = {x: abs(fd[f"Tz_{x}"] - fb[f"Ry_{x}"]) for x in ("vel", "acc")}
    info = {f"f_peak_{n}_hz": v for n, v in fd.items()}
    info.update({f"{n}_max_6_10Hz_over_max": in_band_ratio(n) for n in fd})
    info.update({f"|f_Tz_{x} - f_Ry_{x}|_hz": v for x, v in together.items()})
    out.append(Finding(
        "d", CRITERIA["d"][0], CRITERIA["d"][1],
        all(6.0 <= v <= 10.0 for v in fd.values()) and all(v <= 1.0 for v in together.values()),
        info, [peak_entry(n, v) for n, v in fd.items()],
        "vertical motion of the base and pitch share a mode when the base sits off the "
        "pitch node"))
    # (e) Ty energy above 20 Hz
    shares = {}
    for n in ("Ty", "Ty_vel", "Ty_acc"):
        tot = _band(f, spec[n][1], 0.0, f_max)
        shares[f"{n}_share_20Hz_to_fmax"] = _band(f, spec[n][1], 20.0, f_max) / tot
    fe = pk("Ty_acc", 20.0, f_max)
    out.append(Finding(
        "e", CRITERIA["e"][0], CRITERIA["e"][1], shares["Ty_acc_share_20Hz_to_fmax"] >= 0.5,
        {**shares, "f_peak_Ty_acc_hz": pk("Ty_acc"), "f_peak_Ty_acc_above_20Hz_hz": fe},
        [peak_entry("Ty_acc", pk("Ty_acc")), peak_entry("Ty_acc", fe)],
        "lateral base motion comes from roll of the tall block about the low roll axis and "
        "from the DCDC lateral/roll mount modes"))
    for fd_ in out:
        fd_.criterion = filled_criterion(fd_.criterion, f_max, prominence)
    return out


def filled_criterion(text: str, f_max: float = F_MAX, prominence: float = PEAK_PROMINENCE) -> str:
    """A :data:`CRITERIA` text with its placeholders (F_MAX, PEAK_PROMINENCE) replaced by
    the values used."""
    return text.replace("F_MAX", f"{f_max:g} Hz").replace("PEAK_PROMINENCE", f"{prominence:g}")


def findings_markdown(findings: list[Finding], meta: dict | None = None) -> str:
    """The findings as a markdown table (true/false, criterion, values, modes).

    Parameters
    ----------
    findings : list of Finding
    meta : dict, optional
        Configuration shown above the table.

    Returns
    -------
    str
    """
    lines = ["# Figure 11: the paper's findings for our model", ""]
    if meta:
        lines.append(f"Vehicle {meta.get('vehicle')}, {meta.get('chassis')} chassis, frame "
                     f"stiffness x{meta.get('frame_factor')}, DCDC mounts "
                     f"x{meta.get('mount_factor')}, {meta.get('speed_mps')} m/s, "
                     f"{meta.get('duration_s', 0) - meta.get('t_skip_s', 0):.1f} s analysed.")
        lines.append("")
    note = input_band_note(meta)
    if note:
        lines.append(f"**Road input band.** {note}")
        lines.append("")
    beyond = set(findings_beyond_input(meta))
    lines.append(f"P = power spectrum (mean square per bin), P_s = P smoothed over "
                 f"{SMOOTH_HZ:g} Hz (Hann-weighted), f_peak = frequency of the largest P_s "
                 f"in (0, {F_MAX:g}] Hz, E = band mean square; `X_max_6_10Hz_over_max` = "
                 "largest P_s in 6-10 Hz / largest P_s (1 when the peak is in the band).")
    lines.append("")
    lines.append("Modes: *nearest* = nearest natural frequency; *resonant* = among the modes "
                 "within 25 % (>= 0.5 Hz) of the peak, the one with the largest own "
                 "contribution to the quantity's linear response there, if >= 0.25 (ratio = "
                 "|mode's contribution| / |response|; exact modal decomposition, independent "
                 "left/right tracks with wheelbase delays).")
    lines.append("")
    lines.append("| | paper's finding | for our model | criterion | values | modes at the peaks |")
    lines.append("|---|---|---|---|---|---|")

    def fmt(v):
        if isinstance(v, float):
            return f"{v:.3g}"
        if isinstance(v, list):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return str(v)

    for fd in findings:
        vals = "; ".join(f"{k} = {fmt(v)}" for k, v in fd.values.items())
        mods = "; ".join(
            f"{p['quantity']} {p['freq_hz']:.2f} Hz: nearest {p['mode']['label']} "
            f"{p['mode']['freq_hz']:.2f} Hz"
            + ("" if not p.get("dominant") else
               f", resonant {p['dominant']['label']} {p['dominant']['freq_hz']:.2f} Hz "
               f"(ratio {p['dominant']['ratio']:.2f})" if p["dominant"]["label"]
               else ", no resonance near (quasi-static / spectral shape)")
            for p in fd.peaks if p.get("mode"))
        caveat = (f" (road input ends at {float(meta['road_input_top_hz']):.1f} Hz)"
                  if fd.id in beyond else "")
        lines.append(f"| ({fd.id}) | {fd.claim} | **{'true' if fd.holds else 'false'}**{caveat} | "
                     f"{fd.criterion} | {vals} | {mods or '-'} |")
    lines.append("")
    return "\n".join(lines)


def write_findings(findings: list[Finding], folder: str | Path, meta: dict | None = None
                   ) -> tuple[Path, Path]:
    """Write ``findings.json`` and ``findings.md`` into ``folder``.

    Parameters
    ----------
    findings : list of Finding
    folder : str or Path
    meta : dict, optional

    Returns
    -------
    (Path, Path)
        JSON and markdown files.
    """
    from studies.runs import write_json_atomic

    folder = Path(folder)
    used = {f.id: f.criterion for f in findings}   # filled with the values they were judged by
    pj = write_json_atomic(folder / "findings.json",
                           {"criteria": {k: used.get(k, filled_criterion(v[1]))
                                         for k, v in CRITERIA.items()},
                            "smooth_hz": SMOOTH_HZ, "findings": [f.to_dict() for f in findings]})
    pm = folder / "findings.md"
    tmp = folder / ".findings.md.tmp"
    tmp.write_text(findings_markdown(findings, meta), encoding="utf-8")
    tmp.replace(pm)
    return pj, pm


# ---------------------------------------------------------------------------
# the archived study
# ---------------------------------------------------------------------------
#: study name (folder under the results root)
STUDY = "figure11"


def run_figure11(road_path: str | Path, out_root: str | Path = "results", *,
                 vehicle: Any = DEFAULT_VEHICLE, speed: float = 10.0,
                 duration: float | None = 30.0, chassis: str = "flexible",
                 frame_factor: float = 1.0, mount_factor: float = 1.0, t_skip: float = 1.0,
                 command: list[str] | None = None) -> dict:
    """Figure 11, its findings and the kinematics check on a road file, archived.

    Writes ``<out_root>/figure11/<run-id>/`` with ``data/`` (:func:`save_figure11`,
    ``findings.json``, ``findings.md``), ``figures/figure11.png|pdf`` (drawn from the
    saved data) and ``summary.json``.

    Parameters
    ----------
    road_path : str or Path
        Road file (``.npz`` / ``.crg``).
    out_root : str or Path, optional
        Results root.
    vehicle, speed, duration, chassis, frame_factor, mount_factor, t_skip
        As in :func:`compute_figure11`.
    command : list of str, optional
        Command line recorded in ``run.json`` (default ``sys.argv``).

    Returns
    -------
    dict
        The summary with ``path`` (the run folder).
    """
    from roadlib.surface import RoadSurface

    from studies.runs import RunArchive

    road_path = Path(road_path).resolve()
    road = RoadSurface.load(road_path)
    config = {"road_file": str(road_path), "vehicle": str(vehicle), "speed_mps": float(speed),
              "duration_s": None if duration is None else float(duration), "chassis": chassis,
              "frame_factor": float(frame_factor), "mount_factor": float(mount_factor),
              "t_skip_s": float(t_skip), "method": "linear (paper eq. 9-11)",
              "findings": {"smooth_hz": SMOOTH_HZ, "f_max_hz": F_MAX,
                           "peak_prominence_decades": PEAK_PROMINENCE}}
    with RunArchive(STUDY, config, root=out_root, command=command) as run:
        data = compute_figure11(road, vehicle=vehicle, speed=speed, duration=duration,
                                chassis=chassis, frame_factor=frame_factor,
                                mount_factor=mount_factor, t_skip=t_skip)
        save_figure11(data, run.data_dir)
        saved = load_figure11(run.data_dir)          # findings and plot from the files
        findings = evaluate_findings(saved.motion, saved.fs, saved.modes, saved.contributions)
        write_findings(findings, run.data_dir, saved.meta)
        figs = plot_figure11(saved, run.figures_dir / "figure11.png")
        chk = saved.check or {}
        summary = {
            "study": STUDY, "vehicle": saved.meta.get("vehicle"), "chassis": chassis,
            "frame_factor": float(frame_factor), "mount_factor": float(mount_factor),
            "speed_mps": float(speed), "duration_s": saved.meta.get("duration_s"),
            "cond_A": saved.meta.get("cond"),
            "findings": {f.id: bool(f.holds) for f in findings},
            "findings_claims": {f.id: f.claim for f in findings},
            "road_content_top_cpm": saved.meta.get("road_content_top_cpm"),
            "road_input_top_hz": saved.meta.get("road_input_top_hz"),
            "findings_beyond_road_input": findings_beyond_input(saved.meta),
            "road_input_note": input_band_note(saved.meta),
            "kinematics_check": {
                "cond": chk.get("cond"), "cond_exact_with_yaw": chk.get("cond_exact"),
                "exact_max_rel_error": max(chk["exact"]["rel_error"][c] for c in COMPONENTS)
                if chk else None,
                "linear_max_rel_error": chk["linear"]["rel_error"] if chk else None,
                "forward_max_abs_error_m": chk.get("forward_max_abs_error"),
                "max_angle_rad": chk.get("max_angle_rad")},
            "frame_modes_hz": {m["label"]: m["freq_hz"] for m in saved.modes
                               if m["label"].startswith("frame")},
            "dcdc_modes_hz": {m["label"]: m["freq_hz"] for m in saved.modes
                              if m["label"].startswith("DCDC")},
            "sim_wall_s": saved.meta.get("simulation", {}).get("wall_s"),
            "figures": [str(p.relative_to(run.path)) for p in figs],
        }
        run.write_summary(summary)
    summary["path"] = str(run.path)
    return summary
