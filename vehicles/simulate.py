"""Drive a vehicle model over a road: the time simulation and its outputs.

What it is for: :func:`simulate` takes a vehicle, a :class:`roadlib.surface.RoadSurface`,
a speed (constant or a :class:`SpeedProfile`), effects, and returns a
:class:`vehicles.result.SimResult` with the measurement channels at 200 Hz.  It is the
simulator the virtual test drive, the inverse fit and the gap diagnosis call, many
times, so it is built for speed:

* the road height and slope under every tyre are computed for the whole time grid
  at once (each tyre's own line, linear in x, vectorised) and turned into the generalised road
  forces on the axle nodes (see :mod:`vehicles.builder`);
* one Python ``PreStep`` callback per step only indexes that array and sets the
  road forces with one call; everything else runs in Exudyn's C++;
* the linear model (no nonlinear effect) is integrated with the implicit
  generalized-alpha method as a linear implicit scheme (one solve per step with the
  Jacobian factorised once); nonlinear effects switch Newton iterations on;
* outputs come from world-frame node sensors stored in memory and are turned into
  point motions by rigid-body kinematics in numpy afterwards.

What it is not: the model (:mod:`vehicles.builder`), the effects
(:mod:`vehicles.effects`) or the dataset writer (:mod:`drives.format`).

Kinematics: the vehicle stays at x = 0 and the road moves under it.  The first axle
is at road position ``x_start + s(t)`` with ``s(t)`` the integral of the speed, axle
``a`` at ``x_start + s(t) + axle.x`` (``axle.x <= 0``), so each axle sees the road
delayed by its distance to the first axle.  A tyre at vehicle lateral position ``y``
runs on road lateral position ``y_offset + y`` (y positive to the left).
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass

import numpy as np

from eroad.errors import EroadInputError, SimulationError
from vehicles.builder import SIDE_SIGN, SIDES, _quiet, build_model
from vehicles.effects import EFFECTS, any_nonlinear, resolve_effects, suspension_terms_of
from vehicles.effects.base import EffectContext
from vehicles.params import VehicleParams, load_vehicle
from vehicles.result import SimResult, unit_of
from vehicles.tyre_contact import TYRE_CONTACTS, tyre_forces, unilateral_prestep

#: frame stiffness factor above which Newton iterations are switched on: with the
#: Jacobian factorised once and one solve per step, joints ~1e4 times stiffer than
#: nominal drift (measured: 1e3 fine, 1e4 diverges)
STIFF_FRAME_NEWTON = 300.0
#: integrators of :func:`simulate` (``solver``)
SOLVERS = ("exudyn", "linear")
#: channels larger than this [m] or [m/s^2] mean the solution diverged
DIVERGENCE_LIMIT = {"susp_disp": 2.0, "axle_acc": 5e3, "body_acc": 5e3}
#: how often a failed Newton run is repeated with the time step halved.  Stiff
#: regularised nonlinearities (leaf friction F tanh(v / v0): slope F / v0 up to ~1e6 N s/m)
#: dominate the Newton matrix once F / v0 exceeds the axle's inertia term m / (gamma dt);
#: Newton then jumps between the stick and slip branches and stops after its iteration
#: limit.  Exudyn's own step reduction copes but leaves the output grid; halving dt
#: halves that ratio (measured: 16400 N at dt = 2.5 ms fails, at 1.25 ms runs).  Three
#: halvings bound the cost of a failing run to 1 + 2 + 4 + 8 = 15 runs; the largest
#: advertised friction needs at most two on the roads tried (benchmarks/effect_ranges.py).
MAX_DT_HALVINGS = 3


@dataclass(frozen=True)
class SpeedProfile:
    """Vehicle speed as a piecewise-linear function of time.

    Parameters
    ----------
    t : array_like (n,)
        Times [s], strictly increasing, starting at or before 0.
    v : array_like (n,)
        Speeds [m/s], all > 0.

    Raises
    ------
    EroadInputError
        Non-increasing times, non-positive or non-finite speeds, fewer than 2 points.
    """

    t: np.ndarray
    v: np.ndarray

    def __post_init__(self):
        t = np.asarray(self.t, float).ravel()
        v = np.asarray(self.v, float).ravel()
        if t.size != v.size or t.size < 2:
            raise EroadInputError("speed profile: t and v need the same length >= 2")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
            raise EroadInputError("speed profile: t and v must be finite")
        bad = np.nonzero(np.diff(t) <= 0)[0]
        if bad.size:
            raise EroadInputError(f"speed profile: time not strictly increasing at row {bad[0] + 2}")
        if np.any(v <= 0):
            i = int(np.nonzero(v <= 0)[0][0])
            raise EroadInputError(f"speed profile: speed must be > 0 m/s, got {v[i]:g} at t = {t[i]:g} s")
        if t[0] > 0:
            raise EroadInputError(f"speed profile: must start at t <= 0, starts at {t[0]:g} s")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "v", v)

    def speed(self, tq) -> np.ndarray:
        """Speed [m/s] at times ``tq`` [s] (linear interpolation)."""
        return np.interp(tq, self.t, self.v)

    def distance(self, tq) -> np.ndarray:
        """Distance travelled since t = 0 [m] at times ``tq`` (exact integral of the
        piecewise-linear speed)."""
        return self._abs_distance(np.asarray(tq, float)) - self._abs_distance(np.array(0.0))

    def _abs_distance(self, tq):
        seg = np.diff(self.t) * 0.5 * (self.v[1:] + self.v[:-1])
        S = np.concatenate([[0.0], np.cumsum(seg)])
        i = np.clip(np.searchsorted(self.t, tq, side="right") - 1, 0, self.t.size - 2)
        tau = tq - self.t[i]
        slope = (self.v[i + 1] - self.v[i]) / (self.t[i + 1] - self.t[i])
        return S[i] + self.v[i] * tau + 0.5 * slope * tau ** 2

    @property
    def t_end(self) -> float:
        return float(self.t[-1])

    @classmethod
    def constant(cls, v: float, duration: float) -> "SpeedProfile":
        """A constant speed ``v`` [m/s] over ``[0, duration]`` [s]."""
        v = float(v)
        if not (math.isfinite(v) and v > 0):
            raise EroadInputError(f"speed must be > 0 m/s, got {v!r}")
        return cls(np.array([0.0, float(duration)]), np.array([v, v]))

    @classmethod
    def from_csv(cls, path) -> "SpeedProfile":
        """Read a CSV with a header and columns ``time`` [s] and ``speed`` [m/s].

        Raises
        ------
        EroadInputError
            Missing file or columns, values that are not numbers (file, column, row).
        """
        import pandas as pd
        from pathlib import Path

        path = Path(path)
        if not path.is_file():
            raise EroadInputError(f"{path}: no such speed-profile file")
        try:
            df = pd.read_csv(path)
        except Exception as exc:  # noqa: BLE001 - pandas raises many types
            raise EroadInputError(f"{path}: not a readable CSV ({exc})") from None
        cols = {c.strip().lower(): c for c in df.columns}
        tc = cols.get("time", cols.get("t"))
        vc = cols.get("speed", cols.get("v"))
        if tc is None or vc is None:
            raise EroadInputError(f"{path}: needs columns 'time' [s] and 'speed' [m/s], "
                                  f"has {', '.join(map(str, df.columns))}")
        for c in (tc, vc):
            vals = pd.to_numeric(df[c], errors="coerce")
            if vals.isna().any():
                row = int(np.nonzero(vals.isna().to_numpy())[0][0]) + 2
                raise EroadInputError(f"{path}: column {c}, row {row}: not a number")
        try:
            return cls(df[tc].to_numpy(float), df[vc].to_numpy(float))
        except EroadInputError as exc:
            raise EroadInputError(f"{path}: {exc}") from None


def _speed_profile(speed, duration) -> SpeedProfile:
    if isinstance(speed, SpeedProfile):
        if speed.t_end < duration - 1e-9:
            raise EroadInputError(f"speed profile ends at t = {speed.t_end:g} s, before the "
                                  f"duration {duration:g} s")
        return speed
    try:
        v = float(speed)
    except (TypeError, ValueError):
        raise EroadInputError(f"speed must be a number [m/s] or a SpeedProfile, got {speed!r}") from None
    return SpeedProfile.constant(v, duration)


def road_under_tyres(road, model, x_start, y_offset, s, v):
    """Road height and its time derivative under every tyre.

    The profile of each tyre's track at the road's grid x (the road's own line where the
    surface has exact lines, else interpolated in y), then linear interpolation in x (the
    same numbers as ``road.height``, and the exact slope of the interpolant).

    Parameters
    ----------
    road : RoadSurface
    model : VehicleModel
    x_start : float
        Road x of the first axle at t = 0 [m].
    y_offset : float
        Road y of the vehicle centre line [m].
    s : ndarray (n,)
        Distance travelled [m].
    v : ndarray (n,)
        Speed [m/s].

    Returns
    -------
    (z, z_t) : ndarrays (n, n_contacts)
        Height [m] and its rate [m/s] (slope along x times speed).
    """
    vp = model.vp
    n = s.size
    z = np.empty((n, len(model.contacts)))
    z_t = np.empty_like(z)
    gx = road.x
    dx = road.dx
    # every tyre's track at once (a synthesised road evaluates its field at each tyre's own
    # lateral position, roadlib.surface "Exact lines"; any other road is bilinear in y)
    tracks = road.tracks([y_offset + ct.y for ct in model.contacts])
    for c, ct in enumerate(model.contacts):
        track = tracks[c]
        xq = x_start + vp.axles[ct.axle].x + s
        z[:, c] = np.interp(xq, gx, track)
        i = np.clip(((xq - gx[0]) / dx).astype(np.intp), 0, gx.size - 2)
        z_t[:, c] = (track[i + 1] - track[i]) / dx * v
    return z, z_t


def output_points(model):
    """Body-fixed points behind the output channels.

    Returns
    -------
    list of (channel, kind, body name, design world point (3,))
        kind is ``"z_pos"`` (vertical position), ``"z_acc"`` (vertical acceleration) or
        ``"yz_pos"`` (DCDC points: lateral and vertical position).
    """
    vp = model.vp
    pts = []
    for s in model.suspensions:
        a = s.axle
        ax = vp.axles[a]
        seg = model.segments[s.segment].name
        tag = f"{a + 1}{s.side}"
        pts.append((f"seat_axle_{tag}", "z_pos", model.axles[a].name, s.point))
        pts.append((f"seat_body_{tag}", "z_pos", seg, s.point))
        end = np.array([ax.x, SIDE_SIGN[s.side] * ax.track / 2, ax.tyre_radius])
        pts.append((f"axle_acc_{tag}", "z_acc", model.axles[a].name, end))
        pts.append((f"body_acc_{tag}", "z_acc", seg, s.point))
    if vp.dcdc is not None:
        d = vp.dcdc
        for k, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, -1), (-1, 1)), start=1):
            p = np.array([d.x + sx * d.point_x, d.y + sy * d.point_y, d.z_base + d.height])
            pts.append((f"P{k}", "yz_pos", "dcdc", p))
    return pts


def _static_point(model, body_name, world_point):
    b = model.body(body_name)
    p0, R0 = model.static[body_name]
    return p0 + R0 @ (np.asarray(world_point) - b.cog)


def _sensor_arrays(model, name):
    mbs = model.mbs
    out = {}
    for key, s in model.sensors[name].items():
        d = np.asarray(mbs.GetSensorStoredData(s))
        out[key] = d[:, 1:]
        out["t"] = d[:, 0]
    out["RotationMatrix"] = out["RotationMatrix"].reshape(-1, 3, 3)
    return out


def _body_points(data, L):
    """World positions and accelerations of several body-fixed points.

    Parameters
    ----------
    data : dict
        Node outputs (n samples): Position (n, 3), RotationMatrix (n, 3, 3),
        Acceleration, AngularVelocity, AngularAcceleration (n, 3), world frame.
    L : ndarray (m, 3)
        Points relative to the centre of gravity, body axes [m].

    Returns
    -------
    (P, A) : ndarrays (n, 3, m)
        Positions [m] and accelerations [m/s^2] (a + alpha x d + omega x (omega x d)).
    """
    d = np.matmul(data["RotationMatrix"], np.ascontiguousarray(L.T))       # (n, 3, m)
    P = data["Position"][:, :, None] + d
    w = data["AngularVelocity"][:, :, None]
    al = data["AngularAcceleration"][:, :, None]
    wd = _cross(w, d)
    A = data["Acceleration"][:, :, None] + _cross(al, d) + _cross(w, wd)
    return P, A


def _cross(a, b):
    """Cross product along axis 1 of (n, 3, 1) and (n, 3, m) arrays."""
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=1)


def _small_rotation(R, R0):
    M = np.einsum("nij,kj->nik", R, R0)    # R R0^T
    return np.stack([0.5 * (M[:, 2, 1] - M[:, 1, 2]), 0.5 * (M[:, 0, 2] - M[:, 2, 0]),
                     0.5 * (M[:, 1, 0] - M[:, 0, 1])], axis=1)


def simulate(vehicle, road, speed, duration: float, chassis: str = "rigid", effects=None,
             dt: float | None = None, fs_out: float = 200.0, x_start: float | None = None,
             y_offset: float = 0.0, seed: int | None = None, frame_segments: int | None = None,
             newton: bool | None = None, tyres: str = "unilateral",
             lift_off_expected: bool = False, solver: str = "exudyn") -> SimResult:
    """Simulate a vehicle driving over a road.

    The linear model (no nonlinear effect) is integrated with one linear solve per
    step; should that fail or diverge (motions so large that the geometric
    nonlinearity matters, e.g. a very rough road), the run is repeated with Newton
    iterations (``meta["newton_fallback"] = True``) before an error is raised.  A run
    with Newton iterations whose iterations fail to converge (stiff stick-slip
    friction) is repeated with the time step halved, at most :data:`MAX_DT_HALVINGS`
    times (``meta["dt_halvings"]``; ``meta["dt"]`` is the step used).

    Tyres are unilateral by default: a tyre off the road carries no force
    (:mod:`vehicles.tyre_contact`).  The drive is first run with linear tyres, which is
    exact while every tyre presses on the road; if a tyre would have pulled at any output
    sample, the drive is run again with the one-sided correction
    (``meta["tyre_contact_run"]`` is then ``"unilateral"``, else ``"linear"``).  The
    corrected run looks at the tyres from the start, so it does not depend on the linear
    run: ``lift_off_expected=True`` skips the linear run and gives the same result (callers
    that drive one road many times, as the diagnosis does, save the first run).

    Parameters
    ----------
    vehicle : str or Path or VehicleParams
        Built-in id, TOML file or parameters.
    road : roadlib.surface.RoadSurface
        Must cover the drive: from the last axle at ``t = 0`` to the first axle at
        ``t = duration`` (plus half a tyre footprint when enveloping is on).
    speed : float or SpeedProfile
        Constant speed [m/s] (> 0) or a profile covering ``[0, duration]``.
    duration : float
        Simulated time [s].
    chassis : {"rigid", "flexible"}
        Frame model; the ``frame_flex`` effect also switches to flexible.
    effects : dict or list of str, optional
        ``{name: value | {param: value}}`` or ``["NAME=VALUE", ...]``; off by default.
    dt : float, optional
        Time step [s]; default ``vehicle.solver.dt``, rounded so that the output period
        ``1/fs_out`` is a whole number of steps.
    fs_out : float
        Output sample rate [Hz].
    x_start : float, optional
        Road position of the first axle at ``t = 0`` [m]; default: the last axle at
        the start of the road (plus half a footprint).
    y_offset : float
        Road lateral position of the vehicle centre line [m].
    seed : int, optional
        Root seed for random effects (sensor noise); default 0.
    frame_segments : int, optional
        Segments of the flexible frame (default ``vehicle.frame.segments``).
    newton : bool, optional
        Force (True) or suppress (False) Newton iterations; default: only with
        nonlinear effects.
    tyres : {"unilateral", "bilateral"}
        ``"bilateral"``: linear tyres that also pull (the model before lift-off was
        modelled; the linear frequency response's assumption).
    lift_off_expected : bool
        With unilateral tyres: run with the one-sided correction at once (no linear run
        first).  Same result; faster when a tyre does lift off, slower when none does.
    solver : {"exudyn", "linear"}
        ``"linear"``: where the drive's model is linear (no nonlinear effect, no forced
        Newton iterations, no DCDC body) it is integrated on Exudyn's linearisation with the
        same generalized-alpha scheme and step, tyre lift-off corrected as Exudyn's unilateral
        run corrects it (:mod:`vehicles.linear_sim`; ``meta["solver"]`` says which ran).
        Default: Exudyn always.

    Returns
    -------
    SimResult

    Raises
    ------
    EroadInputError
        Bad input, refused before simulating: missing vehicle file, speed <= 0, road
        shorter than the drive or narrower than the vehicle, unknown effect.
    SimulationError
        The solver failed or diverged; the message names the simulated time and the
        likely cause.
    """
    if tyres not in TYRE_CONTACTS:
        raise EroadInputError(f"tyres must be one of {', '.join(TYRE_CONTACTS)}, got {tyres!r}")
    if solver not in SOLVERS:
        raise EroadInputError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
    kw = dict(chassis=chassis, effects=effects, fs_out=fs_out, x_start=x_start,
              y_offset=y_offset, seed=seed, frame_segments=frame_segments, solver=solver)
    wall0, cpu0 = _time.perf_counter(), _time.process_time()
    direct = tyres == "unilateral" and bool(lift_off_expected)
    res = _simulate_retrying(vehicle, road, speed, duration, dt, newton, direct, kw)
    if tyres == "unilateral" and not direct and res.meta["tyre_pull_fraction"] > 0:
        res = _simulate_retrying(vehicle, road, speed, duration, dt, newton, True, kw)
        _stamp_times(res, wall0, cpu0)
    res.meta["tyres"] = tyres
    return res


def _simulate_retrying(vehicle, road, speed, duration, dt, newton, unilateral, kw) -> SimResult:
    """:func:`_simulate` with the Newton fallback and the time-step halvings; ``unilateral``:
    with the one-sided tyre correction."""
    wall0, cpu0 = _time.perf_counter(), _time.process_time()
    fallback, halvings, dt_try, newton_try = False, 0, dt, newton
    while True:
        try:
            res = _simulate(vehicle, road, speed, duration, newton=newton_try, dt=dt_try,
                            unilateral=unilateral, **kw)
            break
        except SimulationError as exc:
            if newton_try is None and not getattr(exc, "newton", True):
                fallback, newton_try = True, True        # linear run failed: Newton
                continue
            if not (getattr(exc, "newton", False) and getattr(exc, "smaller_dt_may_help", False)
                    and halvings < MAX_DT_HALVINGS):
                if halvings:
                    raise SimulationError(f"{exc} (also with the time step halved {halvings} "
                                          f"time(s), dt = {exc.dt:g} s)") from None
                raise
            halvings, dt_try = halvings + 1, 0.5 * exc.dt
    if not (fallback or halvings):
        return res
    res.meta["newton_fallback"] = fallback
    res.meta["dt_halvings"] = halvings
    _stamp_times(res, wall0, cpu0)
    return res


def _stamp_times(res: SimResult, wall0: float, cpu0: float) -> None:
    """Wall and CPU time since ``wall0``/``cpu0`` and the real-time factors, into ``res.meta``
    (when a drive took more than one run)."""
    res.meta["wall_s"] = _time.perf_counter() - wall0
    res.meta["cpu_s"] = _time.process_time() - cpu0
    res.meta["realtime_factor"] = res.meta["duration"] / res.meta["wall_s"]
    res.meta["cpu_realtime_factor"] = res.meta["duration"] / res.meta["cpu_s"]


def _simulate(vehicle, road, speed, duration, *, solver: str = "exudyn", **kw) -> SimResult:
    """One attempt of :func:`simulate` (``newton`` None: only for nonlinear effects); the
    Exudyn systems it builds are released afterwards, whatever happens.  ``solver="linear"``:
    a linear drive (:func:`vehicles.linear_sim.applies`) is integrated on the linearised model
    by the same scheme instead."""
    if solver == "linear":
        from vehicles import linear_sim

        wall0, cpu0 = _time.perf_counter(), _time.process_time()
        pl = _plan_drive(vehicle, road, speed, duration, kw["chassis"], kw["effects"], kw["dt"],
                         kw["fs_out"], kw["x_start"], kw["seed"], kw["frame_segments"])
        if linear_sim.applies(pl.eff, pl.vp, pl.ctx.chassis, pl.ctx.stiffness_factor, kw["newton"]):
            return linear_sim.run(pl, road, kw["y_offset"], wall0, cpu0, unilateral=kw["unilateral"])
    built: list = []
    try:
        return _simulate_once(vehicle, road, speed, duration, built=built, **kw)
    finally:
        for m in built:
            m.release()


def check_road_width(road, model, y_offset: float) -> None:
    """Refuse a 3D road narrower than the vehicle's tyre tracks (one clear line)."""
    if road.y.size > 1:
        ys = y_offset + np.array([c.y for c in model.contacts])
        if ys.min() < road.y[0] - 1e-9 or ys.max() > road.y[-1] + 1e-9:
            raise EroadInputError(
                f"road too narrow: tyres run at y from {ys.min():.2f} to {ys.max():.2f} m, the road "
                f"covers {road.y[0]:.2f} to {road.y[-1]:.2f} m")


