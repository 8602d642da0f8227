"""The chassis frame: rigid, or rigid segments joined by rotational spring-dampers.

What it is for: cutting the sprung mass items into frame segments (mass, centre of
gravity and inertia per segment), the stiffness and damping of the joints between
segments (bending about y and torsion about x, quasi-rigid otherwise), and tuning
the frame stiffness so that the first torsion and vertical bending modes of the
vehicle fall on their target frequencies.

What it is not: the Exudyn model (that is :mod:`vehicles.builder`, which calls the
functions here) or the labelled modal analysis of the whole vehicle
(``vehicles.modal``).

Discretisation: a beam of bending stiffness EI [N m^2] cut into N rigid segments
joined by rotational springs of stiffness EI / l, with l the distance between the
centres of the two joined segments, converges to the beam as N grows; the same for
torsion with GJ.  A rigid chassis is the case of one segment.  Because every mass
item is cut by the same rule (uniform along its x extent), the segments of a very
stiff flexible frame add up exactly to the rigid chassis: same mass, centre of
gravity and inertia tensor.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from eroad.errors import EroadInputError
from vehicles.params import Frame, MassItem, VehicleParams


@dataclass(frozen=True)
class SegmentMass:
    """Mass properties of one rigid frame segment (or of the whole rigid chassis).

    Attributes
    ----------
    x_front, x_rear : float
        Extent of the segment along x [m].
    mass : float
        [kg]
    cog : ndarray (3,)
        Centre of gravity [m] in vehicle coordinates.
    inertia : ndarray (3, 3)
        Inertia tensor about the centre of gravity [kg m^2].
    """

    x_front: float
    x_rear: float
    mass: float
    cog: np.ndarray
    inertia: np.ndarray

    @property
    def inertia6(self) -> list[float]:
        """Exudyn order [Jxx, Jyy, Jzz, Jyz, Jxz, Jxy] [kg m^2]."""
        J = self.inertia
        return [J[0, 0], J[1, 1], J[2, 2], J[1, 2], J[0, 2], J[0, 1]]


@dataclass(frozen=True)
class FrameJoint:
    """Rotational spring-damper between segment ``i`` and ``i + 1``.

    Attributes
    ----------
    index : int
        The joint joins segments ``index`` and ``index + 1``.
    point : ndarray (3,)
        Joint position [m] on the frame's elastic axis.
    stiffness : ndarray (6,)
        Diagonal [kx, ky, kz (N/m), k_torsion, k_bending, k_lateral (N m/rad)].
    damping : ndarray (6,)
        Diagonal damping [N s/m, N m s/rad].
    """

    index: int
    point: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray


def segment_bounds(frame: Frame, n_segments: int) -> list[tuple[float, float]]:
    """Equal-length segments from the front to the rear of the frame.

    Parameters
    ----------
    frame : Frame
    n_segments : int
        Number of segments (1 = rigid chassis).

    Returns
    -------
    list of (x_front, x_rear) [m]
    """
    edges = np.linspace(frame.x_front, frame.x_rear, int(n_segments) + 1)
    return [(float(edges[i]), float(edges[i + 1])) for i in range(int(n_segments))]


def segment_index(bounds, x: float) -> int:
    """Index of the segment that contains position ``x`` [m] (the front one on a boundary)."""
    for i, (xf, xr) in enumerate(bounds):
        if xr <= x <= xf:
            return i
    raise ValueError(f"x = {x} m lies outside the frame")  # validated in params


def _item_slices(item: MassItem, bounds):
    """Yield (segment index, mass, cog, inertia about cog) of the parts of one item."""
    L = item.x_front - item.x_rear
    w2, h2 = item.width ** 2, item.height ** 2
    if L <= 0:
        i = segment_index(bounds, item.x_front)
        J = item.mass / 12.0 * np.diag([w2 + h2, h2, w2])
        yield i, item.mass, np.array([item.x_front, item.y, item.z]), J
        return
    for i, (xf, xr) in enumerate(bounds):
        a, b = max(xr, item.x_rear), min(xf, item.x_front)
        if b <= a:
            continue
        l = b - a
        m = item.mass * l / L
        J = m / 12.0 * np.diag([w2 + h2, l * l + h2, l * l + w2])
        yield i, m, np.array([(a + b) / 2.0, item.y, item.z]), J


def combine(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of gravity and inertia about it of (m, cog, J) parts.

    Parameters
    ----------
    parts : iterable of (mass [kg], cog (3,) [m], inertia (3, 3) [kg m^2])

    Returns
    -------
    (mass, cog, inertia)
    """
    parts = list(parts)
    M = sum(p[0] for p in parts)
    c = sum(p[0] * p[1] for p in parts) / M
    J = np.zeros((3, 3))
    for m, r, Ji in parts:
        d = r - c
        J += Ji + m * (d @ d * np.eye(3) - np.outer(d, d))
    return float(M), c, J


