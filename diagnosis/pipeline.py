"""Diagnosis of a measured drive against the Exudyn truck: the wiring behind ``eroad diagnose``.

What it is for: read a dataset (never its ``truth/``), identify the road per segment
with the nominal model on calibration data, localise the gap, run the road-independent
comparisons, rank the effects of :data:`vehicles.effects.EFFECTS` and write the report.
What it is not: the statistics (``diagnosis.where``, ``compare``, ``which``, ``gap``)
or the vehicle model (``vehicles.simulate``).

Road identification (the cheap road fit, decision)
-------------------------------------------------
The full inverse fit (``inverse.pipeline.invert``) costs minutes per model; the
ranking needs one road fit per candidate and per calibration evaluation (about 150).
The diagnosis therefore starts from ``nmin = 0.1``, ``nmax = 5`` cycles/m (the ISO 8608
defaults) and identifies level ``Gq(n0)`` and waviness ``w`` per segment
(:func:`fit_road`), then ``nmin`` and ``nmax`` per segment from small grids where the
data resolve them (:func:`fit_nmin`, :func:`fit_nmax`):

1. Segments: :func:`inverse.segmentation.segment` on the suspension displacements
   (level-based change points, BIC for K).
2. Nominal road, once: one simulation over the whole record on a class-C reference
   road (``w = 2``); per segment, on its CALIBRATION samples, the log ratio of measured
   to simulated third-octave band power (1-12 Hz, suspension and axle channels) is
   regressed on ``ln(f / (v n0))``: slope ``2 - w``, exact for a linear model.  A
   second simulation with the fitted ``w`` sets the level (geometric mean of the
   channel power ratios; response power scales with ``Gq``).
3. For each model (nominal or with an effect) and each simulated window, the road
   level is re-profiled per segment piece: the simulated piece is scaled by
   ``sqrt(mean_c P_meas / P_sim)`` (geometric mean over channels, smooth 0.5 s
   ramps between pieces).  This is the fit ``rank_effects`` asks for (road
   identified on the data with the effect fixed) at the cost of no extra
   simulation; exact for a linear model, first order for the nonlinear effects
   (friction, bump stop, damper asymmetry), which see the level of step 2.
   Before the level, the waviness is refitted per model and window as a spectral
   tilt (:func:`window_tilt`, :func:`apply_tilt`): the nominal ``w`` of step 2
   absorbs part of any effect that tilts the spectra (a sensor low-pass, tyre
   enveloping), and without the refit the true effect could not close its gap.

Sensor noise: the measured record carries white sensor noise the simulation lacks.
Its level per channel is the measured minus the simulated spectrum between 0.6 and
0.95 of the Nyquist frequency, and seeded white noise of that level is added to every
simulation ("the nominal model" includes the measured noise floor).  The floor is
profiled per model and window (:func:`window_noise`): a model that attenuates the top
of the band leaves more of the measured power there to noise.  The ``sensor``
candidate calibrates the cutoff only, with its own noise switched off.

speed_scale: realised here (:meth:`TruckModel.run` drives at the recorded speed over
the factor), identified by the front-to-rear delay term of the ranking
(:func:`delay_term`, :class:`diagnosis.which.DelayTerm`) and calibrated from it.

Road grid: ``ROAD_DX`` = 0.025 m, the virtual test drive's grid (the footprint filter
of tyre_enveloping rounds the length to an odd number of grid steps).

Calibration / held-out split (decision): the record is cut into ``n_windows``
(default 4) equal time windows; windows 1 and 3 (odd, counted from 1) calibrate,
windows 2 and 4 are held out.  Alternating windows put every long road segment into
both sets.  Each window is simulated on its own (2 s run-in at the window's starting
speed, discarded).
"""
from __future__ import annotations

import copy
import json
import math
import os
import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from diagnosis.signals import Signals, as_signals
from eroad.archive import finish_run_info, run_info, write_run_json
from eroad.errors import EroadInputError

#: ISO 8608 road shape kept fixed by the cheap road fit
ROAD_W, ROAD_NMIN, ROAD_NMAX = 2.0, 0.1, 5.0
#: a window's runs skip the linear first pass of the one-sided tyres when the nominal run had
#: a tyre off the road inside it or this long before it [s] (its run-in)
LIFT_HINT_MARGIN_S = 2.0
#: reference level of the first (nominal) simulation [m^3] (class C mean)
GQ_REF = 256e-6
#: run-in simulated and discarded before every window [s]
RUNIN_S = 2.0
#: road grid of the diagnosis simulations [m] (that of the virtual test drive, drives/scenarios)
ROAD_DX, ROAD_DY, ROAD_WIDTH = 0.025, 0.1, 3.0
#: measured channel prefixes used
QUANTITIES = ("susp_disp_", "axle_acc_", "body_acc_")
#: smoothing ramp between segment pieces of different level [s]
RAMP_S = 0.5
#: pieces shorter than this take the level of the whole window [s]
MIN_PIECE_S = 1.5
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
#: the skewness of the suspension displacements is a term of every gap (``shape_term``,
#: :class:`diagnosis.which.ShapeTerm`): what separates a bump stop from a payload error
#: with the same spectra (blind case 13: measured skewness -0.4 to -1.1, nominal 0, se 0.13)
SHAPE_TERM = True
#: the skewness of the suspension stroke velocity as a term of every gap
#: (:func:`stroke_velocity_term`, :class:`diagnosis.which.StrokeVelocityTerm`); experimental,
#: off: tried 2026-11-27 to pin a damper asymmetry's ratio (the band gap is flat towards high
#: ratios), but per 7.5 s window the statistic follows the road phase (nominal model on one
#: calibration window: +0.36 and +0.14 on two phases, sigma 0.35 against 0.02 for a
#: Gaussian road), so at the common term weight it is mostly noise: blind case 15's folds
#: moved from 2.34 / 8.0 to 2.34 / 1.75 for a 3.71 truth (docs/diagnosis.md, "Left")
STROKE_VELOCITY_TERM = False

#: candidate search ranges (name -> {param: (lo, hi)}, primary parameter only) narrower
#: than the library's validity ranges: the physically sensible span of a model error
#: for the 8x4 dump truck.  The library's own range is used for effects not listed.
#: tyre_enveloping starts at 0.1 m (linear search): with 0.05-0.6 (log) the 4-point grid
#: and golden search stopped at 0.11 m for a 0.40 m truth (the moving average's gap is
#: not unimodal in the length) and the sensor low-pass won (blind case 9).
SEARCH = {
    "frame_flex": {"stiffness_factor": (0.1, 100.0)},
    "tyre_enveloping": {"length": (0.1, 0.6)},
    "leaf_friction": {"force": (200.0, 12000.0)},
    # from 1 mm (was 5 mm, the blind draw's own lower end: a 6.7 mm truth calibrated at 5 mm
    # in one fold and the edge rule withheld the name by construction, blind cases 3 and 14
    # of 20261127-own-signature-fresh-40); a stop touching at rest (0) simulates
    "bump_stop": {"gap": (0.001, 0.08)},
    # the library's own range (0.3-6 until 2026-11-27: a 4.25 truth calibrated at 6.0 in one
    # fold and the edge rule withheld the name, blind case 15 of 20261127-relevel-fresh-40)
    "damper_asymmetry": {"ratio": (0.2, 8.0)},
    "payload": {"mass": (-14000.0, 14000.0)},
    "speed_scale": {"factor": (0.85, 1.15)},
    "sensor": {"cutoff": (3.0, 60.0)},
}
#: an effect with an own signature (``diagnosis.verdict.OWN_SIGNATURE``) is searched on the
#: side of its neutral value that the measured signature shows (:func:`own_side_record`):
#: a damper asymmetry's stroke-velocity asymmetry (its own signature's statistic, the
#: L-skewness since 2026-11-27) gives the sign of ``ratio - 1`` without the road (0 for a
#: linear truck on a Gaussian road), while the band gap can be flat or
#: two-basined across 1 -- blind cases with a damper asymmetry of 3.85, 3.8 and 2.12 had one
#: fold calibrate at 0.2, 0.3 and 0.64 (diag seeds 67 case 5, 20261127-fresh-40 case 5,
#: 20261125-nominal-liftoff-seed19 case 4).  Only where the measurement lies at least
#: ``verdict.OWN_Z_SIDE`` prediction sd from the nominal model (the verdict's own
#: threshold until stop 59, which lowered the verdict's to 2.0); else the library's whole
#: range.  Added 2026-11-27, after those sets.
OWN_SIDE = True
#: the search ranges of each side: effect -> (param, range above the neutral value, range below)
OWN_SIDE_RANGES = {"damper_asymmetry": ("ratio", (1.0, 8.0), (0.2, 1.0))}
#: effects whose primary parameter sets the static sag (calibrated further on the static
#: offset where the dataset declares its displacement zero: ``which.Candidate.static_param``)
STATIC_PARAM_EFFECTS = ("payload",)
#: parameters held fixed in the candidates (the sensor's noise is part of the nominal model)
FIXED = {"sensor": {"acc_noise": 0.0, "disp_noise": 0.0}}
#: smallest speed factor (recorded / true speed) a simulation may use: every road is made
#: long enough for it, so all models drive the same surface
SPEED_FACTOR_MIN = 0.85
#: effects tried by ``--quick``
QUICK_EFFECTS = ("frame_flex", "leaf_friction", "payload", "sensor")
#: the ranking's budget (``rank_effects`` settings; ``folds`` 2: both roles of the windows).
#: The blind benchmarks (``diagnosis.blind.BLIND_SETTINGS``) run this budget, so their
#: verdicts and times are those of ``eroad diagnose``: refine 3 (until 2026-11-24 the CLI
#: ran refine 4 while every blind set was measured with 3, so the validated budget was
#: not the one shipped)
#: the order the candidates' calibrations are handed to the worker pool
#: (``which.rank_effects(task_order=...)``): longest first, so that two workers finish a fold
#: together (longest-processing-time-first scheduling).  Measured per task on blind drive 2 of
#: results/diagnosis_blind/20261127-frame-grid-fresh-40/nominal (one fold, s): leaf_friction
#: 24.6, damper_asymmetry 15.1, bump_stop 11.2, frame_flex 5.8, tyre_enveloping 3.8, payload
#: 3.1, sensor 3.1, speed_scale 2.0 (stiff friction and bump stop take the solver's small
#: steps).  In the library's order the pair (damper, friction) fell on one worker: 39.7 s
#: against 29 s on the other.  Every task is seeded on its own: the results are the same.
TASK_ORDER = ("leaf_friction", "damper_asymmetry", "bump_stop", "frame_flex", "tyre_enveloping",
              "payload", "sensor", "speed_scale")
#: ``n_calib_seeds`` 1: each candidate is calibrated on its calibration windows over one road
#: realisation.  Two were tried in stop 59 (2026-11-29): on 14 drives of stop 58's fresh set (in
#: sample) they named a 7.5 mm bump stop and a frame flexibility that one seed had left at a range
#: edge; on the fresh set after it (seeds 311 / 307, 40 drives, both run on the same blind datasets)
#: they gave the same verdict on all 40 at +25 % time, so by the test stated before that set the
#: cheaper budget stays (results/diagnosis_blind/20261129-calib-seeds-2/)
BUDGET = dict(n_seeds=4, n_null=12, grid=4, refine=3, n_pair_candidates=2, folds=2, n_calib_seeds=1)
#: ``--quick`` (CI smoke settings)
QUICK_BUDGET = dict(n_seeds=3, n_null=6, grid=3, refine=3, pairs=False, folds=1)


def _say(msg):
    print(msg, flush=True)


# --------------------------------------------------------------------------- noise