@dataclass
class _DrivePlan:
    """What both integrators of a drive share: the effects configured, the road as the
    tyres meet it, the time grid and the distance travelled on it."""

    vp0: VehicleParams
    vp: VehicleParams
    ctx: EffectContext
    eff: dict
    profile: SpeedProfile
    road_used: object
    dt: float
    t_out: float
    n_sub: int
    n_steps: int
    n_out: int
    t_steps: np.ndarray
    s_steps: np.ndarray
    x_start: float
    seed: int
    duration: float
    fs_out: float


def _plan_drive(vehicle, road, speed, duration, chassis, effects, dt, fs_out, x_start, seed,
                frame_segments) -> _DrivePlan:
    """Validate the drive, configure the effects, put the road under the tyres' time grid
    and check that the road covers the drive (refused before anything is simulated)."""
    vp0: VehicleParams = load_vehicle(vehicle)
    try:
        duration = float(duration)
        fs_out = float(fs_out)
    except (TypeError, ValueError):
        raise EroadInputError("duration and fs_out must be numbers") from None
    if not (math.isfinite(duration) and duration > 0):
        raise EroadInputError(f"duration must be > 0 s, got {duration!r}")
    if not (math.isfinite(fs_out) and fs_out > 0):
        raise EroadInputError(f"fs_out must be > 0 Hz, got {fs_out!r}")
    if chassis not in ("rigid", "flexible"):
        raise EroadInputError(f"chassis must be 'rigid' or 'flexible', got {chassis!r}")
    profile = _speed_profile(speed, duration)
    eff = resolve_effects(effects)
    seed = 0 if seed is None else int(seed)

    # ---- time grid
    t_out = 1.0 / fs_out
    dt_req = float(dt) if dt is not None else vp0.solver.dt
    if not (math.isfinite(dt_req) and dt_req > 0):
        raise EroadInputError(f"dt must be > 0 s, got {dt!r}")
    if dt_req > t_out * (1 + 1e-9):
        raise EroadInputError(f"dt = {dt_req:g} s exceeds the output period 1/fs_out = {t_out:g} s")
    n_sub = max(1, int(round(t_out / dt_req)))
    dt = t_out / n_sub
    n_steps = int(round(duration / dt))
    n_out = int(round(duration * fs_out)) + 1
    t_steps = np.arange(n_steps + 1) * dt

    # ---- effects: configuration and road
    ctx = EffectContext(vp=vp0, reference_vp=vp0, chassis=chassis, frame_segments=frame_segments,
                        fs_out=fs_out, dt=dt, seed=seed)
    for name, p in eff.items():
        EFFECTS[name].configure(ctx, p)
    road_used = road
    for name, p in eff.items():
        road_used = EFFECTS[name].road(road_used, p, ctx)

    # ---- road coverage (refuse before simulating)
    xs_axle = np.array([a.x for a in ctx.vp.axles])
    margin = 0.5 * ctx.notes.get("tyre_enveloping_length_m", 0.0)
    if x_start is None:
        x_start = road.x_min - xs_axle.min() + margin + 1e-9
    x_start = float(x_start)
    s_steps = profile.distance(t_steps)
    need_lo = x_start + xs_axle.min() - margin
    need_hi = x_start + s_steps[-1] + margin
    if need_lo < road.x_min - 1e-9 or need_hi > road.x_max + 1e-9:
        raise EroadInputError(
            f"road too short: the drive needs x from {need_lo:.2f} to {need_hi:.2f} m, the road "
            f"covers {road.x_min:.2f} to {road.x_max:.2f} m (duration {duration:g} s, distance "
            f"{s_steps[-1]:.1f} m)")
    return _DrivePlan(vp0=vp0, vp=ctx.vp, ctx=ctx, eff=eff, profile=profile, road_used=road_used,
                      dt=dt, t_out=t_out, n_sub=n_sub, n_steps=n_steps, n_out=n_out,
                      t_steps=t_steps, s_steps=s_steps, x_start=x_start, seed=seed,
                      duration=duration, fs_out=fs_out)


