"""A second truth family: an independently written lumped-parameter 8x4 truck.

What it is for: every other synthetic drive of the project is made by the Exudyn
model (``vehicles.builder``), so they all share its assumptions.  This module is a
second, separately written vehicle model (numpy only, its own equations of
motion and its own fixed-step RK4 integrator) that reads the same vehicle TOML
and writes the same channels, so that inversion and diagnosis can be tested on
data their own model did not make.  It deliberately imports nothing from
``vehicles`` (the TOML file is parsed here with :mod:`tomllib`).  What it is
not: a replacement of the Exudyn model (no flexible frame, no effect library;
small-displacement kinematics).

Model (equations in ``docs/second_family.md``)
----------------------------------------------
Rigid bodies with 6 small-motion coordinates each ``[u_x, u_y, u_z, phi, theta,
psi]`` about their centre of gravity (the chassis, each axle, and optionally the
cab).  A point ``r`` of a body moves by ``u + omega x r``.  Every connection is a
"generalised spring" along a row vector ``g`` over all coordinates (point
springs: ``g = n . (G_A(r_A) - G_B(r_B))``), so ``K = sum k g^T g`` and
``C = sum c g^T g``.  Static preloads ``f0`` of springs and tyres add the load
(geometric) stiffness ``-[f0]x [r]x`` of each body they act on (the pendulum
term ``-m g h`` of a body on springs below its centre of gravity).  Tyre forces,
leaf-spring friction and lift-off are evaluated as nonlinear forces at every
stage of the integrator.  ``q = 0`` is the static equilibrium on a flat road.

Structural options (``[truth.independent]`` of a scenario; ``NOMINAL_OPTIONS``
turns all of them off):

* ``roll_centre_height_front``/``_rear`` [m above the road]: the axle's lateral
  guide is one link at the vehicle centre line at this height instead of the
  two spring seats (0 = at the seats, as the Exudyn model);
* ``arb_front``/``arb_rear`` [N m/rad per axle]: anti-roll bar (torsion spring
  between chassis roll and axle roll);
* ``cab_mount_stiffness`` [N/m per mount, 0 = cab rigid on the chassis],
  ``cab_mount_damping`` [N s/m], ``cab_mount_shear_stiffness`` [N/m]: the cab as
  its own rigid body on four mounts at the front of the frame;
* ``tyre_progressivity`` [-] (0 = linear): tangent stiffness
  ``k_t (1 + p (delta - delta_ref) / delta_ref)``; ``tyre_liftoff`` (0/1): no
  tension force (a tyre off the road carries nothing);
* ``dual_contacts`` (0/1): the two tyres of a dual pair touch the road at
  ``+-dual_spacing/2`` around the track centre (each sampled at its own y) instead
  of one contact at the track centre with twice the stiffness;
* ``guide_slope_front``/``_rear`` [m/m]: the axle moves on an inclined path,
  fore-aft travel ``= slope x`` vertical travel (shackled leaf spring, bogie
  arcs); ``windup_front``/``_rear`` [rad/m]: axle pitch per vertical travel
  (leaf-spring wind-up geometry).

Effects (the project's effect names, written here independently):
``leaf_friction`` (``force`` [N] per spring, ``velocity`` [m/s]: F tanh(v/v0)
at each leaf spring's seat) and ``payload`` (``mass`` [kg], ``dx``, ``dy`` [m]:
mass added to the chassis at the payload item's centre + (dx, dy); outputs stay
zeroed at the nominal vehicle's static equilibrium, so the extra sag shows).
"""
from __future__ import annotations

import math
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from eroad.errors import EroadInputError

G = 9.81
#: folder of the built-in vehicle files (read as data, not through vehicles.params)
PARAMS_DIR = Path(__file__).resolve().parent.parent / "vehicles" / "params"