def noise_std(sig: Signals, names, block_s: float = 4.0) -> dict:
    """White-noise std per channel from the top of the measured spectrum.

    Mean PSD between 0.6 and 0.95 of the Nyquist frequency, minimum over blocks of
    ``block_s`` seconds, times the Nyquist bandwidth.

    Returns
    -------
    dict name -> std (channel unit)
    """
    from diagnosis.welch import welch

    fs = sig.fs
    n = int(block_s * fs)
    out = {}
    for c in names:
        x = sig.channels[c]
        vals = []
        for i0 in range(0, max(1, x.size - n + 1), n):
            seg = x[i0:i0 + n]
            if seg.size < 64:
                continue
            L = min(256, seg.size)
            f, p = welch(seg - seg.mean(), fs, L, hop=L - L // 2)
            m = (f >= 0.6 * fs / 2) & (f <= 0.95 * fs / 2)
            vals.append(float(np.mean(p[m])))
        psd = min(vals) if vals else 0.0
        out[c] = math.sqrt(psd * fs / 2.0)
    return out


def noise_from_residual(sig: Signals, sim: dict) -> dict:
    """White-noise std per channel of the whole record: :func:`window_noise` with
    512-sample Welch segments."""
    return window_noise(sig.channels, sim, sig.fs, nperseg=512)


def window_noise(meas: dict, sim: dict, fs: float, nperseg: int = 256) -> dict:
    """White-noise std per channel of one window for one (noise-free) model simulation.

    Measured minus simulated Welch PSD (``nperseg``-sample Hann segments), mean over
    0.6-0.95 of the Nyquist frequency, floored at zero, times the Nyquist bandwidth.
    The noise floor is a nuisance like the road level: it is identified for every model
    (a model that attenuates the top of the band, e.g. a sensor low-pass or tyre
    enveloping, leaves more of the measured power there to noise), not once with the
    nominal model.
    """
    from diagnosis.welch import welch

    names = list(meas)
    X = np.array([meas[c] - np.mean(meas[c]) for c in names])
    Y = np.array([sim[c] - np.mean(sim[c]) for c in names])
    nper = min(int(nperseg), X.shape[1])
    f, pm = welch(X, fs, nper, hop=nper - nper // 2)
    _, ps = welch(Y, fs, nper, hop=nper - nper // 2)
    m = (f >= 0.6 * fs / 2) & (f <= 0.95 * fs / 2)
    d = np.maximum(pm[:, m].mean(axis=1) - ps[:, m].mean(axis=1), 0.0)
    return {c: math.sqrt(float(v) * fs / 2.0) for c, v in zip(names, d)}


#: refit the road waviness per model and window as a spectral tilt (see window_tilt)
TILT_REFIT = True
#: bound of the per-model waviness change
TILT_MAX = 1.0
#: reference frequency of the tilt [Hz] (the level absorbs the choice)
TILT_F_REF = 3.0


def _band_log_ratios(f, pm, ps, nz, bands, f_unit, xs, ys) -> None:
    """Append ln(fc / f_unit) to ``xs`` and ln(measured band power less the white noise
    ``nz`` per bin / simulated band power) to ``ys`` for every band of ``bands`` (rows lo, fc,
    hi [Hz]) that holds a bin and where both powers are positive (``pm``, ``ps``: PSDs on
    the bins ``f``)."""
    for lo, fc, hi in bands:
        sel = (f >= lo) & (f < hi)
        if sel.sum() == 0:
            continue
        bm = float(np.sum(pm[sel]) - nz * sel.sum())
        bs = float(np.sum(ps[sel]))
        if bm > 0 and bs > 0:
            xs.append(math.log(fc / f_unit))
            ys.append(math.log(bm / bs))


def window_tilt(meas: dict, sim: dict, fs: float, noise: dict) -> float:
    """Waviness change ``dw`` of the road that best matches ``sim`` to ``meas`` in one window.

    For a linear vehicle at speed ``v`` on a road ``Gq (n/n0)^-w`` the response PSD at
    ``f`` is ``|H(f)|^2 Gq (f/(v n0))^-w / v``: a change ``dw`` of the waviness multiplies
    it by ``(f/(v n0))^-dw``, a power law in ``f`` whose speed factor the level absorbs.
    ``dw`` is the negated slope of the regression of ``ln(P_meas/P_sim)`` (measured noise
    removed) on ``ln f`` over the third octaves of ``W_FIT_BAND`` and the channels of
    ``W_FIT_QUANTITIES``, as in :func:`fit_road`, clipped to +-``TILT_MAX``.  This is the
    waviness part of "the road identified with the effect fixed" at no extra simulation
    (the nominal waviness of :func:`fit_road` absorbs part of any effect that tilts the
    spectra, e.g. a sensor low-pass; without the refit the true effect at its true
    strength could not close its gap).
    """
    from diagnosis.welch import welch

    from diagnosis.bandpower import third_octave_bands

    bands = third_octave_bands(*W_FIT_BAND)
    xs, ys = [], []
    names = [c for c in meas if c.startswith(W_FIT_QUANTITIES)]
    if not names:
        return 0.0
    X = np.array([meas[c] - np.mean(meas[c]) for c in names])
    Y = np.array([sim[c] - np.mean(sim[c]) for c in names])
    L = min(256, X.shape[1])
    f, PM = welch(X, fs, L, hop=L - L // 2)
    _, PS = welch(Y, fs, L, hop=L - L // 2)
    for c, pm, ps in zip(names, PM, PS):
        _band_log_ratios(f, pm, ps, 2.0 * noise.get(c, 0.0) ** 2 / fs, bands, 1.0, xs, ys)
    if len(set(np.round(xs, 6))) < 3:
        return 0.0
    return float(np.clip(-np.polyfit(xs, ys, 1)[0], -TILT_MAX, TILT_MAX))


def apply_tilt(sim: dict, fs: float, dw: float) -> dict:
    """Multiply the PSD of every channel by ``(f / TILT_F_REF)^-dw`` (amplitude by the root;
    frequencies below 0.25 Hz take the 0.25 Hz factor)."""
    if dw == 0.0:
        return sim
    out = {}
    for c, x in sim.items():
        X = np.fft.rfft(x - x.mean())
        f = np.fft.rfftfreq(x.size, 1.0 / fs)
        X *= (np.maximum(f, 0.25) / TILT_F_REF) ** (-0.5 * dw)
        out[c] = np.fft.irfft(X, n=x.size) + x.mean()
    return out


# --------------------------------------------------------------------------- the model

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
    #: what :func:`fit_nmax` decided about the high band, for the report: ``{"cut": [segment
    #: indices cut], "rolloff": [segment indices that roll off], "vetoed": bool}``
    high_band: dict | None = None
    #: the inputs :func:`fit_road` gave :func:`fit_nmax` (``{"gq", "noise"}``), so that
    #: :func:`refit_band` repeats that fit with only the effects changed
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


def _power(x):
    return float(np.var(x)) if x.size > 1 else float("nan")


def level_scale(model: TruckModel, meas: dict, sim: dict, t0: float, t1: float,
                noise: dict | None = None) -> np.ndarray:
    """Per-sample amplitude factor that re-levels ``sim`` per segment piece to ``meas``.

    Power ratio per channel (measured less its noise power), geometric mean over
    channels, square root; pieces shorter than ``MIN_PIECE_S`` take the window's
    factor; 0.5 s linear ramps between pieces.
    """
    fs = model.fs
    n = next(iter(sim.values())).size
    whole, vals = piece_levels(model, meas, sim, t0, t1, noise)
    g = np.full(n, whole)
    for a, b, f in vals:
        g[a:b] = f
    # smooth steps between pieces
    r = int(RAMP_S * fs / 2)
    for (a0, b0, f0), (a1, b1, f1) in zip(vals[:-1], vals[1:]):
        lo, hi = max(0, b0 - r), min(n, a1 + r)
        if hi - lo > 1:
            g[lo:hi] = np.linspace(f0, f1, hi - lo)
    return g


def relevel(sim: dict, g) -> dict:
    """``sim`` re-levelled by the per-sample factor ``g`` (:func:`level_scale`): each
    channel's motion about its window mean times ``g``, the mean kept.

    The factor stands for a rougher or smoother road, which scales the response, not the
    static state: a payload change moves the suspension's static position (-23 mm for
    -8.9 t on axle 3 of the 8x4 truck) and that offset must not follow the road level.
    Scaling the whole signal (as until 2026-11-27) turned a static offset into steps of
    a few mm between road pieces with different factors: skewed suspension displacements
    and low-frequency power the measurement does not have, so the true payload model
    scored worse than the nominal one (blind case 006 of results/diagnosis_blind/
    20261127-fresh-40, second fold: held-out gap 1.90 against the nominal model's
    0.51; 0.40 with the offset kept).  The window mean stands for the static state: the
    motion's own mean over a 7.5 s window (about 1 mm) is kept unscaled, so pieces with
    factors 0.5 and 1.5 differ by about 0.5 mm where the whole-signal scaling put 23 mm.
    """
    g = np.asarray(g, float)
    out = {}
    for c, x in sim.items():
        mu = float(np.mean(x))
        out[c] = mu + (x - mu) * g
    return out


def piece_levels(model: TruckModel, meas: dict, sim: dict, t0: float, t1: float,
                 noise: dict | None = None):
    """Amplitude factors of :func:`level_scale`: the whole window's and, per segment piece,
    ``(a, b, factor)`` in window samples (pieces shorter than ``MIN_PIECE_S`` take the
    window's).  The piece's segment is ``model.pieces(t0, t1)[i][0]``."""
    fs = model.fs
    n = next(iter(sim.values())).size
    noise = model.noise if noise is None else noise

    def factor(a, b):
        logs = []
        for c in model.channels:
            pm = _power(meas[c][a:b]) - noise.get(c, 0.0) ** 2
            pm = max(pm, 0.1 * _power(meas[c][a:b]))
            ps = _power(sim[c][a:b])
            if ps > 0 and pm > 0:
                logs.append(math.log(pm / ps))
        return math.exp(0.5 * float(np.mean(logs))) if logs else 1.0

    whole = factor(0, n)
    vals = [(a, b, factor(a, b) if (b - a) / fs >= MIN_PIECE_S else whole)
            for k, a, b in model.pieces(t0, t1)]
    return whole, vals


# --------------------------------------------------------------------------- the callables

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


# --------------------------------------------------------------------------- dataset -> model

def load_measured(dataset):
    """Read the dataset (``drives.format.read_drive``; ``truth/`` is never read).

    Returns
    -------
    (Drive, Signals) with time from 0 and only the measured suspension/axle/body channels.
    """
    from drives.format import read_drive

    drive = read_drive(dataset)
    from drives.cut import require_road_record
    from drives.rate import for_road_methods
    drive, resampled = for_road_methods(drive)   # above the vehicle's solver rate: to 200 Hz
    names = [c for c in drive.channel_names if c.startswith(QUANTITIES)]
    if not names:
        raise EroadInputError(f"{dataset}: no susp_disp/axle_acc/body_acc channels to diagnose")
    require_road_record(drive, "eroad diagnose")   # the road methods run in distance
    t = np.asarray(drive.time, float)
    sig = Signals(t - t[0], {c: np.asarray(drive.channels[c], float) for c in names},
                  {c: drive.units.get(c, "") for c in names}, np.asarray(drive.speed, float),
                  {"dataset": drive.name, "t0": 0.0,
                   "susp_disp_zero": drive.susp_disp_zero,
                   **({"resampled_from_hz": resampled["from_hz"]} if resampled else {})})
    return drive, sig


def windows(sig: Signals, n_windows: int = 4):
    """Alternating calibration / held-out windows: (calib, heldout) lists of Signals."""
    T = sig.time.size / sig.fs
    edges = np.linspace(0.0, T, n_windows + 1)
    cal, held = [], []
    for i in range(n_windows):
        w = sig.window(edges[i], edges[i + 1])
        w = Signals(w.time, w.channels, w.units, w.speed, {**sig.meta, "t0": float(edges[i]),
                                                           "window": i + 1})
        (cal if i % 2 == 0 else held).append(w)
    return cal, held, edges


def segment_axle(names) -> int:
    """The axle whose suspension displacements segment the record (the reference axle of
    :class:`TruckModel`): the inversion's (``inverse.run.reference_axle``: axle 3 where logged,
    else the lowest-numbered axle logged on both sides), else, for a record with one side only,
    the lowest-numbered axle with a displacement at all."""
    from inverse.run import PREFERRED_AXLE, reference_axle

    try:
        return reference_axle(names)
    except EroadInputError:
        pass
    axles = sorted({int(c[len("susp_disp_"):-1]) for c in names
                    if c.startswith("susp_disp_") and c[len("susp_disp_"):-1].isdigit()})
    if not axles:
        raise EroadInputError("diagnosis: no suspension displacement channel (susp_disp_*) to segment the road on")
    return PREFERRED_AXLE if PREFERRED_AXLE in axles else axles[0]


def road_segments(sig: Signals, k=None):
    """Segment boundaries [s] from the suspension displacements of :func:`segment_axle`
    (inverse.segmentation)."""
    from inverse.segmentation import segment

    a = segment_axle(list(sig.channels))
    disp = {c: x for c, x in sig.channels.items() if c in (f"susp_disp_{a}L", f"susp_disp_{a}R")}
    res = segment(sig.time, disp, sig.speed, k=k)
    b = np.asarray(res.t_bounds, float)
    b[0], b[-1] = 0.0, sig.time.size / sig.fs
    return b


#: band of the waviness fit [Hz] and the channel quantities used (road-driven, little
#: affected by the body-side effects)
W_FIT_BAND = (1.0, 12.0)
W_FIT_QUANTITIES = ("susp_disp_", "axle_acc_")
W_RANGE = (1.2, 3.0)
#: lowest spatial frequency of the road [cycles/m] tried per segment by :func:`fit_nmin`:
#: ISO 8608's lowest classified frequency (0.011) up to the 0.1 of the virtual test drive;
#: real and ISO roads carry power down to 0.01 cycles/m, and a road fixed at 0.1 left the
#: simulation short by e^-2 to e^-6 at 0.5-0.8 Hz on a measured road profile
NMIN_GRID = (0.011, 0.02, 0.035, 0.06, 0.1)
#: road-phase seeds averaged per grid value (the simulated share's own realisation scatter)
NMIN_SEEDS = 2
#: log excess of the measured low-band share over the default road's (nmin = ROAD_NMIN)
#: needed before a lower nmin is chosen: the realisation scatter of that share on nominal
#: drives reached about 1 to 2 (diagnosis of virtual test drives, seeds 1-2)
NMIN_EVIDENCE = 1.5
#: fit nmin per segment (else every segment keeps ``ROAD_NMIN``)
FIT_NMIN = True
#: low band [Hz] whose share of power picks ``nmin``, and the band it is referred to (the
#: level is fitted separately)
NMIN_LOW_BAND, NMIN_REF_BAND = (0.25, 1.25), (2.0, 8.0)
#: quantities of the low-band fit (road-driven below the body bounce: suspension travel)
NMIN_QUANTITIES = ("susp_disp_",)


def _runs(mask):
    """(start, stop) of the True runs of a boolean array."""
    d = np.diff(np.concatenate([[0], mask.astype(int), [0]]))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0]))


def _level_logs(model, sig, sim: dict, mk) -> list:
    """ln(measured power less sensor noise / simulated power) per channel on the samples
    ``mk`` (the measured power is kept at least 10 % of itself); channels with no power
    are left out."""
    logs = []
    for c in model.channels:
        x = sig.channels[c][mk]
        pm = max(_power(x) - model.noise.get(c, 0.0) ** 2, 0.1 * _power(x))
        ps = _power(sim[c][mk])
        if ps > 0 and pm > 0:
            logs.append(math.log(pm / ps))
    return logs


def _runs_psd(meas: np.ndarray, sim: np.ndarray, runs, fs: float, nperseg: int):
    """(f, P_meas, P_sim): Welch PSDs of the runs ``(i, j)`` of two records (each run's mean
    removed), summed with the run lengths as weights."""
    from diagnosis.welch import welch

    pm = ps = 0.0
    for i, j in runs:
        L = min(int(nperseg), j - i)
        f, p1 = welch(meas[i:j] - meas[i:j].mean(), fs, L, hop=L - L // 2)
        _, p2 = welch(sim[i:j] - sim[i:j].mean(), fs, L, hop=L - L // 2)
        pm, ps = pm + p1 * (j - i), ps + p2 * (j - i)
    return f, pm, ps


def _low_band_log_ratio(sig: Signals, sim: dict, mask: np.ndarray, names) -> float:
    """``ln(Pm_low / Pm_ref) - ln(Ps_low / Ps_ref)``: the measured against the simulated
    share of low-band power, ``P_low`` the power in ``NMIN_LOW_BAND`` and ``P_ref`` in
    ``NMIN_REF_BAND``, pooled over the channels ``names`` on the samples ``mask``
    (contiguous runs of at least 512 samples; Welch segments of up to 1024 samples, half
    overlap).  Pooling matters: a third octave below 1 Hz holds one or two bins of a
    1024-sample segment, and a per-band log ratio of a 7 s run scatters by more than a
    unit (var ln of a 2-dof chi-square: pi^2/6 per side)."""
    return _band_share_log_ratio(sig, sim, mask, names, NMIN_LOW_BAND, NMIN_REF_BAND)


def _record_run(args):
    """A noise-free run of the whole record with ``attrs`` set on (a copy of) the model and
    ``effects`` in the truck (worker side of :func:`_record_runs`)."""
    model, attrs, T, seed, gq, effects = args
    model = copy.copy(model)        # a thread pool shares the caller's model: never set it
    for name, value in attrs.items():
        setattr(model, name, value)
    return model.run(effects or {}, 0.0, T, seed, gq=gq)


def _record_runs(model: TruckModel, jobs, T: float, gq, mapper=map, effects=None) -> list:
    """Whole-record runs ``jobs`` = [(attrs, seed), ...] (``attrs``: model attributes such as
    ``nmin``, set on a copy for that run only) of the nominal truck, or of the truck with
    ``effects`` (``{name: {param: value}}``), in parallel when ``mapper`` is an executor's
    ``map``; each run is seeded on its own, so the result does not depend on who runs it."""
    return list(mapper(_record_run, [(model, dict(attrs), T, seed, gq, effects)
                                     for attrs, seed in jobs]))


def fit_nmin(model: TruckModel, sig: Signals, gq, seed: int = 0, mapper=map) -> np.ndarray:
    """Lowest road frequency ``nmin`` per segment, from the grid ``NMIN_GRID``.

    One noise-free simulation of the whole record per grid value (all segments at that
    value, the fitted levels and waviness); per segment the value whose share of
    suspension-travel power below the body bounce (``NMIN_LOW_BAND`` against
    ``NMIN_REF_BAND``, :func:`_low_band_log_ratio`) is closest to the measured share, on
    the whole segment (0.5 s after its start skipped; a low band needs the long record:
    the held-out windows share the road anyway, every model is scored on the same road).
    Segments without a 512-sample run keep the virtual test drive's 0.1.  ``mapper``: an
    executor's ``map`` runs the grid's simulations in parallel.  The road fit
    of the diagnosis thereby leaves w and nmin to the data, as the inversion does (nmax:
    :func:`fit_nmax`, after this one).  Effects that move the body bounce (payload) bias
    this choice; the ranking re-levels, it does not refit nmin.
    """
    fs = sig.fs
    T = sig.time.size / fs
    K = len(model.bounds) - 1
    names = [c for c in model.channels if c.startswith(NMIN_QUANTITIES)] or list(model.channels)
    masks = []
    for k in range(K):
        a, b = int(round(model.bounds[k] * fs)), int(round(model.bounds[k + 1] * fs))
        m = np.zeros(sig.time.size, bool)
        m[min(a + int(0.5 * fs), b):b] = True
        masks.append(m)
    d = np.full((len(NMIN_GRID), K), np.nan)
    runs = _record_runs(model, [({"nmin": np.full(K, nmin)}, seed + 17 * r)
                                for nmin in NMIN_GRID for r in range(NMIN_SEEDS)], T, gq, mapper)
    for g, nmin in enumerate(NMIN_GRID):
        sims = runs[g * NMIN_SEEDS:(g + 1) * NMIN_SEEDS]
        for k in range(K):
            v = [_low_band_log_ratio(sig, sm, masks[k], names) for sm in sims]
            v = [x for x in v if math.isfinite(x)]
            d[g, k] = float(np.mean(v)) if v else float("nan")
    out = np.full(K, ROAD_NMIN)
    g0 = NMIN_GRID.index(ROAD_NMIN)
    for k in range(K):
        # the default stands unless the measurement holds clearly more low-band power than
        # the default road gives (a single road realisation of a 20 s segment scatters its
        # low-band share by about a unit in log: few independent harmonics below 0.1 c/m)
        if np.isfinite(d[g0, k]) and d[g0, k] > NMIN_EVIDENCE:
            out[k] = NMIN_GRID[int(np.argmin(np.where(np.isfinite(d[:g0 + 1, k]),
                                                      np.abs(d[:g0 + 1, k]), np.inf)))]
    return out


#: highest spatial frequency of the road [cycles/m] tried per segment by :func:`fit_nmax`:
#: a measured profile sampled every 0.25 m holds nothing above 2 cycles/m, tyre enveloping
#: of a real truck or a profile-based rig cut a road off too; 5 is the ISO 8608 default
NMAX_GRID = (1.0, 1.5, 2.0, 2.5, 3.0, 5.0)
#: road-phase seeds averaged per grid value
NMAX_SEEDS = 2
#: log deficit of the measured high-band share under the default road's (nmax = ROAD_NMAX)
#: needed before a lower nmax is tried.  Realisation scatter of that statistic, the nominal
#: model against itself on ISO roads up to 5 cycles/m (``eroad synth --scenario null``
#: seeds 1-4, 10 segments; blind nominal case 18, second-family case 2, 6 segments): -0.91
#: to +0.70, |d| <= 0.4 on segments longer than 5 s; second-family blind case 0 (measured
#: road, nothing above 2 cycles/m): -2.1 and -1.8; tyre enveloping 0.26 m (blind nominal
#: case 10): -1.6 (stopped by ``NMAX_CUT_TOL``)
NMAX_EVIDENCE = 1.2
#: fit nmax per segment (else every segment keeps ``ROAD_NMAX``)
FIT_NMAX = True
#: high band [Hz] whose share of axle-acceleration power decides whether a lower ``nmax``
#: is tried, and the band it is referred to (above the axle hop, below the cut-offs of
#: interest; the level is fitted separately).  The high band's top is capped at 0.45 fs
NMAX_HIGH_BAND, NMAX_REF_BAND = (20.0, 50.0), (5.0, 15.0)
#: quantities of the high-band fit (the unsprung mass follows the road above the axle hop)
NMAX_QUANTITIES = ("axle_acc_",)
#: the chosen nmax is the lowest grid value at which the measured axle-acceleration power
#: above the cut (from ``NMAX_ABOVE`` x nmax x the segment's top speed to the top of the
#: high band) is within ``NMAX_CUT_TOL`` (log) of a simulation on the cut road, i.e. of the
#: noise floor: a cut road leaves nothing there, a roll-off (tyre enveloping, a sensor
#: low-pass) leaves the road's attenuated power.  Measured (ln, measured over cut-road
#: simulation): 0.10-0.16 on second-family case 0 for cuts at 2-3 cycles/m (5.0 at 1.5);
#: 3.0-5.9 for cuts at 2-3 cycles/m on blind nominal case 10 (tyre enveloping 0.26 m, a
#: sinc^2 roll-off with side lobes)
NMAX_ABOVE, NMAX_CUT_TOL = 1.1, 0.7
#: where a segment whose measured high band lies below the default road's (``d`` beyond
#: ``NMAX_EVIDENCE``) keeps ``ROAD_NMAX`` because the measurement above every trial cut holds
#: more than noise (a roll-off), no segment of the record is cut (see :func:`fit_nmax`).
#: Set 2026-11-28 (stop 44) on the road fits of the 40 drives of 20261128-pool-fresh-40 and 22
#: of 20261127-nested-level-fresh-40 (its 18 second-family drives and 4 sensor / tyre drives;
#: datasets remade by their seeds): it removes the cuts of three sensor drives (6.3, 6.8,
#: 9.1 Hz) and of none of the six measured-profile drives cut at 2 cycles/m (every segment
#: cut, no roll-off).  Not caught: a 7.7 Hz sensor drive whose every segment looked cut.
NMAX_ROLLOFF_VETO = True


def _pooled_psd(sig: Signals, sim: dict, mask: np.ndarray, names, min_run: int = 512):
    """Measured and simulated PSDs summed over the channels ``names`` on the samples ``mask``
    (contiguous runs of at least ``min_run`` samples, Welch segments of up to 1024 samples):
    ``(f, P_measured, P_simulated)``, or None without such a run."""
    runs = [(i, j) for i, j in _runs(mask) if j - i >= min_run]
    if not runs:
        return None
    nper = int(min(1024, min(j - i for i, j in runs)))
    pm = ps = 0.0
    for c in names:
        f, p1, p2 = _runs_psd(sig.channels[c], sim[c], runs, sig.fs, nper)
        pm, ps = pm + p1, ps + p2
    return f, pm, ps


def _band_share_log_ratio(sig: Signals, sim: dict, mask: np.ndarray, names, band, ref,
                          min_run: int = 512) -> float:
    """``ln(Pm_band / Pm_ref) - ln(Ps_band / Ps_ref)`` pooled over the channels ``names`` on the
    samples ``mask`` (runs of at least ``min_run`` samples), as :func:`_low_band_log_ratio`
    with the bands given."""
    return _share_log_ratio(_pooled_psd(sig, sim, mask, names, min_run), band, ref)


def _share_log_ratio(pooled, band, ref) -> float:
    """:func:`_band_share_log_ratio` of an already pooled ``(f, Pm, Ps)`` (None: NaN)."""
    if pooled is None:
        return float("nan")
    f, pm, ps = pooled
    hi = (f >= band[0]) & (f < band[1])
    rf = (f >= ref[0]) & (f < ref[1])
    vals = [pm[hi].sum(), pm[rf].sum(), ps[hi].sum(), ps[rf].sum()]
    if not (hi.any() and rf.any() and min(vals) > 0):
        return float("nan")
    return math.log(vals[0] / vals[1]) - math.log(vals[2] / vals[3])


def _power_log_ratio(pooled, band) -> float:
    """``ln(Pm_band / Ps_band)``: measured over simulated power in ``band`` [Hz] of a pooled
    ``(f, Pm, Ps)`` (:func:`_pooled_psd`; None, or an empty band: NaN)."""
    if pooled is None or not band[1] > band[0]:
        return float("nan")
    f, pm, ps = pooled
    m = (f >= band[0]) & (f < band[1])
    if not m.any() or pm[m].sum() <= 0 or ps[m].sum() <= 0:
        return float("nan")
    return math.log(pm[m].sum() / ps[m].sum())


def choose_nmax(d: np.ndarray, e: np.ndarray, low: np.ndarray,
                veto: bool | None = None) -> tuple[np.ndarray, list, bool]:
    """The nmax per segment from :func:`fit_nmax`'s statistics (rows ``NMAX_GRID``, columns
    segments; ``low``: segments whose high-band share lies beyond ``NMAX_EVIDENCE`` below the
    default road's).  A low segment takes the lowest grid value whose ``e`` (measured over
    cut-road power above the cut) is below ``NMAX_CUT_TOL``; one where no computed ``e``
    gets there is a roll-off and keeps ``ROAD_NMAX``; and with ``veto``
    (``NMAX_ROLLOFF_VETO``) a roll-off anywhere leaves every segment at ``ROAD_NMAX``.
    Returns ``(nmax, roll-off segments, vetoed)``; segments without the statistics are left
    at ``ROAD_NMAX`` here (the caller gives them a neighbour's value)."""
    veto = NMAX_ROLLOFF_VETO if veto is None else bool(veto)
    g0 = NMAX_GRID.index(ROAD_NMAX)
    K = d.shape[1]
    out = np.full(K, ROAD_NMAX)
    for k in np.nonzero(low)[0]:
        # the lowest cut above which the measurement holds nothing but noise (a roll-off
        # never gets there: the segment keeps ROAD_NMAX)
        ok = [g for g in range(g0) if np.isfinite(e[g, k]) and e[g, k] < NMAX_CUT_TOL]
        if ok:
            out[k] = NMAX_GRID[ok[0]]
    # a roll-off in one segment is the record's (a low-pass acts on every segment, a road
    # cut on its own): no segment is cut
    rolloff = [int(k) for k in np.nonzero(low)[0]
               if out[k] == ROAD_NMAX and np.isfinite(e[:g0, k]).any()]
    vetoed = bool(veto and rolloff and np.any(out < ROAD_NMAX))
    if vetoed:
        out[:] = ROAD_NMAX
    return out, rolloff, vetoed


def fit_nmax(model: TruckModel, sig: Signals, gq, seed: int = 0, diag: dict | None = None,
             mapper=map, effects=None) -> np.ndarray:
    """Highest road frequency ``nmax`` per segment, from the grid ``NMAX_GRID``.

    Two statistics of the axle accelerations (channels ``NMAX_QUANTITIES``, pooled; whole
    segment, 0.5 s after its start skipped; every simulation with the measured white noise
    floor ``model.noise`` added, seeded: where the road holds nothing the measurement is its
    noise, and so is a simulation on a road cut off there):

    * ``d``: :func:`fit_nmin`'s statistic turned upside down, the measured against the
      simulated share of power in ``NMAX_HIGH_BAND`` (20-50 Hz, top capped at 0.45 fs)
      against ``NMAX_REF_BAND`` (5-15 Hz);
    * ``e``: for a cut at ``g``, ``ln`` of measured over simulated power from ``NMAX_ABOVE
      g v_max`` (``v_max`` the segment's top speed) to the top of the high band, where the
      simulation on the cut road is noise only.

    First ``NMAX_SEEDS`` whole-record simulations with every segment at ``ROAD_NMAX``
    (fitted levels, w and nmin).  A segment keeps ``ROAD_NMAX`` unless its measured share
    lies more than ``NMAX_EVIDENCE`` (log) below the simulated one.  Only then are the lower
    grid values simulated (those the record can tell from ``ROAD_NMAX``: ``NMAX_ABOVE g v_max``
    below the top of the high band; a cut above it, or above the record's Nyquist in space,
    changes nothing the statistics see), and the segment takes the LOWEST grid value whose
    ``e`` is below ``NMAX_CUT_TOL``: the lowest cut above which the measurement is noise.
    A roll-off never gets there and keeps ``ROAD_NMAX``; and where one segment shows a
    roll-off, no segment is cut (``NMAX_ROLLOFF_VETO``, below).  (A first version took the value
    whose share ``d`` was closest, as fit_nmin does; on second-family blind case 0, road cut
    at 2 cycles/m, a segment whose speed ran 7.5-11.2 m/s took 2.5: the share is dominated
    by the bottom of the band, where the independent truck's axle response differs from
    ours, and the held-out windows kept e^5.8 too much power at 20-25 Hz.)  Segments too
    short for the statistics (no 512-sample run) take the value of the nearest segment
    that has them: the same record's road (case 0's first 1.9 s, two short segments left
    at 5, put the excess back for the fold that held them out).

    What moves ``d`` besides the road: a low-pass at the sensor and tyre enveloping (a
    moving average of the road in space, first zero at ``1 / length``).  They are roll-offs,
    not cuts: above any cut the measurement keeps attenuated road power (``e`` 3.0-3.7 on
    blind nominal case 10, tyre enveloping 0.26 m, against 0.10-0.16 for the 2-3 cycles/m
    cuts of second-family case 0), so they leave nmax at ``ROAD_NMAX`` and stay for the
    ranking.  A low-pass so steep that the band above it is noise (a sensor cutoff far
    below 20 Hz) would be taken up here, on the segments whose road is so smooth that the
    attenuated band sinks into the noise: blind nominal cases 9 and 19 of
    20261128-pool-fresh-40 (sensor 6.3 and 6.8 Hz) cut their smoothest segments (Gq 10^-4.6
    and 10^-4.5 m^3) at 2-3 cycles/m, and a short neighbour with them, while every rougher
    segment showed the same high-band deficit as a roll-off.  On a road so cut, the sensor
    candidate calibrated on one fold's windows to 4.8 Hz and on the other's to 22 Hz, and
    tyre enveloping won the ranking.  Hence ``NMAX_ROLLOFF_VETO``: a low-pass of the
    vehicle or the sensors acts on every segment, a road cut on its own segment; where one
    segment (with the statistics computed) shows the deficit as a roll-off, the deficit is
    the record's, and the segments that looked cut are those too smooth to show the
    roll-off above the noise: none is cut, and the roll-off is left to the ranking (sensor,
    tyre enveloping).  The ranking re-levels, it does not refit nmax.

    ``diag``: if a dict, filled with ``d`` and ``e`` (rows ``NMAX_GRID``, columns segments,
    NaN where not simulated), the segments' top speeds and the high band.  ``mapper``: an
    executor's ``map`` runs the seeds' simulations in parallel.  ``effects``: the simulations
    carry these effects (``{name: {param: value}}``; default the nominal truck): the band
    refitted with a candidate in the model (:func:`refit_band`).
    """
    fs = sig.fs
    T = sig.time.size / fs
    K = len(model.bounds) - 1
    names = [c for c in model.channels if c.startswith(NMAX_QUANTITIES)] or list(model.channels)
    band = (NMAX_HIGH_BAND[0], min(NMAX_HIGH_BAND[1], 0.45 * fs))
    masks, vmax = [], np.zeros(K)
    for k in range(K):
        a, b = int(round(model.bounds[k] * fs)), int(round(model.bounds[k + 1] * fs))
        m = np.zeros(sig.time.size, bool)
        m[min(a + int(0.5 * fs), b):b] = True
        masks.append(m)
        vmax[k] = float(np.max(sig.speed[a:b])) if b > a else float("nan")
    g0 = NMAX_GRID.index(ROAD_NMAX)
    d = np.full((len(NMAX_GRID), K), np.nan)
    e = np.full((len(NMAX_GRID), K), np.nan)

    def stat(g, todo, also=None):
        # ``also``: segments without the statistics, driven at the trial cut too (they take
        # a neighbour's value below; left at 5 their road bled into the neighbour's window)
        nmax = np.where(todo if also is None else todo | also, NMAX_GRID[g], ROAD_NMAX)
        runs = _record_runs(model, [({"nmax": nmax}, seed + 23 * r) for r in range(NMAX_SEEDS)],
                            T, gq, mapper, effects=effects)
        model.nmax = nmax
        sims = [model.add_noise(sm, seed + 23 * r + 1) for r, sm in enumerate(runs)]
        for k in np.nonzero(todo)[0]:
            pooled = [_pooled_psd(sig, sm, masks[k], names) for sm in sims]   # once for both statistics
            v = [_share_log_ratio(pl, band, NMAX_REF_BAND) for pl in pooled]
            v = [x for x in v if math.isfinite(x)]
            d[g, k] = float(np.mean(v)) if v else float("nan")
            if g < g0:
                # above the cut the simulation is noise only: is the measurement too?
                above = (NMAX_ABOVE * NMAX_GRID[g] * vmax[k], band[1])
                v = [_power_log_ratio(pl, above) for pl in pooled]
                v = [x for x in v if math.isfinite(x)]
                e[g, k] = float(np.mean(v)) if v else float("nan")

    stat(g0, np.ones(K, bool))
    # segments whose measured high-band share is clearly below the full-band road's
    low = np.isfinite(d[g0]) & (d[g0] < -NMAX_EVIDENCE)
    if low.any():
        for g in range(g0):
            todo = low & (NMAX_ABOVE * NMAX_GRID[g] * vmax < band[1])
            if todo.any():
                stat(g, todo, ~np.isfinite(d[g0]))
    out, rolloff, vetoed = choose_nmax(d, e, low)
    # segments too short for the statistic take the value of the nearest one that has it
    # (the record's road: a short segment left at 5 between cut ones put the whole excess
    # back for its seconds)
    has = np.isfinite(d[g0])
    if has.any() and not has.all():
        mid = 0.5 * (np.asarray(model.bounds[1:]) + np.asarray(model.bounds[:-1]))
        src = np.nonzero(has)[0]
        for k in np.nonzero(~has)[0]:
            out[k] = out[src[int(np.argmin(np.abs(mid[src] - mid[k])))]]
    model.nmax = out
    model.high_band = {"cut": [int(k) for k in np.nonzero(out < ROAD_NMAX)[0]],
                       "rolloff": list(rolloff), "vetoed": bool(vetoed)}
    if diag is not None:
        diag.update(d=d, e=e, vmax=vmax, band=band, rolloff=rolloff, vetoed=vetoed)
    return out


def fit_road(model: TruckModel, sig: Signals, calib_edges, seed: int = 0, mapper=map):
    """Nominal road level and waviness per segment from calibration samples (one simulation).

    The whole record is simulated once on a reference road (``GQ_REF``, ``w = 2``).  Per
    segment, on its calibration samples (0.5 s after the segment start skipped), the log
    ratio of measured to simulated band power in the third octaves of ``W_FIT_BAND`` over
    the channels of ``W_FIT_QUANTITIES`` (measured noise power removed) is regressed on
    ``ln(f / (v n0))``: for a linear model a road ``Gq (n/n0)^-w`` gives exactly
    ``ln(P_meas/P_sim) = ln(Gq/GQ_REF) + (2 - w) ln(f/(v n0))``.  The level then comes
    from the total power over all channels (as the re-levelling does).

    Returns
    -------
    (gq, w) : (K,) arrays [m^3], [-]
    """
    from diagnosis.bandpower import third_octave_bands

    T = sig.time.size / sig.fs
    K = len(model.bounds) - 1
    model.w = np.full(K, ROAD_W)
    sim = model.run({}, 0.0, T, seed, gq=np.full(K, GQ_REF))
    fs = sig.fs
    calmask = np.zeros(sig.time.size, bool)
    for a, b in calib_edges:
        calmask[int(round(a * fs)):int(round(b * fs))] = True
    skip = int(0.5 * fs)
    bands = third_octave_bands(*W_FIT_BAND)
    wchan = [c for c in model.channels if c.startswith(W_FIT_QUANTITIES)] or list(model.channels)
    gq, w = np.empty(K), np.full(K, ROAD_W)
    for k in range(K):
        a, b = int(round(model.bounds[k] * fs)), int(round(model.bounds[k + 1] * fs))
        m = np.zeros_like(calmask)
        m[min(a + skip, b):b] = True
        mk = m & calmask
        if mk.sum() < 2.0 * fs:     # too little calibration data here: use the whole segment
            mk = m if m.sum() >= fs else np.zeros_like(m)
            if not mk.any():
                mk[a:b] = True
        v = float(np.mean(sig.speed[mk]))
        runs = [(i, j) for i, j in _runs(mk) if j - i >= 256]
        if runs:
            xs, ys = [], []
            for c in wchan:
                f, pm, ps = _runs_psd(sig.channels[c], sim[c], runs, fs, 256)
                nz = 2.0 * model.noise.get(c, 0.0) ** 2 / fs * sum(j - i for i, j in runs)
                _band_log_ratios(f, pm, ps, nz, bands, v * 0.1, xs, ys)
            if len(set(np.round(xs, 6))) >= 3:
                slope = float(np.polyfit(xs, ys, 1)[0])
                w[k] = float(np.clip(ROAD_W - slope, *W_RANGE))
        # level over all channels with the fitted tilt applied to the reference simulation
        logs = _level_logs(model, sig, sim, mk)
        gq[k] = GQ_REF * math.exp(float(np.mean(logs))) if logs else GQ_REF
    # the level above was measured with w = 2; choose nmin with the fitted w, then
    # re-simulate once with both and re-level
    model.w = w
    if FIT_NMIN:
        model.nmin = fit_nmin(model, sig, gq, seed, mapper=mapper)
    if FIT_NMAX:
        model.band_inputs = {"gq": gq.copy(), "noise": dict(model.noise)}
        model.nmax = fit_nmax(model, sig, gq, seed, mapper=mapper)
    return relevel_road(model, sig, calib_edges, gq, seed), w


def relevel_road(model: TruckModel, sig: Signals, calib_edges, gq, seed: int = 0) -> np.ndarray:
    """The segment levels ``gq`` [m^3] re-levelled on the calibration windows by one nominal
    simulation of the whole record with the model's w, nmin and nmax (the last step of
    :func:`fit_road`, and of :func:`refit_band` after the band moved)."""
    fs = sig.fs
    T = sig.time.size / fs
    gq = np.array(gq, float)
    calmask = np.zeros(sig.time.size, bool)
    for a, b in calib_edges:
        calmask[int(round(a * fs)):int(round(b * fs))] = True
    skip = int(0.5 * fs)
    sim2 = model.run({}, 0.0, T, seed, gq=gq)
    for k in range(len(model.bounds) - 1):
        a, b = int(round(model.bounds[k] * fs)), int(round(model.bounds[k + 1] * fs))
        mk = np.zeros_like(calmask)
        mk[min(a + skip, b):b] = True
        mk &= calmask
        if mk.sum() < fs:
            mk[:] = False
            mk[a:b] = True
        logs = _level_logs(model, sig, sim2, mk)
        if logs:
            gq[k] *= math.exp(float(np.mean(logs)))
    return gq


def model_nmax(model: TruckModel) -> np.ndarray:
    """The model's nmax per segment [cycles/m], ``ROAD_NMAX`` where it was not fitted."""
    K = len(model.bounds) - 1
    return np.full(K, float(ROAD_NMAX)) if model.nmax is None else np.asarray(model.nmax, float)


def refit_band(model: TruckModel, sig: Signals, effects, seed: int = 0, mapper=map):
    """The road's high band refitted with ``effects`` (``{name: {param: value}}``) in the truck.

    :func:`fit_nmax` compares the measured and the simulated share of 20-50 Hz axle power; an
    effect that adds high-frequency power of its own (leaf-spring friction) makes the measured
    share look like a road that carries power to 5 cycles/m although the road stops at 2
    (``results/diagnosis_blind/20261129-twin-tracks/``).  Here the same fit (same levels,
    noise and seeds as :func:`fit_road` gave it) runs with the effect in the simulations, so
    the effect's own high band is on both sides of the comparison.  The model is not changed.

    Returns
    -------
    (nmax, high_band, changed) : (K,) array [cycles/m], dict as ``TruckModel.high_band``,
    bool (``nmax`` differs from the model's)
    """
    base = model.band_inputs or {}
    tmp = copy.copy(model)
    tmp.noise = dict(base.get("noise", model.noise))
    tmp.lift_times = None           # as in fit_road: the nominal run had not been made yet
    tmp._roads = {}
    new = fit_nmax(tmp, sig, np.asarray(base.get("gq", model.gq), float), seed, mapper=mapper,
                   effects=effects)
    return new, tmp.high_band, bool(not np.array_equal(new, model_nmax(model)))


def candidates(names=None, vehicle=None, sides=None):
    """Candidates over the library, primary parameter only, ranges of :data:`SEARCH`
    narrowed to what the effect allows on ``vehicle`` (``Effect.vehicle_ranges``: payload
    never below an empty truck); ``sides``: effect -> +1 / -1 / 0, the side of the neutral
    value an effect of :data:`OWN_SIDE_RANGES` is searched on (0: the whole range)."""
    from diagnosis.which import Candidate, Param
    from vehicles.effects import EFFECTS
    from vehicles.params import load_vehicle

    vp = load_vehicle(vehicle) if vehicle is not None else None

    out = []
    for name in (names or list(EFFECTS)):
        if name not in EFFECTS:
            raise EroadInputError(f"--effects: unknown effect {name!r}; known: {', '.join(EFFECTS)}")
        eff = EFFECTS[name]
        pname = eff.primary
        par = eff.parameter(pname)
        lo, hi = SEARCH.get(name, {}).get(pname, tuple(par.range))
        side = (sides or {}).get(name, 0)
        if side and name in OWN_SIDE_RANGES and OWN_SIDE_RANGES[name][0] == pname:
            lo, hi = OWN_SIDE_RANGES[name][1] if side > 0 else OWN_SIDE_RANGES[name][2]
        if vp is not None:
            vlo, vhi, _ = eff.vehicle_ranges(vp)[pname]
            lo, hi = max(lo, vlo), min(hi, vhi)
        fixed = {p.name: p.default for p in eff.parameters if p.name != pname}
        fixed.update(FIXED.get(name, {}))
        out.append(Candidate(name, (Param(pname, float(lo), float(hi),
                                          log=(lo > 0 and hi / lo >= 10)),), fixed,
                             delay_factor=(name == "speed_scale"),
                             static_param=(name in STATIC_PARAM_EFFECTS)))
    return out


# --------------------------------------------------------------------------- the diagnosis

@dataclass
class Context:
    """What the diagnosis knows after the road fit (see :func:`prepare`)."""

    model: TruckModel
    calib: list
    held: list
    edges: np.ndarray
    bounds: np.ndarray
    cal_edges: list
    sim_nominal: dict
    segs: list
    road_fit_s: float


def inverse_road(sig: Signals, vehicle, workers: int = 2):
    """The full inverse fit (``inverse.pipeline.invert`` with ``inverse.truck``) of the whole
    record: boundaries [s] and per-segment (Gq_n0, w, nmin, nmax)."""
    from eroad.threads import process_pool
    from inverse.pipeline import InversionConfig, invert
    from inverse.sensitivity import FitConfig
    from inverse.truck import TruckSimulator, truck_predict_rms

    chans = dict(sig.channels)

    a = segment_axle(list(chans))
    seg = sorted(c for c in chans if c in (f"susp_disp_{a}L", f"susp_disp_{a}R"))

    def make(t_bounds):
        return TruckSimulator(str(vehicle), sig.time, sig.speed, t_bounds, list(chans), ref_axle=a)

    cfg = InversionConfig(fit=FitConfig(n_workers=1))
    predict = truck_predict_rms(str(vehicle), tuple(seg))
    if workers > 1:
        with process_pool(workers) as pool:
            inv = invert(sig.time, chans, sig.speed, make, predict_rms=predict, config=cfg, map_fn=pool.map,
                         segment_channels=seg)
    else:
        inv = invert(sig.time, chans, sig.speed, make, predict_rms=predict, config=cfg, segment_channels=seg)
    rows = inv.segments()
    b = np.asarray(inv.t_bounds, float)
    b[0], b[-1] = 0.0, sig.time.size / sig.fs
    par = np.array([[r["Gq_n0"], r["w"], r["nmin"], r["nmax"]] for r in rows], float)
    return b, par


def prepare(sig: Signals, vehicle, *, seed: int = 0, n_windows: int = 4, road_fit: str = "levels",
            workers: int = 2, executor=None, solver: str | None = None) -> Context:
    """Segments, noise, calibration/held-out windows, nominal road, and the nominal
    simulation of the whole record (road-phase seed ``seed + 1``, noise-free).

    ``road_fit``: ``"levels"`` (default, :func:`fit_road` on the calibration windows) or
    ``"inverse"`` (:func:`inverse_road`, the full inverse fit of the whole record, used
    as it is; the held-out windows then take part in the road fit, which the per-window
    re-levelling of the ranking does anyway).  ``executor``: a process pool the road fit's
    independent simulations are spread over (same results as without).  ``solver``: the
    model's integrator (:attr:`TruckModel.solver`; default :data:`SIM_SOLVER`).
    """
    solver = SIM_SOLVER if solver is None else solver
    t = _time.perf_counter()
    noise = noise_std(sig, list(sig.channels))
    calib, held, edges = windows(sig, n_windows)
    cal_edges = [(float(edges[i]), float(edges[i + 1])) for i in range(n_windows) if i % 2 == 0]
    if road_fit == "inverse":
        bounds, par = inverse_road(sig, vehicle, workers)
        model = TruckModel(vehicle, sig.time, sig.speed, bounds, par[:, 0].copy(), noise,
                           list(sig.channels), ref_axle=segment_axle(list(sig.channels)), w=par[:, 1].copy(),
                           nmin=par[:, 2].copy(), nmax=par[:, 3].copy(), solver=solver)
    elif road_fit == "levels":
        bounds = road_segments(sig)
        model = TruckModel(vehicle, sig.time, sig.speed, bounds, np.full(len(bounds) - 1, GQ_REF),
                           noise, list(sig.channels), ref_axle=segment_axle(list(sig.channels)),
                           solver=solver)
        model.gq, model.w = fit_road(model, sig, cal_edges, seed,
                                     mapper=executor.map if executor is not None else map)
    else:
        raise EroadInputError(f"road_fit must be 'levels' or 'inverse', got {road_fit!r}")
    simc = nominal_record(model, sig, seed)
    segs = [(f"S{k + 1}", float(bounds[k]), float(bounds[k + 1])) for k in range(len(bounds) - 1)]
    return Context(model, calib, held, edges, bounds, cal_edges, simc, segs,
                   _time.perf_counter() - t)


def nominal_record(model: TruckModel, sig: Signals, seed: int = 0) -> dict:
    """The nominal simulation of the whole record on the model's road (road-phase seed
    ``seed + 1``, noise-free), setting the model's lift-off times and its noise floor from the
    residual (the last step of :func:`prepare`, and of a band refit in :func:`diagnose`)."""
    model.lift_times = None         # the run that finds them takes no hint from earlier ones
    simc, model.lift_times = model.run({}, 0.0, sig.time.size / sig.fs, seed + 1, with_lift_times=True)
    model.noise = noise_from_residual(sig, simc)
    return simc


def front_rear_or_none(sig, sim, **kw):
    """:func:`diagnosis.compare.front_rear`, or None where the record has no axle
    acceleration of axles 1 and 3 on one side (a logger on one axle only): the report then
    says the front-to-rear comparison was not made, and the ranking runs without its delay
    term (:func:`delay_term`)."""
    from diagnosis.compare import front_rear

    if not any(f"axle_acc_1{s}" in sig.channels and f"axle_acc_3{s}" in sig.channels for s in "LR"):
        return None
    return front_rear(sig, sim, **kw)


def delay_term(model: TruckModel):
    """The front-to-rear delay term of the gap (:class:`diagnosis.which.DelayTerm`): axle
    accelerations of the front axles (1, 2) against the rear axles (3, 4), both sides, with
    their distances (pairs whose delay does not fit a window are skipped there)."""
    from diagnosis.which import DelayTerm

    vp = model._vp()
    ax = [a.x for a in vp.axles]
    if len(ax) < 2:
        return None
    fronts = [1, 2] if len(ax) >= 4 else [1]
    rears = [len(ax) - 1, len(ax)] if len(ax) >= 4 else [len(ax)]
    pairs = [(f"axle_acc_{a}{s}", f"axle_acc_{b}{s}") for a in fronts for b in rears
             for s in ("L", "R")
             if f"axle_acc_{a}{s}" in model.channels and f"axle_acc_{b}{s}" in model.channels]
    if not pairs:
        return None
    dist = [abs(ax[int(a[9]) - 1] - ax[int(b[9]) - 1]) for a, b in pairs]
    return DelayTerm(pairs, dist)


#: the axle-to-body transmissibility as a third term of the gap (:func:`transmissibility_term`);
#: experimental, off: see docs/diagnosis.md "Left" (payload)
TRANSMISSIBILITY_TERM = False


def transmissibility_term(model: TruckModel):
    """The transmissibility term of the gap (:class:`diagnosis.which.TransmissibilityTerm`):
    every wheel position with an axle and a body acceleration."""
    from diagnosis.which import TransmissibilityTerm

    if not TRANSMISSIBILITY_TERM:
        return None
    pairs = [(c, "body_acc_" + c[len("axle_acc_"):]) for c in model.channels
             if c.startswith("axle_acc_") and "body_acc_" + c[len("axle_acc_"):] in model.channels]
    return TransmissibilityTerm(pairs) if pairs else None


def shape_term(model: TruckModel):
    """The amplitude-distribution term of the gap (:class:`diagnosis.which.ShapeTerm`): the
    skewness of every suspension displacement channel."""
    from diagnosis.which import ShapeTerm

    ch = [c for c in model.channels if c.startswith("susp_disp_")]
    return ShapeTerm(ch) if ch and SHAPE_TERM else None


def stroke_velocity_term(model: TruckModel):
    """The stroke-velocity term of the gap (:class:`diagnosis.which.StrokeVelocityTerm`): the
    skewness of the stroke velocity of every suspension displacement channel."""
    from diagnosis.which import StrokeVelocityTerm

    ch = [c for c in model.channels if c.startswith("susp_disp_")]
    return StrokeVelocityTerm(ch) if ch and STROKE_VELOCITY_TERM else None


#: the static suspension offset as a term of the gap where the dataset declares the
#: displacement zero at the nominal vehicle at rest (:func:`static_term`); on since 2026-11-27
#: (night), docs/diagnosis.md "The static offset"
STATIC_TERM = True


def static_term(model: TruckModel, sig: Signals):
    """The static-offset term of the gap (:class:`diagnosis.which.StaticOffsetTerm`): the mean
    of every suspension displacement channel, only where the measurement declares its zero to
    be the nominal vehicle at rest (``sig.meta["susp_disp_zero"]``); else None (a sensor zeroed
    on the laden truck, or an unknown zero, says nothing about the static load)."""
    from diagnosis.which import StaticOffsetTerm
    from drives.format import ZERO_NOMINAL_STATIC

    if not STATIC_TERM or (sig.meta or {}).get("susp_disp_zero") != ZERO_NOMINAL_STATIC:
        return None
    ch = [c for c in model.channels if c.startswith("susp_disp_")]
    return StaticOffsetTerm(ch) if ch else None


def gap_terms(model: TruckModel, sig: Signals) -> list:
    """The road-independent terms of the gap, fresh instances (each holds its prepared
    statistics): delay, shape, transmissibility, stroke velocity, static offset (None where
    off).  One list for the ranking (:func:`diagnose`, one per fold) and
    :func:`heldout_shrink`, so a term added here reaches both."""
    return [delay_term(model), shape_term(model), transmissibility_term(model),
            stroke_velocity_term(model), static_term(model, sig)]


def heldout_shrink(dataset, effects, *, vehicle=None, seed: int = 0, n_seeds: int = 4,
                   n_windows: int = 4, n_null: int = 12, delay: bool = True) -> dict:
    """Held-out gap of the nominal model and of the model with ``effects`` (given, not
    calibrated), on the seeds ``rank_effects`` uses: the "true shrink" of a blind case
    when ``effects`` is the truth, and whether that model would pass the ranking's paired
    gate.

    Returns
    -------
    dict with ``before``, ``after`` (mean gaps), ``shrink_fraction``, ``improvement``,
    ``null_improvement_mean`` and ``null_improvement_sd`` (the paired null of
    :func:`diagnosis.which.rank_effects` for this model) and ``paired_z`` (improvement less
    the null mean, in null sd).
    """
    from diagnosis.which import _Scorer

    drive, sig = load_measured(dataset)
    ctx = prepare(sig, vehicle if vehicle is not None else drive.vehicle, seed=seed,
                  n_windows=n_windows)
    sc = _Scorer(Fit(ctx.model), Simulate(ctx.model), ctx.calib, ctx.held, seed, 1, n_seeds,
                 None, None)
    terms = gap_terms(ctx.model, sig) if delay else []
    surrogates = _set_terms(sc, terms, n_null)
    sc.set_null(surrogates)
    g0, m0 = sc.heldout_scores({})
    g1, m1 = sc.heldout_scores(effects)
    before = float(np.mean([g.value for g in g0]))
    after = float(np.mean([g.value for g in g1]))
    null = (m0 - m1).mean(axis=0)
    mu, sd = float(np.mean(null)), float(np.std(null, ddof=1))
    imp = before - after
    return {"before": before, "after": after, "shrink_fraction": 1.0 - after / before,
            "improvement": imp, "null_improvement_mean": mu, "null_improvement_sd": sd,
            "paired_z": (imp - mu) / sd if sd > 0 else float("nan")}


def _set_terms(sc, terms, n_null: int) -> list:
    """Give scorer ``sc`` the gap terms (delay, shape; None entries skipped) with the sigma
    and weight ``rank_effects`` would set; returns the ``n_null`` surrogate measurements
    (stream 2)."""
    from diagnosis.gap import band_gap, reference
    from diagnosis.which import nominal_sim_sets, term_weight

    sur = nominal_sim_sets(sc, [("held", 2, i) for i in range(n_null)])
    terms = [t for t in terms if t is not None]
    if not terms:
        return sur
    n = max(sc.n_seeds, n_null)
    nom = nominal_sim_sets(sc, [("held", 1, i) for i in range(n)])
    nb = [band_gap(nom[i], reference(sur[i], sc.ref_held.channels, sc.ref_held.bands)).value
          for i in range(n_null)]
    w = term_weight(nb)
    for t in terms:
        t.weight = w
    sc.add_terms(terms, nom + sur, n)
    return sur


#: surrogate records of the winner (other road phases) that give what a correct
#: model's signature reaches on a drive (:func:`signature_null`); about 1 s of simulation each
SIGNATURE_NULL_N = 4


def signature_null(model: TruckModel, sig: Signals, sim: Signals, records, seeds) -> dict:
    """What the signature of a correct model reaches on this drive.

    ``sim``: the candidate's record on the signature's road phase; ``records``: the same
    model's noise-free channels on other road phases ``seeds`` (same fitted road statistics
    and speed), which become surrogate measurements with their own sensor noise.  Returns the
    mean z^2 of each surrogate against ``sim``, single-input and two-input axle-to-body
    transmissibility (:func:`diagnosis.verdict.transmissibility_chi2`): if the candidate were
    the truck, its signature against the measurement would scatter like this.  About 1 for
    an estimator the road does not enter; the single-input ratio of a four-axle truck is not
    such an estimator (docs/diagnosis.md; :func:`diagnosis.verdict.signature_threshold`).

    Returns
    -------
    dict
        ``{"single_input": [one per record], "two_input": [one per record, or none]}``.
    """
    from diagnosis.compare import transmissibility
    from diagnosis.verdict import transmissibility_chi2

    out = {"single_input": [], "two_input": []}
    for rec, sd in zip(records, seeds):
        surr = Signals(sig.time, model.add_noise(rec, sd), dict(sig.units), sig.speed,
                       {"model": f"road phase {sd}"})
        out["single_input"].append(transmissibility_chi2(transmissibility(surr, sim))[0])
        t2 = two_input_or_none(surr, sim)
        if t2 is not None:
            out["two_input"].append(transmissibility_chi2(t2)[0])
    return out


def two_input_or_none(measured, simulated):
    """:func:`diagnosis.compare.transmissibility_two_input` of two records, or None where no
    station has both axle accelerations and a body acceleration (the signature then falls
    back to the single-input transmissibility, :func:`diagnosis.verdict.chosen_signature`)."""
    from diagnosis.compare import transmissibility_two_input, two_input_stations

    if not two_input_stations(measured, simulated):
        return None
    return transmissibility_two_input(measured, simulated)


def close_rival(ranking):
    """The best accepted rival that comes within noise of the ranking winner's held-out
    gap (:func:`diagnosis.which.close_rivals`: what makes the ranking's confidence
    "ambiguous"), or None."""
    from diagnosis.which import close_rivals

    if ranking.winner is None:
        return None
    return next((e for e in close_rivals(ranking.entries, ranking.winner, ranking.null.std)
                 if e.accepted), None)


def _model_signature(model: TruckModel, sig: Signals, sim: Signals, tr, tr2, ranking, seed: int,
                      executor=None, entry=None):
    """The ranking winner's (or ``entry``'s) signature records (single- and two-input, each
    with what the model reaches against its own records, :func:`signature_null`), the
    seconds taken and the model's noise-free records on the signature's road phases
    (:func:`signature_seeds`; :func:`own_signature_record` reuses them);
    ``(None, None, None, None)`` without a winner.  The records run on ``executor`` when given."""
    from diagnosis.compare import transmissibility
    from diagnosis.verdict import signature

    entry = entry if entry is not None else ranking.winner
    if entry is None:
        return None, None, None, None
    t = _time.perf_counter()
    seeds = signature_seeds(seed)
    runs = _phase_runs(model, entry.effects, sig.time.size / sig.fs, seeds, executor)
    simw = Signals(sig.time, model.add_noise(runs[0], seeds[0]), dict(sig.units), sig.speed,
                   {"model": entry.effect})
    null = signature_null(model, sig, simw, runs[1:], seeds[1:])
    sig_w = signature(entry.effect, tr, transmissibility(sig, simw), null=null["single_input"])
    sig_w2 = None
    tr2w = two_input_or_none(sig, simw) if tr2 is not None else None
    if tr2w is not None:
        sig_w2 = signature(entry.effect, tr2, tr2w, method="two_input", null=null["two_input"])
    return sig_w, sig_w2, _time.perf_counter() - t, runs


def signature_seeds(seed: int) -> list:
    """The road phases the signatures drive: ``seed + 1`` and the ``SIGNATURE_NULL_N`` after it."""
    return [seed + 1] + [seed + 2 + j for j in range(SIGNATURE_NULL_N)]


def _phase_runs(model: TruckModel, effects, T: float, seeds, executor=None) -> list:
    """Noise-free records of ``model`` with ``effects`` over ``[0, T]`` on road phases ``seeds``."""
    if executor is not None:
        return [f.result() for f in [executor.submit(model.run, effects, 0.0, T, sd) for sd in seeds]]
    return [model.run(effects, 0.0, T, sd) for sd in seeds]


def own_signature_stats(model: TruckModel, sig: Signals, runs, seeds, statistic: str) -> list:
    """The own-signature statistic ``statistic`` (a key of
    :data:`diagnosis.compare.OWN_STATISTICS`) of noise-free records ``runs`` made on road
    phases ``seeds``, each with its sensor noise."""
    from diagnosis.compare import OWN_STATISTICS

    fn = OWN_STATISTICS[statistic]
    return [fn(Signals(sig.time, model.add_noise(r, sd), dict(sig.units), sig.speed, {}))
            for r, sd in zip(runs, seeds)]


def _own_side_statistic() -> str:
    """The one own-signature statistic of the effects in :data:`OWN_SIDE_RANGES`."""
    from diagnosis.verdict import OWN_SIGNATURE

    stats_ = {OWN_SIGNATURE[name] for name in OWN_SIDE_RANGES}
    if len(stats_) != 1:
        raise ValueError(f"OWN_SIDE_RANGES mixes own-signature statistics: {sorted(stats_)}")
    return stats_.pop()


def own_side_record(model: TruckModel, sig: Signals, seed: int, executor=None):
    """Before the ranking: the nominal model on the own signature's road phases
    (:func:`signature_seeds`), the statistic of each record and of the measurement, and the
    side (:func:`diagnosis.verdict.own_side`) each effect of :data:`OWN_SIDE_RANGES` is
    searched on.  Returns ``(record, nominal_runs, seconds)``; ``record`` is None (and no run
    made) without :data:`OWN_SIDE` or a suspension displacement channel.  The runs are
    handed on to :func:`own_signature_record` (the same phases), so the step costs nothing
    where a damper wins."""
    from diagnosis.compare import OWN_STATISTICS
    from diagnosis.verdict import own_side

    stat = _own_side_statistic()
    m = OWN_STATISTICS[stat](sig)
    if not OWN_SIDE or m is None:
        return None, None, None
    t = _time.perf_counter()
    T = sig.time.size / sig.fs
    seeds = signature_seeds(seed)
    runs = _phase_runs(model, {}, T, seeds, executor)
    nominal = own_signature_stats(model, sig, runs, seeds, stat)
    side = own_side(m, nominal, statistic=stat)
    rec = {"statistic": stat, "measured": float(m),
           "nominal": [float(v) if v is not None else None for v in nominal],
           "sides": {name: side for name in OWN_SIDE_RANGES},
           "ranges": {name: (list(r[1]) if side > 0 else list(r[2])) if side else None
                      for name, r in OWN_SIDE_RANGES.items()}}
    return rec, runs, _time.perf_counter() - t


def own_signature_record(model: TruckModel, sig: Signals, entry, seed: int, executor=None,
                         model_runs=None, nominal_runs=None):
    """The ``signature_own`` record of a winner whose effect has a signature of its own
    (:data:`diagnosis.verdict.OWN_SIGNATURE`), and the seconds taken; ``(None, None)`` for
    any other effect.  The nominal model and the calibrated candidate each drive the road
    phases of the transmissibility signature (:func:`signature_seeds`: the same roads for
    both, so the comparison is paired), with sensor noise, and the statistic
    (``OWN_SIGNATURE[effect]``, :data:`diagnosis.compare.OWN_STATISTICS`) is taken of every
    record and of the measurement.  ``model_runs``: the candidate's records on those phases where already made
    (:func:`_model_signature` returns them), else they are run here; ``nominal_runs`` the
    nominal model's (:func:`own_side_record`), likewise."""
    from diagnosis.compare import OWN_STATISTICS
    from diagnosis.verdict import OWN_SIGNATURE, own_signature

    if entry is None or entry.effect not in OWN_SIGNATURE:
        return None, None
    stat = OWN_SIGNATURE[entry.effect]
    t = _time.perf_counter()
    T = sig.time.size / sig.fs
    seeds = signature_seeds(seed)
    if model_runs is None:
        model_runs = _phase_runs(model, entry.effects, T, seeds, executor)
    if nominal_runs is None:
        nominal_runs = _phase_runs(model, {}, T, seeds, executor)
    rec = own_signature(entry.effect, OWN_STATISTICS[stat](sig),
                        own_signature_stats(model, sig, nominal_runs, seeds, stat),
                        own_signature_stats(model, sig, model_runs, seeds, stat))
    return rec, _time.perf_counter() - t


#: refit the road's high band with the ranking's first effect in the truck (see
#: :func:`diagnose`, ``settings["band_refit"]``).  Off: it failed its stated test on a fresh
#: independent-truck set (right names 9/9 -> 8/9; the effect calibrated on the wrong band is too
#: weak to show the cut), ``results/diagnosis_blind/20261129-band-refit/``; kept for that folder's
#: command and as the record of what was tried.
BAND_REFIT = False
#: the road's band chosen jointly with the effect (``diagnose(settings={"joint_band": ...})``):
#: where the measured axle spectrum steps down at a spatial frequency (``diagnosis.band_edge``)
#: and the first pass found a gap, the whole pass is made again on a road cut there, and the
#: pass whose best model (nominal or ranked) reaches the lower held-out gap is reported; the cut
#: must win by ``JOINT_BAND_MARGIN`` (its gap below that fraction of the fitted band's).  Stop 56
#: read 0.36-0.60 (and 0.45, 0.82 fresh) on measured-profile friction drives, 1.21-31 on
#: full-band drives and one tie (1.00): results/diagnosis_blind/20261129-band-refit/.  On by
#: default since stop 57: the test stated before its fresh set (20261129-joint-band/decision.txt)
#: passed, independent truck 7/9 -> 9/9 library effects named (values within x1.5 7/7 -> 9/9),
#: our truck unchanged (16/16, 6/6, values 16/16), no wrong name; cost: 8 of 40 diagnoses over
#: 120 s against 2, max 207 s
JOINT_BAND = True
JOINT_BAND_MARGIN = 0.9
#: the integrator of the diagnosis's runs (``diagnose(settings={"solver": ...})``,
#: :attr:`TruckModel.solver`): ``"linear"`` integrates every run whose model is linear (the
#: nominal truck, and candidates that change only the road, speed, sensors, masses or frame)
#: on Exudyn's linearisation with Exudyn's own scheme (:mod:`vehicles.linear_sim`); nonlinear
#: effects stay in Exudyn.  Adopted at stop 58: on 14 drives of stop 57's fresh set (both
#: trucks, 10 effects and none, lift-off, the cut band) the same verdict and confidence on every
#: drive, the first-ranked model's value within 0.01 %, time 0.7-1.6x
#: (results/diagnosis_blind/20261129-linear-solver/); on the next fresh set the six drives with
#: a wrong or missing verdict gave the same verdicts with Exudyn (a test stated before those
#: runs, results/diagnosis_blind/20261129-linear-fresh-40/ab_exudyn.txt)
SIM_SOLVER = "linear"


def best_heldout_gap(ranking) -> float:
    """The lowest held-out gap a pass reaches: the nominal model's or any ranked model's (mean
    over seeds, as ``summary.json`` reports them)."""
    gaps = [float(np.mean(ranking.before))] + [float(np.mean(e.after)) for e in ranking.entries]
    return float(min(gaps))


def _report_args(ps: dict) -> dict:
    """The keyword arguments of diagnosis.report.build_summary / write_report from one pass."""
    return dict(localization=ps["loc"], transmissibility=ps["tr"], front_rear=ps["fr"], shape=ps["sh"],
                ranking=ps["ranking"], signature=ps["sig_w"], transmissibility_two_input=ps["tr2"],
                signature_two_input=ps["sig_w2"], signature_rival=ps["sig_r"],
                signature_own=ps["sig_own"])


def diagnose(dataset, out, *, vehicle=None, effects=None, workers: int = 2, quick: bool = False,
             force: bool = False, seed: int = 0, n_windows: int = 4, settings=None,
             road_fit: str = "levels", progress=_say) -> dict:
    """Diagnose a measured dataset against the nominal truck and write the report.

    Parameters
    ----------
    dataset : str or Path
        Dataset folder (measurement format); ``truth/`` is not read.
    out : str or Path
        Run folder (refused if it exists and is not empty, unless ``force``).
    vehicle : str or Path, optional
        Nominal vehicle (built-in id or TOML); default the dataset's vehicle.
    effects : sequence of str, optional
        Candidate effects (default: the whole library; ``quick``: ``QUICK_EFFECTS``).
    workers : int
        Processes for the candidate calibrations.
    quick : bool
        CI smoke settings: 4 candidates, 3 held-out seeds, 6 null pairs, a 3 + 3
        search, no pairs.
    force : bool
        Replace an existing report.
    seed : int
        Root seed of all road phases.
    n_windows : int
        Alternating windows (odd calibrate, even held out).
    road_fit : {"levels", "inverse"}
        The cheap road fit (default) or the full inverse fit of the whole record
        (``inverse.pipeline.invert`` on the Exudyn truck; segments, Gq, w, nmin, nmax).
    settings : dict, optional
        Overrides of the ``rank_effects`` budget.  ``folds``: 2 (default; 1 with ``quick``)
        runs the ranking twice with the calibration and held-out windows swapped and
        combines the two (:func:`diagnosis.which.combine_folds`; twice the time, no pairs);
        1 ranks once and tries pairs.  Budget keys: ``n_seeds``, ``n_null``, ``grid``,
        ``refine``, ``pairs``, ``n_pair_candidates``.  ``band_refit`` (default
        :data:`BAND_REFIT`): after the ranking, the road's high band is refitted with the
        ranking's first effect in the truck (:func:`refit_band`); where it moves, the pass is
        made again on the new band and ``summary["meta"]["band_refit"]`` keeps the first
        pass's verdict.  ``joint_band`` (default :data:`JOINT_BAND`): where a gap is present and
        the measured axle spectrum steps down at a spatial frequency below the fitted band's top
        (:func:`diagnosis.band_edge.trial_cut`), the pass is made again on a road cut there and
        the pass whose best model reaches the lower held-out gap (the cut by
        :data:`JOINT_BAND_MARGIN`) is reported; ``summary["meta"]["joint_band"]`` keeps the
        other pass's verdict and ranking.

    Returns
    -------
    dict
        The summary written to ``out/summary.json``.
    """
    from diagnosis.band_edge import trial_cut
    from diagnosis.compare import distribution_shape, transmissibility
    from diagnosis.report import build_summary, write_report
    from diagnosis.verdict import SIGNATURE_METHOD, own_statistic, search_ranges
    from diagnosis.which import combine_folds, rank_effects, rank_effects_folds
    from diagnosis.where import localize
    from eroad.threads import process_pool
    from vehicles.params import load_vehicle
    from vehicles.simulate import SOLVERS

    wall0 = _time.perf_counter()
    record = run_info("diagnose", seed=seed, extra={"quick": bool(quick), "workers": int(workers)})
    out = Path(out)
    if out.exists() and any(out.iterdir()) and not force:
        raise EroadInputError(f"{out}: exists and is not empty (use --force to replace it)")
    drive, sig = load_measured(dataset)
    veh = vehicle if vehicle is not None else drive.vehicle
    vp = load_vehicle(veh)
    timing = {}
    calib = held = None

    progress(f"dataset {drive.name}: {sig.duration:.1f} s, {len(sig.channels)} channels, "
             f"vehicle {vp.id}" + (f"; resampled from {sig.meta['resampled_from_hz']:g} to {sig.fs:g} Hz"
                                   if "resampled_from_hz" in sig.meta else ""))
    settings = dict(settings or {})
    band_refit = bool(settings.pop("band_refit", BAND_REFIT))
    joint_band = bool(settings.pop("joint_band", JOINT_BAND))
    solver = str(settings.pop("solver", SIM_SOLVER))
    from diagnosis.which import FOLD_EDGE_CHOICE
    edge_choice = bool(settings.pop("fold_edge_choice", FOLD_EDGE_CHOICE))
    if solver not in SOLVERS:       # the integrators vehicles.simulate offers
        raise EroadInputError(f"solver must be {' or '.join(map(repr, SOLVERS))}, got {solver!r}")
    # one pool for the road fit, the ranking and the signatures; shut down however it ends
    ex = process_pool(workers) if workers and workers > 1 else None
    T = sig.time.size / sig.fs      # record length [s]

    def one_pass(model, simc):
        """Localisation, ranking and signatures on the model's road (one pass)."""
        # where: nominal over the whole record
        t = _time.perf_counter()
        sim = Signals(sig.time, model.add_noise(simc, seed + 1), dict(sig.units), sig.speed,
                      {"model": "nominal"})
        loc = localize(sig, sim, segments=segs)
        wheelbase = float(vp.axles[0].x - vp.axles[2].x) if len(vp.axles) >= 3 else None
        tr = transmissibility(sig, sim)
        tr2 = two_input_or_none(sig, sim)
        fr = front_rear_or_none(sig, sim, wheelbase=wheelbase)
        sh = distribution_shape(sig, sim)
        timing["localization_s"] = _time.perf_counter() - t

        # which
        t = _time.perf_counter()
        names = list(effects) if effects else (list(QUICK_EFFECTS) if quick else None)
        kw = dict(QUICK_BUDGET) if quick else dict(BUDGET)
        kw.update(settings or {})
        folds = int(kw.pop("folds", 1))
        if folds not in (1, 2):
            raise EroadInputError(f"folds must be 1 or 2, got {folds}")
        # pairs are calibrated per fold and not combined: one fold tries them by default
        kw["pairs"] = bool(kw.get("pairs", True)) and folds == 1
        fit, simulate = Fit(model), Simulate(model)
        # the side of 1 a damper asymmetry is searched on, from its own signature (OWN_SIDE)
        wants_side = any(n in OWN_SIDE_RANGES for n in (names or OWN_SIDE_RANGES))
        side_rec, nominal_own_runs, t_side = (own_side_record(model, sig, seed, ex) if wants_side
                                              else (None, None, None))
        if t_side is not None:
            timing["own_side_s"] = t_side
        cands = candidates(names, veh, sides=(side_rec or {}).get("sides"))
        for name, rng in ((side_rec or {}).get("ranges") or {}).items():
            if rng is not None and any(c.name == name for c in cands):
                progress(f"{name}: searched over {rng[0]:g}-{rng[1]:g} (the measured "
                         f"{own_statistic(side_rec['statistic']).name} "
                         f"{side_rec['measured']:+.3f} against the nominal model's "
                         f"{np.mean([v for v in side_rec['nominal'] if v is not None]):+.3f})")
        progress(f"ranking {len(cands)} candidate effect(s) on {len(calib)} calibration + "
                 f"{len(held)} held-out windows ({workers} worker(s)"
                 + (", two folds: then the roles swapped)" if folds == 2 else ")"))
        splits = [(calib, held, seed)] + ([(held, calib, seed + 1)] if folds == 2 else [])

        def terms():
            d_term, s_term, *extra = gap_terms(model, sig)
            return dict(delay=d_term, shape=s_term, extra_terms=extra)

        if folds == 1:
            ranking = rank_effects(cands, fit, simulate, calib, held, seed=seed, executor=ex,
                                   progress=progress, task_order=TASK_ORDER, **terms(), **kw)
        else:
            # both folds' calibrations in one batch (no worker idle at the end of a fold)
            ranking = combine_folds(rank_effects_folds(cands, fit, simulate, splits, executor=ex,
                                                       terms=terms, progress=progress,
                                                       task_order=TASK_ORDER, **kw),
                                    candidates=cands, edge_choice=edge_choice)
        timing["ranking_s"] = _time.perf_counter() - t
        # the winner's signature: its axle-to-body transmissibility on the
        # nominal model's road and seed, against the measurement (diagnosis.verdict); both the
        # single-input ratio (``signature``) and the two-input estimate (``signature_two_input``,
        # where both sides are measured), each with what the winner reaches against itself;
        # the verdict uses diagnosis.verdict.SIGNATURE_METHOD
        sig_w, sig_w2, t_sig, runs_w = _model_signature(model, sig, sim, tr, tr2, ranking, seed, ex)
        if t_sig is not None:
            timing["signature_s"] = t_sig
        # an effect the transmissibility cannot test (damper asymmetry): its own signature
        sig_own, t_own = own_signature_record(model, sig, ranking.winner, seed, ex, model_runs=runs_w,
                                              nominal_runs=nominal_own_runs)
        if t_own is not None:
            timing["signature_own_s"] = t_own
        # a rival within noise of the winner's gap: its signature too, so the verdict can
        # break the tie on the transmissibility (diagnosis.verdict.decide, tie_break)
        rival = close_rival(ranking)
        sig_r = None
        if rival is not None:
            r1, r2, t_r, _ = _model_signature(model, sig, sim, tr, tr2, ranking, seed, ex,
                                            entry=rival)
            sig_r = {"effect": rival.effect, "single_input": r1, "two_input": r2}
            timing["signature_rival_s"] = t_r
        return dict(loc=loc, tr=tr, tr2=tr2, fr=fr, sh=sh, ranking=ranking, sig_w=sig_w,
                    sig_w2=sig_w2, sig_r=sig_r, sig_own=sig_own, cands=cands, side_rec=side_rec,
                    kw=kw, folds=folds, wheelbase=wheelbase)

    def make_meta(model, ps, band_refit_record, joint_record=None):
        cands, side_rec, kw, folds = ps['cands'], ps['side_rec'], ps['kw'], ps['folds']
        wheelbase = ps['wheelbase']
        meta = {
            "dataset": os.path.relpath(Path(dataset).resolve(), out.resolve()),
            "dataset_name": drive.name, "vehicle": str(vp.id),
            # record time of the first sample: every *_s window and segment time in this summary
            # counts from that sample; the report adds this to show record times (as Table 1)
            "record_t0_s": float(np.asarray(drive.time, float)[0]),
            "duration_s": float(T), "channels": list(sig.channels),
            "sample_rate_hz": float(sig.fs), "resampled_from_hz": sig.meta.get("resampled_from_hz"),
            "road_segments": [{"segment": s[0], "t_start_s": s[1], "t_end_s": s[2],
                               "Gq_n0_m3": float(model.gq[k]), "w": float(model.w[k]),
                               "nmin": float(ROAD_NMIN if model.nmin is None else model.nmin[k]),
                               "nmax": float(model_nmax(model)[k])}
                              for k, s in enumerate(segs)],
            "road_w_range": list(W_RANGE) if road_fit == "levels" else None,
            "road_high_band": (None if model.high_band is None else
                               {"cut": [segs[k][0] for k in model.high_band["cut"]],
                                "rolloff": [segs[k][0] for k in model.high_band["rolloff"]],
                                "vetoed": model.high_band["vetoed"]}),
            "road_fit": ("segment level and waviness from the nominal model on the calibration "
                         "windows" if road_fit == "levels" else
                         "inverse.pipeline.invert on the whole record (nominal truck)")
            + "; level re-profiled per segment piece for every model and window",
            "split": f"{n_windows} equal time windows; odd windows calibrate, even windows held out"
            + ("; then the other way round (two folds, combined)" if folds == 2 else ""),
            "calibration_windows_s": [list(map(float, e)) for e in cal_edges],
            "heldout_windows_s": [[float(edges[i]), float(edges[i + 1])] for i in range(n_windows)
                                  if i % 2 == 1],
            "noise_std": model.noise, "wheelbase_m": wheelbase, "quick": bool(quick), "seed": int(seed),
            "workers": int(workers), "solver": model.solver, "fold_edge_choice": edge_choice,
            "candidates": [c.name for c in cands],
            "search_ranges": search_ranges(cands),
            "own_side": side_rec,
            "signature_method": SIGNATURE_METHOD,
            "ranking_settings": {**{k: v for k, v in kw.items()}, "folds": folds},
            "timing": {k: round(v, 2) for k, v in timing.items()},
            "band_refit": band_refit_record,
            "joint_band": joint_record,
        }
        return meta

    def pass_record(ps, refit_record):
        """Verdict, confidence, reason and ranking of a pass not reported (kept in the meta)."""
        s = build_summary(**_report_args(ps), meta=make_meta(model, ps, refit_record))
        return {k: s.get(k) for k in ('verdict', 'verdict_confidence', 'verdict_reason', 'ranking')}

    def road_on_band(nmax, high_band):
        """The model's road on another band: nmax set, levels refitted, the nominal record run
        again (lift-off times and noise floor with it); returns that record."""
        model.nmax, model.high_band = nmax, high_band
        model.gq = relevel_road(model, sig, cal_edges, model.gq, seed)
        return nominal_record(model, sig, seed)

    try:
        ctx = prepare(sig, veh, seed=seed, n_windows=n_windows, road_fit=road_fit, workers=workers,
                      executor=ex, solver=solver)
        model, calib, held, edges, bounds = ctx.model, ctx.calib, ctx.held, ctx.edges, ctx.bounds
        cal_edges, simc, segs = ctx.cal_edges, ctx.sim_nominal, ctx.segs
        timing["road_fit_s"] = ctx.road_fit_s
        progress(f"road: {len(bounds) - 1} segment(s), Gq(n0) = "
                 + ", ".join(f"{g * 1e6:.3g}" for g in model.gq) + " x 1e-6 m^3, w = "
                 + ", ".join(f"{x:.2f}" for x in model.w)
                 + "".join(f", {lab} = " + ", ".join(f"{x:g}" for x in v)
                           for lab, v in (("nmin", model.nmin), ("nmax", model.nmax)) if v is not None)
                 + " (calibration windows)")

        ps = one_pass(model, simc)
        refit = joint = None
        if band_refit and ps['ranking'].gap_present and ps['ranking'].entries:
            # the road's high band refitted with the closest effect in the truck (refit_band);
            # where it moves, the whole pass is made again on the new band and the first
            # pass's verdict is kept in the record
            t = _time.perf_counter()
            first_pass_s = t - wall0        # what the diagnosis took without the refit
            top = ps['ranking'].entries[0]
            nmax_before = model_nmax(model)
            new, high_band, changed = refit_band(model, sig, top.effects, seed,
                                                 mapper=ex.map if ex is not None else map)
            refit = {'effect': top.effect, 'parameters': top.effects,
                     'nmax_before': [float(x) for x in nmax_before],
                     'nmax_after': [float(x) for x in new], 'changed': changed,
                     'first_pass_s': round(first_pass_s, 2)}
            if changed:
                refit['first_pass'] = pass_record(ps, None)
                refit['first_pass']['Gq_n0_m3'] = [float(g) for g in model.gq]
                simc = road_on_band(new, high_band)
                progress(f"road band refitted with {top.effect} in the truck: nmax = "
                         + ', '.join(f'{x:g}' for x in new) + f" (was "
                         + ', '.join(f'{x:g}' for x in nmax_before) + '); the ranking again on it')
                refit['first_pass']['timing'] = {k: round(v, 2) for k, v in timing.items()}
                ps = one_pass(model, simc)
            refit['time_s'] = round(_time.perf_counter() - t, 2)
            timing['band_refit_s'] = refit['time_s']
        if joint_band and ps['ranking'].gap_present:
            # the band chosen with the effect: a cut where the measured spectrum steps down in
            # spatial frequency (diagnosis.band_edge), the whole pass made on it, the pass whose
            # best model reaches the lower held-out gap kept (JOINT_BAND_MARGIN)
            t = _time.perf_counter()
            tc = trial_cut(sig, NMAX_GRID, ROAD_NMAX)
            before = model_nmax(model)
            joint = {'step': {f'{g:g}': v for g, v in tc['step'].items()}, 'trial_cut': tc['cut'],
                     'threshold': tc['threshold'], 'windows': tc['windows'],
                     'nmax_before': [float(x) for x in before], 'margin': JOINT_BAND_MARGIN,
                     'first_pass_s': round(t - wall0, 2), 'chosen': 'fitted'}
            if tc['cut'] is not None and np.any(before > tc['cut']):
                first = pass_record(ps, refit)
                # the fitted band's state, put back if its pass is the one reported
                kept = dict(nmax=model.nmax, high_band=model.high_band, gq=model.gq,
                            lift_times=model.lift_times, noise=model.noise)
                kept_simc, kept_timing = simc, dict(timing)
                new = np.minimum(before, tc['cut'])
                simc = road_on_band(new, {"cut": [int(k) for k in np.nonzero(new < ROAD_NMAX)[0]],
                                          "rolloff": [], "vetoed": False})
                progress(f"measured axle spectrum steps down at {tc['cut']:g} cycles/m: the pass "
                         f"again on a road cut there")
                ps_cut = one_pass(model, simc)
                g_fit, g_cut = best_heldout_gap(ps['ranking']), best_heldout_gap(ps_cut['ranking'])
                joint.update(nmax_after=[float(x) for x in new], gap_fitted=round(g_fit, 4),
                             gap_cut=round(g_cut, 4))
                if g_cut < JOINT_BAND_MARGIN * g_fit:
                    joint['chosen'] = 'cut'
                    joint['first_pass'] = first
                    joint['first_pass']['Gq_n0_m3'] = [float(g) for g in kept['gq']]
                    joint['first_pass']['timing'] = {k: round(v, 2) for k, v in kept_timing.items()}
                    ps = ps_cut
                else:
                    joint['cut_pass'] = pass_record(ps_cut, refit)
                    for name, value in kept.items():
                        setattr(model, name, value)
                    simc = kept_simc
                    timing.clear()
                    timing.update(kept_timing)
                progress(f"band: held-out gap {g_fit:.3g} on the fitted band, {g_cut:.3g} on the cut "
                         f"(margin {JOINT_BAND_MARGIN:g}): the {joint['chosen']} band's pass reported")
            joint['time_s'] = round(_time.perf_counter() - t, 2)
            timing['joint_band_s'] = joint['time_s']
    finally:
        if ex is not None:
            ex.shutdown()
    timing["total_s"] = _time.perf_counter() - wall0

    meta = make_meta(model, ps, refit, joint)
    write_report(out, **_report_args(ps), meta=meta, force=force)
    write_run_json(out, finish_run_info(record, "complete", wall_s=_time.perf_counter() - wall0))
    summary = json.loads((out / "summary.json").read_text())
    progress(f"verdict: {summary['verdict']} ({summary['verdict_confidence']}); "
             f"{summary['verdict_reason']}")
    progress(f"wrote {out} in {timing['total_s']:.0f} s")
    return summary


def diagnose_dataset(path, out, quick: bool = False, workers: int = 2) -> dict:
    """Entry point for ``eroad reproduce``: :func:`diagnose` with defaults, replacing ``out``.

    Returns
    -------
    dict
        The summary (``summary.json``).
    """
    return diagnose(path, out, quick=quick, workers=workers, force=True)