def _simulate_once(vehicle, road, speed, duration, chassis, effects, dt, fs_out, x_start,
                   y_offset, seed, frame_segments, newton, unilateral, built) -> SimResult:
    wall0 = _time.perf_counter()
    cpu0 = _time.process_time()
    import exudyn as exu
    pl = _plan_drive(vehicle, road, speed, duration, chassis, effects, dt, fs_out, x_start, seed,
                     frame_segments)
    vp, ctx, eff, profile, road_used = pl.vp, pl.ctx, pl.eff, pl.profile, pl.road_used
    dt, t_out, n_steps, n_out = pl.dt, pl.t_out, pl.n_steps, pl.n_out
    t_steps, s_steps, x_start, seed = pl.t_steps, pl.s_steps, pl.x_start, pl.seed
    duration, fs_out = pl.duration, pl.fs_out

    # ---- model
    terms_of = suspension_terms_of(eff, ctx)
    model = build_model(vp, chassis=ctx.chassis, frame_segments=ctx.frame_segments,
                        stiffness_factor=ctx.stiffness_factor, suspension_terms=terms_of)
    built.append(model)
    check_road_width(road, model, y_offset)
    ref_model = model
    if ctx.reference_vp is not vp:
        ref_model = build_model(ctx.reference_vp, chassis=ctx.chassis,
                                frame_segments=ctx.frame_segments,
                                stiffness_factor=ctx.stiffness_factor)
        built.append(ref_model)

    # ---- road input on the step grid
    zr, zr_t = road_under_tyres(road_used, model, x_start, y_offset, s_steps,
                                profile.speed(t_steps))
    nc = len(model.contacts)
    kc = np.array([c.stiffness for c in model.contacts])
    cc = np.array([c.damping for c in model.contacts])
    f_c = zr * kc + zr_t * cc
    # start at static equilibrium on the road under the tyres at t = 0
    B = model.road_input_matrix()
    model.set_injector(B @ (zr[0] * kc))
    try:
        model.solve_static()
    except SimulationError:
        raise SimulationError(
            f"solver failed at simulated time t = 0.000 s of {duration:g} s (no static "
            f"equilibrium on the road at the start, heights up to {np.abs(zr[0]).max():.3g} m "
            "under the tyres); likely cause: the road is far too rough for the model (check "
            "the road's units: metres)") from None
    Q = f_c @ B.T          # (n_steps + 1, n_injector): generalised road forces per step
    Q = np.vstack([Q, Q[-1:], Q[-1:]])     # the solver may ask a hair beyond the end
    inv_dt = 1.0 / dt
    set_obj = model.mbs.SetObjectParameter
    inj = model.injector

    def prestep(mbs, t):   # t is the end of the step; keep this minimal (once per step)
        set_obj(inj, "forceVector", Q[int(t * inv_dt + 0.5)])
        return True

    off = None
    if unilateral:
        prestep, off = unilateral_prestep(model, Q, B, zr, zr_t, kc, cc, dt)
    model.mbs.SetPreStepUserFunction(prestep)
    nonlinear = any_nonlinear(eff) if newton is None else bool(newton)
    if newton is None and ctx.chassis == "flexible" and ctx.stiffness_factor > STIFF_FRAME_NEWTON:
        nonlinear = True   # one linear solve per step drifts with extremely stiff joints
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.numberOfSteps = n_steps
    ti.startTime = 0.0
    ti.endTime = n_steps * dt
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = vp.solver.spectral_radius
    ti.generalizedAlpha.computeInitialAccelerations = True
    ti.newton.useModifiedNewton = True
    ti.newton.active = nonlinear
    ti.newton.relativeTolerance = 1e-4
    ti.newton.absoluteTolerance = 1e-6
    ti.newton.modifiedNewtonJacUpdatePerStep = False
    s.solution.file.write = False
    s.solution.sensors.writePeriod = t_out
    s.show.computationTime = False

    solver = exu.MainSolverImplicitSecondOrder()
    solve0 = _time.perf_counter()
    solve_cpu0 = _time.process_time()
    ok, err = False, ""
    try:
        with _quiet():
            ok = solver.SolveSystem(model.mbs, s)
    except Exception as exc:  # noqa: BLE001 - Exudyn raises several types
        err = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    solve_s = _time.perf_counter() - solve0
    solve_cpu = _time.process_time() - solve_cpu0
    t_fail = float(solver.it.currentTime)
    if not ok:
        exc = SimulationError(_failure_message(t_fail, duration, eff, dt, err))
        exc.newton, exc.dt, exc.smaller_dt_may_help = nonlinear, dt, True
        raise exc
    steps = int(solver.it.currentStepIndex) - 1

    # ---- outputs
    out_cpu0 = _time.process_time()
    data = {b.name: _sensor_arrays(model, b.name) for b in model.bodies}
    # stored rows: the initial state and then every output period (possibly with
    # repeated times); take the last row stored at each output time
    ts = data[model.segments[0].name]["t"]
    want = np.arange(n_out) * t_out
    # A long run sums n_steps steps of dt to a time a little short of endTime (1.5e-10 s after
    # 40 000 steps) and the solver then takes one more step of that length to reach endTime; a
    # step of 1e-10 s gives generalised-alpha accelerations of 1e7 and more (measured: body
    # angular acceleration -2.3e7 rad/s^2 at t = 200 s of a 200 s run on a class A road). That
    # row repeats the last output time: keep the regular row before it.
    if ts.size >= 2 and ts[-1] - ts[-2] < 0.25 * dt and abs(ts[-2] - want[-1]) <= 0.25 * dt:
        keep = ts.size - 1
        for name in data:
            for key in data[name]:
                data[name][key] = data[name][key][:keep]
        ts = data[model.segments[0].name]["t"]
    rows = np.searchsorted(ts, want + 0.25 * dt, side="right") - 1
    if rows.min() < 0 or np.any(np.abs(ts[np.maximum(rows, 0)] - want) > 0.25 * dt):
        j = int(np.nonzero((rows < 0) | (np.abs(ts[np.maximum(rows, 0)] - want) > 0.25 * dt))[0][0])
        # the solver reached the end but its adaptive step reduction (after Newton failed
        # to converge) moved the steps off the output grid; or it stopped early
        why = ("Newton did not converge and the solver's step reduction left the output grid"
               if t_fail >= n_steps * dt - 0.25 * dt else "the solver stopped early")
        exc = SimulationError(f"no output stored at t = {want[j]:.4f} s (simulated up to "
                              f"{t_fail:.3f} s); likely cause: {why}; {_likely_cause(eff, dt)}")
        exc.newton, exc.dt, exc.smaller_dt_may_help = nonlinear, dt, True
        raise exc
    for name in data:
        for key in data[name]:
            data[name][key] = data[name][key][rows]
    time = np.arange(n_out) * t_out

    channels, pos = {}, {}
    groups: dict = {}
    for ch, kind, body, wp in output_points(model):
        groups.setdefault(body, []).append((ch, kind, np.asarray(wp, float)))
    # contacts: dynamic deflection of the tyres (for the lift-off check)
    for c, ct in enumerate(model.contacts):
        ab = model.axles[ct.axle]
        groups[ab.name].append((f"contact{c}", "z_pos_own", ab.cog + ct.local))
    zc = np.empty((n_out, nc))
    with np.errstate(all="ignore"):
        for body, items in groups.items():
            b = model.body(body)
            L = np.array([wp - b.cog for _, _, wp in items])
            P, A = _body_points(data[body], L)
            for j, (ch, kind, wp) in enumerate(items):
                if kind == "z_acc":
                    channels[ch] = A[:, 2, j]
                elif kind == "z_pos":
                    pos[ch] = P[:, 2, j] - _static_point(ref_model, body, wp)[2]
                elif kind == "yz_pos":
                    pos[ch] = P[:, :, j] - _static_point(ref_model, body, wp)
                else:   # tyre deflection relative to this model's own static state
                    zc[:, int(ch[7:])] = P[:, 2, j] - _static_point(model, body, wp)[2]
    ordered = {}
    for a, ax in enumerate(vp.axles):
        for side in SIDES:
            tag = f"{a + 1}{side}"
            ordered[f"susp_disp_{tag}"] = pos[f"seat_axle_{tag}"] - pos[f"seat_body_{tag}"]
    for a, ax in enumerate(vp.axles):
        for side in SIDES:
            ordered[f"axle_acc_{a + 1}{side}"] = channels[f"axle_acc_{a + 1}{side}"]
    for a, ax in enumerate(vp.axles):
        for side in SIDES:
            ordered[f"body_acc_{a + 1}{side}"] = channels[f"body_acc_{a + 1}{side}"]
    extra = {}
    if vp.dcdc is not None:
        for k in range(1, 5):
            ordered[f"dcdc_y_P{k}"] = pos[f"P{k}"][:, 1]
        for k in range(1, 5):
            ordered[f"dcdc_z_P{k}"] = pos[f"P{k}"][:, 2]
        extra.update(_dcdc_reference(model, ref_model, data["dcdc"]))
    ordered["speed"] = profile.speed(time)
    run = {"chassis": model.chassis,
           "frame_segments": len(model.segments) if model.chassis == "flexible" else 1,
           "frame_stiffness_factor": model.stiffness_factor, "steps": steps, "solve_s": solve_s,
           "solve_cpu_s": solve_cpu, "n_dof": model.n_dof, "n_bodies": len(model.bodies),
           "newton": nonlinear, "tyre_off_steps": int(off["steps_off"]) if off is not None else 0,
           "tyre_contact_run": "unilateral" if unilateral else "linear",
           "exudyn_version": exu.__version__, "solver": "exudyn"}
    return _finish_result(pl, ordered, extra, zc, zr, zr_t, kc, cc, model.static_tyre_loads(),
                          unilateral, run, road, y_offset, wall0, cpu0, out_cpu0)


