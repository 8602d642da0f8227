"""Finite-element model of an overhead contact line in the vertical plane.

What it is for: the mass, damping and stiffness matrices (sparse) of a contact wire,
optionally with a messenger wire and droppers, over a number of spans with supports,
for the moving-contact simulation in :mod:`catenary.contact`.

Model
-----
Each wire is a tensioned Euler-Bernoulli beam, ``rho_A w_tt + EI w_xxxx - T w_xx = f``,
discretised with two-node Hermite-cubic elements (DOFs per node: vertical displacement
``w`` [m] and slope ``w_x`` [rad]).  Element matrices: consistent mass
``rho_A l / 420 [...]``, bending ``EI / l^3 [...]`` and the geometric (tension) stiffness
``T / (30 l) [...]``.  With ``EI = 0`` the model is a taut string; as the Hermite
elements keep the slope continuous, the kink under a point load is smeared over one
element (static uplift 0.12 % low with 0.1 m elements on a 20 m span).

Droppers are linear springs (with their mass lumped half at each end) between the
messenger and the contact wire at the dropper positions; clamps are point masses.  At
each pole the contact wire hangs on a steady arm (point mass + vertical spring) and the
messenger on its support (spring, or fixed).  Both wire ends of the model are anchored
(``w = 0``).  Damping is Rayleigh, ``C = a M + b K``.

Displacements are measured from the static equilibrium under gravity: the model is
linear, gravity only sets the static state, and the designed contact wire height
profile (pre-sag) enters the contact as a known function :meth:`ContactLine.profile`.
Droppers can slacken (``dropper_slack = true``): a dropper carries its static tension
``T0`` (:meth:`ContactLine.dropper_static_tension`, the contact wire's weight between
neighbouring droppers less the share the tension carries through the pre-sag curvature)
and cannot push, so it goes slack when the contact wire rises above the messenger by
more than ``T0 / k_d``; the time integrator (:mod:`catenary.contact`) then removes its
stiffness by a low-rank update.  With ``dropper_slack = false`` droppers are linear
springs that also push.

Coordinates: x along the line [m] from the first anchor, z up [m].

What it is not: the static form-finding of a catenary (dropper lengths), 3-D (lateral)
wire motion, or the time integration (:mod:`catenary.contact`).
"""
from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from eroad.errors import EroadInputError

__all__ = ["WireParams", "LineParams", "ContactLine", "load_line", "line_ids", "DATA_DIR"]

#: folder of the built-in contact line files
DATA_DIR = Path(__file__).with_name("data")


def _f(unit: str, doc: str, **kw):
    return field(metadata={"unit": unit, "doc": doc}, **kw)


@dataclass(frozen=True)
class WireParams:
    """One wire (contact wire or messenger)."""

    tension: float = _f("N", "axial tension T")
    mass_per_length: float = _f("kg/m", "mass per unit length rho_A")
    bending_stiffness: float = _f("N m^2", "bending stiffness EI (0 for a string)")

    @property
    def wave_speed(self) -> float:
        """Transverse wave speed of the string, ``sqrt(T / rho_A)`` [m/s]."""
        return math.sqrt(self.tension / self.mass_per_length)