def segment_masses(items, bounds) -> list[SegmentMass]:
    """Cut the sprung mass items into the segments.

    Parameters
    ----------
    items : sequence of MassItem
    bounds : list of (x_front, x_rear)
        From :func:`segment_bounds`.

    Returns
    -------
    list of SegmentMass
        One per segment; a segment that no item reaches raises ``ValueError``
        (the frame item of a vehicle spans the whole frame).
    """
    per = [[] for _ in bounds]
    for item in items:
        for i, m, c, J in _item_slices(item, bounds):
            per[i].append((m, c, J))
    out = []
    for i, parts in enumerate(per):
        if not parts:
            raise ValueError(f"frame segment {i} carries no mass; add a frame item spanning the frame")
        M, c, J = combine(parts)
        out.append(SegmentMass(bounds[i][0], bounds[i][1], M, c, J))
    return out


def frame_joints(frame: Frame, segments: list[SegmentMass], stiffness_factor: float = 1.0
                 ) -> list[FrameJoint]:
    """Joint stiffness and damping between adjacent segments.

    Parameters
    ----------
    frame : Frame
    segments : list of SegmentMass
    stiffness_factor : float
        Multiplies the bending, torsion and lateral bending stiffness [-].  The
        damping is scaled by its square root so that the modal damping ratio of the
        frame modes stays ``frame.damping_ratio``.

    Returns
    -------
    list of FrameJoint
    """
    f = float(stiffness_factor)
    zeta = frame.damping_ratio
    w_t = 2 * np.pi * frame.target_torsion_hz * np.sqrt(f)
    w_b = 2 * np.pi * frame.target_bending_hz * np.sqrt(f)
    joints = []
    for i in range(len(segments) - 1):
        xb = segments[i].x_rear
        l = 0.5 * (segments[i].x_front - segments[i].x_rear) + 0.5 * (
            segments[i + 1].x_front - segments[i + 1].x_rear)
        kt = f * frame.torsion_stiffness / l
        kb = f * frame.bending_stiffness / l
        kl = f * frame.lateral_bending_stiffness / l
        ktr = frame.joint_translational_stiffness
        k = np.array([ktr, ktr, ktr, kt, kb, kl])
        # stiffness-proportional damping tuned at the torsion / bending targets; the
        # quasi-rigid directions get a small numerical damping (1e-4 s x stiffness)
        c = np.array([1e-4 * ktr, 1e-4 * ktr, 1e-4 * ktr,
                      2 * zeta * kt / w_t, 2 * zeta * kb / w_b, 2 * zeta * kl / w_b])
        joints.append(FrameJoint(i, np.array([xb, 0.0, frame.z]), k, c))
    return joints


