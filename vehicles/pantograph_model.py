"""Lumped pantograph: the three-mass structure of EN 50318 plus a lateral head DOF.

What it is for: the pantograph that stands on the e-tractor's DCDC block, as

* a vertical chain of three masses (head ``m1``, upper frame ``m2``, lower frame ``m3``)
  joined by spring-dampers (``k1, c1`` head-upper, ``k2, c2`` upper-lower, ``k3, c3``
  lower-base) with a constant static uplift force on the lower frame, the structure of
  the EN 50318 reference pantograph; it becomes a :class:`catenary.contact.Collector`
  whose base is the pantograph base (the DCDC top, vertical ``Tz``);
* a lateral head DOF (mass, spring, damper to the base at head height) driven by the
  base's lateral motion at head height, ``Ty - Rx h`` (roll ``Rx`` lifts the left side,
  so a point ``h`` above the base moves by ``-Rx h`` in y, see
  :mod:`studies.pantograph`), and the head's usable half-width.

Parameters are TOML files in ``vehicles/data/pantograph_*.toml`` with a ``[sources]``
table giving the origin of each number.

Friction in the frame joints (EN 50318 lists it) is ``frame_friction``: a Coulomb force
between the frame DOF that stands on the base and the base, solved with sticking by
:func:`catenary.contact.simulate_contact`.  It is optional in the TOML (0 when absent) and
0 in the built-in files, which have no sourced value for it.

What it is not: aerodynamic uplift, a flexible collector strip, active lateral positioning of the head, or the
contact line (:mod:`catenary`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from catenary.contact import Collector
from eroad.errors import EroadInputError

__all__ = ["PantographParams", "load_pantograph", "pantograph_ids", "collector",
           "with_frame_friction",
           "lateral_response", "vertical_modes", "DATA_DIR"]

#: folder of the built-in pantograph files
DATA_DIR = Path(__file__).with_name("data")


def _f(unit: str, doc: str):
    return field(metadata={"unit": unit, "doc": doc})


@dataclass(frozen=True)
class PantographParams:
    """Three-mass pantograph with a lateral head DOF (all fields required except
    ``frame_friction``)."""

    name: str = _f("-", "label")
    head_mass: float = _f("kg", "m1, pan head (collector strips)")
    upper_mass: float = _f("kg", "m2, upper frame")
    lower_mass: float = _f("kg", "m3, lower frame (0: two-mass model, the upper frame "
                           "stands on the base through k2, c2)")
    head_stiffness: float = _f("N/m", "k1, head suspension (head - upper frame)")
    upper_stiffness: float = _f("N/m", "k2, upper frame - lower frame")
    lower_stiffness: float = _f("N/m", "k3, lower frame - base")
    head_damping: float = _f("N s/m", "c1")
    upper_damping: float = _f("N s/m", "c2")
    lower_damping: float = _f("N s/m", "c3")
    static_force: float = _f("N", "static uplift force on the lower frame (net of gravity)")
    lateral_mass: float = _f("kg", "mass of the lateral head DOF")
    lateral_stiffness: float = _f("N/m", "lateral stiffness of the head to the base")
    lateral_damping: float = _f("N s/m", "lateral damping of the head to the base")
    head_half_width: float = _f("m", "usable half-width of the collector strip")
    head_height: float = _f("m", "working height of the contact point above the base")
    sources: tuple[tuple[str, str], ...] = _f("-", "field -> where the number comes from")
    frame_friction: float = field(default=0.0, metadata={
        "unit": "N", "doc": "Coulomb friction of the frame joints, between the frame DOF on "
        "the base (the lower frame; the frame of a two-mass model) and the base; 0: none"})

    def validate(self, where: str = "pantograph") -> None:
        """Refuse impossible values, naming the field."""
        for f in fields(self):
            if f.name in ("name", "sources"):
                continue
            v = getattr(self, f.name)
            if not (isinstance(v, float) and math.isfinite(v) and v >= 0):
                raise EroadInputError(f"{where}: {f.name} must be a finite number >= 0, got {v!r}")
        if self.lower_mass == 0.0 and (self.lower_stiffness or self.lower_damping):
            raise EroadInputError(f"{where}: a two-mass pantograph (lower_mass = 0) must have "
                                  "lower_stiffness = lower_damping = 0 (the upper frame stands "
                                  "on the base through k2, c2)")
        for name in ("head_mass", "upper_mass", "lateral_mass",
                     "head_stiffness", "upper_stiffness", "lateral_stiffness",
                     "head_half_width"):
            if getattr(self, name) <= 0:
                raise EroadInputError(f"{where}: {name} must be positive")


def pantograph_ids() -> list[str]:
    """Ids of the built-in pantographs (``vehicles/data/pantograph_<id>.toml``)."""
    return sorted(p.stem[len("pantograph_"):] for p in DATA_DIR.glob("pantograph_*.toml"))


#: fields a pantograph file may leave out (their dataclass default applies)
_OPTIONAL = ("frame_friction",)


def load_pantograph(name_or_path: str | Path) -> PantographParams:
    """Load a pantograph from a built-in id or a TOML file.

    The file holds one top-level table of :class:`PantographParams` fields (numbers in SI)
    and a ``[sources]`` table mapping field names to provenance strings.

    Raises
    ------
    EroadInputError
        Unknown id, missing file, bad TOML, unknown/missing key, bad value.
    """
    from eroad.tomlfile import read_builtin_or_file

    p, data = read_builtin_or_file(name_or_path, DATA_DIR, "pantograph_", "pantograph", pantograph_ids)
    names = [f.name for f in fields(PantographParams)]
    for key in data:
        if key not in names:
            raise EroadInputError(f"{p}: unknown key '{key}'")
    kw = {}
    for name in names:
        if name not in data:
            if name in _OPTIONAL:
                continue
            raise EroadInputError(f"{p}: missing key '{name}'")
        v = data[name]
        if name == "name":
            kw[name] = str(v)
        elif name == "sources":
            if not isinstance(v, dict):
                raise EroadInputError(f"{p}: [sources] must be a table")
            for k in v:
                if k not in names:
                    raise EroadInputError(f"{p}: [sources] names unknown field '{k}'")
            kw[name] = tuple((str(k), str(s)) for k, s in v.items())
        else:
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise EroadInputError(f"{p}: '{name}' must be a number, got {v!r}")
            kw[name] = float(v)
    pp = PantographParams(**kw)
    pp.validate(str(p))
    return pp


def with_frame_friction(pp: PantographParams, friction: float | None) -> PantographParams:
    """``pp`` with its ``frame_friction`` replaced by ``friction`` [N] (None: ``pp`` as is).

    Raises
    ------
    EroadInputError
        A negative or non-finite friction.
    """
    if friction is None:
        return pp
    if not (math.isfinite(friction) and friction >= 0):
        raise EroadInputError(f"frame friction must be a finite force >= 0 N, got {friction}")
    return replace(pp, frame_friction=float(friction))


def _matrices(pp: PantographParams):
    k1, k2, k3 = pp.head_stiffness, pp.upper_stiffness, pp.lower_stiffness
    c1, c2, c3 = pp.head_damping, pp.upper_damping, pp.lower_damping
    if pp.lower_mass == 0.0:  # two-mass model (EN 50318:2002 reference structure)
        m = np.diag([pp.head_mass, pp.upper_mass])
        K = np.array([[k1, -k1], [-k1, k1 + k2]])
        C = np.array([[c1, -c1], [-c1, c1 + c2]])
        return m, C, K
    m = np.diag([pp.head_mass, pp.upper_mass, pp.lower_mass])
    K = np.array([[k1, -k1, 0.0], [-k1, k1 + k2, -k2], [0.0, -k2, k2 + k3]])
    C = np.array([[c1, -c1, 0.0], [-c1, c1 + c2, -c2], [0.0, -c2, c2 + c3]])
    return m, C, K


def collector(pp: PantographParams, static_force: float | None = None) -> Collector:
    """The vertical three-mass chain as a :class:`catenary.contact.Collector`.

    DOFs ``(head, upper, lower)``, z up [m]; the contact DOF is the head; the base drives
    the lower frame through ``k3, c3``; the static force and the frame friction act on the
    lower frame.  With ``lower_mass = 0`` (two-mass model) the DOFs are ``(head, frame)``,
    the base drives the frame through ``k2, c2`` and the static force and friction act on
    the frame.

    Parameters
    ----------
    pp : PantographParams
    static_force : float, optional
        Override of ``pp.static_force`` [N] (e.g. a speed-dependent mean force).
    """
    M, C, K = _matrices(pp)
    F0 = pp.static_force if static_force is None else float(static_force)
    if pp.lower_mass == 0.0:
        return Collector(M=M, C=C, K=K, head=0, f_static=np.array([0.0, F0]),
                         base_k=np.array([0.0, pp.upper_stiffness]),
                         base_c=np.array([0.0, pp.upper_damping]), labels=("head", "frame"),
                         friction=pp.frame_friction, friction_dof=-1)
    return Collector(M=M, C=C, K=K, head=0, f_static=np.array([0.0, 0.0, F0]),
                     base_k=np.array([0.0, 0.0, pp.lower_stiffness]),
                     base_c=np.array([0.0, 0.0, pp.lower_damping]),
                     labels=("head", "upper", "lower"), friction=pp.frame_friction,
                     friction_dof=-1)


def vertical_modes(pp: PantographParams, contact_stiffness: float = 0.0) -> np.ndarray:
    """Undamped natural frequencies [Hz] of the vertical chain on a fixed base, with the
    head on a ground spring ``contact_stiffness`` [N/m] (0: free head)."""
    M, _, K = _matrices(pp)
    K = K.copy()
    K[0, 0] += contact_stiffness
    ev = np.linalg.eigvals(np.linalg.solve(M, K)).real
    return np.sort(np.sqrt(np.clip(ev, 0.0, None))) / (2 * math.pi)


def lateral_response(pp: PantographParams, time, base_y, base_ydot=None) -> np.ndarray:
    """Lateral head displacement [m] under a lateral base motion at head height.

    ``m y'' + c (y' - yb') + k (y - yb) = 0`` integrated exactly for piecewise-linear
    ``yb`` (``scipy.signal.lsim`` with first-order hold), from rest at ``y = yb(0)``.

    Parameters
    ----------
    pp : PantographParams
    time : array_like
        Uniform time [s].
    base_y : array_like
        Base lateral displacement at head height [m] (``Ty - Rx * head_height``).
    base_ydot : array_like, optional
        Its velocity [m/s]; default ``numpy.gradient``.
    """
    from scipy import signal

    t = np.asarray(time, dtype=float)
    yb = np.asarray(base_y, dtype=float)
    if t.shape != yb.shape or t.ndim != 1 or t.size < 2:
        raise EroadInputError("lateral_response: time and base_y must be 1-D of equal length")
    ybd = np.gradient(yb, t) if base_ydot is None else np.asarray(base_ydot, dtype=float)
    m, k, c = pp.lateral_mass, pp.lateral_stiffness, pp.lateral_damping
    # state (e, e') with e = y - yb(0); input u = (yb - yb0, yb')
    A = np.array([[0.0, 1.0], [-k / m, -c / m]])
    B = np.array([[0.0, 0.0], [k / m, c / m]])
    Cm = np.array([[1.0, 0.0]])
    D = np.zeros((1, 2))
    u = np.column_stack([yb - yb[0], ybd])
    _, y, _ = signal.lsim((A, B, Cm, D), u, t, X0=[0.0, 0.0], interp=True)
    return np.asarray(y).ravel() + yb[0]