def _finish_result(pl: _DrivePlan, channels: dict, extra: dict, zc, zr, zr_t, kc, cc, f_static,
                   unilateral: bool, run: dict, road, y_offset: float, wall0: float, cpu0: float,
                   out_cpu0: float) -> SimResult:
    """The part of a drive's result both integrators make alike: the divergence check, the
    tyre forces and lift-off on the output grid, the effects' output hooks and the meta."""
    time = np.arange(pl.n_out) * pl.t_out
    duration = pl.duration
    try:
        _check_divergence(channels, time, pl.eff, pl.dt, duration)
    except SimulationError as exc:
        exc.newton, exc.dt = run["newton"], pl.dt
        raise

    # tyre forces (dynamic part) and lift-off: a linear tyre "pulls" where it would carry
    # tension or press while off the road (what the unilateral correction changes)
    k_out = np.arange(pl.n_out) * pl.n_sub
    zr_o, zr_t_o = zr[k_out], zr_t[k_out]
    zc_t = np.gradient(zc, pl.t_out, axis=0)
    defl = f_static / kc + zr_o - zc
    rate = zr_t_o - zc_t
    f_lin = kc * defl + cc * rate
    f_uni = tyre_forces(defl, rate, kc, cc)
    pull = np.any(f_uni != f_lin, axis=1)
    lift = np.any(f_uni <= 0.0, axis=1)
    extra["road_z"] = zr_o
    extra["tyre_force"] = (f_uni if unilateral else f_lin) - f_static
    extra["tyre_off"] = lift

    meta_eff = {n: dict(p) for n, p in pl.eff.items()}
    for name, p in pl.eff.items():
        EFFECTS[name].outputs(time, channels, p, pl.ctx)
    units = {n: unit_of(n) for n in channels}
    wall = _time.perf_counter() - wall0
    cpu = _time.process_time() - cpu0
    out_cpu = _time.process_time() - out_cpu0
    meta = {
        "vehicle": pl.vp0.id, "vehicle_name": pl.vp0.name, "chassis": run["chassis"],
        "frame_segments": run["frame_segments"],
        "frame_stiffness_factor": run["frame_stiffness_factor"],
        "effects": meta_eff, "effect_notes": dict(pl.ctx.notes),
        "dt": pl.dt, "fs_out": pl.fs_out, "duration": duration, "steps": run["steps"],
        "wall_s": wall, "solve_s": run["solve_s"], "realtime_factor": duration / wall,
        "cpu_s": cpu, "solve_cpu_s": run["solve_cpu_s"], "cpu_realtime_factor": duration / cpu,
        "outputs_cpu_s": out_cpu, "prepare_cpu_s": cpu - run["solve_cpu_s"] - out_cpu,
        "n_dof": run["n_dof"], "n_bodies": run["n_bodies"], "newton": run["newton"],
        "newton_fallback": False, "dt_halvings": 0,
        "speed_mean": float(np.mean(pl.profile.speed(time))), "distance_m": float(pl.s_steps[-1]),
        "x_start": pl.x_start, "y_offset": float(y_offset), "seed": pl.seed,
        "tyre_lift_off_fraction": float(lift.mean()),
        "tyre_pull_fraction": float(pull.mean()),
        "tyre_contact_run": run["tyre_contact_run"],
        "tyre_off_steps": run["tyre_off_steps"],
        "road": {k: v for k, v in (getattr(road, "meta", {}) or {}).items()
                 if isinstance(v, (int, float, str, bool))},
        "exudyn_version": run["exudyn_version"],
        "solver": run["solver"],
    }
    return SimResult(time=time, channels=channels, units=units, meta=meta, extra=extra, vehicle=pl.vp,
                     nominal_vehicle=pl.vp0)


