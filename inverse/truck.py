"""The Exudyn truck as the response simulator of the inverse fit.

What this module is for: binding ``vehicles.simulate`` and ``roadlib`` to the
simulator contract of :mod:`inverse.sensitivity` (``simulate(params (K, 4),
seed) -> {channel: (N,) array}`` on the measured record's time grid, noise-free)
for a measured drive, with common random numbers; the linear-model prediction
``predict_rms`` that gives the segmentation its initial class; and the road a
parameter set and a seed stand for (the global road of section 2.5).  What it is
not: the fit itself (``inverse.sensitivity``), the command (``inverse.cli``).

Geometry (as ``drives.synth.plan_drive`` lays out a virtual drive): the
simulation starts ``runin_s`` before the record with the speed of the first
record sample, the rearmost axle ``drives.synth.ROAD_MARGIN_M`` into the road.
A segment boundary in time t_b is where the REFERENCE axle (axle 3, the axle the
segmentation looks at) is at t_b; the last segment runs to the end of the road.

Common random numbers: the road of ``(params, seed)`` is
``roadlib.segments.segmented_surface(..., seed=seed)`` on a FIXED grid (dx, dy,
width and segment lengths depend on the drive and the boundaries only), whose
synthesis keys the phases by frequency bin, segment and seed
(``roadlib.synthesis``): the parameters change amplitudes only.  dx is fixed
(0.025 m) and nmax is capped at 1 / (4 dx) = 10 cycles/m, so the grid never
moves with nmax.

Everything here is picklable plain data (Exudyn systems with Python user
functions do not pickle: the model is built inside the worker at each call).
"""
from __future__ import annotations

import math

import numpy as np

from eroad.errors import EroadInputError

#: road grid of the simulator [m]: fixed so the harmonic grid does not move with nmax
SIM_DX = 0.025
#: lateral step [m]
SIM_DY = 0.1
#: road width [m]
SIM_WIDTH = 3.0
#: run-in before the record [s] (lets the start transient decay)
RUNIN_S = 2.0
#: band of the class prediction [Hz] (the segmentation's class_band)
CLASS_BAND = (0.2, 20.0)
#: integrator of the inversion's time simulations (``vehicles.simulate(solver=...)``):
#: ``"linear"`` integrates a drive whose model the linear integrator covers (the nominal truck,
#: the linear effects, leaf friction, damper asymmetry and bump stops as local force elements;
#: :func:`vehicles.linear_sim.applies`) on Exudyn's linearisation with the same scheme and step,
#: and everything else (a DCDC body, forced Newton) in Exudyn.  The A/B that made it the default
#: is in docs/inverse.md ("The time simulations on the linear integrator").
SIM_SOLVER = "linear"


def nmax_cap(dx: float = SIM_DX) -> float:
    """Highest nmax the simulator's grid carries: 1 / (4 dx) [cycles/m]."""
    return 1.0 / (4.0 * dx)


def _travelled(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])


