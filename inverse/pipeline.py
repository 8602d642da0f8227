"""The inverse-modelling pipeline on one record: segment, initialise, fit, diagnose.

What it is for: one call that runs sections 2.2-2.4 of the paper on a drive given
as arrays, with the response simulator supplied by the caller, and returns a
result that serialises to the ``segments`` list of ``summary.json``.  What it is
not: the command line, dataset reading, the global road (roadlib) or the Exudyn
wiring (the caller's ``make_simulator``).

Seeds: the fit's road phases come from one root seed,
``SeedSequence(seed, spawn_key=(5, 1))`` (5 = issue/stage "inverse", 1 = fit
phases); an independent validation realisation uses ``spawn_key=(5, 2)``.  The
identified road is the fitted parameters WITH the fit's phases (the realisation
the parameters were tuned on): synthesise the global road and run the validation
with the fit's stream.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError
from inverse.features import FeatureSet, FeatureSpec
from inverse.segmentation import SegmentationResult, segment
from inverse.sensitivity import FitConfig, FitResult, fit_segments
from inverse.spectral import ParamBounds
from inverse.validation import response_table
from roadlib.psd import ISO_CLASSES

#: spawn keys of the pipeline's random streams (see module docstring)
SEED_KEY_FIT = (5, 1)
SEED_KEY_VALIDATION = (5, 2)


def stream_seed(seed: int, key: tuple) -> int:
    """An int seed for one documented stream of a root seed."""
    return int(np.random.SeedSequence(seed, spawn_key=key).generate_state(1)[0])


@dataclass(frozen=True)
class InversionConfig:
    """Settings of :func:`invert`.

    Parameters
    ----------
    k : int, optional
        Number of segments; chosen by the segmentation's criterion when None.
    segmentation : dict
        Extra keyword arguments of :func:`inverse.segmentation.segment`.
    feature_spec : FeatureSpec, optional
        Features; default: all response channels present, other settings default.
    fit : FitConfig
    bounds : ParamBounds
        Before the Nyquist cap (applied from the record).
    w0, nmin0, nmax0 : float
        Initial w [-], nmin and nmax [cycles/m] of every segment (the level comes
        from the segmentation).  The band starts INSIDE the range the response
        is sensitive to (nmin0 * v and nmax0 * v within the feature bands), so
        the data push its edges outwards as far as they can tell; an edge
        started outside that range would have no sensitivity and never move.
    w_prior, nmin_prior, nmax_prior : float
        Prior mean of w, nmin, nmax (the level's prior mean is the
        segmentation's level); defaults are the typical values of the paper's
        Table 1.
    seed : int
        Root seed (see module docstring).
    noise_psd : dict, optional
        Channel -> known white sensor-noise PSD [unit^2/Hz] (e.g. from the data
        sheet: sd^2 / (fs / 2)); channels not given are estimated from the top
        of their spectrum (:func:`inverse.features.estimate_noise_psd`).
    fit_model : {"simulation", "linear"}
        "simulation": every feature evaluation of the fit is a time simulation
        (:func:`inverse.sensitivity.fit_segments`); "linear": the linear model's
        expected features with simulation offsets (:func:`inverse.linear_features.fit_hybrid`,
        docs/inverse.md section 12).
    linear_corrections : int
        Most simulate-and-refit rounds of the "linear" fit (0: linear model alone);
        at least ``inverse.linear_features.CORRECTIONS_NONLINEAR`` (4) when the
        simulator has nonlinear effects the linear model leaves out.
    model_form : {"open", "diagnosed", "unexplained"}
        Which model-form term the reported uncertainty carries
        (:data:`inverse.uncertainty.MODEL_FORMS`): "diagnosed" where the diagnosis found no
        gap on this drive or named and singled out the effect the fit carries
        (``diagnosis.closed_loop.model_form``).
    calibration : str, optional
        Key of the uncertainty calibration (:data:`inverse.uncertainty.CALIBRATIONS`,
        :func:`inverse.uncertainty.calibration_key`: fit model and channel set); None: the
        fit model's own (its axle-3 calibration).
    segment_on : {"displacement", "axle_acc"}
        What locates the segment boundaries: "displacement" (default) the suspension
        displacements' 3-20 Hz power; "axle_acc" the octave-band powers of the axle
        accelerations of the segmentation's wheels (``axle_acc_<a><s>`` beside each
        ``susp_disp_<a><s>``; :data:`inverse.segmentation.BOUNDARY_BANDS`), falling back to
        the displacements where a drive lacks one of them.  Measured on 245 blind drives
        (docs/inverse.md, section 1, 2026-11-28): more true boundaries found, G(1 cycle/m)
        within 20 % not better beyond sampling noise, two segments worse on the
        independent truck: built, not the default.
    """

    k: int | None = None
    segmentation: dict = field(default_factory=dict)
    feature_spec: FeatureSpec | None = None
    fit: FitConfig = FitConfig()
    bounds: ParamBounds = ParamBounds()
    w0: float = 2.0
    nmin0: float = 0.1
    nmax0: float = 2.5
    w_prior: float = 2.0
    nmin_prior: float = 0.05
    nmax_prior: float = 5.0
    seed: int = 0
    noise_psd: dict | None = None
    fit_model: str = "simulation"
    linear_corrections: int = 2
    model_form: str = "open"
    calibration: str | None = None
    segment_on: str = "displacement"


def boundary_channels(channels: dict, segment_channels, segment_on: str = "displacement") -> dict | None:
    """The signals whose band powers locate the boundaries (:func:`inverse.segmentation.segment`):
    with ``segment_on`` "axle_acc" the axle acceleration at each segmentation wheel when the drive
    has all of them, else None (the displacements themselves)."""
    if segment_on not in ("axle_acc", "displacement"):
        raise EroadInputError(f"segment_on must be 'axle_acc' or 'displacement', got {segment_on!r}")
    if segment_on == "displacement":
        return None
    names = [c.replace("susp_disp_", "axle_acc_", 1) for c in segment_channels]
    if not names or any(n not in channels for n in names):
        return None
    return {n: channels[n] for n in names}


#: a fitted parameter this close to a bound is reported as on it (w [-]; ln Gq_n0 [-])
AT_BOUND_TOL = {"w": 0.01, "ln_Gq_n0": 0.01}


def w_bound_side(w: float, bounds) -> str | None:
    """'upper' or 'lower' when a waviness sits on that bound of ``bounds.w`` (within
    ``AT_BOUND_TOL``), else None."""
    lw, hw = bounds.w
    if w >= hw - AT_BOUND_TOL["w"]:
        return "upper"
    if w <= lw + AT_BOUND_TOL["w"]:
        return "lower"
    return None


def at_bounds(Gq_n0: float, w: float, bounds) -> list:
    """Which of a segment's fitted level and waviness sit on a bound of the fit, as
    strings such as ``"w = 3.5 (upper bound)"``: the data pushed the parameter out of
    the range the road model allows, so its value (and the level traded against it) is
    the bound's, not the road's."""
    out = []
    side = w_bound_side(w, bounds)
    if side:
        out.append(f"w = {bounds.w[side == 'upper']:g} ({side} bound)")
    lg = math.log(Gq_n0)
    if lg >= math.log(bounds.Gq_n0[1]) - AT_BOUND_TOL["ln_Gq_n0"]:
        out.append(f"Gq_n0 = {bounds.Gq_n0[1]:g} m^3 (upper bound"
                   + (", class E's mean: a rougher road is fitted here, its level reads low"
                      if bounds.Gq_n0[1] == ISO_CLASSES["E"].gd0 else "") + ")")
    elif lg <= math.log(bounds.Gq_n0[0]) + AT_BOUND_TOL["ln_Gq_n0"]:
        out.append(f"Gq_n0 = {bounds.Gq_n0[0]:g} m^3 (lower bound)")
    return out


def unresolved_row(segment_s: float, resolution: dict) -> dict | None:
    """summary.json's ``unresolved`` of one segment: ``piece_s`` (3 s) and ``ln_level`` [lo, hi],
    the range of ln level, against the segment's, within which a stretch of that length inside
    the segment is, as often as not, left in it by the segmentation
    (:func:`inverse.segmentation.unresolved_level`; None for an unbounded side); None where it
    does not apply (segment not longer than the piece, K given, boundaries on several series)."""
    from inverse.segmentation import UNRESOLVED_PIECE_S, unresolved_level

    r = unresolved_level(UNRESOLVED_PIECE_S, segment_s, resolution)
    if r is None:
        return None
    return {"piece_s": UNRESOLVED_PIECE_S, "ln_level": [v if math.isfinite(v) else None for v in r]}


@dataclass
class Inversion:
    """Result of :func:`invert`."""

    time: np.ndarray
    segmentation: SegmentationResult
    features: FeatureSet
    fit: FitResult
    params0: np.ndarray
    config: InversionConfig

    @property
    def t_bounds(self) -> np.ndarray:
        return self.segmentation.t_bounds

    def segments(self) -> list:
        """Per-segment rows of summary.json (Table 1).

        Returns
        -------
        list of dict
            t_start, t_end [s], proportion [-], Gq_n0 [m^3], w [-], nmin, nmax
            [cycles/m], dx, dy [m], class, initial_class, identifiable, objective,
            n_features, converged, and where the level is best determined: n_best
            [cycles/m], G_n_best [m^3] (:func:`inverse.sensitivity.best_level`).
            Uncertainty (:mod:`inverse.uncertainty`): ``sd`` per theta component,
            ``sd_ln_Gq_n0`` and ``sd_ln_G_n_best`` are the REPORTED standard deviations
            (noise, realisation and model-form error, calibrated on blind drives);
            ``sd_laplace`` and ``sd_ln_G_n_best_laplace`` the fit's noise-only ones;
            ``interval90`` the 90 % intervals of Gq_n0, w and G_n_best; ``fit_quality``
            the gate (status 'clean' or 'poor', misfit per feature); ``at_bound`` the
            fitted level or waviness sitting on a bound of the fit (:func:`at_bounds`);
            ``unresolved`` the segmentation's resolution (:func:`unresolved_row`).
        """
        from inverse.report import class_identified
        from inverse.uncertainty import fit_quality, honest_sd, interval90

        rows = []
        tb = self.t_bounds
        prop = self.segmentation.proportions
        for k, s in enumerate(self.fit.segments):
            d = s.as_dict()
            fm = self.config.calibration or self.config.fit_model
            sd = honest_sd(d["sd"], d.get("sd_ln_G_n_best"), d["objective"], d["n_features"], fit_model=fm,
                           model_form=self.config.model_form)
            iv = {"Gq_n0": interval90(d["Gq_n0"], sd["ln_Gq_n0"], log=True),
                  "w": interval90(d["w"], sd["w"], log=False)}
            best = {}
            if "n_best" in d:
                best = {"n_best": d["n_best"], "G_n_best": d["G_n_best"], "sd_ln_G_n_best": sd["ln_G_n_best"],
                        "sd_ln_G_n_best_laplace": d["sd_ln_G_n_best"]}
                iv["G_n_best"] = interval90(d["G_n_best"], sd["ln_G_n_best"], log=True)
            rows.append({"t_start": float(tb[k]), "t_end": float(tb[k + 1]), "proportion": float(prop[k]),
                         "Gq_n0": d["Gq_n0"], "w": d["w"], "nmin": d["nmin"], "nmax": d["nmax"],
                         "dx": d["dx"], "dy": d["dy"], "class": d["class"],
                         "class_identified": class_identified(d),
                         "initial_class": self.segmentation.classes[k],
                         "identifiable": d["identifiable"],
                         "sd": {key: v for key, v in sd.items() if key != "ln_G_n_best"},
                         "sd_laplace": d["sd"], "sd_ln_Gq_n0": sd["ln_Gq_n0"], "interval90": iv,
                         "fit_quality": fit_quality(d["objective"], d["n_features"], fit_model=fm),
                         "objective": d["objective"], "n_features": d["n_features"], "converged": d["converged"],
                         "at_bound": at_bounds(d["Gq_n0"], d["w"], self.config.bounds),
                         "unresolved": unresolved_row(float(tb[k + 1] - tb[k]), self.segmentation.resolution),
                         **{key: d[key] for key in ("sd_robust", "consistency") if key in d},
                         **best})
        return rows

    def summary(self) -> dict:
        """JSON-ready summary: segments, fit statistics, iteration history."""
        rounds = [h for h in self.fit.history if h.get("kind") == "trust_region" and "move" in h]
        hybrid = {"corrections": len(rounds), "last_move": rounds[-1]["move"]} if rounds else {}
        return {"segments": self.segments(),
                "fit": {"model": self.config.fit_model, "model_form": self.config.model_form, **hybrid, "n_sims": self.fit.n_sims, "wall_s": self.fit.wall_s,
                        "iterations": sum(h.get("kind") == "trust_region" for h in self.fit.history[1:]),
                        "polished": any(h.get("kind") == "polish" for h in self.fit.history),
                        "objective": float(self.fit.history[-1]["objective"]),
                        "n_features": int(self.features.n_features().sum())},
                "segmentation": {"criterion": {str(k): float(v) for k, v in self.segmentation.criterion.items()},
                                 "boundaries_from": self.segmentation.boundary_source},
                "history": self.fit.history}


def invert(time, channels: dict, speed, make_simulator, *, predict_rms=None,
           segment_channels=None, config: InversionConfig = InversionConfig(),
           map_fn=None, progress=None, linear_model=None) -> Inversion:
    """Segment a drive and fit the road spectrum of every segment.

    Parameters
    ----------
    time : (N,) array
        Uniform time [s].
    channels : dict
        Channel name -> (N,) array, SI units (shared/docs/measurement-format.md).
    speed : float or (N,) array
        [m/s].
    make_simulator : callable
        ``make_simulator(t_bounds) -> simulate``: given the K + 1 segment
        boundaries [s] on ``time``, a simulator with the contract of
        :mod:`inverse.sensitivity` (``simulate(params (K, 4), seed) -> dict``).
    predict_rms : callable, optional
        ``predict_rms(Gq_n0, w, speed) -> rms`` of the segmentation channels'
        displacement in the segmentation's ``class_band`` (see
        :func:`inverse.segmentation.segment`); without it every segment starts at
        class C.
    segment_channels : list of str, optional
        Displacement channels to segment on; default all ``susp_disp_3*``, else
        all ``susp_disp_*``.
    config : InversionConfig
    map_fn : callable, optional
        Parallel map for the sampled simulations (see :func:`fit_segments`).
    progress : callable, optional
        Called with each fit history entry.
    linear_model : vehicles.linear.LinearModel, optional
        The linear model of ``config.fit_model == "linear"``; default built from the
        simulator's ``vehicle``, ``chassis`` and ``effects`` (its linear effects,
        :func:`inverse.linear_features.linear_model_for`).

    Returns
    -------
    Inversion
    """
    if config.fit_model not in ("simulation", "linear"):
        raise EroadInputError(f"fit_model must be 'simulation' or 'linear', got {config.fit_model!r}")
    from inverse.uncertainty import MODEL_FORMS
    if config.model_form not in MODEL_FORMS:
        raise EroadInputError(f"model_form must be one of {', '.join(MODEL_FORMS)}, got {config.model_form!r}")
    t = np.asarray(time, dtype=float)
    if segment_channels is None:
        segment_channels = sorted(c for c in channels if c.startswith("susp_disp_3")) or \
            sorted(c for c in channels if c.startswith("susp_disp_"))
    if not segment_channels:
        raise EroadInputError("invert: no suspension displacement channel (susp_disp_*) to segment on")
    seg = segment(t, {c: channels[c] for c in segment_channels}, speed, k=config.k,
                  predict_rms=predict_rms, w_init=config.w0,
                  boundary_channels=boundary_channels(channels, segment_channels, config.segment_on),
                  **config.segmentation)
    spec = config.feature_spec
    if spec is None:
        names = sorted(c for c in channels if c.split("_")[0] in ("susp", "axle", "body"))
        spec = FeatureSpec(channels=tuple(names))
    feats = FeatureSet.from_measurement(t, channels, seg.t_bounds, spec, noise_psd=config.noise_psd)
    K = seg.n_segments
    Gq0 = np.where(np.isfinite(seg.Gq_init), seg.Gq_init, 256e-6)
    params0 = np.column_stack([Gq0, np.full(K, config.w0), np.full(K, config.nmin0), np.full(K, config.nmax0)])
    prior = np.column_stack([Gq0, np.full(K, config.w_prior), np.full(K, config.nmin_prior),
                             np.full(K, config.nmax_prior)])
    fs = 1.0 / float(np.mean(np.diff(t)))
    v_max = float(np.max(np.broadcast_to(np.asarray(speed, float), t.shape)))
    bounds = config.bounds.for_record(fs, v_max)
    simulate = make_simulator(seg.t_bounds)
    if config.fit_model == "linear":
        from inverse.linear_features import CORRECTIONS_NONLINEAR, features_for_simulator, fit_hybrid

        lin, left_out = features_for_simulator(
            feats, speed, simulate, linear_model,
            "invert: fit_model 'linear' needs linear_model= or a simulator with a vehicle")
        corrections = config.linear_corrections
        if left_out:   # offsets that depend on the road: more rounds (docs/inverse.md section 12)
            corrections = max(corrections, CORRECTIONS_NONLINEAR)
        fit = fit_hybrid(simulate, feats, params0, linear=lin, seed=stream_seed(config.seed, SEED_KEY_FIT),
                         bounds=bounds, config=config.fit, prior=prior, map_fn=map_fn, progress=progress,
                         corrections=corrections)
    else:
        fit = fit_segments(simulate, feats, params0, seed=stream_seed(config.seed, SEED_KEY_FIT),
                           bounds=bounds, config=config.fit, prior=prior, map_fn=map_fn, progress=progress)
    return Inversion(t, seg, feats, fit, params0, config)


def validate(simulate, params, measured: dict, channels, seed: int = 0, stream: tuple = SEED_KEY_FIT) -> tuple:
    """Simulate the identified road once and compare with the measurement.

    Parameters
    ----------
    simulate : callable
        Simulator (contract of :mod:`inverse.sensitivity`).
    params : (K, 4) array
        Fitted parameters.
    measured : dict
        Channel -> (N,) array.
    channels : list of str
    seed : int
        Root seed of the inversion.
    stream : tuple
        Spawn key of the phases: ``SEED_KEY_FIT`` (default) drives the road the
        fit tuned, ``SEED_KEY_VALIDATION`` an independent realisation of the same
        spectra (its response RMS scatters by the realisation's statistics, e.g.
        9% for body acceleration over 30 s on the quarter truck).

    Returns
    -------
    simulated : dict
        Channel -> (N,) array.
    table : list of dict
        :func:`inverse.validation.response_table` rows.
    """
    sim = simulate(np.asarray(params, dtype=float), stream_seed(seed, stream))
    return sim, response_table(measured, sim, channels)


def segment_errors(t_true, t_found) -> np.ndarray:
    """Boundary errors [s]: for each interior true boundary, the signed distance
    to the nearest interior found boundary (nan when none was found)."""
    tt = np.asarray(t_true, dtype=float)[1:-1]
    tf = np.asarray(t_found, dtype=float)[1:-1]
    if tf.size == 0:
        return np.full(tt.size, math.nan)
    return np.array([tf[np.argmin(np.abs(tf - b))] - b for b in tt])