def _dcdc_reference(model, ref_model, data) -> dict:
    d = model.vp.dcdc
    top = dcdc_top(d)
    b = model.body("dcdc")
    P, A = _body_points(data, (top - b.cog)[None, :])
    pos, acc = P[:, :, 0], A[:, :, 0]
    p_ref = _static_point(ref_model, "dcdc", top)
    R0 = ref_model.static["dcdc"][1]
    rot = _small_rotation(data["RotationMatrix"], R0)
    return dcdc_extra(d, pos - p_ref, rot, acc, data["AngularAcceleration"], data["AngularVelocity"])


def dcdc_top(d) -> np.ndarray:
    """The DCDC top-face centre, design position [m] (``vp.dcdc``)."""
    return np.array([d.x, d.y, d.z_base + d.height])


def dcdc_extra(d, pos, rot, acc, ang_acc, ang_vel) -> dict:
    """``SimResult.extra``'s DCDC entries, alike from either integrator: the top-face centre's
    translation from the reference vehicle's static point and small global rotation from its
    static orientation (``dcdc_ref``, Tx Ty Tz [m] Rx Ry Rz [rad]), their accelerations
    (``dcdc_ref_acc``), the angular velocity (``dcdc_ref_vel``) and the four top-face points in
    the block's frame (``dcdc_points``)."""
    pts = np.array([[sx * d.point_x, sy * d.point_y, 0.0]
                    for sx, sy in ((1, 1), (1, -1), (-1, -1), (-1, 1))])
    return {"dcdc_ref": np.hstack([pos, rot]),
            "dcdc_ref_acc": np.hstack([acc, ang_acc]),
            "dcdc_ref_vel": np.array(ang_vel, dtype=float, copy=True),
            "dcdc_points": pts,
            "dcdc_ref_columns": np.array(["Tx", "Ty", "Tz", "Rx", "Ry", "Rz"])}


