"""Diagnosis of a measured drive against the Exudyn truck: the wiring behind ``eroad diagnose``.

What it is for: read a dataset (never its ``truth/``), identify the road per segment
with the nominal model on calibration data, localise the gap, run the road-independent
comparisons, rank the effects of :data:`vehicles.effects.EFFECTS` and write the report.
What it is not: the statistics (``diagnosis.where``, ``compare``, ``which``, ``gap``)
or the vehicle model (``vehicles.simulate``).

Its parts, one module each: :mod:`diagnosis.truck_model` (the truck driven like the record and the
callables the ranking calls), :mod:`diagnosis.nuisance` (what every model is matched on per
window: the road's level and waviness, the sensor-noise floor), :mod:`diagnosis.road_fit` (the
road per segment: level, waviness, band).  This module reads the dataset, splits it into
calibration and held-out windows, builds the candidates and the comparison terms and runs it all.

Calibration / held-out split (decision): the record is cut into ``n_windows``
(default 4) equal time windows; windows 1 and 3 (odd, counted from 1) calibrate,
windows 2 and 4 are held out.  Alternating windows put every long road segment into
both sets.  Each window is simulated on its own (2 s run-in at the window's starting
speed, discarded).  Road segments shorter than ``LOCAL_FEATURE_MAX_S`` (local road features
no random-road model represents) are cut out of the windows (stop 65).
"""
from __future__ import annotations

import json
import os
import time as _time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from diagnosis.nuisance import W_FIT_BAND, noise_from_residual, noise_std
from diagnosis.road_fit import (GQ_REF, NMAX_GRID, W_RANGE, fit_road, model_nmax, refit_band,
                                relevel_road, road_segments, segment_axle)
from diagnosis.signals import Signals
from diagnosis.truck_model import ROAD_NMAX, ROAD_NMIN, Fit, Simulate, TruckModel
from eroad.archive import finish_run_info, run_info, write_run_json
from eroad.errors import EroadInputError


#: measured channel prefixes used
QUANTITIES = ("susp_disp_", "axle_acc_", "body_acc_")
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


#: a road segment shorter than one period of the lowest band the waviness regression uses
#: (``1 / W_FIT_BAND[0]``, 1 s) cannot hold a road spectrum: the segmentation cuts such a piece
#: around a local road feature (a joint, a patch, a step), which no random-road model
#: represents.  Stop 65: on our own truck over the measured profile every drive held one (0.5 s
#: around a 5 m stretch six times rougher than the road about it); simulated as a random road at
#: its level it put 40-270 times the measured power into the 22-56 Hz axle bands, which a sensor
#: low-pass then "explained" on 5 of 8 drives without any vehicle difference.  Such segments are
#: left out of the calibration and held-out windows (the road is still simulated under them)
LOCAL_FEATURE_MAX_S = 1.0 / W_FIT_BAND[0]
#: shortest piece of a window kept once local features are cut out of it [s] (a shorter piece
#: holds no band below about 4 Hz with the three Welch averages the band powers ask for)
MIN_WINDOW_PIECE_S = 2.0
#: leave local road features out of the windows (``LOCAL_FEATURE_MAX_S``)
EXCLUDE_LOCAL = True


def local_features(bounds) -> list:
    """Road segments shorter than :data:`LOCAL_FEATURE_MAX_S`: ``[(t_start, t_end), ...]`` [s]."""
    b = np.asarray(bounds, float)
    return [(float(b[k]), float(b[k + 1])) for k in range(len(b) - 1)
            if b[k + 1] - b[k] < LOCAL_FEATURE_MAX_S]


def window_pieces(a: float, b: float, exclude=()) -> list:
    """Window ``[a, b)`` [s] less the intervals ``exclude``: the pieces of at least
    :data:`MIN_WINDOW_PIECE_S` that are left, ``[(start, end), ...]``."""
    pieces = [(a, b)]
    for x0, x1 in sorted(exclude):
        nxt = []
        for p0, p1 in pieces:
            if x1 <= p0 or x0 >= p1:
                nxt.append((p0, p1))
                continue
            if x0 > p0:
                nxt.append((p0, x0))
            if x1 < p1:
                nxt.append((x1, p1))
        pieces = nxt
    return [(float(p0), float(p1)) for p0, p1 in pieces if p1 - p0 >= MIN_WINDOW_PIECE_S - 1e-9]


