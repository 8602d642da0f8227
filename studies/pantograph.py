"""Pantograph-base kinematics (paper eq. 9-11) and its spectra.

The pantograph stands on the DCDC converter box.  The lateral (Y) and vertical
(Z) displacements of a few characteristic points on the box top (channels
``dcdc_y_P<k>``, ``dcdc_z_P<k>``) are reduced, at every time step, to the small
rigid-body motion of the box top at a reference point (the pantograph base)::

    X = (Ty, Tz, Rx, Ry)        [m, m, rad, rad]

Vehicle frame: x forward, y left, z up (ISO 8855), right-handed.  A point at
``p_k = (x_k, y_k, z_k)`` relative to the reference point moves, for a small
rotation vector ``r = (Rx, Ry, Rz)`` and translation ``T``, by
``T + r x p_k``, whose Y and Z components are::

    dY_k = Ty            - Rx z_k           + Rz x_k
    dZ_k =      Tz + Rx y_k - Ry x_k

Positive Rx (roll) lifts the left side, positive Ry (pitch) lowers the front.
Stacking the Y rows of all points above their Z rows gives ``D = A X`` with
``A`` of shape (2n, 4) and ``D`` of shape (2n, N) for N time steps, solved by
one least-squares call for all steps.  Yaw Rz is not in the paper's X: by
default it is left out (it leaks into the estimates only through
``sum_k x_k z_k`` and ``sum_k x_k``, both zero for points on a level top
centred on the reference point in x); ``include_yaw=True`` adds it as a fifth
unknown.  ``method="exact"`` refines the linear solution by Gauss-Newton on the
finite rigid-body map ``d_k = T + (A_xyz - I) p_k`` with Exudyn's Tait-Bryan
angles ``A_xyz = A_x(Rx) A_y(Ry) A_z(Rz)``, so that it agrees with a rigid
Exudyn body to round-off also for finite angles.

The second half of the module holds spectra: single-sided amplitude spectra
(peak-reading, Hann window), mean-square power spectra (Parseval-exact), band
energies, with derivatives taken in the frequency domain.  See
``docs/studies.md`` for the equations and scalings.

This module does not simulate: it takes displacements (measured or from a
``SimResult``) and returns the base motion and its spectra.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from eroad.errors import EroadInputError, SimulationError

__all__ = [
    "DEFAULT_MAX_COND",
    "BANDS",
    "QUANTITIES",
    "BaseMotion",
    "kinematics_matrix",
    "check_points",
    "point_displacements",
    "rotation_xyz",
    "solve_base_motion",
    "base_motion_from_channels",
    "amplitude_spectrum",
    "power_spectrum",
    "band_energies",
    "band_label",
    "motion_spectra",
    "motion_band_table",
]

#: largest accepted 2-norm condition number of A (points in metres)
DEFAULT_MAX_COND = 1.0e3

#: frequency bands [Hz] of the chassis-stiffness study, half-open [lo, hi)
BANDS: tuple[tuple[float, float], ...] = ((0.0, 0.5), (0.5, 5.0), (5.0, 15.0), (15.0, 40.0))

#: spectra quantities: name -> (motion component, time-derivative order, unit, label)
QUANTITIES: dict[str, tuple[str, int, str, str]] = {
    "Rx": ("Rx", 0, "rad", "roll angle"),
    "Rx_vel": ("Rx", 1, "rad/s", "roll angular velocity"),
    "Rx_acc": ("Rx", 2, "rad/s^2", "roll angular acceleration"),
    "Ry": ("Ry", 0, "rad", "pitch angle"),
    "Ry_vel": ("Ry", 1, "rad/s", "pitch angular velocity"),
    "Ry_acc": ("Ry", 2, "rad/s^2", "pitch angular acceleration"),
    "Ty": ("Ty", 0, "m", "lateral displacement"),
    "Ty_vel": ("Ty", 1, "m/s", "lateral velocity"),
    "Ty_acc": ("Ty", 2, "m/s^2", "lateral acceleration"),
    "Tz": ("Tz", 0, "m", "vertical displacement"),
    "Tz_vel": ("Tz", 1, "m/s", "vertical velocity"),
    "Tz_acc": ("Tz", 2, "m/s^2", "vertical acceleration"),
}


# ---------------------------------------------------------------------------
# geometry: A, its condition, forward model
# ---------------------------------------------------------------------------
def _as_points(points: Any) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 2:
        raise EroadInputError(f"pantograph points: expected an (n, 3) array of (x, y, z) [m] "
                              f"with n >= 2, got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        row = int(np.argwhere(~np.isfinite(p))[0, 0])
        raise EroadInputError(f"pantograph points: point P{row + 1} has a non-finite coordinate")
    return p


def kinematics_matrix(points: Any, include_yaw: bool = False) -> np.ndarray:
    """Matrix A of the linear point-displacement model ``D = A X`` (eq. 10).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Characteristic points ``(x_k, y_k, z_k)`` [m] in the vehicle frame (x
        forward, y left, z up) relative to the reference point (pantograph
        base), n >= 2.
    include_yaw : bool, optional
        Add yaw Rz as a fifth unknown (default False, as in the paper).

    Returns
    -------
    numpy.ndarray, shape (2n, 4) or (2n, 5)
        Rows ``0..n-1``: dY_k = Ty - Rx z_k (+ Rz x_k); rows ``n..2n-1``:
        dZ_k = Tz + Rx y_k - Ry x_k.  Columns: Ty [-], Tz [-], Rx [m/rad],
        Ry [m/rad] (, Rz [m/rad]).
    """
    p = _as_points(points)
    n = p.shape[0]
    x, y, z = p.T
    m = 5 if include_yaw else 4
    a = np.zeros((2 * n, m))
    a[:n, 0] = 1.0
    a[:n, 2] = -z
    a[n:, 1] = 1.0
    a[n:, 2] = y
    a[n:, 3] = -x
    if include_yaw:
        a[:n, 4] = x
    return a


def check_points(points: Any, include_yaw: bool = False,
                 max_cond: float = DEFAULT_MAX_COND) -> float:
    """Condition number of A; refuse degenerate point sets.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Characteristic points [m] relative to the reference point.
    include_yaw : bool, optional
        Whether yaw Rz is an unknown (default False).
    max_cond : float, optional
        Largest accepted condition number (default :data:`DEFAULT_MAX_COND`,
        1e3).  A relative error e in the displacements gives a relative error
        of at most ``cond * e`` in X; the value depends on the length unit
        (metres here) because A mixes [-] and [m/rad] columns.

    Returns
    -------
    float
        The 2-norm condition number ``s_max / s_min`` of A [-].

    Raises
    ------
    eroad.errors.EroadInputError
        If A has rank below its number of columns (e.g. all points on one
        line along x, or along y, or coincident) or its condition number
        exceeds ``max_cond``.
    """
    a = kinematics_matrix(points, include_yaw)
    s = np.linalg.svd(a, compute_uv=False)
    m = a.shape[1]
    tol = s[0] * max(a.shape) * np.finfo(float).eps
    rank = int(np.sum(s > tol))
    names = "(Ty, Tz, Rx, Ry, Rz)" if include_yaw else "(Ty, Tz, Rx, Ry)"
    if rank < m:
        raise EroadInputError(
            f"pantograph points are degenerate: A has rank {rank} < {m}, so {names} cannot "
            "be separated (points collinear or coincident; need a spread in x and in y"
            f"{' and x for yaw' if include_yaw else ''})")
    cond = float(s[0] / s[-1])
    if not cond <= max_cond:
        raise EroadInputError(
            f"pantograph points are nearly degenerate: condition number of A {cond:.3g} > "
            f"{max_cond:.3g} (spread the points further apart in x and y)")
    return cond


def rotation_xyz(rx: Any, ry: Any, rz: Any = 0.0) -> np.ndarray:
    """Rotation matrices ``A_x(rx) A_y(ry) A_z(rz)`` (Tait-Bryan xyz, as
    Exudyn's ``RotXYZ2RotationMatrix``), vectorised.

    Parameters
    ----------
    rx, ry, rz : array_like
        Angles [rad], broadcast against each other.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Rotation matrices.
    """
    rx, ry, rz = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (rx, ry, rz)))
    c0, s0, c1, s1, c2, s2 = (np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry),
                              np.cos(rz), np.sin(rz))
    out = np.empty(rx.shape + (3, 3))
    out[..., 0, 0] = c1 * c2
    out[..., 0, 1] = -c1 * s2
    out[..., 0, 2] = s1
    out[..., 1, 0] = s0 * s1 * c2 + c0 * s2
    out[..., 1, 1] = -s0 * s1 * s2 + c0 * c2
    out[..., 1, 2] = -s0 * c1
    out[..., 2, 0] = -c0 * s1 * c2 + s0 * s2
    out[..., 2, 1] = c0 * s1 * s2 + s0 * c2
    out[..., 2, 2] = c0 * c1
    return out


def point_displacements(points: Any, Ty: Any, Tz: Any, Rx: Any, Ry: Any, Rz: Any = 0.0,
                        method: str = "linear") -> tuple[np.ndarray, np.ndarray]:
    """Forward model: Y and Z displacements of the points for a given motion.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Points [m] relative to the reference point.
    Ty, Tz : array_like, shape (N,) or scalar
        Translations of the reference point [m].
    Rx, Ry, Rz : array_like, shape (N,) or scalar
        Roll, pitch, yaw [rad] (rotation vector for ``"linear"``, Tait-Bryan
        xyz angles for ``"exact"``).
    method : {"linear", "exact"}
        ``"linear"``: ``T + r x p`` (eq. 9); ``"exact"``: ``T + (A_xyz - I) p``.

    Returns
    -------
    dY, dZ : numpy.ndarray, shape (N, n)
        Lateral and vertical displacement of each point [m].
    """
    p = _as_points(points)
    ty, tz, rx, ry, rz = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=float)) for v in (Ty, Tz, Rx, Ry, Rz)))
    if method == "linear":
        x, y, z = p.T
        dy = ty[:, None] - rx[:, None] * z + rz[:, None] * x
        dz = tz[:, None] + rx[:, None] * y - ry[:, None] * x
    elif method == "exact":
        rot = rotation_xyz(rx, ry, rz)                      # (N, 3, 3)
        moved = np.einsum("tij,kj->tki", rot, p) - p        # (N, n, 3)
        dy = ty[:, None] + moved[..., 1]
        dz = tz[:, None] + moved[..., 2]
    else:
        raise ValueError(f"method must be 'linear' or 'exact', not {method!r}")
    return dy, dz


# ---------------------------------------------------------------------------
# solving for the base motion
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class BaseMotion:
    """Rigid-body motion of the pantograph base over time.

    Attributes
    ----------
    Ty, Tz : numpy.ndarray, shape (N,)
        Lateral and vertical translation of the reference point [m].
    Rx, Ry : numpy.ndarray, shape (N,)
        Roll and pitch [rad].
    Rz : numpy.ndarray or None
        Yaw [rad] when solved for (``include_yaw=True``), else None.
    time : numpy.ndarray or None
        Time [s], shape (N,), if given.
    cond : float
        Condition number of A [-].
    residual_rms : numpy.ndarray, shape (N,)
        RMS over the 2n equations of the misfit ``model(X) - D`` [m]: zero
        (round-off) for a rigid top, larger for deformation, noise, or yaw
        when yaw is not solved for.
    points : numpy.ndarray, shape (n, 3)
        The points used [m].
    method : str
        ``"linear"`` or ``"exact"``.
    """

    Ty: np.ndarray
    Tz: np.ndarray
    Rx: np.ndarray
    Ry: np.ndarray
    Rz: np.ndarray | None
    time: np.ndarray | None
    cond: float
    residual_rms: np.ndarray
    points: np.ndarray = field(repr=False)
    method: str = "linear"

    #: units of the components
    units = {"time": "s", "Ty": "m", "Tz": "m", "Rx": "rad", "Ry": "rad", "Rz": "rad",
             "residual_rms": "m"}

    def as_dict(self) -> dict[str, np.ndarray]:
        """Components as ``{name: array}`` (time first if present, Rz only if solved)."""
        out: dict[str, np.ndarray] = {}
        if self.time is not None:
            out["time"] = self.time
        out.update(Ty=self.Ty, Tz=self.Tz, Rx=self.Rx, Ry=self.Ry)
        if self.Rz is not None:
            out["Rz"] = self.Rz
        out["residual_rms"] = self.residual_rms
        return out

    def to_dataframe(self):
        """Components as a pandas DataFrame (one column each, SI units).

        Returns
        -------
        pandas.DataFrame
        """
        import pandas as pd

        return pd.DataFrame(self.as_dict())


def _as_series(name: str, values: Any, n_points: int) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.ndim == 1 and v.shape[0] == n_points:
        v = v[None, :]
    if v.ndim != 2 or v.shape[1] != n_points:
        raise EroadInputError(f"{name}: expected shape (N, {n_points}) = (time steps, points), "
                              f"got {np.shape(values)}")
    bad = ~np.isfinite(v)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise EroadInputError(f"{name}: non-finite value for point P{col + 1} at row {row}")
    return v


def solve_base_motion(points: Any, dY: Any, dZ: Any, *, time: Any = None,
                      include_yaw: bool = False, method: str = "linear",
                      max_cond: float = DEFAULT_MAX_COND, max_iter: int = 20) -> BaseMotion:
    """Solve ``A X = D`` for the base motion at all time steps at once (eq. 11).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Characteristic points [m] relative to the reference point (vehicle
        frame x forward, y left, z up), n >= 2 (the paper uses 4).
    dY, dZ : array_like, shape (N, n)
        Lateral and vertical displacement of each point from its static
        position [m]; column k is point k.  Shape (n,) is one time step.
    time : array_like, shape (N,), optional
        Time [s], stored in the result (for spectra).
    include_yaw : bool, optional
        Solve for yaw Rz too (default False, as in the paper).
    method : {"linear", "exact"}, optional
        ``"linear"`` (default, the paper): one least-squares solve
        ``X = lstsq(A, D)`` for the (4, N) right-hand side.  ``"exact"``:
        start from it and iterate Gauss-Newton on the finite rigid-body map
        with Tait-Bryan xyz angles (all time steps at once), until the update
        is at round-off (1e-13 of each
        component's largest value over the record).
    max_cond : float, optional
        Refuse point sets whose A has a larger condition number (default 1e3).
    max_iter : int, optional
        Gauss-Newton iterations allowed for ``"exact"`` (default 20).

    Returns
    -------
    BaseMotion
        Ty, Tz [m], Rx, Ry (, Rz) [rad] per time step, cond(A), residual RMS.

    Raises
    ------
    eroad.errors.EroadInputError
        Degenerate or ill-conditioned points, shapes that do not match,
        non-finite displacements (naming point and row).
    eroad.errors.SimulationError
        If the exact refinement does not converge (angles far beyond the
        small-motion range).
    """
    if method not in ("linear", "exact"):
        raise EroadInputError(f"pantograph kinematics: method must be 'linear' or 'exact', "
                              f"not {method!r}")
    p = _as_points(points)
    n = p.shape[0]
    cond = check_points(p, include_yaw, max_cond)
    a = kinematics_matrix(p, include_yaw)
    dy = _as_series("dY", dY, n)
    dz = _as_series("dZ", dZ, n)
    if dy.shape != dz.shape:
        raise EroadInputError(f"dY has shape {dy.shape} but dZ has shape {dz.shape}")
    t = None
    if time is not None:
        t = np.asarray(time, dtype=float)
        if t.shape != (dy.shape[0],):
            raise EroadInputError(f"time: expected shape ({dy.shape[0]},), got {t.shape}")
    d = np.vstack([dy.T, dz.T])                             # (2n, N)
    x, *_ = np.linalg.lstsq(a, d, rcond=None)               # (m, N)
    if method == "exact":
        x = _refine_exact(p, x, dy, dz, include_yaw, max_iter)
        my, mz = point_displacements(p, x[0], x[1], x[2], x[3],
                                     x[4] if include_yaw else 0.0, method="exact")
        resid = np.hstack([my - dy, mz - dz])               # (N, 2n)
    else:
        resid = (a @ x - d).T
    return BaseMotion(Ty=x[0].copy(), Tz=x[1].copy(), Rx=x[2].copy(), Ry=x[3].copy(),
                      Rz=x[4].copy() if include_yaw else None, time=t, cond=cond,
                      residual_rms=np.sqrt(np.mean(resid ** 2, axis=1)), points=p,
                      method=method)


def _refine_exact(p: np.ndarray, x0: np.ndarray, dy: np.ndarray, dz: np.ndarray,
                  include_yaw: bool, max_iter: int) -> np.ndarray:
    """Gauss-Newton on d_k = T + (A_x A_y A_z - I) p_k, Y and Z rows, vectorised
    over time (batched QR of the (N, 2n, m) Jacobians)."""
    n_t = dy.shape[0]
    m = x0.shape[0]
    n = p.shape[0]
    q = x0.T.copy()                                        # (N, m)
    target = np.hstack([dy, dz])                            # (N, 2n)
    for _ in range(max_iter):
        rx, ry = q[:, 2], q[:, 3]
        rz = q[:, 4] if include_yaw else np.zeros(n_t)
        c0, s0, c1, s1, c2, s2 = (np.cos(rx), np.sin(rx), np.cos(ry), np.sin(ry),
                                  np.cos(rz), np.sin(rz))
        zero, one = np.zeros(n_t), np.ones(n_t)
        ax = _stack3(one, zero, zero, zero, c0, -s0, zero, s0, c0)
        ay = _stack3(c1, zero, s1, zero, one, zero, -s1, zero, c1)
        az = _stack3(c2, -s2, zero, s2, c2, zero, zero, zero, one)
        dax = _stack3(zero, zero, zero, zero, -s0, -c0, zero, c0, -s0)
        day = _stack3(-s1, zero, c1, zero, zero, zero, -c1, zero, -s1)
        daz = _stack3(-s2, -c2, zero, c2, -s2, zero, zero, zero, zero)
        rot = ax @ ay @ az
        moved = np.einsum("tij,kj->tki", rot, p) - p        # (N, n, 3)
        model = np.hstack([q[:, [0]] + moved[..., 1], q[:, [1]] + moved[..., 2]])
        r = model - target                                  # (N, 2n)
        jac = np.zeros(r.shape + (m,))                      # (N, 2n, m)
        jac[:, :n, 0] = 1.0
        jac[:, n:, 1] = 1.0
        derivs = [dax @ ay @ az, ax @ day @ az]
        if include_yaw:
            derivs.append(ax @ ay @ daz)
        for j, dr in enumerate(derivs, start=2):
            dp = np.einsum("tij,kj->tki", dr, p)            # (N, n, 3)
            jac[:, :n, j] = dp[..., 1]
            jac[:, n:, j] = dp[..., 2]
        qq, rr = np.linalg.qr(jac)                          # batched reduced QR
        rhs = -np.einsum("tij,ti->tj", qq, r)
        step = np.linalg.solve(rr, rhs[..., None])[..., 0]
        q += step
        # converged when every update is at round-off relative to the size of
        # its component over the record (quadratic convergence gets there in
        # 2-4 iterations for small-motion data)
        scale = np.max(np.abs(q), axis=0) + 1e-300
        if np.all(np.max(np.abs(step), axis=0) <= 1e-13 * scale):
            return q.T
    raise SimulationError(f"pantograph kinematics: exact rigid-body refinement did not "
                          f"converge in {max_iter} iterations (max angle "
                          f"{np.max(np.abs(q[:, 2:])):.3g} rad)")


def _stack3(*entries: np.ndarray) -> np.ndarray:
    return np.stack(entries, axis=-1).reshape(entries[0].shape + (3, 3))


def base_motion_from_channels(channels: Mapping[str, Any], points: Any, *,
                              time_column: str = "time", **kwargs: Any) -> BaseMotion:
    """Base motion from dataset channels ``dcdc_y_P<k>``, ``dcdc_z_P<k>``.

    Parameters
    ----------
    channels : Mapping or pandas.DataFrame
        Columns ``dcdc_y_P1..n`` and ``dcdc_z_P1..n`` [m] (design.md project
        extension), optionally ``time`` [s].
    points : array_like, shape (n, 3)
        Positions [m] of P1..Pn relative to the reference point.
    time_column : str, optional
        Name of the time column (default ``"time"``; ignored if absent).
    **kwargs
        Passed to :func:`solve_base_motion` (``include_yaw``, ``method``,
        ``max_cond``).

    Returns
    -------
    BaseMotion

    Raises
    ------
    eroad.errors.EroadInputError
        If a needed channel is missing (naming it).
    """
    p = _as_points(points)
    cols = {}
    for axis in ("y", "z"):
        for k in range(1, p.shape[0] + 1):
            name = f"dcdc_{axis}_P{k}"
            if name not in channels:
                raise EroadInputError(f"missing channel {name} (pantograph-base kinematics "
                                      f"needs dcdc_y_P1..{p.shape[0]} and dcdc_z_P1.."
                                      f"{p.shape[0]})")
            cols[name] = np.asarray(channels[name], dtype=float)
    n = p.shape[0]
    dy = np.column_stack([cols[f"dcdc_y_P{k}"] for k in range(1, n + 1)])
    dz = np.column_stack([cols[f"dcdc_z_P{k}"] for k in range(1, n + 1)])
    time = np.asarray(channels[time_column], dtype=float) if time_column in channels else None
    return solve_base_motion(p, dy, dz, time=time, **kwargs)


# ---------------------------------------------------------------------------
# spectra
# ---------------------------------------------------------------------------
def _prepare(x: Any, fs: float, window: str, detrend: str | None,
             order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from scipy.signal import get_window
    from scipy.signal import detrend as sp_detrend

    x = np.asarray(x, dtype=float)
    n = x.shape[-1]
    if n < 2:
        raise EroadInputError(f"spectrum: need at least 2 samples, got {n}")
    if not fs > 0:
        raise EroadInputError(f"spectrum: sample rate must be positive, got {fs}")
    if not np.all(np.isfinite(x)):
        raise EroadInputError("spectrum: signal has non-finite values")
    if order not in (0, 1, 2, 3, 4):
        raise ValueError(f"derivative order must be 0..4, got {order}")
    w = get_window(window, n, fftbins=True)                 # periodic (DFT-even) window
    if detrend in ("mean", "constant"):
        # window-weighted mean: the DC bin of the windowed signal becomes zero;
        # the plain mean of a non-integer number of periods would leak a^2/(pi f T)^2
        # into DC (the same as the plain mean for a boxcar window)
        x = x - np.sum(x * w, axis=-1, keepdims=True) / w.sum()
    elif detrend == "linear":
        x = sp_detrend(x, axis=-1, type="linear")
    elif detrend is not None:
        raise ValueError(f"detrend must be 'mean', 'linear' or None, not {detrend!r}")
    f = np.fft.rfftfreq(n, d=1.0 / fs)
    spec = np.fft.rfft(x * w, axis=-1)
    return f, spec, w


def _one_sided(n: int) -> np.ndarray:
    """Factor 2 on the bins that stand for +f and -f (not DC, not Nyquist)."""
    fac = np.full(n // 2 + 1, 2.0)
    fac[0] = 1.0
    if n % 2 == 0:
        fac[-1] = 1.0
    return fac


def amplitude_spectrum(x: Any, fs: float, *, order: int = 0, window: str = "hann",
                       detrend: str | None = "mean") -> tuple[np.ndarray, np.ndarray]:
    """Single-sided, peak-reading amplitude spectrum, optionally of a derivative.

    ``A_k = c_k |sum_n w_n x_n exp(-2 pi j k n / N)| / sum_n w_n * (2 pi f_k)^order``
    with ``c_k = 2`` except at DC and Nyquist (``c_k = 1``).  A sinusoid of
    amplitude a at a bin frequency reads a at its bin exactly (Hann: exactly
    for bins 1..N/2-1; between bins the peak reads low by up to 15 %, the
    Hann scalloping loss; use ``window="flattop"`` for amplitudes between bins).

    Parameters
    ----------
    x : array_like, shape (..., N)
        Signal sampled at ``fs`` (along the last axis), unit U.
    fs : float
        Sample rate [Hz].
    order : int, optional
        Time-derivative order 0..4 (0: x itself, 1: velocity, 2: acceleration),
        taken in the frequency domain by multiplying by ``|j 2 pi f|^order``,
        exact for a periodic band-limited signal (a central finite difference
        would read 24 % low at 40 Hz for fs = 200 Hz).
    window : str, optional
        ``scipy.signal.get_window`` name (default ``"hann"``; ``"boxcar"`` for
        none).
    detrend : {"mean", "linear", None}, optional
        Removed before windowing (default ``"mean"``: the window-weighted mean
        ``sum w x / sum w``, which makes the DC bin zero; ``"linear"``: a
        least-squares line).

    Returns
    -------
    f : numpy.ndarray, shape (N//2 + 1,)
        Frequencies [Hz], resolution ``fs / N``.
    amp : numpy.ndarray, shape (..., N//2 + 1)
        Amplitude [U / s^order].
    """
    f, spec, w = _prepare(x, fs, window, detrend, order)
    n = w.size
    amp = np.abs(spec) * _one_sided(n) / w.sum()
    if order:
        amp = amp * (2.0 * np.pi * f) ** order
    return f, amp


def power_spectrum(x: Any, fs: float, *, order: int = 0, window: str = "hann",
                   detrend: str | None = "mean") -> tuple[np.ndarray, np.ndarray]:
    """Single-sided mean-square (power) spectrum per bin, Parseval-exact.

    ``P_k = c_k |sum_n w_n x_n exp(-2 pi j k n / N)|^2 / (N sum_n w_n^2) *
    (2 pi f_k)^(2 order)``, so that ``sum_k P_k = sum_n w_n^2 x_n^2 / sum_n
    w_n^2`` exactly (order 0): the window-weighted mean square, which is the
    mean square itself for ``window="boxcar"`` and its estimate for a
    stationary signal.  Relation to :func:`amplitude_spectrum`:
    ``P_k = A_k^2 / (2 ENBW)`` on interior bins with the equivalent noise
    bandwidth ``ENBW = N sum w^2 / (sum w)^2`` in bins (1.5 for Hann); a
    sinusoid of amplitude a contributes ``a^2 / 2`` spread over its bins.

    Parameters
    ----------
    x : array_like, shape (..., N)
        Signal (unit U) along the last axis.
    fs : float
        Sample rate [Hz].
    order : int, optional
        Time-derivative order 0..4, in the frequency domain.
    window : str, optional
        Window name (default ``"hann"``).
    detrend : {"mean", "linear", None}, optional
        Removed before windowing (default ``"mean"``).

    Returns
    -------
    f : numpy.ndarray, shape (N//2 + 1,)
        Frequencies [Hz].
    power : numpy.ndarray, shape (..., N//2 + 1)
        Mean square per bin [U^2 / s^(2 order)] (divide by ``fs / N`` for a
        density per Hz).
    """
    f, spec, w = _prepare(x, fs, window, detrend, order)
    n = w.size
    power = np.abs(spec) ** 2 * _one_sided(n) / (n * np.sum(w ** 2))
    if order:
        power = power * (2.0 * np.pi * f) ** (2 * order)
    return f, power


def band_label(band: tuple[float, float]) -> str:
    """Label of a band [Hz]: ``"<0.5"`` for ``(0, 0.5)``, else ``"5-15"``.

    Parameters
    ----------
    band : (float, float)
        Lower and upper edge [Hz].

    Returns
    -------
    str
    """
    lo, hi = band
    return f"<{hi:g}" if lo <= 0 else f"{lo:g}-{hi:g}"


def band_energies(x: Any, fs: float, bands: tuple[tuple[float, float], ...] = BANDS, *,
                  order: int = 0, window: str = "hann",
                  detrend: str | None = "mean") -> dict[str, float]:
    """Mean-square content of a signal in frequency bands.

    The band energy is ``sum of P_k over lo <= f_k < hi`` of
    :func:`power_spectrum` (DC belongs to a band starting at 0), so the bands
    add up to the (window-weighted) mean square when they cover 0..fs/2.

    Parameters
    ----------
    x : array_like, shape (N,)
        Signal (unit U).
    fs : float
        Sample rate [Hz].
    bands : tuple of (float, float), optional
        Half-open bands [lo, hi) [Hz] (default :data:`BANDS`: <0.5, 0.5-5,
        5-15, 15-40 Hz).
    order : int, optional
        Time-derivative order (0 displacement/angle, 1 velocity, 2
        acceleration).
    window, detrend : optional
        As in :func:`power_spectrum`.

    Returns
    -------
    dict
        ``{band_label: mean square [U^2 / s^(2 order)]}`` in band order.
    """
    f, p = power_spectrum(x, fs, order=order, window=window, detrend=detrend)
    out = {}
    for lo, hi in bands:
        sel = (f >= lo) & (f < hi)
        out[band_label((lo, hi))] = float(np.sum(p[..., sel], axis=-1))
    return out


def _sample_rate(motion: BaseMotion, fs: float | None) -> float:
    if fs is not None:
        return float(fs)
    t = motion.time
    if t is None or t.size < 2:
        raise EroadInputError("spectra: give fs or a BaseMotion with a time vector")
    dt = np.diff(t)
    if np.max(np.abs(dt - dt.mean())) > 1e-6 * dt.mean():
        raise EroadInputError("spectra: time vector is not uniformly sampled")
    return 1.0 / float(dt.mean())


def motion_spectra(motion: BaseMotion, fs: float | None = None, *,
                   window: str = "hann") -> dict[str, np.ndarray]:
    """Amplitude spectra of the base motion quantities of Figure 11.

    Parameters
    ----------
    motion : BaseMotion
        Result of :func:`solve_base_motion`.
    fs : float, optional
        Sample rate [Hz] (default: from ``motion.time``).
    window : str, optional
        Window (default ``"hann"``).

    Returns
    -------
    dict
        ``"f"`` [Hz] and one amplitude spectrum per :data:`QUANTITIES` name:
        Rx, Rx_vel, Rx_acc, Ry, ... [rad, rad/s, rad/s^2]; Ty, Ty_vel, Ty_acc,
        Tz, ... [m, m/s, m/s^2].
    """
    fs = _sample_rate(motion, fs)
    out: dict[str, np.ndarray] = {}
    for name, (comp, order, _, _) in QUANTITIES.items():
        f, amp = amplitude_spectrum(getattr(motion, comp), fs, order=order, window=window)
        out.setdefault("f", f)
        out[name] = amp
    return out


def motion_band_table(motion: BaseMotion, fs: float | None = None,
                      bands: tuple[tuple[float, float], ...] = BANDS, *,
                      window: str = "hann"):
    """Band energies of every Figure-11 quantity (chassis-stiffness study).

    Parameters
    ----------
    motion : BaseMotion
        Result of :func:`solve_base_motion`.
    fs : float, optional
        Sample rate [Hz] (default: from ``motion.time``).
    bands : tuple of (float, float), optional
        Bands [Hz] (default :data:`BANDS`).
    window : str, optional
        Window (default ``"hann"``).

    Returns
    -------
    pandas.DataFrame
        Index: quantity names of :data:`QUANTITIES`; columns: band labels;
        values: mean square in the band [unit^2]; column ``unit`` gives the
        squared unit.
    """
    import pandas as pd

    fs = _sample_rate(motion, fs)
    rows = {}
    for name, (comp, order, unit, _) in QUANTITIES.items():
        rows[name] = band_energies(getattr(motion, comp), fs, bands, order=order, window=window)
        rows[name]["unit"] = f"({unit})^2"
    return pd.DataFrame.from_dict(rows, orient="index")