def _likely_cause(eff, dt) -> str:
    stiff = [n for n in ("bump_stop", "leaf_friction", "damper_asymmetry") if n in eff]
    if stiff:
        return (f"the nonlinear effect(s) {', '.join(stiff)} are too stiff for the time step "
                f"dt = {dt:g} s (smaller dt, softer bump stop or larger friction velocity)")
    return (f"the time step dt = {dt:g} s is too large for the stiffest element, or the road is "
            "far too rough for the model (check the road's units: metres)")


def _failure_message(t_fail, duration, eff, dt, err) -> str:
    detail = f" ({err})" if err else ""
    return (f"solver failed at simulated time t = {t_fail:.3f} s of {duration:g} s{detail}; "
            f"likely cause: {_likely_cause(eff, dt)}")


def _check_divergence(channels, time, eff, dt, duration):
    for name, x in channels.items():
        prefix = name.rsplit("_", 1)[0]
        lim = DIVERGENCE_LIMIT.get(prefix)
        if lim is None:
            if not np.all(np.isfinite(x)):
                bad = np.nonzero(~np.isfinite(x))[0][0]
                raise SimulationError(f"{name} is not finite from t = {time[bad]:.3f} s; likely "
                                      f"cause: {_likely_cause(eff, dt)}")
            continue
        badmask = ~np.isfinite(x) | (np.abs(x) > lim)
        if badmask.any():
            bad = int(np.nonzero(badmask)[0][0])
            raise SimulationError(
                f"solution diverged at simulated time t = {time[bad]:.3f} s of {duration:g} s "
                f"({name} = {x[bad]:.3g}); likely cause: {_likely_cause(eff, dt)}")
