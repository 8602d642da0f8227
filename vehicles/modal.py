"""Modal analysis of a vehicle: eigenfrequencies, damping ratios and mode labels.

What it is for: the mode table of a vehicle (rigid or flexible chassis, any frame
stiffness, effects that change its configuration) -- body bounce, pitch and roll,
axle hop and tramp, frame torsion and bending, the DCDC block's modes -- with
frequency, damping ratio, shape and the energy distribution over bodies, degrees of
freedom and force elements that the label was read from.  It explains the peaks of
response spectra (the pantograph-base spectra of Figure 11) and checks the model
against the ranges heavy vehicles have.

What it is not: the response to a road (:mod:`vehicles.linear` gives FRFs and
response PSDs from the same linearisation) or the frame tuning
(:func:`vehicles.frame.tune_frame`).

Method
------
1. ``M, K, D`` from Exudyn's linearisation at static equilibrium
   (:func:`vehicles.linear.linear_model`, Tait-Bryan ``Rxyz`` nodes: 6 coordinates per
   body and no constraints, so no nullspace projection is needed).
2. Damped modes: eigenvalues ``lambda`` of the first-order form
   ``A = [[0, I], [-M^-1 K, -M^-1 D]]``; one mode per pair ``Im(lambda) > 0`` (an
   overdamped mode, a real ``lambda``, is one mode with damping ratio 1).
   ``freq_hz = |lambda| / 2 pi`` (the undamped natural frequency of the damped mode),
   ``damping = -Re(lambda) / |lambda|`` and ``freq_damped_hz = Im(lambda) / 2 pi``.
   ``freq_undamped_hz`` is the frequency of the undamped problem ``K phi = w^2 M phi``
   (K symmetrised) whose mode shape matches best (mass-weighted MAC).
3. Labels from the energy distribution of the (complex) mode shape ``phi``:

   * sprung rigid motion: ``phi`` of all sprung bodies (frame segments and DCDC) is
     projected (mass-weighted least squares) on the 6 rigid motions of the sprung
     mass about the point at its centre of gravity in x, y and at the mean spring
     seat height in z (a roll-axis proxy, so that roll about a low axis counts as
     roll, not as lateral motion); its kinetic energy per component is
     ``body bounce/pitch/roll/lateral/longitudinal/yaw``;
   * frame deformation: the kinetic energy of the segments' motion left after that
     projection (flexible chassis); the kind (torsion, vertical bending, lateral
     bending) is the frame joint direction holding the most strain energy;
   * DCDC: kinetic energy of the block's motion relative to the frame segment it is
     mounted on, per component (``DCDC bounce/pitch/roll/lateral/...``);
   * axle ``a``: kinetic energy per component: ``axle hop a`` (z), ``axle tramp a``
     (roll), ``axle a lateral/wind-up/yaw/longitudinal`` (held by the guides).

   A mode whose strain energy lies for more than :data:`FRAME_STRAIN_SHARE` in the
   frame joints' torsion, bending and lateral-bending springs is a frame mode
   (``frame torsion``, ``frame bending``, ``frame lateral`` by the largest of the
   three: counter-rolling front and rear segments would otherwise look like body
   yaw); otherwise the kinetic group with the largest share names the mode.  When
   two axles share a mode of the same kind (tandem axles: the second holds more
   than :data:`SHARED_AXLE_RATIO` of the first's energy) the label names both with
   the phase, e.g. ``axle hop 3+4 in phase``.  A label that occurs again gets a
   number: ``frame bending (2)``.
4. Modes above ``f_max`` (default 100 Hz: the quasi-rigid frame joints, stiff
   guides) are left out of the table and counted.

Strain energy per force-element group is ``Re(phi^H K_g phi)`` with ``K_g`` the
stiffness contribution of the group (the linearised stiffness with and without the
group's stiffness components), so it includes the geometric terms of its preload.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vehicles.linear import DOF_NAMES, LinearModel, linear_model

#: default upper frequency of the mode table [Hz]; modes above are counted only
F_MAX = 100.0
#: a second axle whose energy of the same kind exceeds this share of the first's
#: makes the mode a shared (tandem) mode
SHARED_AXLE_RATIO = 0.5
#: a mode whose strain energy lies more than this share in the frame joints' torsion,
#: bending and lateral bending springs is a frame mode
FRAME_STRAIN_SHARE = 0.5
BODY_KINDS = {"z": "bounce", "ry": "pitch", "rx": "roll", "y": "lateral", "x": "longitudinal", "rz": "yaw"}
AXLE_KINDS = {"z": "hop", "rx": "tramp", "y": "lateral", "ry": "wind-up", "rz": "yaw", "x": "longitudinal"}
DCDC_KINDS = BODY_KINDS
#: strain-energy groups of the force elements
STRAIN_GROUPS = ("tyre vertical", "tyre horizontal", "suspension", "axle guides", "frame torsion",
                 "frame bending", "frame lateral", "frame joint translation", "DCDC mounts", "surge",
                 "other")


@dataclass
class Mode:
    """One mode of the linearised vehicle.

    Attributes
    ----------
    label : str
        ``body bounce``, ``axle hop 3``, ``frame torsion``, ``DCDC roll``, ...
    freq_hz : float
        Natural frequency of the damped mode ``|lambda| / 2 pi`` [Hz] (equals the
        undamped frequency for proportional damping).
    damping : float
        Damping ratio ``-Re(lambda) / |lambda|`` [-].
    freq_damped_hz : float
        Damped frequency ``Im(lambda) / 2 pi`` [Hz] (0 for an overdamped mode).
    freq_undamped_hz : float
        Frequency of the best-matching mode of the undamped system [Hz].
    mac : float
        Mass-weighted modal assurance criterion of that match [-] (1 = same shape).
    eigenvalue : complex
        ``lambda`` [1/s].
    shape : ndarray (n,), complex
        Displacement part of the eigenvector in the ODE2 coordinates
        (:attr:`ModalResult.dof_names`), scaled so that its largest component is 1.
    kinetic : dict
        ``{body: {dof: share}}`` of the kinetic energy ``Re(conj(phi_i) (M phi)_i)``
        per body and coordinate (dof ``x, y, z, rx, ry, rz``); sums to 1.
    strain : dict
        ``{group: share}`` of the strain energy per force-element group
        (:data:`STRAIN_GROUPS`); sums to 1.
    indicators : dict
        ``{group: {kind: share}}`` the label was read from (``body``, ``frame``,
        ``dcdc``, ``axle<a>``); sums to 1.
    """

    label: str
    freq_hz: float
    damping: float
    freq_damped_hz: float
    freq_undamped_hz: float
    mac: float
    eigenvalue: complex
    shape: np.ndarray
    kinetic: dict = field(default_factory=dict)
    strain: dict = field(default_factory=dict)
    indicators: dict = field(default_factory=dict)

    def to_dict(self, energies: bool = False) -> dict:
        """JSON-ready summary ``{label, freq_hz, damping, freq_damped_hz,
        freq_undamped_hz}`` (plus the energy shares when ``energies``)."""
        out = {"label": self.label, "freq_hz": round(float(self.freq_hz), 4),
               "damping": round(float(self.damping), 4),
               "freq_damped_hz": round(float(self.freq_damped_hz), 4),
               "freq_undamped_hz": round(float(self.freq_undamped_hz), 4)}
        if energies:
            out["kinetic"] = {b: {k: round(v, 4) for k, v in d.items() if v >= 1e-4}
                              for b, d in self.kinetic.items() if sum(d.values()) >= 1e-4}
            out["strain"] = {k: round(v, 4) for k, v in self.strain.items() if v >= 1e-4}
        return out


@dataclass
class ModalResult:
    """All modes of one vehicle configuration.

    Attributes
    ----------
    modes : list of Mode
        Modes with ``freq_hz <= f_max``, ascending in frequency.
    f_max : float
        [Hz]
    n_stiff : int
        Modes above ``f_max`` (quasi-rigid frame joints, stiff guides and mounts).
    n_dof : int
        Degrees of freedom of the model.
    dof_names : list of str
        ``"<body>.<dof>"`` of each coordinate of :attr:`Mode.shape`.
    meta : dict
        Vehicle id, chassis, stiffness factor, frame segments, effects, notes.
    linear : LinearModel
        The linearised model the modes come from.
    """

    modes: list
    f_max: float
    n_stiff: int
    n_dof: int
    dof_names: list
    meta: dict
    linear: LinearModel = None

    def table(self) -> list:
        """``[{label, freq_hz, damping, freq_damped_hz, freq_undamped_hz}, ...]``."""
        return [m.to_dict() for m in self.modes]

    def by_label(self, label: str) -> list:
        """Modes whose label equals ``label`` (or starts with ``label + " "``)."""
        return [m for m in self.modes if m.label == label or m.label.startswith(label + " ")]

    def summary(self) -> dict:
        """JSON-ready summary with the table, the stiff-mode count and the metadata."""
        return {**{k: v for k, v in self.meta.items()}, "f_max_hz": self.f_max,
                "n_dof": self.n_dof, "n_modes": len(self.modes), "n_stiff_modes": self.n_stiff,
                "frequency": "freq_hz = |lambda|/(2 pi), undamped natural frequency of the damped mode",
                "modes": self.table()}


# --------------------------------------------------------------------------- element groups
def _body_names(model) -> dict:
    names = {int(b.body): b.name for b in model.bodies}
    names[int(model.ground)] = "ground"
    return names


def _kind_of(name: str) -> str:
    if name == "ground":
        return "ground"
    if name == "chassis" or name.startswith("segment"):
        return "segment"
    if name.startswith("axle"):
        return "axle"
    if name == "dcdc":
        return "dcdc"
    return "other"


#: components of a 6-DOF spring-damper (x, y, z, rot x, rot y, rot z) per group, by the
#: kinds of the two bodies it joins; Cartesian spring-dampers use the first three
_GROUPS_6 = {
    ("axle", "ground"): {"tyre vertical": (2, 3), "tyre horizontal": (0, 1, 4, 5)},
    ("axle", "segment"): {"suspension": (2, 3), "axle guides": (0, 1, 4, 5)},
    ("ground", "segment"): {"surge": (0, 1, 2, 3, 4, 5)},
    ("segment", "segment"): {"frame joint translation": (0, 1, 2), "frame torsion": (3,),
                             "frame bending": (4,), "frame lateral": (5,)},
    ("dcdc", "segment"): {"DCDC mounts": (0, 1, 2, 3, 4, 5)},
}


def element_groups(model) -> dict:
    """Force-element stiffness components of the model, grouped.

    Elements are recognised by the kinds of the two bodies they join (ground, frame
    segment or chassis, axle, DCDC) and split by component: for the tyres and the
    suspension, vertical and roll (z, rot x) against the horizontal guiding
    directions (x, y, rot y, rot z); for the frame joints, translation, torsion
    (rot x), vertical bending (rot y) and lateral bending (rot z).

    Parameters
    ----------
    model : vehicles.builder.VehicleModel

    Returns
    -------
    dict
        ``{group: [(object number, components, kind), ...]}`` with kind ``"vector"``
        (Cartesian spring-damper, components of x, y, z) or ``"matrix"`` (rigid-body
        spring-damper, rows of its 6x6 stiffness).  Elements that fit no rule (effect
        elements with user functions, ...) are not listed: their share is ``other``.
    """
    mbs = model.mbs
    names = _body_names(model)
    groups: dict = {g: [] for g in STRAIN_GROUPS}
    for i in range(mbs.systemData.NumberOfObjects()):
        o = mbs.GetObject(i)
        typ = o.get("objectType", "")
        if typ == "ConnectorCartesianSpringDamper":
            kind, ncomp = "vector", 3
        elif typ == "ConnectorRigidBodySpringDamper":
            kind, ncomp = "matrix", 6
        else:
            continue
        if kind == "vector" and o.get("springForceUserFunction", 0) not in (0, None):
            continue
        pair = tuple(sorted(_kind_of(names.get(int(mbs.GetMarker(m)["bodyNumber"]), "other"))
                            for m in o["markerNumbers"]))
        for g, comps in _GROUPS_6.get(pair, {}).items():
            comps = tuple(c for c in comps if c < ncomp)
            if comps:
                groups[g].append((i, comps, kind))
    return {g: v for g, v in groups.items() if v}


def group_stiffness(model, K: np.ndarray) -> dict:
    """Stiffness contribution ``K_g`` of every element group (see :func:`element_groups`).

    ``K_g = K - K'`` with ``K'`` linearised by Exudyn at the same (static) state after
    zeroing the group's components: entries of a Cartesian stiffness vector, rows of
    a 6x6 stiffness matrix (so that an energy cross term between two groups is
    shared half and half).  The parameters are restored afterwards.  ``K_g``
    includes the geometric stiffness of the group's preload.

    Returns
    -------
    dict
        ``{group: ndarray (n, n)}``.
    """
    mbs = model.mbs
    out = {}
    for g, items in element_groups(model).items():
        saved = {}
        for obj, comps, kind in items:
            if obj not in saved:
                saved[obj] = np.array(mbs.GetObjectParameter(obj, "stiffness"), float)
        new = {obj: v.copy() for obj, v in saved.items()}
        for obj, comps, kind in items:
            for c in comps:
                if kind == "vector":
                    new[obj][c] = 0.0
                else:
                    new[obj][c, :] = 0.0
        try:
            for obj, v in new.items():
                mbs.SetObjectParameter(obj, "stiffness", v)
            _M, K0, _D = model.linearized_system()
        finally:
            for obj, v in saved.items():
                mbs.SetObjectParameter(obj, "stiffness", v)
        out[g] = K - K0
    return out


# --------------------------------------------------------------------------- energy groups
def _rigid_transfer(points: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """(6 m, 6) map from a rigid motion (u, phi) at ``ref`` to the motions (u_i, phi)
    of bodies with centres ``points`` (m, 3)."""
    T = np.zeros((6 * len(points), 6))
    for i, p in enumerate(points):
        d = np.asarray(p, float) - ref
        T[6 * i:6 * i + 3, 0:3] = np.eye(3)
        # u_i = u + phi x d = u - [d]x phi
        T[6 * i:6 * i + 3, 3:6] = -np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
        T[6 * i + 3:6 * i + 6, 3:6] = np.eye(3)
    return T


class _EnergyMap:
    """Precomputed projections for the labelling energies of one model."""

    def __init__(self, lm: LinearModel):
        model = lm.model
        self.lm = lm
        self.M = lm.M
        idx = lm.body_dofs
        self.sprung = [b for b in model.segments] + ([model.dcdc] if model.dcdc is not None else [])
        self.s_idx = np.concatenate([idx[b.name] for b in self.sprung])
        cogs = np.array([b.cog for b in self.sprung])
        masses = np.array([b.mass for b in self.sprung])
        c = (masses[:, None] * cogs).sum(axis=0) / masses.sum()
        z_ref = float(np.mean([s.point[2] for s in model.suspensions])) if model.suspensions else c[2]
        self.ref = np.array([c[0], c[1], z_ref])
        self.T = _rigid_transfer(cogs, self.ref)
        Ms = self.M[np.ix_(self.s_idx, self.s_idx)]
        self.Ms = Ms
        self.Mr = self.T.T @ Ms @ self.T
        self.P = np.linalg.solve(self.Mr, self.T.T @ Ms)          # q_s -> rigid motion
        n_seg = len(model.segments)
        self.seg_rows = np.arange(6 * n_seg)
        self.axles = [(b.name, idx[b.name]) for b in model.axles]
        self.dcdc = None
        if model.dcdc is not None:
            seg = model.segments[model.segment_of(model.dcdc.cog[0])] if model.chassis == "flexible" \
                else model.segments[0]
            Tsd = _rigid_transfer(np.array([model.dcdc.cog]), seg.cog)
            self.dcdc = (idx["dcdc"], idx[seg.name], Tsd)
        self.is_flexible = model.chassis == "flexible"

    def indicators(self, phi: np.ndarray, strain: dict) -> dict:
        M = self.M
        out = {}
        qs = phi[self.s_idx]
        r = self.P @ qs
        out["body"] = {BODY_KINDS[DOF_NAMES[k]]: float(self.Mr[k, k] * abs(r[k]) ** 2) for k in range(6)}
        if self.is_flexible:
            d = qs - self.T @ r
            ds = d[self.seg_rows]
            Mss = self.Ms[np.ix_(self.seg_rows, self.seg_rows)]
            e = float(np.real(ds.conj() @ Mss @ ds))
            fr = {k: strain.get(f"frame {k}", 0.0) for k in ("torsion", "bending", "lateral")}
            tot = sum(fr.values())
            out["frame"] = {k: (e * v / tot if tot > 0 else e / 3) for k, v in fr.items()}
        if self.dcdc is not None:
            i_d, i_s, Tsd = self.dcdc
            rel = phi[i_d] - Tsd @ phi[i_s]
            Md = M[np.ix_(i_d, i_d)]
            out["dcdc"] = {DCDC_KINDS[DOF_NAMES[k]]: float(Md[k, k] * abs(rel[k]) ** 2) for k in range(6)}
        for name, ii in self.axles:
            Ma = M[np.ix_(ii, ii)]
            out[name] = {AXLE_KINDS[DOF_NAMES[k]]: float(Ma[k, k] * abs(phi[ii][k]) ** 2) for k in range(6)}
        tot = sum(sum(d.values()) for d in out.values())
        return {g: {k: v / tot for k, v in d.items()} for g, d in out.items()}


def _label(ind: dict, strain: dict, phi: np.ndarray, lm: LinearModel) -> str:
    frame = {k: strain.get(f"frame {k}", 0.0) for k in ("torsion", "bending", "lateral")}
    if sum(frame.values()) > FRAME_STRAIN_SHARE:
        return "frame " + max(frame, key=frame.get)
    totals = {g: sum(d.values()) for g, d in ind.items()}
    g = max(totals, key=totals.get)
    kind = max(ind[g], key=ind[g].get)
    if g == "body":
        return f"body {kind}"
    if g == "frame":
        return f"frame {kind}"
    if g == "dcdc":
        return f"DCDC {kind}"
    # an axle: look for a partner axle of the same kind (tandem)
    a = int(g[4:])
    e_a = ind[g][kind]
    partners = [(ind[h][kind], h) for h in ind if h.startswith("axle") and h != g
                and ind[h][kind] > SHARED_AXLE_RATIO * e_a]
    if partners:
        _, h = max(partners)
        b = int(h[4:])
        dof = {v: k for k, v in AXLE_KINDS.items()}[kind]
        j = DOF_NAMES.index(dof)
        qa = phi[lm.body_dofs[g]][j]
        qb = phi[lm.body_dofs[h]][j]
        phase = "in phase" if np.real(qa * np.conj(qb)) >= 0 else "anti-phase"
        lo, hi = sorted((a, b))
        if kind in ("hop", "tramp"):
            return f"axle {kind} {lo}+{hi} {phase}"
        return f"axle {lo}+{hi} {kind} {phase}"
    if kind in ("hop", "tramp"):
        return f"axle {kind} {a}"
    return f"axle {a} {kind}"


def _per_dof_kinetic(phi, M, lm: LinearModel) -> dict:
    e = np.real(np.conj(phi) * (M @ phi))
    tot = e.sum()
    out = {}
    for name, ii in lm.body_dofs.items():
        out[name] = {DOF_NAMES[k]: float(e[i] / tot) for k, i in enumerate(ii)}
    return out


def _strain_shares(phi, Kg: dict) -> dict:
    e = {g: float(np.real(np.conj(phi) @ Kg_ @ phi)) for g, Kg_ in Kg.items()}
    tot = sum(abs(v) for v in e.values())
    return {g: (v / tot if tot > 0 else 0.0) for g, v in e.items()}


# --------------------------------------------------------------------------- analysis
def modal_analysis(vp, chassis: str = "rigid", frame_segments: int | None = None,
                   stiffness_factor: float = 1.0, effects=None, f_max: float = F_MAX,
                   linear: LinearModel | None = None) -> ModalResult:
    """Damped modes of a vehicle at static equilibrium, labelled.

    Parameters
    ----------
    vp : str or Path or VehicleParams
        Built-in id, TOML file or parameters.
    chassis : {"rigid", "flexible"}
    frame_segments : int, optional
        Segments of the flexible frame (default ``vp.frame.segments``).
    stiffness_factor : float
        Frame stiffness scale [-] (flexible chassis).
    effects : dict or list of str, optional
        Effects whose configuration hooks apply (:func:`vehicles.linear.configured_build`).
    f_max : float
        Modes above this natural frequency [Hz] are counted, not listed.
    linear : LinearModel, optional
        Use this linearisation instead of building one.

    Returns
    -------
    ModalResult
    """
    import scipy.linalg

    lm = linear if linear is not None else linear_model(vp, chassis, frame_segments, stiffness_factor, effects)
    M, K, D = lm.M, lm.K, lm.D
    n = M.shape[0]
    A, _B = lm.state_space()
    lam, V = np.linalg.eig(A)
    # undamped reference modes
    w2, U = scipy.linalg.eigh(0.5 * (K + K.T), M)
    f_und = np.sqrt(np.clip(w2, 0.0, None)) / (2 * np.pi)
    Kg = group_stiffness(lm.model, K)
    emap = _EnergyMap(lm)
    modes, n_stiff = [], 0
    used_real = False
    for j in np.argsort(np.abs(lam)):
        lj = lam[j]
        if lj.imag < -1e-9 * max(abs(lj), 1.0):
            continue
        is_real = abs(lj.imag) <= 1e-9 * max(abs(lj), 1.0)
        fn = abs(lj) / (2 * np.pi)
        if fn > f_max:
            n_stiff += 1
            continue
        used_real |= is_real
        phi = V[:n, j].copy()
        k = int(np.argmax(np.abs(phi)))
        phi = phi / phi[k]
        mw = np.abs(U.T @ M @ phi) ** 2 / (np.real(phi.conj() @ M @ phi) * np.einsum("ij,ik,kj->j", U, M, U))
        ju = int(np.argmax(mw))
        strain = _strain_shares(phi, Kg)
        ind = emap.indicators(phi, strain)
        modes.append(Mode(label=_label(ind, strain, phi, lm), freq_hz=float(fn),
                          damping=float(min(1.0, -lj.real / abs(lj))) if abs(lj) > 0 else 1.0,
                          freq_damped_hz=float(max(lj.imag, 0.0) / (2 * np.pi)),
                          freq_undamped_hz=float(f_und[ju]), mac=float(mw[ju]), eigenvalue=complex(lj),
                          shape=phi, kinetic=_per_dof_kinetic(phi, M, lm), strain=strain,
                          indicators=ind))
    modes.sort(key=lambda m: m.freq_hz)
    seen: dict = {}
    for m in modes:
        seen[m.label] = seen.get(m.label, 0) + 1
        if seen[m.label] > 1:
            m.label = f"{m.label} ({seen[m.label]})"
    meta = dict(lm.meta)
    if used_real:
        meta.setdefault("notes", []).append("overdamped modes (real eigenvalues) listed with damping 1")
    return ModalResult(modes=modes, f_max=float(f_max), n_stiff=n_stiff, n_dof=n,
                       dof_names=list(lm.dof_names), meta=meta, linear=lm)


def modes(vp, chassis: str = "rigid", frame_segments: int | None = None, stiffness_factor: float = 1.0,
          effects=None, f_max: float = F_MAX) -> list:
    """Labelled modes of a vehicle below ``f_max`` (see :func:`modal_analysis`).

    Parameters
    ----------
    vp : str or Path or VehicleParams
    chassis : {"rigid", "flexible"}
    frame_segments : int, optional
    stiffness_factor : float
        Frame stiffness scale [-].
    effects : dict or list of str, optional
    f_max : float
        [Hz]

    Returns
    -------
    list of Mode
        Ascending in ``freq_hz`` (natural frequency of the damped mode, Hz).
    """
    return modal_analysis(vp, chassis, frame_segments, stiffness_factor, effects, f_max).modes


def format_table(result: ModalResult) -> str:
    """Plain-text mode table (label, natural and damped frequency, damping ratio)."""
    lines = [f"{'mode':<32s} {'f_n [Hz]':>9s} {'f_d [Hz]':>9s} {'zeta [-]':>9s}"]
    for m in result.modes:
        lines.append(f"{m.label:<32s} {m.freq_hz:9.2f} {m.freq_damped_hz:9.2f} {m.damping:9.3f}")
    lines.append(f"({result.n_stiff} stiff modes above {result.f_max:g} Hz not listed; "
                 f"{result.n_dof} degrees of freedom)")
    return "\n".join(lines)


__all__ = ["Mode", "ModalResult", "modal_analysis", "modes", "format_table", "element_groups",
           "group_stiffness", "F_MAX"]