class TruckSimulator:
    """Simulator contract of :mod:`inverse.sensitivity` for the Exudyn truck.

    Parameters
    ----------
    vehicle : str
        Built-in vehicle id or TOML path.
    time : (N,) array
        Record time [s] (uniform).
    speed : (N,) array or float
        Record speed [m/s].
    t_bounds : (K + 1,) array
        Segment boundaries on ``time`` [s].
    channels : sequence of str
        Channels to return.
    effects : dict, optional
        Effects of the nominal model (``vehicles.simulate``), e.g. candidate
        effects of the diagnosis; default none.
    chassis : str
        "rigid" (default) or "flexible".
    dt : float, optional
        Time step [s]; default the vehicle's.
    width, dx, dy : float
        Road width and grid [m].
    runin_s : float
        Simulated time before the record [s].
    ref_axle : int
        Axle whose position defines the segment boundaries (1-based).
    lam : float
        Anisotropy of the synthesised surface [-].
    solver : {"linear", "exudyn"}
        Integrator of the runs (:data:`SIM_SOLVER`; ``vehicles.simulate``).
    """

    def __init__(self, vehicle, time, speed, t_bounds, channels, *, effects=None, chassis: str = "rigid",
                 dt: float | None = None, width: float = SIM_WIDTH, dx: float = SIM_DX, dy: float = SIM_DY,
                 runin_s: float = RUNIN_S, ref_axle: int = 3, lam: float = 1.0, solver: str = SIM_SOLVER):
        from vehicles.simulate import SOLVERS

        if solver not in SOLVERS:
            raise EroadInputError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
        self.solver = str(solver)
        self.vehicle = str(vehicle)
        self.time = np.asarray(time, dtype=float)
        if self.time.ndim != 1 or self.time.size < 4:
            raise EroadInputError("TruckSimulator: time must be a 1D array of at least 4 samples")
        self.speed = np.broadcast_to(np.asarray(speed, dtype=float), self.time.shape).copy()
        if not np.all(np.isfinite(self.speed)) or np.any(self.speed <= 0):
            raise EroadInputError("TruckSimulator: speed must be positive and finite (the model needs v > 0)")
        self.t_bounds = np.asarray(t_bounds, dtype=float)
        self.channels = tuple(channels)
        self.effects = dict(effects or {})
        self.chassis = str(chassis)
        self.dt = None if dt is None else float(dt)
        self.width, self.dx, self.dy = float(width), float(dx), float(dy)
        self.runin_s, self.ref_axle, self.lam = float(runin_s), int(ref_axle), float(lam)
        self._layout = None

    # ------------------------------------------------------------------ layout
    def layout(self) -> dict:
        """Simulation time, speed, road length and segment lengths (cached).

        Returns
        -------
        dict
            ``t_sim`` [s] from 0, ``v_sim`` [m/s], ``n_runin`` samples,
            ``x_front0`` [m], ``road_length`` [m], ``seg_lengths`` [m],
            ``x_bounds`` [m] (reference axle at the boundaries).
        """
        if self._layout is not None:
            return self._layout
        from drives.synth import ROAD_MARGIN_M
        from vehicles.params import load_vehicle

        vp = load_vehicle(self.vehicle)
        axle_x = [float(a.x) for a in vp.axles]
        if not 1 <= self.ref_axle <= len(axle_x):
            raise EroadInputError(f"reference axle {self.ref_axle}: the vehicle has {len(axle_x)} axles")
        t_rec = self.time - self.time[0]
        fs = 1.0 / float(np.mean(np.diff(t_rec)))
        n_run = int(round(self.runin_s * fs))
        t_run = (np.arange(-n_run, 0)) / fs
        t_all = np.concatenate([t_run, t_rec])
        v_all = np.concatenate([np.full(n_run, self.speed[0]), self.speed])
        s = _travelled(t_all, v_all)
        x_front0 = ROAD_MARGIN_M - min(axle_x)
        x_ref = x_front0 + axle_x[self.ref_axle - 1] + s
        tb = self.t_bounds - self.time[0]
        x_b = np.interp(tb, t_all, x_ref)
        road_length = float(math.ceil((x_front0 + s[-1] + ROAD_MARGIN_M) / self.dx) * self.dx)
        edges = np.concatenate([[0.0], x_b[1:-1], [road_length]])
        if np.any(np.diff(edges) <= 2 * self.dx):
            raise EroadInputError("TruckSimulator: a segment is shorter than two road grid steps")
        self._layout = {"t_sim": t_all - t_all[0], "v_sim": v_all, "n_runin": n_run, "fs": fs,
                        "x_front0": float(x_front0), "road_length": road_length,
                        "seg_lengths": np.diff(edges), "x_bounds": edges}
        return self._layout

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_layout"] = None
        return d

    # ------------------------------------------------------------------ road
    def road(self, params, seed):
        """The segmented road surface of ``params`` (K, 4) or (K, 6) (:func:`road_from_params`)
        and ``seed``.

        ``seed`` is an int (one realisation) or a pair ``(seed_left, seed_right)``:
        the left half of the road (y > 0) from the first, the right half from the
        second (:func:`join_sides`), so each wheel track's realisation can be
        chosen on its own (realisation selection, docs/inverse.md section 8).

        Returns
        -------
        roadlib.surface.RoadSurface
        """
        if isinstance(seed, (tuple, list)):
            left, right = (int(v) for v in seed)
            return join_sides(self.road(params, left), self.road(params, right))
        return road_from_params(params, self.layout()["seg_lengths"], seed=seed, width=self.width,
                                dx=self.dx, dy=self.dy, lam=self.lam)

    # ------------------------------------------------------------------ contract
    def __call__(self, params, seed) -> dict:
        """Simulate the nominal model over the road of ``params`` and ``seed``.

        ``seed``: int, or ``(seed_left, seed_right)`` (see :meth:`road`).

        Returns
        -------
        dict
            Channel -> (N,) array on the record's time grid (noise-free).
        """
        from vehicles.simulate import SpeedProfile, simulate

        lay = self.layout()
        road = self.road(params, seed)
        kw = {}
        if self.dt is not None:
            kw["dt"] = self.dt
        t_sim, v_sim = lay["t_sim"], lay["v_sim"]
        # one-sided tyres with the correction on from the start (lift_off_expected): the same
        # result as the two-pass drive, and one run instead of two on a road where a tyre
        # leaves the ground (every run of the embedded record does, 0.3-0.7 % of its samples:
        # 0.48 s instead of 0.85 s; a road where none does pays 0.48 s instead of 0.35 s)
        res = simulate(self.vehicle, road, speed=SpeedProfile(t_sim, v_sim), duration=float(t_sim[-1]),
                       chassis=self.chassis, effects=self.effects or None, fs_out=lay["fs"],
                       x_start=lay["x_front0"], y_offset=0.0, seed=0, lift_off_expected=True,
                       solver=self.solver, **kw)
        n_run, n = lay["n_runin"], self.time.size
        out = {}
        for c in self.channels:
            if c not in res.channels:
                raise EroadInputError(f"TruckSimulator: the model has no channel {c!r}")
            y = np.asarray(res.channels[c], dtype=float)[n_run:n_run + n]
            if y.size < n:
                y = np.concatenate([y, np.full(n - y.size, y[-1])])
            out[c] = y
        return out


