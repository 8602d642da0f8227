"""International Roughness Index (IRI) of a longitudinal profile, by the golden quarter car.

What this module is for: IRI per segment of a measured or generated profile,
following Sayers (World Bank TP-46) and ASTM E1926: the "golden car" quarter
car (k1 = 653 s^-2, k2 = 63.3 s^-2, c = 6.0 s^-1, mu = 0.15) at 80 km/h, driven
by the profile slope; a 250 mm moving average only where dx < 0.25 m; states
initialised with the slope over the first 11 m; the exact discrete state
transition (matrix exponential) per sample step.  What it is not: a vehicle
model (``vehicles``) or a PSD metric (``roadlib.metrics``).

Algorithm
---------
States Z = [zs, zs', zu, zu'] driven by the slope s of the (averaged) profile,
held constant over each step dx (exact for a piecewise-linear profile)::

    Z_{i+1} = ST Z_i + PR s_i,  ST = expm(A dt),  PR = A^-1 (ST - I) B,  dt = dx / v
    IRI(segment) = 1000 * mean_{steps i in segment} |Z_{i+1}[0] - Z_{i+1}[2]|   [m/km]

(the slope-driven "displacements" are the slopes of the true response, so
|zs - zu| is the rectified suspension velocity divided by v).  The simulation
runs once over the whole profile; segments only partition the average.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from scipy.linalg import expm

from eroad.errors import EroadInputError

#: golden-car parameters (ASTM E1926): tyre k1 = kt/ms [1/s^2], suspension
#: k2 = ks/ms [1/s^2], damping c = cs/ms [1/s], mass ratio mu = mu/ms [-]
K1, K2, C, MU = 653.0, 63.3, 6.0, 0.15
#: IRI simulation speed [m/s] (80 km/h)
SPEED = 80.0 / 3.6
#: moving-average base length [m], applied when dx < BASE_LENGTH
BASE_LENGTH = 0.25
#: length over which the initial slope is taken [m]
INIT_LENGTH = 11.0


@dataclass(frozen=True)
class IriSegment:
    """IRI of one segment: ``start`` and ``end`` [m], ``iri`` [m/km]."""

    start: float
    end: float
    iri: float

    def to_dict(self) -> dict:
        return asdict(self)


def golden_car_matrices(dx: float, speed: float = SPEED):
    """Discrete golden-car transition for a step dx [m] at ``speed`` [m/s].

    Returns
    -------
    ST : (4, 4) ndarray
        State transition expm(A dx/v).
    PR : (4,) ndarray
        Response to a slope held constant over the step.
    """
    a = np.array([[0.0, 1.0, 0.0, 0.0],
                  [-K2, -C, K2, C],
                  [0.0, 0.0, 0.0, 1.0],
                  [K2 / MU, C / MU, -(K1 + K2) / MU, -C / MU]])
    b = np.array([0.0, 0.0, 0.0, K1 / MU])
    st = expm(a * (dx / speed))
    pr = np.linalg.solve(a, (st - np.eye(4)) @ b)
    return st, pr


def _check_profile(x, z):
    x = np.asarray(x, float)
    z = np.asarray(z, float)
    if x.ndim != 1 or z.shape != x.shape:
        raise EroadInputError(f"IRI: x and z must be 1-D of equal length, got shapes {x.shape} and {z.shape}")
    if x.size < 3:
        raise EroadInputError("IRI: profile needs at least 3 samples")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(z))):
        bad = int(np.flatnonzero(~(np.isfinite(x) & np.isfinite(z)))[0])
        raise EroadInputError(f"IRI: profile has NaN/inf at row {bad + 1}")
    d = np.diff(x)
    if np.any(d <= 0):
        bad = int(np.flatnonzero(d <= 0)[0])
        raise EroadInputError(f"IRI: x must increase strictly; row {bad + 2} (x = {x[bad + 1]:g} m) does not")
    dx = float(np.median(d))
    if np.max(np.abs(d - dx)) > 1e-6 * dx + 1e-9:
        bad = int(np.argmax(np.abs(d - dx)))
        raise EroadInputError(
            f"IRI: profile must be uniformly sampled (dx = {dx:g} m), but step at row {bad + 2} is {d[bad]:g} m; "
            "resample it first")
    return x, z, dx


def rectified_slope(x, z, speed: float = SPEED):
    """Rectified slope |zs' - zu'| of the golden car for every sample step.

    Parameters
    ----------
    x, z : array_like
        Uniformly sampled profile: positions [m], heights [m].
    speed : float
        Simulation speed [m/s] (80 km/h for IRI).

    Returns
    -------
    xs : ndarray
        Start of each step [m]: slope i of the k-sample moving average joins the
        averages centred at x_i + (k-1) dx/2 and one dx further.
    rs : ndarray
        |zs' - zu'| after each step [m/m].
    """
    x, z, dx = _check_profile(x, z)
    # base length in samples, rounded half away from zero like the ASTM code (nint)
    k = max(1, int(math.floor(BASE_LENGTH / dx + 0.5))) if dx < BASE_LENGTH else 1
    slope = (z[k:] - z[:-k]) / (k * dx)             # slope of the k-sample moving average
    i11 = int(round(INIT_LENGTH / dx))
    if i11 >= x.size:
        raise EroadInputError(
            f"IRI: profile of {x[-1] - x[0]:g} m is shorter than the {INIT_LENGTH:g} m initialisation length")
    s0 = (z[i11] - z[0]) / (i11 * dx)
    st, pr = golden_car_matrices(dx, speed)
    (a00, a01, a02, a03), (a10, a11, a12, a13), (a20, a21, a22, a23), (a30, a31, a32, a33) = st.tolist()
    p0, p1, p2, p3 = pr.tolist()
    z0, z1, z2, z3 = s0, 0.0, s0, 0.0
    rs = np.empty(slope.size)
    for i, s in enumerate(slope.tolist()):
        z0, z1, z2, z3 = (a00 * z0 + a01 * z1 + a02 * z2 + a03 * z3 + p0 * s,
                          a10 * z0 + a11 * z1 + a12 * z2 + a13 * z3 + p1 * s,
                          a20 * z0 + a21 * z1 + a22 * z2 + a23 * z3 + p2 * s,
                          a30 * z0 + a31 * z1 + a32 * z2 + a33 * z3 + p3 * s)
        rs[i] = abs(z0 - z2)
    return x[:slope.size] + 0.5 * (k - 1) * dx, rs


def iri_segments(x, z, segment_length: float, start: float | None = None,
                 partial: bool = False) -> list[IriSegment]:
    """IRI [m/km] of consecutive segments of a profile.

    Parameters
    ----------
    x, z : array_like
        Uniformly sampled longitudinal profile: positions [m], heights [m].
    segment_length : float
        Segment length [m] (e.g. 100).
    start : float, optional
        Start of the first segment [m] (default: the first sample).  The
        quarter car still runs from the first sample.
    partial : bool
        Also report a last, incomplete segment.

    Returns
    -------
    list of IriSegment
        ``start``, ``end`` [m] and ``iri`` [m/km]; a sample step belongs to the
        segment that contains its midpoint.
    """
    if not (isinstance(segment_length, (int, float)) and math.isfinite(segment_length)
            and segment_length > 0):
        raise EroadInputError(f"IRI: segment length must be a positive number of metres, got {segment_length!r}")
    xs, rs = rectified_slope(x, z)
    x = np.asarray(x, float)
    dx = float(x[1] - x[0])
    x_start = float(x[0]) if start is None else float(start)
    if not (x[0] <= x_start < x[-1]):
        raise EroadInputError(f"IRI: segment start {x_start:g} m is outside the profile {x[0]:g}..{x[-1]:g} m")
    x_end = float(x[-1])                           # a segment is complete if the data cover it
    mid = xs + 0.5 * dx
    out = []
    a = x_start
    tol = 1e-9 * max(1.0, abs(x_end))
    while a < x_end - tol:
        b = a + segment_length
        if b > x_end + tol:
            if not partial:
                break
            b = x_end
        sel = (mid >= a) & (mid < b)
        if sel.any():
            out.append(IriSegment(float(a), float(b), float(1000.0 * rs[sel].mean())))
        a = b
    if not out:
        raise EroadInputError(
            f"IRI: no complete {segment_length:g} m segment in the profile {x_start:g}..{x_end:g} m "
            "(shorter segment length, or partial=True)")
    return out


def iri(x, z) -> float:
    """IRI [m/km] of a whole profile (positions x [m], heights z [m])."""
    _, rs = rectified_slope(x, z)
    return float(1000.0 * rs.mean())