#: structural options: name -> (default, lowest, highest, unit, meaning)
OPTIONS = {
    "roll_centre_height_front": (0.60, 0.0, 1.5, "m", "front axles' roll-centre height (0: at the spring seats)"),
    "roll_centre_height_rear": (0.95, 0.0, 1.5, "m", "tandem axles' roll-centre height (0: at the spring seats)"),
    "arb_front": (1.5e5, 0.0, 2e6, "N m/rad", "anti-roll bar per front axle"),
    "arb_rear": (3.0e5, 0.0, 3e6, "N m/rad", "anti-roll bar per tandem axle"),
    "cab_mount_stiffness": (1.2e5, 0.0, 5e7, "N/m", "vertical stiffness of one of 4 cab mounts (0: rigid cab)"),
    "cab_mount_damping": (3.0e3, 0.0, 1e5, "N s/m", "vertical damping of one cab mount"),
    "cab_mount_shear_stiffness": (2.0e5, 0.0, 5e7, "N/m", "fore-aft and lateral stiffness of one cab mount"),
    "tyre_progressivity": (0.3, 0.0, 0.9, "-", "tangent tyre stiffness rise per static deflection (0: linear)"),
    "tyre_liftoff": (1.0, 0.0, 1.0, "-", "1: a tyre carries no tension (lifts off); 0: bilateral"),
    "dual_contacts": (1.0, 0.0, 1.0, "-", "1: dual tyres touch at +-dual_spacing/2; 0: one contact at the track centre"),
    "guide_slope_front": (0.10, -0.5, 0.5, "m/m", "front axles' fore-aft travel per vertical travel"),
    "guide_slope_rear": (-0.15, -0.5, 0.5, "m/m", "tandem axles' fore-aft travel per vertical travel"),
    "windup_front": (0.10, -1.0, 1.0, "rad/m", "front axles' pitch per vertical travel"),
    "windup_rear": (0.20, -1.0, 1.0, "rad/m", "tandem axles' pitch per vertical travel"),
    "dt_s": (0.001, 1e-4, 0.005, "s", "integrator step (rounded to divide the output period)"),
}
#: every structural difference off: the vertical-plane twin of the Exudyn model
NOMINAL_OPTIONS = {"roll_centre_height_front": 0.0, "roll_centre_height_rear": 0.0,
                   "arb_front": 0.0, "arb_rear": 0.0, "cab_mount_stiffness": 0.0,
                   "tyre_progressivity": 0.0, "tyre_liftoff": 0.0, "dual_contacts": 1.0,
                   "guide_slope_front": 0.0, "guide_slope_rear": 0.0,
                   "windup_front": 0.0, "windup_rear": 0.0}
#: effects this model writes itself: name -> {param: (default, lo, hi)}
EFFECTS = {"leaf_friction": {"force": (2000.0, 0.0, 20000.0), "velocity": (0.01, 1e-3, 0.1)},
           "payload": {"mass": (2000.0, -50000.0, 50000.0), "dx": (0.0, -3.0, 3.0),
                       "dy": (0.0, -1.0, 1.0)}}
#: surge (speed-control) spring: frequency [Hz] and damping ratio, as the vehicle docs state
SURGE_HZ, SURGE_ZETA = 3.0, 0.5
#: damping of the axle guides and tyres that the vehicle TOML does not give: fore-aft guide
#: damping = GUIDE_DAMPING_LON x the axle's ``damping``, lateral guide = GUIDE_DAMPING_LAT x it,
#: lateral tyre damping = TYRE_LATERAL_DAMPING x ``tyre_damping`` (bushing and carcass damping;
#: values set so that the nominal options reproduce the Exudyn model's roll-plane and fore-aft
#: response, docs/second_family.md "Agreement")
GUIDE_DAMPING_LON, GUIDE_DAMPING_LAT, TYRE_LATERAL_DAMPING = 1.0, 0.4, 1.0


def resolve_options(opts: dict | None, src="[truth.independent]") -> dict:
    """All options with defaults filled in and ranges checked.

    Raises
    ------
    EroadInputError
        Unknown option or value outside its range.
    """
    out = {k: v[0] for k, v in OPTIONS.items()}
    for k, v in dict(opts or {}).items():
        if k not in OPTIONS:
            raise EroadInputError(f"{src}: unknown option {k!r} (known: {', '.join(OPTIONS)})")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise EroadInputError(f"{src}: {k} must be a number, got {v!r}")
        lo, hi = OPTIONS[k][1], OPTIONS[k][2]
        if not lo <= v <= hi:
            raise EroadInputError(f"{src}: {k} = {v} outside {lo:g} .. {hi:g} {OPTIONS[k][3]}")
        out[k] = float(v)
    for k in ("tyre_liftoff", "dual_contacts"):
        if out[k] not in (0.0, 1.0):
            raise EroadInputError(f"{src}: {k} must be 0 or 1, got {out[k]:g}")
    return out