#: half-width of the centre strip where join_sides blends the two sides [m]
JOIN_HALF_WIDTH = 0.3


def join_sides(left, right, half_width: float = JOIN_HALF_WIDTH):
    """One road from the left half (y > 0) of ``left`` and the right half of ``right``.

    z = s(y) z_left + (1 - s(y)) z_right with a raised-cosine step s across
    |y| < ``half_width`` (default 0.3 m: the wheel tracks of a truck, at about
    +-1 m, lie outside it, so each track is exactly one side's realisation).
    Inside the strip the mix of two independent fields has a lower variance
    (down to half at y = 0); nothing of the vehicle touches it.

    Parameters
    ----------
    left, right : roadlib.surface.RoadSurface
        Same grid.
    half_width : float
        [m].

    Returns
    -------
    roadlib.surface.RoadSurface
    """
    from roadlib.surface import RoadSurface

    if left.z.shape != right.z.shape or not np.array_equal(left.y, right.y):
        raise EroadInputError("join_sides: the two roads must share one grid")
    y = np.asarray(left.y, float)

    def share(yy):
        u = np.clip((yy + half_width) / (2 * half_width), 0.0, 1.0)
        return 0.5 - 0.5 * np.cos(np.pi * u)

    sgm = share(y)
    z = left.z * sgm[None, :] + right.z * (1.0 - sgm)[None, :]
    meta = dict(left.meta)
    meta.update({"generator": "inverse.truck.join_sides", "seed_left": left.meta.get("seed"),
                 "seed_right": right.meta.get("seed"), "join_half_width_m": float(half_width),
                 "right_meta": right.meta})

    def lines(ys):   # each side's exact lines, blended as the grid is
        a, b = left.lines(ys), right.lines(ys)
        if a is None or b is None:
            return None
        w = share(np.asarray(ys, float))
        return a * w[None, :] + b * (1.0 - w)[None, :]

    exact = left.lines is not None and right.lines is not None
    return RoadSurface(left.x, y, z, meta, lines=lines if exact else None)