@dataclass(frozen=True)
class LineParams:
    """A contact line of ``n_spans`` equal spans between two anchors.

    ``messenger = None`` gives a single wire (trolley-type line, or the closed-form
    string cases); then the dropper fields are ignored and the contact wire is held at
    the poles by the steady arm only.
    """

    name: str = _f("-", "label")
    contact: WireParams = _f("-", "contact wire")
    messenger: WireParams | None = _f("-", "messenger wire, or None")
    span: float = _f("m", "span length (pole spacing)")
    n_spans: int = _f("-", "number of spans between the two anchors")
    dropper_x: tuple[float, ...] = _f("m", "dropper positions from the start of each span")
    dropper_stiffness: float = _f("N/m", "axial stiffness of a dropper")
    dropper_mass: float = _f("kg", "mass of one dropper (half to each end)")
    clamp_mass_contact: float = _f("kg", "dropper clamp mass on the contact wire")
    clamp_mass_messenger: float = _f("kg", "dropper clamp mass on the messenger")
    steady_arm_stiffness: float = _f("N/m", "vertical stiffness holding the contact wire at a "
                                     "pole (inf: fixed, 0: free)")
    steady_arm_mass: float = _f("kg", "steady arm mass at the contact wire at a pole")
    messenger_support_stiffness: float = _f("N/m", "vertical stiffness of the messenger "
                                            "support at a pole (inf: fixed)")
    messenger_support_mass: float = _f("kg", "mass at the messenger support")
    presag: float = _f("m", "contact wire pre-sag at mid-span (designed height profile, "
                       "positive downwards)")
    stagger: float = _f("m", "lateral zig-zag amplitude of the contact wire (+/- at "
                        "alternate poles)")
    rayleigh_mass: float = _f("1/s", "Rayleigh mass coefficient a in C = a M + b K")
    rayleigh_stiffness: float = _f("s", "Rayleigh stiffness coefficient b")
    element_length: float = _f("m", "largest finite-element length")
    source: str = _f("-", "where the numbers come from", default="")
    dropper_slack: bool = _f("-", "droppers cannot push: slack when compressed beyond "
                             "their static tension", default=False)
    gravity: float = _f("m/s^2", "gravity for the dropper static tensions", default=9.81)
    sources: tuple[tuple[str, str], ...] = _f("-", "field -> where the number comes from",
                                              default=())

    @property
    def length(self) -> float:
        """Anchor-to-anchor length [m]."""
        return self.span * self.n_spans

    def validate(self, where: str = "line parameters") -> None:
        """Refuse impossible values with :class:`EroadInputError` naming the field."""
        def bad(name, msg):
            raise EroadInputError(f"{where}: {name} {msg}")

        for wname, w in (("contact", self.contact), ("messenger", self.messenger)):
            if w is None:
                continue
            if not (w.tension > 0 and math.isfinite(w.tension)):
                bad(f"{wname}.tension", f"must be positive and finite, got {w.tension!r}")
            if not (w.mass_per_length > 0 and math.isfinite(w.mass_per_length)):
                bad(f"{wname}.mass_per_length", f"must be positive, got {w.mass_per_length!r}")
            if not (w.bending_stiffness >= 0 and math.isfinite(w.bending_stiffness)):
                bad(f"{wname}.bending_stiffness", f"must be >= 0, got {w.bending_stiffness!r}")
        if not (self.span > 0 and math.isfinite(self.span)):
            bad("span", f"must be positive, got {self.span!r}")
        if int(self.n_spans) != self.n_spans or self.n_spans < 1:
            bad("n_spans", f"must be an integer >= 1, got {self.n_spans!r}")
        if not (0 < self.element_length <= self.span):
            bad("element_length", f"must be in (0, span], got {self.element_length!r}")
        for x in self.dropper_x:
            if not (0 < x < self.span):
                bad("dropper_x", f"positions must lie strictly inside (0, span), got {x!r}")
        for name in ("dropper_stiffness", "dropper_mass", "clamp_mass_contact",
                     "clamp_mass_messenger", "steady_arm_stiffness", "steady_arm_mass",
                     "messenger_support_stiffness", "messenger_support_mass",
                     "rayleigh_mass", "rayleigh_stiffness"):
            v = getattr(self, name)
            if not (v >= 0) or (math.isinf(v) and "stiffness" not in name):
                bad(name, f"must be >= 0, got {v!r}")
        if abs(self.presag) >= self.span or abs(self.stagger) > 1.0:
            bad("presag/stagger", "out of range (|presag| < span, |stagger| <= 1 m)")


# ---------------------------------------------------------------------------
# loading
# ---------------------------------------------------------------------------
def _from_table(cls, table: dict, path: str, prefix: str = ""):
    names = {f.name for f in fields(cls)}
    for key in table:
        if key not in names:
            raise EroadInputError(f"{path}: unknown key '{prefix}{key}' (allowed: "
                                  f"{', '.join(sorted(names))})")
    kw = {}
    for f in fields(cls):
        if f.name not in table:
            if f.default is not MISSING:
                continue
            raise EroadInputError(f"{path}: missing key '{prefix}{f.name}'")
        kw[f.name] = table[f.name]
    return kw


def _num(v, path, key):
    if isinstance(v, str) and v.strip().lower() in ("inf", "infinity"):
        return math.inf
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise EroadInputError(f"{path}: '{key}' must be a number, got {v!r}")
    return float(v)


def line_ids() -> list[str]:
    """Ids of the built-in contact lines (stems of ``catenary/data/line_*.toml``)."""
    return sorted(p.stem[len("line_"):] for p in DATA_DIR.glob("line_*.toml"))