def resolve_effects(effects: dict | None) -> dict:
    """The supported effects with defaults filled in; others refused in one line."""
    out = {}
    for name, params in dict(effects or {}).items():
        if name not in EFFECTS:
            raise EroadInputError(f"effect {name!r} is not available with [truth] model = "
                                  f"\"independent\" (supported: {', '.join(EFFECTS)})")
        spec = EFFECTS[name]
        p = {k: v[0] for k, v in spec.items()}
        for k, v in dict(params or {}).items():
            if k not in spec:
                raise EroadInputError(f"effect {name}: unknown parameter {k!r} (known: {', '.join(spec)})")
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) \
                    or not spec[k][1] <= v <= spec[k][2]:
                raise EroadInputError(f"effect {name}.{k} = {v!r} outside {spec[k][1]:g} .. {spec[k][2]:g}")
            p[k] = float(v)
        out[name] = p
    return out


# --------------------------------------------------------------------------- vehicle data

def read_vehicle_toml(vehicle) -> dict:
    """The vehicle file as a plain dict (built-in id or path), parsed here with tomllib."""
    s = str(vehicle)
    p = Path(s)
    if not p.suffix == ".toml":
        p = PARAMS_DIR / f"{s}.toml"
    if not p.is_file():
        raise EroadInputError(f"{vehicle}: no such vehicle file for the independent model")
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise EroadInputError(f"{p}: not valid TOML: {exc}") from None
    for key in ("axle", "mass", "frame"):
        if key not in doc:
            raise EroadInputError(f"{p}: missing [{key}] for the independent model")
    if "dcdc" in doc:
        raise EroadInputError(f"{p}: the independent model has no DCDC block (dump truck only)")
    return doc


def _box_inertia(m, lx, ly, lz) -> np.ndarray:
    return m / 12.0 * np.diag([ly * ly + lz * lz, lx * lx + lz * lz, lx * lx + ly * ly])