def road_from_params(params, seg_lengths, *, seed: int, width: float = SIM_WIDTH, dx: float = SIM_DX,
                     dy: float = SIM_DY, lam: float = 1.0, labels=None):
    """Segmented road surface of fitted parameters (junctions smoothed by roadlib).

    Parameters
    ----------
    params : (K, 4) or (K, 6) array
        (Gq_n0 [m^3], w [-], nmin, nmax [cycles/m]) per segment; nmax is capped
        at the grid's 1 / (2 dx).  Six columns add (w2 [-], n_break [cycles/m]) of a
        two-slope segment (``roadlib.psd.two_slope_psd``; Gq_n0 is then the level of
        the low-frequency line), NaN in both for one slope.
    seg_lengths : (K,) array
        Road length of each segment [m].
    seed : int
        Phase seed (``segmented_surface``: segment s uses ``SeedSequence(seed, (s,))``).
    width, dx, dy : float
        Road width and grid [m].
    lam : float
        Anisotropy [-].
    labels : list of str, optional

    Returns
    -------
    roadlib.surface.RoadSurface
    """
    from roadlib.segments import RoadSegment, segmented_surface

    P = np.atleast_2d(np.asarray(params, dtype=float))
    L = np.asarray(seg_lengths, dtype=float)
    if P.ndim != 2 or P.shape[0] != L.size or P.shape[1] not in (4, 6):
        raise EroadInputError(f"road_from_params: params of shape {P.shape} for {L.size} segments "
                              "(4 or 6 columns expected)")
    nyq = 1.0 / (2.0 * dx)
    total = float(np.sum(L))

    def two(p):
        if p.size < 6 or not (np.isfinite(p[4]) and np.isfinite(p[5])):
            return {}
        return {"w2": float(p[4]), "n_break": float(p[5])}

    segs = [RoadSegment(Gq_n0=float(p[0]), share=float(l), w=float(p[1]), nmin=float(p[2]),
                        nmax=float(min(p[3], nyq)), lam=lam, label=str(labels[i]) if labels else "", **two(p))
            for i, (p, l) in enumerate(zip(P, L))]
    return segmented_surface(segs, total, width, dx, dy, seed=int(seed))


def make_truck_simulator(drive, *, effects=None, chassis: str = "rigid", vehicle=None, channels=None, **kwargs):
    """``make_simulator(t_bounds) -> TruckSimulator`` for :func:`inverse.pipeline.invert`.

    Parameters
    ----------
    drive : drives.format.Drive
        The measured drive (its time, speed, vehicle and channels).
    effects : dict, optional
        Effects of the nominal model.
    chassis : str
    vehicle : str, optional
        Vehicle id or path; default the drive's.
    channels : sequence of str, optional
        Channels to simulate; default every response channel of the drive
        (``susp_*``, ``axle_*``, ``body_*``).
    **kwargs
        Passed to :class:`TruckSimulator`.

    Returns
    -------
    callable
    """
    veh = str(vehicle if vehicle is not None else drive.vehicle)
    if channels is None:
        channels = [c for c in drive.channel_names if c.split("_")[0] in ("susp", "axle", "body")]
    time = np.asarray(drive.time, float)
    speed = np.asarray(drive.speed, float)

    def make(t_bounds):
        return TruckSimulator(veh, time, speed, t_bounds, channels, effects=effects, chassis=chassis, **kwargs)
    return make


class TruckPredictRms:
    """``predict_rms(Gq_n0, w, speed) -> rms`` from the truck's linear model.

    Displacement RMS in ``band`` (0.2-20 Hz), power-averaged over ``channels``
    (the segmentation channels), road band (nmin, nmax) = the prior's (0.05, 5)
    cycles/m.  The linear model is built on first use and cached per process.
    """

    def __init__(self, vehicle, channels=("susp_disp_3L", "susp_disp_3R"), chassis: str = "rigid",
                 band=CLASS_BAND, nmin: float = 0.05, nmax: float = 5.0, effects=None):
        self.vehicle, self.channels, self.chassis = str(vehicle), tuple(channels), str(chassis)
        self.band, self.nmin, self.nmax = tuple(band), float(nmin), float(nmax)
        self.effects = dict(effects or {})
        self._lm = None

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_lm"] = None
        return d

    def __call__(self, Gq_n0, w, speed) -> float:
        from vehicles.linear import linear_model
        from vehicles.params import load_vehicle

        if self._lm is None:
            self._lm = linear_model(load_vehicle(self.vehicle), self.chassis, effects=self.effects or None)
        r = self._lm.response_rms({"Gq_n0": float(Gq_n0), "w": float(w), "nmin": self.nmin, "nmax": self.nmax},
                                  float(speed), "surface", list(self.channels), self.band)
        return float(np.sqrt(np.mean([r[c] ** 2 for c in self.channels])))


def truck_predict_rms(vehicle, channels=("susp_disp_3L", "susp_disp_3R"), **kwargs) -> TruckPredictRms:
    """The segmentation's ``predict_rms`` for a vehicle (see :class:`TruckPredictRms`)."""
    return TruckPredictRms(vehicle, channels, **kwargs)