def load_line(name_or_path: str | Path) -> LineParams:
    """Load contact line parameters from a TOML file or a built-in id.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A built-in id (see :func:`line_ids`) or a path to a TOML file with a top-level
        table of :class:`LineParams` fields and sub-tables ``[contact]`` and (optional)
        ``[messenger]`` of :class:`WireParams` fields.  ``"inf"`` is accepted for the
        support stiffnesses.  Keys starting with ``source_`` are free-text provenance
        notes and are ignored.

    Returns
    -------
    LineParams

    Raises
    ------
    EroadInputError
        Missing file, unknown or missing key, non-numeric or impossible value.
    """
    from eroad.tomlfile import read_builtin_or_file

    p, data = read_builtin_or_file(name_or_path, DATA_DIR, "line_", "contact line", line_ids)
    data = {k: v for k, v in data.items() if not k.startswith("source_")}
    srcs = data.pop("sources", {})
    if not isinstance(srcs, dict):
        raise EroadInputError(f"{p}: [sources] must be a table")
    wires = {}
    for wname in ("contact", "messenger"):
        t = data.pop(wname, None)
        if t is None:
            if wname == "contact":
                raise EroadInputError(f"{p}: missing table [contact]")
            wires[wname] = None
            continue
        t = {k: v for k, v in t.items() if not k.startswith("source_")}
        kw = _from_table(WireParams, t, str(p), prefix=f"{wname}.")
        wires[wname] = WireParams(**{k: _num(v, p, f"{wname}.{k}") for k, v in kw.items()})
    data.setdefault("messenger", None)
    kw = _from_table(LineParams, {**data, "contact": None}, str(p))
    out = {}
    for k, v in kw.items():
        if k in ("name", "source"):
            out[k] = str(v)
        elif k == "dropper_slack":
            if not isinstance(v, bool):
                raise EroadInputError(f"{p}: 'dropper_slack' must be true or false")
            out[k] = v
        elif k in ("contact", "messenger"):
            out[k] = wires[k]
        elif k == "dropper_x":
            if not isinstance(v, list):
                raise EroadInputError(f"{p}: 'dropper_x' must be a list of numbers")
            out[k] = tuple(_num(x, p, "dropper_x") for x in v)
        elif k == "n_spans":
            if not isinstance(v, int) or isinstance(v, bool):
                raise EroadInputError(f"{p}: 'n_spans' must be an integer, got {v!r}")
            out[k] = v
        else:
            out[k] = _num(v, p, k)
    out["sources"] = tuple((str(k), str(v)) for k, v in srcs.items())
    lp = LineParams(**out)
    lp.validate(str(p))
    return lp


# ---------------------------------------------------------------------------
# element matrices
# ---------------------------------------------------------------------------
def _hermite_mass(l: float) -> np.ndarray:
    return (l / 420.0) * np.array([[156, 22 * l, 54, -13 * l],
                                   [22 * l, 4 * l * l, 13 * l, -3 * l * l],
                                   [54, 13 * l, 156, -22 * l],
                                   [-13 * l, -3 * l * l, -22 * l, 4 * l * l]])


def _hermite_bending(l: float) -> np.ndarray:
    return (1.0 / l ** 3) * np.array([[12, 6 * l, -12, 6 * l],
                                      [6 * l, 4 * l * l, -6 * l, 2 * l * l],
                                      [-12, -6 * l, 12, -6 * l],
                                      [6 * l, 2 * l * l, -6 * l, 4 * l * l]])


def _hermite_geometric(l: float) -> np.ndarray:
    return (1.0 / (30.0 * l)) * np.array([[36, 3 * l, -36, 3 * l],
                                          [3 * l, 4 * l * l, -3 * l, -l * l],
                                          [-36, -3 * l, 36, -3 * l],
                                          [3 * l, -l * l, -3 * l, 4 * l * l]])


def hermite_shape(xi: float, l: float) -> np.ndarray:
    """Hermite cubic shape functions at local coordinate ``xi`` in [0, 1] of an element of
    length ``l`` [m], for the DOFs ``(w_i, w_x_i, w_j, w_x_j)``."""
    x2, x3 = xi * xi, xi * xi * xi
    return np.array([1 - 3 * x2 + 2 * x3, l * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, l * (x3 - x2)])


def _mesh(span: float, n_spans: int, marks: tuple[float, ...], h: float) -> np.ndarray:
    """Node coordinates: every pole and mark is a node; intervals cut to <= h."""
    brk = [0.0]
    for s in range(n_spans):
        x0 = s * span
        brk += [x0 + m for m in sorted(marks)] + [x0 + span]
    nodes = [0.0]
    for a, b in zip(brk[:-1], brk[1:]):
        n = max(1, int(math.ceil((b - a) / h - 1e-9)))
        nodes += list(np.linspace(a, b, n + 1)[1:])
    return np.asarray(nodes)