# --------------------------------------------------------------------------- tuning
def frame_mode_frequencies(vp: VehicleParams, n_segments: int | None = None,
                           stiffness_factor: float = 1.0) -> dict:
    """First frame torsion and vertical bending frequencies of the whole vehicle.

    The vehicle (flexible chassis, on its suspension and tyres, at static
    equilibrium) is linearised with Exudyn; undamped modes are classified by the
    share of their strain energy in the torsion and in the bending springs of the
    frame joints.  The torsion (bending) mode is the lowest mode in which the
    torsion (bending) joint springs hold more than 30 % of the strain energy.

    Parameters
    ----------
    vp : VehicleParams
    n_segments : int, optional
        Default ``vp.frame.segments``.
    stiffness_factor : float

    Returns
    -------
    dict
        ``torsion_hz``, ``bending_hz`` [Hz] (NaN where no such mode is found) and
        ``modes``: list of (freq_hz, torsion_share, bending_share) below 40 Hz.
    """
    from vehicles.builder import build_model

    model = build_model(vp, chassis="flexible", frame_segments=n_segments,
                        stiffness_factor=stiffness_factor, node_type="Rxyz")
    M, K = model.linearized_mass_stiffness()
    w2, V = _generalized_eig(M, K)
    idx = model.joint_rotation_indices()
    out = []
    for j in range(len(w2)):
        f = np.sqrt(max(w2[j], 0.0)) / (2 * np.pi)
        if f > 40.0:
            break
        v = V[:, j]
        e_total = v @ K @ v
        shares = []
        for kind in ("torsion", "bending"):
            e = 0.0
            for (ia, ib), k in idx[kind]:
                e += k * (v[ia] - v[ib]) ** 2
            shares.append(e / e_total if e_total > 0 else 0.0)
        out.append((f, shares[0], shares[1]))
    tors = [m[0] for m in out if m[1] > 0.3]
    bend = [m[0] for m in out if m[2] > 0.3]
    return {"torsion_hz": tors[0] if tors else float("nan"),
            "bending_hz": bend[0] if bend else float("nan"), "modes": out}


def _generalized_eig(M, K):
    import scipy.linalg

    w2, V = scipy.linalg.eigh(K, M)
    order = np.argsort(w2)
    return w2[order], V[:, order]


def tune_frame(vp: VehicleParams, n_segments: int | None = None, iterations: int = 24,
               rtol: float = 0.002) -> VehicleParams:
    """Set the frame's torsion and bending stiffness so the modes hit their targets.

    Bisection on the logarithm of GJ (torsion) and of EI (bending), alternately, within
    a factor 30 of the start values (the two modes are nearly uncoupled; a frame
    mode's frequency grows with its stiffness, and bisection tolerates the jumps of
    the mode classification where a frame mode crosses an axle-hop mode).

    Parameters
    ----------
    vp : VehicleParams
        ``vp.frame.target_torsion_hz`` and ``target_bending_hz`` are the targets.
    n_segments : int, optional
    iterations : int
        Bisection steps per stiffness.
    rtol : float
        Stop when both frequencies are within this relative error.

    Returns
    -------
    VehicleParams
        With tuned ``frame.torsion_stiffness`` and ``frame.bending_stiffness``.

    Raises
    ------
    EroadInputError
        A target the search range cannot reach (the bisection ends on a range edge with
        the mode more than ``REACH_TOL`` off): the line names the mode, the target, the
        frequency reached and the stiffness.
    """
    fr = vp.frame
    bounds = {"torsion": [np.log(fr.torsion_stiffness / 30), np.log(fr.torsion_stiffness * 30)],
              "bending": [np.log(fr.bending_stiffness / 30), np.log(fr.bending_stiffness * 30)]}
    field_of = {"torsion": "torsion_stiffness", "bending": "bending_stiffness"}
    target = {"torsion": fr.target_torsion_hz, "bending": fr.target_bending_hz}
    for _ in range(iterations):
        done = True
        for kind in ("torsion", "bending"):
            lo, hi = bounds[kind]
            mid = 0.5 * (lo + hi)
            vp = replace(vp, frame=replace(vp.frame, **{field_of[kind]: float(np.exp(mid))}))
            f = frame_mode_frequencies(vp, n_segments)[f"{kind}_hz"]
            if not np.isfinite(f) or f < target[kind]:
                bounds[kind][0] = mid
            else:
                bounds[kind][1] = mid
            if not (np.isfinite(f) and abs(f / target[kind] - 1) < rtol):
                done = False
        if done:
            break
    got = frame_mode_frequencies(vp, n_segments)
    for kind in ("torsion", "bending"):
        f = got[f"{kind}_hz"]
        if not (np.isfinite(f) and abs(f / target[kind] - 1) < REACH_TOL):
            stiff = getattr(vp.frame, field_of[kind])
            raise EroadInputError(
                f"frame tuning: the {kind} target {target[kind]:g} Hz is not reached within a factor 30 of "
                f"the start {field_of[kind]} (got {f:.3g} Hz at {stiff:.3g}); change the target or the start value")
    return vp


#: relative frequency error above which tune_frame reports the target as not reached
#: (10x its default stopping tolerance: the bisection's own stop is 0.2 %, a mode-classification
#: jump can leave it at about that; an unreachable target ends tens of per cent off)
REACH_TOL = 0.02