def windows(sig: Signals, n_windows: int = 4, exclude=()):
    """Alternating calibration / held-out windows.

    The record is cut into ``n_windows`` equal windows; odd ones (counted from 1) calibrate,
    even ones are held out.  ``exclude``: intervals [s] left out (local road features,
    :func:`local_features`); a window they cut becomes its pieces (:func:`window_pieces`).

    Returns
    -------
    (calib, held, edges, cal_edges, held_edges): lists of Signals (meta ``t0``, ``window``),
    the equal windows' edges [s], and the ``(start, end)`` [s] of every calibration and
    held-out piece
    """
    fs, N = sig.fs, sig.time.size
    T = N / fs
    # every edge on a sample: the simulation of a window starts at round(t0 * fs) and the
    # measured window at the first sample at or after t0; an edge between samples (a record
    # of 8001 samples cut in four) made them differ by one sample and stopped the ranking
    edges = np.round(np.linspace(0.0, N, n_windows + 1)) / fs
    cal, held, cal_edges, held_edges = [], [], [], []
    for i in range(n_windows):
        for a, b in window_pieces(float(edges[i]), float(edges[i + 1]), exclude):
            a, b = round(a * fs) / fs, round(b * fs) / fs
            w = sig.window(a, b)
            w = Signals(w.time, w.channels, w.units, w.speed, {**sig.meta, "t0": a, "window": i + 1})
            (cal if i % 2 == 0 else held).append(w)
            (cal_edges if i % 2 == 0 else held_edges).append((a, b))
    if not cal or not held:
        raise EroadInputError(
            f"diagnosis: the record ({T:.1f} s) leaves no calibration or no held-out window of "
            f"{MIN_WINDOW_PIECE_S:g} s once its local road features ("
            + ", ".join(f"{a:.1f}-{b:.1f} s" for a, b in exclude) + ") are left out")
    return cal, held, edges, cal_edges, held_edges


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
    held_edges: list = field(default_factory=list)
    #: local road features left out of the windows (``[(t_start, t_end), ...]`` [s])
    excluded: list = field(default_factory=list)


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

    ``road_fit``: ``"levels"`` (default, :func:`diagnosis.road_fit.fit_road` on the calibration
    windows) or ``"inverse"`` (:func:`inverse_road`, the full inverse fit of the whole record, used
    as it is; the held-out windows then take part in the road fit, which the per-window
    re-levelling of the ranking does anyway).  ``executor``: a process pool the road fit's
    independent simulations are spread over (same results as without).  ``solver``: the
    model's integrator (:attr:`TruckModel.solver`; default :data:`SIM_SOLVER`).
    """
    solver = SIM_SOLVER if solver is None else solver
    t = _time.perf_counter()
    noise = noise_std(sig, list(sig.channels))
    if road_fit == "inverse":
        bounds, par = inverse_road(sig, vehicle, workers)
        excluded = local_features(bounds) if EXCLUDE_LOCAL else []
        calib, held, edges, cal_edges, held_edges = windows(sig, n_windows, excluded)
        model = TruckModel(vehicle, sig.time, sig.speed, bounds, par[:, 0].copy(), noise,
                           list(sig.channels), ref_axle=segment_axle(list(sig.channels)), w=par[:, 1].copy(),
                           nmin=par[:, 2].copy(), nmax=par[:, 3].copy(), solver=solver)
    elif road_fit == "levels":
        bounds = road_segments(sig)
        excluded = local_features(bounds) if EXCLUDE_LOCAL else []
        calib, held, edges, cal_edges, held_edges = windows(sig, n_windows, excluded)
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
                   _time.perf_counter() - t, held_edges, excluded)


def nominal_record(model: TruckModel, sig: Signals, seed: int = 0) -> dict:
    """The nominal simulation of the whole record on the model's road (road-phase seed
    ``seed + 1``, noise-free), setting the model's lift-off times and its noise floor from the
    residual (the last step of :func:`prepare`, and of a band refit in :func:`diagnose`)."""
    model.lift_times = None         # the run that finds them takes no hint from earlier ones
    simc, model.lift_times = model.run({}, 0.0, sig.time.size / sig.fs, seed + 1, with_lift_times=True)
    model.noise = noise_from_residual(sig, simc)
    return simc


def set_road_band(model: TruckModel, sig: Signals, cal_edges, nmax, seed: int = 0,
                  high_band=None) -> dict:
    """The model's road on another band: ``nmax`` [cycles/m] per segment set (``high_band``
    default: the segments below ``ROAD_NMAX`` recorded as cut), the levels refitted on the
    calibration windows, the nominal record run again (lift-off times and noise floor with it);
    returns that record.  What the band refit and the joint band of :func:`diagnose` do, and the
    oracle of :func:`heldout_shrink` on the band a diagnosis reported."""
    model.nmax = nmax
    model.high_band = high_band if high_band is not None else {
        "cut": [int(k) for k in np.nonzero(np.asarray(nmax) < ROAD_NMAX)[0]],
        "rolloff": [], "vetoed": False}
    model.gq = relevel_road(model, sig, cal_edges, model.gq, seed)
    return nominal_record(model, sig, seed)


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
                   n_windows: int = 4, n_null: int = 12, delay: bool = True, nmax=None) -> dict:
    """Held-out gap of the nominal model and of the model with ``effects`` (given, not
    calibrated), on the seeds ``rank_effects`` uses: the "true shrink" of a blind case
    when ``effects`` is the truth, and whether that model would pass the ranking's paired
    gate.

    ``nmax``: the road's top spatial frequency per segment [cycles/m] the diagnosis ended
    with, where its band refit or joint band moved it (``meta.joint_band.nmax_after`` when the
    cut was chosen); the levels are then refitted on it as :func:`diagnose` does.  Default: the
    band :func:`prepare` fits (before stop 65 always this, so on a drive whose reported pass ran
    on a cut road the true shrink was measured on another road than the verdict's).

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
    if nmax is not None:
        set_road_band(ctx.model, sig, ctx.cal_edges, np.asarray(nmax, float), seed)
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


def transmissibility_or_none(measured, simulated):
    """:func:`diagnosis.compare.transmissibility` of two records, or None where no wheel
    station has both an axle and a body acceleration (a logger without body accelerometers):
    the drive is diagnosed without the transmissibility signature, and the verdict names an
    effect only where its rules for an unconfirmed signature allow
    (:func:`diagnosis.verdict.decide_one`)."""
    from diagnosis.compare import axle_body_pairs, transmissibility

    if not axle_body_pairs(measured, simulated):
        return None
    return transmissibility(measured, simulated)


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
    if tr is None:     # no axle and body acceleration at one station: no transmissibility
        return None, None, _time.perf_counter() - t, runs
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


def hz_signature_record(model: TruckModel, sig: Signals, entries, seed: int, executor=None,
                        nominal_runs=None):
    """The ``signature_hz`` record (:func:`diagnosis.hz_fixed.hz_record`) of the low-pass
    entries among ``entries`` (``(ranking entry or None, its noise-free records on the
    signature's road phases or None)``: the winner and the close rival), and the seconds
    taken; ``(None, None)`` where none is a low-pass.  The nominal model's records on the same
    phases are ``nominal_runs`` where :func:`own_side_record` made them, else run here; every
    record gets its sensor noise as the transmissibility signature's do."""
    from diagnosis.hz_fixed import EFFECTS, hz_record

    todo = {e.effect: (e, r) for e, r in entries if e is not None and e.effect in EFFECTS}
    if not todo:
        return None, None
    t = _time.perf_counter()
    T = sig.time.size / sig.fs
    seeds = signature_seeds(seed)
    if nominal_runs is None:
        nominal_runs = _phase_runs(model, {}, T, seeds, executor)

    def noisy(runs):
        return [model.add_noise(r, sd) for r, sd in zip(runs, seeds)]

    models = {name: noisy(runs if runs is not None else _phase_runs(model, e.effects, T, seeds, executor))
              for name, (e, runs) in todo.items()}
    rec = hz_record(sig.channels, noisy(nominal_runs), models, sig.fs, sig.speed, model.bounds)
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
                signature_own=ps["sig_own"], signature_hz=ps.get("sig_hz"))


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
        ranking's first effect in the truck (:func:`diagnosis.road_fit.refit_band`); where it
        moves, the pass is made again on the new band and ``summary["meta"]["band_refit"]`` keeps the first
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
    from diagnosis.compare import distribution_shape
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
        tr = transmissibility_or_none(sig, sim)
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
            r1, r2, t_r, runs_r = _model_signature(model, sig, sim, tr, tr2, ranking, seed, ex,
                                                   entry=rival)
            sig_r = {"effect": rival.effect, "single_input": r1, "two_input": r2}
            timing["signature_rival_s"] = t_r
        # a low-pass winner or rival: the speed test (fixed in Hz or in cycles/m?)
        sig_hz, t_hz = hz_signature_record(
            model, sig, [(ranking.winner, runs_w)] + ([(rival, runs_r)] if rival is not None else []),
            seed, ex, nominal_runs=nominal_own_runs)
        if t_hz is not None:
            timing["signature_hz_s"] = t_hz
        return dict(loc=loc, tr=tr, tr2=tr2, fr=fr, sh=sh, ranking=ranking, sig_w=sig_w,
                    sig_w2=sig_w2, sig_r=sig_r, sig_own=sig_own, sig_hz=sig_hz, cands=cands,
                    side_rec=side_rec,
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
                                "vetoed": model.high_band["vetoed"],
                                "unstepped": bool(model.high_band.get("unstepped", False))}),
            "road_fit": ("segment level and waviness from the nominal model on the calibration "
                         "windows" if road_fit == "levels" else
                         "inverse.pipeline.invert on the whole record (nominal truck)")
            + "; level re-profiled per segment piece for every model and window",
            "split": f"{n_windows} equal time windows; odd windows calibrate, even windows held out"
            + ("; then the other way round (two folds, combined)" if folds == 2 else "")
            + (f"; segments shorter than {LOCAL_FEATURE_MAX_S:g} s (local road features) left out, "
               f"and window pieces shorter than {MIN_WINDOW_PIECE_S:g} s" if excluded else ""),
            "calibration_windows_s": [list(map(float, e)) for e in cal_edges],
            "heldout_windows_s": [list(map(float, e)) for e in held_edges],
            "local_road_features_s": [list(map(float, e)) for e in excluded],
            # the recorded speed [m/s]: with the road's nmax it says up to which frequency the
            # road excites the vehicle (verdict.gap_side reads only the bands below)
            "speed_mps": {"p05": float(np.percentile(sig.speed, 5)), "mean": float(np.mean(sig.speed)),
                          "max": float(np.max(sig.speed))},
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

    def road_on_band(nmax, high_band=None):
        return set_road_band(model, sig, cal_edges, nmax, seed, high_band)

    try:
        ctx = prepare(sig, veh, seed=seed, n_windows=n_windows, road_fit=road_fit, workers=workers,
                      executor=ex, solver=solver)
        model, calib, held, bounds = ctx.model, ctx.calib, ctx.held, ctx.bounds
        cal_edges, simc, segs = ctx.cal_edges, ctx.sim_nominal, ctx.segs
        held_edges, excluded = ctx.held_edges, ctx.excluded
        if excluded:
            progress("local road feature(s) left out of the windows (segments shorter than "
                     f"{LOCAL_FEATURE_MAX_S:g} s): "
                     + ", ".join(f"{a:.2f}-{b:.2f} s" for a, b in excluded))
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
                         + ', '.join(f'{x:g}' for x in new) + " (was "
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
                simc = road_on_band(new)
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
    # a measurement beside the verdict, no road needed (it changes no verdict)
    from diagnosis.force_balance import describe, leaf_friction
    meta["force_balance"] = leaf_friction(drive, vp)
    progress(describe(meta["force_balance"]))
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