class ContactLine:
    """Assembled FE model of a contact line.

    Parameters
    ----------
    params : LineParams

    Attributes
    ----------
    x : numpy.ndarray
        Node coordinates [m] (shared by both wires).
    M, C, K : scipy.sparse.csc_matrix
        Mass [kg], damping [N s/m] and stiffness [N/m] matrices on the free DOFs.
    n_dof : int
        Number of free DOFs.
    """

    def __init__(self, params: LineParams):
        params.validate()
        self.params = params
        p = params
        marks = p.dropper_x if p.messenger is not None else ()
        self.x = _mesh(p.span, p.n_spans, marks, p.element_length)
        nn = self.x.size
        self.n_nodes = nn
        n_wires = 1 if p.messenger is None else 2
        n_full = 2 * nn * n_wires
        rows, cols, mv, kv = [], [], [], []

        def add_wire(w: WireParams, offset: int):
            le = np.diff(self.x)
            for e, l in enumerate(le):
                idx = offset + 2 * e + np.arange(4)
                me = w.mass_per_length * _hermite_mass(l)
                ke = w.bending_stiffness * _hermite_bending(l) + w.tension * _hermite_geometric(l)
                r, c = np.meshgrid(idx, idx, indexing="ij")
                rows.append(r.ravel()); cols.append(c.ravel())
                mv.append(me.ravel()); kv.append(ke.ravel())

        def add_point(i: int, m: float = 0.0, k: float = 0.0):
            rows.append(np.array([i])); cols.append(np.array([i]))
            mv.append(np.array([m])); kv.append(np.array([k]))

        def add_spring(i: int, j: int, k: float):
            rows.append(np.array([i, i, j, j])); cols.append(np.array([i, j, i, j]))
            mv.append(np.zeros(4)); kv.append(k * np.array([1.0, -1.0, -1.0, 1.0]))

        add_wire(p.contact, 0)
        mo = 2 * nn  # messenger DOF offset
        if p.messenger is not None:
            add_wire(p.messenger, mo)
        fixed = {0, 2 * (nn - 1)}
        if p.messenger is not None:
            fixed |= {mo, mo + 2 * (nn - 1)}
        poles = [s * p.span for s in range(1, p.n_spans)]
        self.pole_nodes = np.array([self.node_at(xp) for xp in poles], dtype=int)
        for n in self.pole_nodes:
            if math.isinf(p.steady_arm_stiffness):
                fixed.add(2 * n)
            else:
                add_point(2 * n, p.steady_arm_mass, p.steady_arm_stiffness)
            if p.messenger is not None:
                if math.isinf(p.messenger_support_stiffness):
                    fixed.add(mo + 2 * n)
                else:
                    add_point(mo + 2 * n, p.messenger_support_mass, p.messenger_support_stiffness)
        self.dropper_nodes = np.zeros(0, dtype=int)
        if p.messenger is not None:
            dx = [s * p.span + d for s in range(p.n_spans) for d in p.dropper_x]
            self.dropper_nodes = np.array([self.node_at(v) for v in dx], dtype=int)
            for n in self.dropper_nodes:
                add_point(2 * n, p.clamp_mass_contact + 0.5 * p.dropper_mass)
                add_point(mo + 2 * n, p.clamp_mass_messenger + 0.5 * p.dropper_mass)
                add_spring(2 * n, mo + 2 * n, p.dropper_stiffness)
        r = np.concatenate(rows); c = np.concatenate(cols)
        Mf = sp.coo_matrix((np.concatenate(mv), (r, c)), shape=(n_full, n_full)).tocsc()
        Kf = sp.coo_matrix((np.concatenate(kv), (r, c)), shape=(n_full, n_full)).tocsc()
        free = np.setdiff1d(np.arange(n_full), np.array(sorted(fixed)))
        self._full_to_free = -np.ones(n_full, dtype=int)
        self._full_to_free[free] = np.arange(free.size)
        self.free = free
        self.n_full = n_full
        self.M = Mf[free][:, free].tocsc()
        self.K = Kf[free][:, free].tocsc()
        self.C = (p.rayleigh_mass * self.M + p.rayleigh_stiffness * self.K).tocsc()
        self.n_dof = free.size
        self._messenger_offset = mo

    # -- geometry -----------------------------------------------------------
    def node_at(self, x: float) -> int:
        """Index of the node at ``x`` [m] (must be a node within 1e-9 m)."""
        i = int(np.argmin(np.abs(self.x - x)))
        if abs(self.x[i] - x) > 1e-9 * max(1.0, abs(x)):
            raise EroadInputError(f"contact line: no node at x = {x} m")
        return i

    def profile(self, x: Any) -> np.ndarray:
        """Designed contact wire height relative to the support height [m] at ``x`` [m]:
        a parabolic pre-sag of ``presag`` at mid-span (0 at the poles)."""
        s = np.mod(np.asarray(x, dtype=float), self.params.span) / self.params.span
        return -4.0 * self.params.presag * s * (1.0 - s)

    def lateral(self, x: Any) -> np.ndarray:
        """Lateral contact wire position [m] at ``x`` [m]: straight zig-zag between
        +stagger and -stagger at alternate poles."""
        s = np.asarray(x, dtype=float) / self.params.span
        tri = 2.0 * np.abs(np.mod(s, 2.0) - 1.0) - 1.0  # +1 at even poles, -1 at odd
        return self.params.stagger * tri

    def shape(self, x: float) -> tuple[np.ndarray, np.ndarray]:
        """Free-DOF indices and weights of the contact wire height at ``x`` [m].

        Returns
        -------
        idx : numpy.ndarray of int
            Free DOF indices (anchored DOFs dropped).
        w : numpy.ndarray
            Weights: ``w_contact(x) = w @ q[idx]``.
        """
        xs = self.x
        if not (xs[0] <= x <= xs[-1]):
            raise EroadInputError(f"contact line: x = {x} m outside [0, {xs[-1]}] m")
        e = int(np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2))
        l = xs[e + 1] - xs[e]
        N = hermite_shape((x - xs[e]) / l, l)
        full = 2 * e + np.arange(4)
        fr = self._full_to_free[full]
        keep = fr >= 0
        return fr[keep], N[keep]

    def wire_dofs(self, which: str = "contact") -> np.ndarray:
        """Free-DOF index of the vertical displacement at every node (-1 where anchored)."""
        off = 0 if which == "contact" else self._messenger_offset
        if which == "messenger" and self.params.messenger is None:
            raise EroadInputError("contact line has no messenger")
        return self._full_to_free[off + 2 * np.arange(self.n_nodes)]

    def wire_displacement(self, q: np.ndarray, which: str = "contact") -> np.ndarray:
        """Nodal vertical displacement [m] of a wire from the free-DOF vector ``q``."""
        idx = self.wire_dofs(which)
        out = np.zeros(self.n_nodes)
        ok = idx >= 0
        out[ok] = q[idx[ok]]
        return out

    def dropper_static_tension(self) -> np.ndarray:
        """Static tension ``T0`` [N] of each dropper (order of ``dropper_nodes``).

        Each dropper carries the contact wire's weight over its tributary length (half
        the distance to the neighbouring droppers; a pole counts as a neighbour, the
        steady arm carrying the part next to it) less what the wire tension carries
        through the pre-sag curvature (``8 T presag / span^2`` per metre, the parabola's
        ``T w''``), plus its contact wire clamp and half its own mass.  The exact values
        follow from the dropper lengths of a form-finding, which this model does not do.
        """
        p = self.params
        if p.messenger is None or not p.dropper_x:
            return np.zeros(0)
        xs = [0.0] + sorted(p.dropper_x) + [p.span]
        trib = {xs[i]: 0.5 * (xs[i + 1] - xs[i - 1]) for i in range(1, len(xs) - 1)}
        q = p.contact.mass_per_length * p.gravity - 8.0 * p.contact.tension * p.presag / p.span ** 2
        t0 = np.array([q * trib[d] + p.gravity * (p.clamp_mass_contact + 0.5 * p.dropper_mass)
                       for d in p.dropper_x])
        return np.tile(t0, p.n_spans)

    def dropper_dofs(self) -> tuple[np.ndarray, np.ndarray]:
        """Free-DOF indices (contact wire, messenger) of every dropper's ends (-1 where
        anchored), in the order of ``dropper_nodes``."""
        if self.params.messenger is None:
            return np.zeros(0, int), np.zeros(0, int)
        c = self._full_to_free[2 * self.dropper_nodes]
        m = self._full_to_free[self._messenger_offset + 2 * self.dropper_nodes]
        return c, m

    def point_load(self, x: float, force: float) -> np.ndarray:
        """Free-DOF load vector of a vertical point force ``force`` [N] on the contact wire
        at ``x`` [m] (positive up)."""
        f = np.zeros(self.n_dof)
        idx, w = self.shape(x)
        f[idx] += force * w
        return f
