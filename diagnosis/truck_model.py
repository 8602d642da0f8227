"""The nominal truck driven like the measured record (:class:`TruckModel`) and the callables
``diagnosis.which.rank_effects`` calls (:class:`Fit`, :class:`Simulate`): a model with an
effect over a fresh road realisation, re-profiled to each measured window
(:mod:`diagnosis.nuisance`), plus the measured sensor noise.

speed_scale: realised here (:meth:`TruckModel.run` drives at the recorded speed over
the factor), identified by the front-to-rear delay term of the ranking
(:func:`diagnosis.pipeline.delay_term`, :class:`diagnosis.which.DelayTerm`) and calibrated from it.

Road grid: ``ROAD_DX`` = 0.025 m, the virtual test drive's grid (the footprint filter
of tyre_enveloping rounds the length to an odd number of grid steps).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from diagnosis.nuisance import (apply_tilt, level_scale, piece_levels, relevel, window_noise,
                                window_tilt)
from diagnosis.signals import Signals, as_signals
from eroad.errors import EroadInputError


#: ISO 8608 road shape kept fixed by the cheap road fit
ROAD_W, ROAD_NMIN, ROAD_NMAX = 2.0, 0.1, 5.0
#: a window's runs skip the linear first pass of the one-sided tyres when the nominal run had
#: a tyre off the road inside it or this long before it [s] (its run-in)
LIFT_HINT_MARGIN_S = 2.0
#: run-in simulated and discarded before every window [s]
RUNIN_S = 2.0
#: road grid of the diagnosis simulations [m] (that of the virtual test drive, drives/scenarios)
ROAD_DX, ROAD_DY, ROAD_WIDTH = 0.025, 0.1, 3.0
#: the road level every model is simulated on (the nuisance "how rough was this piece"):
#: the fitted road's level is that of the calibration windows as a whole, so a window's piece
#: may be 30 % rougher or smoother; an amplitude-dependent effect must see the road amplitude
#: the truck saw (a bump stop simulated at a level 30 % low never engages), so models are
#: simulated on a re-levelled road, then their response re-levelled as every model is.
#: ``"nested"`` (since stop 42, 2026-11-27): the nominal model and the linear candidates drive the
#: road at which the NOMINAL model's run matches the measured level piece by piece (factors
#: squared into Gq; one extra nominal run per window and road seed, cached); a nonlinear
#: candidate drives the road at which ITS OWN run does (its amplitude-dependent response
#: needs its own level: a bump stop that lowers the response on a rough piece would drive a
#: road too smooth at the nominal level).  A candidate at its neutral value, linear or not,
#: then is the nominal model, window by window.  ``"nonlinear"`` (until stop 42): the
#: same for nonlinear candidates but the nominal model and the linear candidates on the
#: fitted road: a bump stop 300 mm away scored 0.34 where the nominal model scored 0.23 on
#: the same windows (blind case 3 of results/diagnosis_blind/20261127-static-offset-
#: fresh-40); the nominal model was not in the nonlinear candidates' family.  ``"off"``: every
#: model on the fitted road.  (Every model on the nominal model's level was tried and dropped
#: before its blind run, docs/diagnosis.md.)
PRE_LEVEL = "nested"
#: refit the road waviness per model and window as a spectral tilt (see
#: :func:`diagnosis.nuisance.window_tilt`)
TILT_REFIT = True
#: smallest speed factor (recorded / true speed) a simulation may use: every road is made
#: long enough for it, so all models drive the same surface
SPEED_FACTOR_MIN = 0.85


@dataclass
class TruckModel:
    """The nominal truck driven like the measured record (picklable; simulations built
    inside each process).

    Parameters
    ----------
    vehicle : str or Path
        Built-in id or vehicle TOML.
    time : (N,) array, s
        Record time from 0.
    speed : (N,) array, m/s
        Recorded speed.
    bounds : (K + 1,) array, s
        Road-segment boundaries (record time from 0, reference axle).
    gq : (K,) array, m^3
        Road level per segment (``GQ_REF`` before the level fit).
    w : (K,) array, optional
        Road waviness per segment (default ``ROAD_W``).
    nmin, nmax : (K,) arrays, optional
        Road band per segment [cycles/m] (default ``ROAD_NMIN``, ``ROAD_NMAX``).
    noise : dict channel -> std
        White sensor noise added to simulations.
    channels : list of str
        Channels returned.
    ref_axle : int
        Axle whose position defines the segment boundaries (1-based).
    """

    vehicle: object
    time: np.ndarray
    speed: np.ndarray
    bounds: np.ndarray
    gq: np.ndarray
    noise: dict
    channels: list
    ref_axle: int = 3
    w: np.ndarray | None = None
    nmin: np.ndarray | None = None
    nmax: np.ndarray | None = None
    _roads: dict = field(default_factory=dict, repr=False, compare=False)
    #: record times [s] at which the nominal run of the whole record had a tyre off the road
    #: (set by :func:`context`): runs of windows that contain one skip the linear first pass
    #: (``vehicles.simulate(lift_off_expected=True)``, same physics, less time).  Fixed before
    #: the model is sent to the workers, so which path a run takes does not depend on them.
    lift_times: np.ndarray | None = None
    #: what :func:`diagnosis.road_fit.fit_nmax` decided about the high band, for the report:
    #: ``{"cut": [segment indices cut], "rolloff": [segment indices that roll off],
    #: "vetoed": bool, "unstepped": bool}`` (``unstepped``: cuts left out because the spatial
    #: spectrum showed no step, ``road_fit.NMAX_SPATIAL_STEP``)
    high_band: dict | None = None
    #: the inputs :func:`diagnosis.road_fit.fit_road` gave ``fit_nmax`` (``{"gq", "noise"}``),
    #: so that :func:`diagnosis.road_fit.refit_band` repeats that fit with only the effects
    #: changed
    band_inputs: dict | None = None
    #: integrator of the runs (``vehicles.simulate(solver=...)``): ``"linear"`` integrates
    #: the runs whose model is linear on Exudyn's linearisation by the same scheme
    #: (:mod:`vehicles.linear_sim`), ``"exudyn"`` every run in Exudyn
    solver: str = "exudyn"

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_roads"] = {}
        return d

    @property
    def fs(self) -> float:
        return float((self.time.size - 1) / (self.time[-1] - self.time[0]))

    def _vp(self):
        from vehicles.params import load_vehicle

        vp = getattr(self, "_vp_cache", None)
        if vp is None:
            vp = load_vehicle(self.vehicle)
            object.__setattr__(self, "_vp_cache", vp)
        return vp

    def _plan(self, t0: float, t1: float, speed_factor: float = 1.0):
        """Sim-time speed samples, axle-1 start position and the road for window [t0, t1).

        ``speed_factor``: recorded speed / true speed (the ``speed_scale`` candidate); the
        truck is driven at the recorded speed divided by it."""
        fs = self.fs
        n_run = int(round(RUNIN_S * fs))
        i0 = int(round(t0 * fs))
        i1 = min(int(round(t1 * fs)), self.time.size)
        v_rec = self.speed[i0:i1] / float(speed_factor)
        v = np.concatenate([np.full(n_run, v_rec[0]), v_rec])
        tau = np.arange(v.size) / fs
        s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) / fs)])
        vp = self._vp()
        ax = [a.x for a in vp.axles]
        x_start = -min(ax) + 1.5
        x_ref = x_start + ax[self.ref_axle - 1] + s
        t_rec = t0 + tau - RUNIN_S
        return tau, v, s, x_start, x_ref, t_rec, n_run, i1 - i0

    def _road(self, t0, t1, seed, gq):
        """The road of window [t0, t1) for road-phase ``seed``: the same surface for every
        model, speed_scale included (common random numbers: the synthesis depends on the
        road length, so the length covers the fastest speed factor ``SPEED_FACTOR_MIN`` and
        the segment edges are placed at the recorded speed)."""
        from roadlib.segments import RoadSegment, segmented_surface

        wv = np.full(len(gq), ROAD_W) if self.w is None else np.asarray(self.w, float)
        key = (round(t0, 6), round(t1, 6), int(seed), tuple(np.round(np.log(gq), 9)),
               tuple(np.round(wv, 9)), None if self.nmin is None else tuple(self.nmin),
               None if self.nmax is None else tuple(self.nmax))
        if key in self._roads:
            return self._roads[key]
        tau, v, s, x_start, x_ref, t_rec, n_run, n = self._plan(t0, t1)
        length = x_start + s[-1] / SPEED_FACTOR_MIN + 3.0
        # boundaries outside the drive go where the truck would meet them at its first /
        # last speed (clamping them to the window's ends put the next segment under the
        # front axles before the window ended: a class-F segment 19 s later drove the last
        # 0.4 s of a class-A window)
        tb = np.asarray(self.bounds[1:-1], float)
        xb = np.interp(tb, t_rec, x_ref)
        xb = np.where(tb > t_rec[-1], x_ref[-1] + v[-1] * (tb - t_rec[-1]), xb)
        xb = np.where(tb < t_rec[0], x_ref[0] - v[0] * (t_rec[0] - tb), xb)
        edges = np.concatenate([[0.0], np.clip(xb, 0.0, length), [length]])
        segs, k_used = [], []
        for k in range(len(gq)):
            L = edges[k + 1] - edges[k]
            if L > 2 * ROAD_DX:
                segs.append(RoadSegment(
                    Gq_n0=float(gq[k]), share=float(L), w=float(wv[k]),
                    nmin=float(ROAD_NMIN if self.nmin is None else self.nmin[k]),
                    nmax=float(ROAD_NMAX if self.nmax is None else self.nmax[k]), lam=1.0))
                k_used.append(k)
        road = segmented_surface(segs, float(sum(s_.share for s_ in segs)), ROAD_WIDTH, ROAD_DX,
                                 ROAD_DY, seed=int(seed))
        if len(self._roads) > 64:
            self._roads.clear()
        self._roads[key] = road
        return road

    def run(self, effects, t0: float, t1: float, seed: int, gq=None, with_lift_times: bool = False):
        """Noise-free channels over record window [t0, t1) s (run-in discarded); with
        ``with_lift_times`` also the record times [s] at which a tyre was off the road."""
        from vehicles.simulate import SpeedProfile, simulate

        gq = self.gq if gq is None else np.asarray(gq, float)
        # speed_scale is realised here, not by the library effect (which only rescales the
        # output 'speed' channel): the recorded speed is 'factor' x the true speed, so the
        # truck drives at the recorded speed / factor (road wavelengths, front-to-rear delay)
        effects = dict(effects or {})
        sf = float(effects.pop("speed_scale", {}).get("factor", 1.0))
        tau, v, s, x_start, x_ref, t_rec, n_run, n = self._plan(t0, t1, sf)
        if sf < SPEED_FACTOR_MIN:
            raise EroadInputError(f"speed_scale factor {sf:g} below {SPEED_FACTOR_MIN:g}: the "
                                  f"diagnosis road is not long enough")
        road = self._road(t0, t1, seed, gq)
        prof = SpeedProfile(tau, v)
        dur = (tau.size - 1) / self.fs
        lt = self.lift_times
        expected = lt is not None and bool(np.any((lt >= t0 - LIFT_HINT_MARGIN_S) & (lt < t1)))
        res = simulate(self._vp(), road, prof, dur, effects=effects or None, x_start=x_start,
                       fs_out=self.fs, seed=int(seed), lift_off_expected=expected,
                       solver=self.solver)
        out = {}
        for c in self.channels:
            x = np.asarray(res.channels[c], float)[n_run:n_run + n]
            if x.size < n:
                x = np.concatenate([x, np.full(n - x.size, x[-1])])
            out[c] = x
        if with_lift_times:
            off = np.asarray(res.extra["tyre_off"])[n_run:n_run + n]
            return out, float(t0) + np.nonzero(off)[0] / self.fs
        return out

    def add_noise(self, chans: dict, seed: int, noise: dict | None = None) -> dict:
        noise = self.noise if noise is None else noise
        ss = np.random.SeedSequence(int(seed), spawn_key=(0x4E01,)).spawn(len(self.channels))
        return {c: chans[c] + noise.get(c, 0.0) * np.random.default_rng(s).standard_normal(chans[c].size)
                for c, s in zip(self.channels, ss)}

    def pieces(self, t0: float, t1: float):
        """(index slices) of the segment pieces inside window [t0, t1) in window samples."""
        fs = self.fs
        n = int(round(t1 * fs)) - int(round(t0 * fs))
        out = []
        for k in range(len(self.bounds) - 1):
            a = max(self.bounds[k], t0) - t0
            b = min(self.bounds[k + 1], t1) - t0
            if b - a > 1.0 / fs:
                out.append((k, int(round(a * fs)), min(n, int(round(b * fs)))))
        return out


@dataclass(frozen=True)
class State:
    """A fitted model: effects (the road is re-levelled per simulated window)."""

    effects: dict


class Fit:
    """``fit(effects, data) -> State`` for :func:`diagnosis.which.rank_effects`."""

    def __init__(self, model: TruckModel):
        self.model = model

    def __call__(self, effects, data):
        return State({k: dict(v) for k, v in (effects or {}).items()})


class Simulate:
    """``simulate(state, window, seed) -> Signals``: the truck with the state's effects over a
    fresh road (seed), re-levelled per segment piece to ``window``, plus sensor noise."""

    def __init__(self, model: TruckModel):
        self.model = model
        # (t0, t1, seed) -> the nominal model's pre-levelled Gq; pickled with the instance,
        # so the workers of a ranking get the levels of every held-out window and seed the
        # parent made for the nominal simulations (a level is a function of model, window
        # and seed alone: which process makes it does not change it)
        self._levels = {}

    def export_cache(self) -> dict:
        """What this simulator has learnt (the pre-levelled Gq per window and seed), for
        :func:`diagnosis.which.nominal_sim_sets` to hand from a worker to the parent."""
        return dict(self._levels)

    def import_cache(self, cache: dict) -> None:
        """Keep the levels another process made (:meth:`export_cache`)."""
        for k, v in cache.items():
            self._levels.setdefault(k, v)

    def road_level(self, w: Signals, t0: float, t1: float, seed: int, effects) -> np.ndarray | None:
        """Per-segment Gq the model with ``effects`` drives in window [t0, t1), road seed
        ``seed`` (:data:`PRE_LEVEL`); None: the fitted road."""
        from eroad.errors import SimulationError
        from vehicles.effects import any_nonlinear

        try:
            if PRE_LEVEL not in ("nested", "nonlinear", "off"):
                raise ValueError(f"PRE_LEVEL must be nested, nonlinear or off, got {PRE_LEVEL!r}")
            if PRE_LEVEL == "off":
                return None
            if any_nonlinear(effects):
                return self.prelevel_gq(w, t0, t1, seed, effects)       # its own level
            if PRE_LEVEL == "nested":
                key = (round(t0, 6), round(t1, 6), int(seed))
                if key not in self._levels:
                    self._levels[key] = self.prelevel_gq(w, t0, t1, seed, {})
                return self._levels[key]
        except SimulationError:     # the scored run below diverges too, or runs unlevelled
            pass
        return None

    def prelevel_gq(self, w: Signals, t0: float, t1: float, seed: int, effects=None,
                    sim=None) -> np.ndarray:
        """Per-segment Gq of window [t0, t1) and road seed ``seed`` at which the model with
        ``effects`` matches the measured level piece by piece (``PRE_LEVEL``): its run on
        the fitted road (``sim`` when already made), tilted, re-levelled per piece, the
        factors squared into Gq."""
        m = self.model
        if sim is None:
            sim = m.run(effects or {}, t0, t1, seed)
        if TILT_REFIT:
            sim = apply_tilt(sim, m.fs, window_tilt(w.channels, sim, m.fs, m.noise))
        _, vals = piece_levels(m, w.channels, sim, t0, t1, m.noise)
        gq = np.array(m.gq, float)
        for (k, _a, _b), (_a2, _b2, f) in zip(m.pieces(t0, t1), vals):
            gq[k] *= f * f
        return gq

    def __call__(self, state, window, seed):
        from eroad.errors import SimulationError

        w = as_signals(window)
        m = self.model
        t0 = float(w.meta["t0"])
        t1 = t0 + w.time.size / m.fs
        gq = self.road_level(w, t0, t1, seed, state.effects)
        try:
            sim = m.run(state.effects, t0, t1, seed, gq=gq)
        except SimulationError:         # a diverging candidate scores as a very bad model
            sim = {c: np.full(w.time.size, 1e3) for c in m.channels}
        # nuisances profiled per model and window: the road waviness (a spectral tilt, see
        # window_tilt), the level with the
        # nominal noise floor, then the white-noise floor of THIS model (measured minus
        # simulated PSD at the top of the band), the level again with that floor
        noise = m.noise
        if any(np.var(x) > 0 for x in sim.values()):
            if TILT_REFIT:
                dw = window_tilt(w.channels, sim, m.fs, m.noise)
                sim = apply_tilt(sim, m.fs, dw)
            for _ in range(2):
                g = level_scale(m, w.channels, sim, t0, t1, noise=noise)
                levelled = relevel(sim, g)
                noise = window_noise(w.channels, levelled, m.fs)
            sim = levelled
        sim = m.add_noise(sim, seed, noise)
        return Signals(w.time, sim, dict(w.units), w.speed, {"model": "truck", **state.effects})