def _rigid_props(items) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of gravity and 3x3 inertia tensor about it of (m, centre, box) items."""
    m = sum(i[0] for i in items)
    c = sum(i[0] * np.asarray(i[1]) for i in items) / m
    J = np.zeros((3, 3))
    for mi, ci, box in items:
        d = np.asarray(ci) - c
        J += _box_inertia(mi, *box) + mi * (d @ d * np.eye(3) - np.outer(d, d))
    return float(m), c, J


def _skew(a) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


# --------------------------------------------------------------------------- the model

@dataclass
class TruckModel:
    """Assembled linear part, nonlinear element tables and output maps."""

    n: int
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    bodies: dict
    tyres: dict                   # arrays per tyre: G rows, k, c, y, x, static load, ...
    friction: dict                # G rows (seat relative motion), force, velocity
    outputs: dict                 # channel -> (kind, G row)
    static_offset: np.ndarray     # output offsets (payload sag w.r.t. the nominal vehicle)
    static: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    effects: dict = field(default_factory=dict)


class _Assembler:
    def __init__(self):
        self.bodies = {}          # name -> (offset, ref point)
        self.n = 0

    def add_body(self, name, ref):
        self.bodies[name] = (self.n, np.asarray(ref, float))
        self.n += 6

    def point_map(self, body, p) -> np.ndarray:
        """3 x n map from coordinates to the small displacement of world point p on body."""
        out = np.zeros((3, self.n))
        if body is None:
            return out
        i, ref = self.bodies[body]
        r = np.asarray(p, float) - ref
        out[:, i:i + 3] = np.eye(3)
        out[:, i + 3:i + 6] = -_skew(r)       # omega x r = -r x omega
        return out

    def row(self, body_a, pa, body_b, pb, n) -> np.ndarray:
        """Generalised direction: n . (displacement of pa on A - displacement of pb on B)."""
        n = np.asarray(n, float)
        return n @ self.point_map(body_a, pa) - n @ self.point_map(body_b, pb)

    def rot_row(self, body, k) -> np.ndarray:
        out = np.zeros(self.n)
        if body is not None:
            out[self.bodies[body][0] + 3 + k] = 1.0
        return out

    def geometric(self, body, p, f0) -> np.ndarray:
        """Load stiffness of a constant world force f0 at world point p of body."""
        Kg = np.zeros((self.n, self.n))
        if body is None:
            return Kg
        i, ref = self.bodies[body]
        r = np.asarray(p, float) - ref
        Kg[i + 3:i + 6, i + 3:i + 6] = -_skew(f0) @ _skew(r)
        return Kg


def build_truck(vehicle="dump_truck_8x4", options: dict | None = None,
                effects: dict | None = None) -> TruckModel:
    """Assemble the independent truck model.

    Parameters
    ----------
    vehicle : str or Path
        Built-in vehicle id or vehicle TOML file.
    options : dict, optional
        Structural options (:data:`OPTIONS`; missing ones take their defaults).
    effects : dict, optional
        ``{"leaf_friction": {...}, "payload": {...}}`` (:data:`EFFECTS`).

    Returns
    -------
    TruckModel
    """
    opt = resolve_options(options)
    eff = resolve_effects(effects)
    doc = read_vehicle_toml(vehicle)
    axles = doc["axle"]
    masses = list(doc["mass"])
    frame = doc["frame"]
    na = len(axles)
    front = [bool(a.get("steered", i < na // 2)) for i, a in enumerate(axles)]

    def items_of(ms, extra=()):
        out = []
        for m in ms:
            lx = float(m["x_front"]) - float(m["x_rear"])
            c = (0.5 * (float(m["x_front"]) + float(m["x_rear"])), float(m["y"]), float(m["z"]))
            out.append((float(m["mass"]), c, (lx, float(m["width"]), float(m["height"]))))
        return out + list(extra)

    cab_on = opt["cab_mount_stiffness"] > 0
    cab_idx = [i for i, m in enumerate(masses) if "cab" in str(m.get("name", "")).lower()]
    if cab_on and len(cab_idx) != 1:
        raise EroadInputError(f"{vehicle}: exactly one [[mass]] item named 'cab...' is needed for "
                              "the cab on mounts")
    cab_items = items_of([masses[cab_idx[0]]]) if cab_on else []
    chassis_ms = [m for i, m in enumerate(masses) if not (cab_on and i == cab_idx[0])]
    extra = []
    if "payload" in eff:
        pl = [m for m in masses if m.get("payload", False)]
        ref = pl[0] if pl else masses[-1]
        c = (0.5 * (float(ref["x_front"]) + float(ref["x_rear"])) + eff["payload"]["dx"],
             float(ref["y"]) + eff["payload"]["dy"], float(ref["z"]))
        box = (float(ref["x_front"]) - float(ref["x_rear"]), float(ref["width"]), float(ref["height"]))
        extra = [(eff["payload"]["mass"], c, box)]

    def assemble(chassis_items):
        A = _Assembler()
        mb, cb, Jb = _rigid_props(chassis_items)
        A.add_body("chassis", cb)
        mass_blocks = [(mb, Jb)]
        if cab_on:
            mc, cc, Jc = _rigid_props(cab_items)
            A.add_body("cab", cc)
            mass_blocks.append((mc, Jc))
        for i, a in enumerate(axles):
            A.add_body(f"axle{i + 1}", (float(a["x"]), 0.0, float(a["tyre_radius"])))
            mass_blocks.append((float(a["unsprung_mass"]),
                                np.diag([float(a["roll_inertia"]), float(a["pitch_inertia"]),
                                         float(a["yaw_inertia"])])))
        M = np.zeros((A.n, A.n))
        for b, (mi, Ji) in enumerate(mass_blocks):
            M[6 * b:6 * b + 3, 6 * b:6 * b + 3] = mi * np.eye(3)
            M[6 * b + 3:6 * b + 6, 6 * b + 3:6 * b + 6] = Ji
        return A, M, mb, cb

    A, M, m_ch, c_ch = assemble(items_of(chassis_ms, extra))
    n = A.n
    K = np.zeros((n, n))
    C = np.zeros((n, n))
    ez, ex, ey = np.eye(3)[2], np.eye(3)[0], np.eye(3)[1]
    preloaded = []   # (row, body_a, point, body_b, point, direction) of load-carrying springs
    fric_rows, fric_force = [], []
    leaf = eff.get("leaf_friction")
    outputs = {}

    def spring(g, k, c=0.0):
        K[:] += k * np.outer(g, g)
        if c:
            C[:] += c * np.outer(g, g)

    for i, a in enumerate(axles):
        ax = f"axle{i + 1}"
        xa = float(a["x"])
        hs = float(a["seat_height"])
        st = float(a["spring_track"])
        R = float(a["tyre_radius"])
        key = "front" if front[i] else "rear"
        rc = opt[f"roll_centre_height_{key}"]
        slope = opt[f"guide_slope_{key}"]
        wind = opt[f"windup_{key}"]
        for side, sy in (("L", 1.0), ("R", -1.0)):
            p = (xa, sy * st / 2, hs)
            gz = A.row(ax, p, "chassis", p, ez)          # compression: axle seat up vs chassis seat
            spring(gz, float(a["spring_stiffness"]), float(a["damping"]))
            preloaded.append((gz, ax, p, "chassis", p))
            # fore-aft guide along the inclined axle path: x_rel - slope z_rel
            gx = A.row(ax, p, "chassis", p, ex) - slope * gz
            spring(gx, float(a["guide_longitudinal_stiffness"]), GUIDE_DAMPING_LON * float(a["damping"]))
            if rc <= 0:
                spring(A.row(ax, p, "chassis", p, ey), float(a["guide_lateral_stiffness"]), GUIDE_DAMPING_LAT * float(a["damping"]))
            if leaf is not None and str(a.get("spring_type", "leaf")) == "leaf" and leaf["force"] > 0:
                fric_rows.append(gz)
                fric_force.append(leaf["force"])
            outputs[f"susp_disp_{i + 1}{side}"] = ("disp", gz)
            outputs[f"axle_acc_{i + 1}{side}"] = ("acc", ez @ A.point_map(ax, (xa, sy * float(a["track"]) / 2, R)))
            outputs[f"body_acc_{i + 1}{side}"] = ("acc", ez @ A.point_map("chassis", p))
        if rc > 0:   # one lateral link at the centre line, at the roll-centre height
            pc = (xa, 0.0, rc)
            spring(A.row(ax, pc, "chassis", pc, ey), 2.0 * float(a["guide_lateral_stiffness"]),
                   2.0 * GUIDE_DAMPING_LAT * float(a["damping"]))
        # wind-up: axle pitch relative to the chassis minus the geometric wind-up per travel
        gz_mean = 0.5 * (preloaded[-1][0] + preloaded[-2][0])
        gw = A.rot_row(ax, 1) - A.rot_row("chassis", 1) - wind * gz_mean
        spring(gw, float(a["windup_stiffness"]))
        arb = opt[f"arb_{key}"]
        if arb > 0:
            spring(A.rot_row(ax, 0) - A.rot_row("chassis", 0), arb)

    # tyres: contact points (wheel centres; the rolling contact stays below them)
    t_rows, t_k, t_c, t_y, t_x, t_axle, t_p, t_lat = [], [], [], [], [], [], [], []
    for i, a in enumerate(axles):
        ax = f"axle{i + 1}"
        xa, R = float(a["x"]), float(a["tyre_radius"])
        npers = int(a["tyres_per_side"])
        ds = float(a["dual_spacing"])
        for sy in (1.0, -1.0):
            yc = sy * float(a["track"]) / 2
            if npers == 2 and opt["dual_contacts"] > 0:
                ys, mult = [yc - ds / 2, yc + ds / 2], 1.0
            else:
                ys, mult = [yc], float(npers)
            for y in ys:
                p = (xa, y, R)
                t_rows.append(ez @ A.point_map(ax, p))   # wheel-centre z; deflection = road - it
                t_k.append(mult * float(a["tyre_stiffness"]))
                t_c.append(mult * float(a["tyre_damping"]))
                t_y.append(y)
                t_x.append(xa)
                t_axle.append(i)
                t_p.append(p)
                spring(A.row(ax, p, None, p, ey), mult * float(a["tyre_lateral_stiffness"]),
                       TYRE_LATERAL_DAMPING * mult * float(a["tyre_damping"]))
    Gt = np.array(t_rows)
    kt = np.array(t_k)
    ct = np.array(t_c)

    if cab_on:
        cab = masses[cab_idx[0]]
        xf, xr = float(cab["x_front"]) - 0.2, float(cab["x_rear"]) + 0.2
        zm = float(frame["z"]) + 0.15
        kv, cv, ks = opt["cab_mount_stiffness"], opt["cab_mount_damping"], opt["cab_mount_shear_stiffness"]
        for xm in (xf, xr):
            for ym in (0.55, -0.55):
                p = (xm, ym, zm)
                g = A.row("chassis", p, "cab", p, ez)
                spring(g, kv, cv)
                preloaded.append((g, "chassis", p, "cab", p))
                spring(A.row("chassis", p, "cab", p, ex), ks, 0.1 * cv)
                spring(A.row("chassis", p, "cab", p, ey), ks, 0.1 * cv)

    # surge: the speed control holds the chassis along x (3 Hz, 50 % damped, total mass)
    m_tot = float(sum(M[6 * b, 6 * b] for b in range(n // 6)))
    ks_ = m_tot * (2 * math.pi * SURGE_HZ) ** 2
    gs = A.row("chassis", A.bodies["chassis"][1], None, (0, 0, 0), ex)
    spring(gs, ks_, 2 * SURGE_ZETA * math.sqrt(ks_ * m_tot))

    # ---------------- static equilibrium (flat road): springs linear, tyres possibly not
    fg = np.zeros(n)
    for name, (off, _) in A.bodies.items():
        fg[off + 2] = -M[off, off] * G
    p_prog = opt["tyre_progressivity"]
    # reference deflection: the tyre's load in the linear-tyre solution / k
    Kfull = K + Gt.T @ (kt[:, None] * Gt)
    u_lin = np.linalg.solve(Kfull, fg)
    d_lin = -(Gt @ u_lin)                  # deflection (road 0 minus wheel displacement)
    d_ref = np.maximum(d_lin, 1e-6)

    def tyre_static_force(d):
        return kt * ((1 - p_prog) * d + p_prog * d * d / (2 * d_ref))

    def tyre_tangent(d):
        return kt * ((1 - p_prog) + p_prog * d / d_ref)

    u = u_lin.copy()
    for _ in range(50):
        d = -(Gt @ u)
        r = K @ u - Gt.T @ tyre_static_force(d) - fg
        J = K + Gt.T @ (tyre_tangent(d)[:, None] * Gt)
        du = np.linalg.solve(J, -r)
        u += du
        if np.max(np.abs(du)) < 1e-12:
            break
    d_static = -(Gt @ u)
    F_tyre_static = tyre_static_force(d_static)
    # static spring forces (compression positive) and their load stiffness
    Kg = np.zeros((n, n))
    # static spring loads: k (g . u), g . u the compression from the unloaded spring
    ks_list = [float(a["spring_stiffness"]) for a in axles for _ in (0, 1)]
    if cab_on:
        ks_list += [opt["cab_mount_stiffness"]] * 4
    spring_loads = np.array([k * (g @ u) for (g, *_), k in zip(preloaded, ks_list)])
    for (g, ba, pa, bb, pb), F in zip(preloaded, spring_loads):
        # a compression spring pushes body A (below) down and body B (above) up
        Kg += A.geometric(ba, pa, -F * ez) + A.geometric(bb, pb, F * ez)
    for j in range(len(kt)):
        Kg += A.geometric(f"axle{t_axle[j] + 1}", t_p[j], F_tyre_static[j] * ez)
    K_dyn = K + Kg

    # payload: outputs zeroed at the nominal vehicle's static equilibrium
    offset = {}
    if "payload" in eff:
        nominal = build_truck(vehicle, options=options,
                              effects={k: v for k, v in eff.items() if k != "payload"})
        u0 = nominal.static["u"]
        for ch, (kind, g) in outputs.items():
            if kind == "disp":
                offset[ch] = float(g @ u - nominal.outputs[ch][1] @ u0)

    tyres = {"G": Gt, "k": kt, "c": ct, "y": np.array(t_y), "x": np.array(t_x),
             "axle": np.array(t_axle), "d_static": d_static, "F_static": F_tyre_static,
             "d_ref": d_ref, "progressivity": p_prog, "liftoff": bool(opt["tyre_liftoff"] > 0)}
    friction = {"G": np.array(fric_rows).reshape(len(fric_rows), n), "force": np.array(fric_force),
                "velocity": float(leaf["velocity"]) if leaf else 0.01}
    static = {"u": u, "tyre_loads": F_tyre_static, "spring_loads": spring_loads[:2 * na],
              "cab_mount_loads": spring_loads[2 * na:],
              "weight": float(-fg.sum()), "sprung_weight": float((M[0, 0] + (M[6, 6] if cab_on else 0.0)) * G),
              "cab_weight": float(M[6, 6] * G) if cab_on else 0.0,
              "axle_loads": np.array([F_tyre_static[np.array(t_axle) == i].sum() / G for i in range(na)])}
    # channel order of the project's datasets: quantity, then axle, then side
    order = {"susp_disp": 0, "axle_acc": 1, "body_acc": 2}
    outputs = dict(sorted(outputs.items(), key=lambda kv: (order[kv[0][:-3]], kv[0][-2:])))
    static_offset = np.array([offset.get(ch, 0.0) for ch in outputs])
    return TruckModel(n=n, M=M, K=K_dyn, C=C, bodies=dict(A.bodies), tyres=tyres, friction=friction,
                      outputs=outputs, static_offset=static_offset, static=static, options=opt,
                      effects=eff)


def modal_frequencies(model: TruckModel) -> np.ndarray:
    """Undamped natural frequencies [Hz] of the linearised model (tyres at their tangent)."""
    t = model.tyres
    kt = t["k"] * ((1 - t["progressivity"]) + t["progressivity"] * t["d_static"] / t["d_ref"])
    K = model.K + t["G"].T @ (kt[:, None] * t["G"])
    lam = np.linalg.eigvals(np.linalg.solve(model.M, K))
    return np.sort(np.sqrt(np.abs(lam.real)) / (2 * math.pi))


# --------------------------------------------------------------------------- simulation

@dataclass
class IndependentResult:
    """What :func:`simulate_independent` returns (the fields ``drives.synth`` reads)."""

    time: np.ndarray
    channels: dict
    meta: dict
    extra: dict = field(default_factory=dict)


def _distance(t_knots, v_knots, t):
    """Distance travelled at times t for a speed linear between knots (exact)."""
    tk = np.asarray(t_knots, float)
    vk = np.asarray(v_knots, float)
    sk = np.concatenate([[0.0], np.cumsum(0.5 * (vk[1:] + vk[:-1]) * np.diff(tk))])
    j = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, tk.size - 2)
    tau = t - tk[j]
    h = tk[j + 1] - tk[j]
    return sk[j] + vk[j] * tau + 0.5 * (vk[j + 1] - vk[j]) / h * tau * tau


def simulate_independent(model: TruckModel, road, *, t_speed, v_speed, duration: float,
                         fs_out: float, x_start: float, y_offset: float = 0.0) -> IndependentResult:
    """Drive the independent truck over a road.

    Parameters
    ----------
    model : TruckModel
    road : roadlib.surface.RoadSurface
        Anything with ``height(x, y)`` (bilinear, vectorised).
    t_speed, v_speed : array_like
        Speed samples [s], [m/s] (linear in between).
    duration : float
        Simulated time [s] from 0.
    fs_out : float
        Output rate [Hz]; outputs at k / fs_out, k = 0 .. duration * fs_out.
    x_start : float
        Road x of axle 1 at t = 0 [m].
    y_offset : float
        Road y of the vehicle centre line [m].

    Returns
    -------
    IndependentResult
        ``channels`` in the measurement format (+ ``speed``), ``meta``.
    """
    t_wall = time.perf_counter()
    n = model.n
    n_out = int(round(duration * fs_out)) + 1
    sub = max(1, int(math.ceil(1.0 / (fs_out * model.options["dt_s"]) - 1e-9)))
    tyr, fr = model.tyres, model.friction
    Minv = np.linalg.inv(model.M)
    # stiff friction (F/v0 as a viscous gradient) must stay inside RK4's stability region
    if fr["force"].size:
        m_min = min(model.M[6 * b + 2, 6 * b + 2] for b in range(n // 6))
        rate = 2.0 * float(fr["force"].max()) / fr["velocity"] / m_min
        sub = max(sub, int(math.ceil(rate / (fs_out * 2.0))))
    dt = 1.0 / (fs_out * sub)
    n_steps = (n_out - 1) * sub
    # road under every contact on a half-step grid (RK4 stages)
    th = np.arange(2 * n_steps + 3) * (dt / 2)
    s = _distance(t_speed, v_speed, th)
    xs = x_start + s[:, None] + tyr["x"][None, :]
    zr = road.height(xs, y_offset + tyr["y"][None, :] + 0 * xs)
    vr = np.gradient(zr, dt / 2, axis=0)
    # road elevation at t = 0 is carried by a static shift of the whole vehicle: start from
    # the static equilibrium on the road heights at t = 0 (linear, tangent tyres)
    Gt, kt, ct = tyr["G"], tyr["k"], tyr["c"]
    p = tyr["progressivity"]
    d0, dref, F0 = tyr["d_static"], tyr["d_ref"], tyr["F_static"]
    liftoff = tyr["liftoff"]
    Kt_tan = kt * ((1 - p) + p * d0 / dref)
    q = np.linalg.solve(model.K + Gt.T @ (Kt_tan[:, None] * Gt), Gt.T @ (Kt_tan * zr[0]))
    # one Newton polish with the nonlinear tyres
    for _ in range(20):
        dd = zr[0] - Gt @ q
        F = _tyre_force(d0 + dd, 0.0 * dd, kt, ct, p, dref, liftoff) - F0
        r = model.K @ q - Gt.T @ F
        if np.max(np.abs(r)) < 1e-6:
            break
        q -= np.linalg.solve(model.K + Gt.T @ (Kt_tan[:, None] * Gt), r)
    v = np.zeros(n)
    A_K = Minv @ model.K
    A_C = Minv @ model.C
    B_t = Minv @ Gt.T
    has_fric = fr["force"].size > 0
    if has_fric:
        Gf, Ff, v0 = fr["G"], fr["force"], fr["velocity"]
        B_f = Minv @ Gf.T
    lift_count = 0

    def accel(q, v, k):
        dd = zr[k] - Gt @ q
        dv = vr[k] - Gt @ v
        F = _tyre_force(d0 + dd, dv, kt, ct, p, dref, liftoff) - F0
        a = B_t @ F - A_K @ q - A_C @ v
        if has_fric:
            a -= B_f @ (Ff * np.tanh((Gf @ v) / v0))
        return a

    out_q = np.empty((n_out, n))
    out_v = np.empty((n_out, n))
    out_a = np.empty((n_out, n))
    out_q[0] = q
    out_v[0] = v
    out_a[0] = accel(q, v, 0)
    half = dt / 2
    k = 0
    for step in range(n_steps):
        k1v = accel(q, v, k)
        k1q = v
        q2 = q + half * k1q
        v2 = v + half * k1v
        k2v = accel(q2, v2, k + 1)
        q3 = q + half * v2
        v3 = v + half * k2v
        k3v = accel(q3, v3, k + 1)
        q4 = q + dt * v3
        v4 = v + dt * k3v
        k4v = accel(q4, v4, k + 2)
        q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
        k += 2
        if (step + 1) % sub == 0:
            j = (step + 1) // sub
            out_q[j] = q
            out_v[j] = v
            out_a[j] = accel(q, v, k)
            if not np.all(np.isfinite(q)):
                from eroad.errors import SimulationError

                raise SimulationError(f"independent truck diverged at t = {j / fs_out:.3f} s")
    t_out = np.arange(n_out) / fs_out
    ko = np.arange(n_out) * 2 * sub
    defl = d0[None, :] + zr[ko] - out_q @ Gt.T
    tyre_force = _tyre_force(defl, vr[ko] - out_v @ Gt.T, kt, ct, p, dref, liftoff)
    lift_frac = float(np.mean(np.any(defl < 0, axis=1)))
    channels = {}
    for (ch, (kind, g)), off in zip(model.outputs.items(), model.static_offset):
        channels[ch] = (out_q @ g + off) if kind == "disp" else out_a @ g
    channels["speed"] = np.interp(t_out, np.asarray(t_speed, float), np.asarray(v_speed, float))
    meta = {"model": "independent (drives.independent_truck)", "n_dof": n, "dt": dt,
            "integrator": "RK4, fixed step", "steps": n_steps, "fs_out": fs_out,
            "x_start": x_start, "y_offset": y_offset, "options": dict(model.options),
            "effects": {k: dict(v) for k, v in model.effects.items()},
            "n_contacts": int(len(kt)), "tyre_lift_off_fraction": lift_frac,
            "axle_loads_t": [float(x) / 1000 for x in model.static["axle_loads"]],
            "wall_s": time.perf_counter() - t_wall}
    return IndependentResult(time=t_out, channels=channels, meta=meta,
                             extra={"road_z": zr[ko], "q": out_q, "tyre_force": tyre_force,
                                    "contact_y": y_offset + tyr["y"], "contact_x": tyr["x"]})


def _tyre_force(d, dv, kt, ct, p, dref, liftoff):
    """Total tyre force [N] (compression positive) at deflection d and rate dv."""
    if p > 0:
        F = kt * ((1 - p) * d + p * d * d / (2 * dref))
    else:
        F = kt * d
    F = F + ct * dv
    if liftoff:
        F = np.where(d > 0, np.maximum(F, 0.0), 0.0)
    return F
