"""Synthetic quarter-truck drives with known truth, and a blind recovery study.

What it is for: developing and scoring the inverse fit where the truth is known,
in seconds, on the linear quarter truck of :mod:`inverse.quarter`.  What it is
not: the project's virtual test drive (``eroad synth`` in ``drives``), whose
truth vehicle differs from the nominal model on purpose.  Here the "measured"
data come from the same model as the fit (the inverse crime): the study measures
the statistical accuracy of the method itself, not the model gap.

Seeds: a drive's road phases come from SeedSequence(seed, spawn_key=(0,)), its
sensor noise from spawn_key=(1,); a random scenario's draws from spawn_key=(2,).

Run ``python -m inverse.synthetic --cases 20`` for the accuracy table.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time as _time
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError
from inverse.features import FeatureSet, FeatureSpec
from inverse.pipeline import SEED_KEY_FIT, InversionConfig, invert, segment_errors, stream_seed
from inverse.quarter import (QuarterTruck, QuarterTruckParams, QuarterTruckSimulator, add_sensor_noise,
                             travelled_distance)
from inverse.segmentation import band_pass, classify
from inverse.sensitivity import fit_segments
from inverse.spectral import ISO_CLASS_GD0, iso_class

#: default white sensor noise per quantity [m, m/s^2, m/s^2]
DEFAULT_NOISE = {"susp_disp": 2e-4, "axle_acc": 0.05, "body_acc": 0.02}


def _seed(seed: int, key: int) -> int:
    return int(np.random.SeedSequence(seed, spawn_key=(key,)).generate_state(1)[0])


@dataclass
class SyntheticDrive:
    """A synthetic 'measured' drive with its truth.

    Attributes
    ----------
    time : (N,) array [s]
    speed : (N,) array [m/s]
    channels : dict
        Channel -> (N,) array with sensor noise.
    t_bounds : (K + 1,) array
        True segment boundaries [s].
    params : (K, 4) array
        True (Gq_n0, w, nmin, nmax).
    noise_std : dict
        Sensor noise standard deviation per quantity.
    vehicle : QuarterTruckParams
    """

    time: np.ndarray
    speed: np.ndarray
    channels: dict
    t_bounds: np.ndarray
    params: np.ndarray
    noise_std: dict = field(default_factory=lambda: dict(DEFAULT_NOISE))
    vehicle: QuarterTruckParams = field(default_factory=QuarterTruckParams)

    @property
    def fs(self) -> float:
        return 1.0 / float(self.time[1] - self.time[0])

    def noise_psd(self) -> dict:
        """Known white-noise PSD per channel [unit^2/Hz]."""
        return {c: self.noise_std.get(c.rsplit("_", 1)[0], 0.0) ** 2 / (0.5 * self.fs) for c in self.channels}


def x_bounds_of(t_bounds, time, speed) -> np.ndarray:
    """Segment boundaries along the road [m] for boundaries in time [s].

    x = 0 at time[0]; the last boundary is pushed far ahead so the last segment
    covers the run-out of the simulation.
    """
    t = np.asarray(time, dtype=float)
    x = travelled_distance(t, speed)
    xb = np.interp(np.asarray(t_bounds, dtype=float), t, x)
    xb[0] = min(xb[0], -1.0)
    xb[-1] = x[-1] + 1e3
    return xb


def quarter_simulator_factory(time, speed, vehicle: QuarterTruckParams = QuarterTruckParams(), **kwargs):
    """``make_simulator(t_bounds) -> QuarterTruckSimulator`` for :func:`inverse.pipeline.invert`.

    Parameters
    ----------
    time : (N,) array [s]
    speed : float or (N,) array [m/s]
    vehicle : QuarterTruckParams
    **kwargs
        Passed to :class:`QuarterTruckSimulator`.
    """
    def make(t_bounds):
        return QuarterTruckSimulator(time, speed, x_bounds_of(t_bounds, time, speed), vehicle=vehicle, **kwargs)
    return make


def make_drive(params, durations, *, speed=10.0, fs: float = 200.0, seed: int = 0,
               noise_std=None, vehicle: QuarterTruckParams = QuarterTruckParams()) -> SyntheticDrive:
    """A synthetic drive over segments of known spectra.

    Parameters
    ----------
    params : (K, 4) array
        True (Gq_n0 [m^3], w, nmin, nmax [cycles/m]) per segment.
    durations : (K,) array
        Segment durations [s].
    speed : float, (N,) array or callable
        Speed [m/s]; a callable gets the time array.
    fs : float
        Sample rate [Hz].
    seed : int
        Root seed (phases: spawn_key (0,), noise: (1,)).
    noise_std : dict, optional
        Sensor noise per quantity; :data:`DEFAULT_NOISE` by default.
    vehicle : QuarterTruckParams

    Returns
    -------
    SyntheticDrive
    """
    P = np.atleast_2d(np.asarray(params, dtype=float))
    d = np.asarray(durations, dtype=float)
    if P.shape != (d.size, 4):
        raise EroadInputError("make_drive: params must be (K, 4) with one duration per segment")
    t = np.arange(int(round(d.sum() * fs))) / fs
    v = speed(t) if callable(speed) else np.broadcast_to(np.asarray(speed, float), t.shape).copy()
    tb = np.concatenate([[0.0], np.cumsum(d)])
    tb[-1] = t[-1] + 1.0 / fs
    sim = QuarterTruckSimulator(t, v, x_bounds_of(tb, t, v), vehicle=vehicle)
    noise = dict(DEFAULT_NOISE) if noise_std is None else dict(noise_std)
    clean = sim(P, _seed(seed, 0))
    return SyntheticDrive(t, v, add_sensor_noise(clean, noise, _seed(seed, 1)), tb, P, noise, vehicle)


def random_scenario(seed: int, duration: float = 30.0, min_len: float = 3.0):
    """Random blind scenario in the spirit of ``eroad synth --scenario random``.

    2-6 segments of at least ``min_len`` s, classes A-E with Gq_n0 log-uniform
    inside the class bounds, w uniform 1.5-2.5, nmin log-uniform 0.01-0.1,
    nmax log-uniform 3-7 cycles/m, a smooth speed between 6 and 14 m/s.

    Returns
    -------
    params : (K, 4) array
    durations : (K,) array [s]
    speed : callable t -> v [m/s]
    """
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(2,)))
    K = int(rng.integers(2, 7))
    durations = min_len + (duration - K * min_len) * rng.dirichlet(np.ones(K))
    classes = rng.choice(list("ABCDE"), K)
    Gq = np.array([ISO_CLASS_GD0[c] for c in classes]) * 2.0 ** rng.uniform(-1, 1, K)
    w = rng.uniform(1.5, 2.5, K)
    nmin = np.exp(rng.uniform(math.log(0.01), math.log(0.1), K))
    nmax = np.exp(rng.uniform(math.log(3.0), math.log(7.0), K))
    v0 = rng.uniform(7.0, 13.0)
    amp = rng.uniform(0.0, min(v0 - 6.0, 14.0 - v0, 2.0))
    period = rng.uniform(20.0, 60.0)
    phase = rng.uniform(0, 2 * np.pi)

    def speed(t):
        return v0 + amp * np.sin(2 * np.pi * t / period + phase)

    return np.column_stack([Gq, w, nmin, nmax]), durations, speed


def luliang_like_scenario():
    """The paper's 460-490 s window (issue 4's ``luliang``) on the quarter truck.

    Five segments in the time proportions of the paper's Table 1 (42.08, 4.70,
    37.28, 2.92, 13.02 % of 30 s) with the class geometric means of its Gq ranges
    (16, 256, 256, 1024, 1024 e-6 m^3), nmin 0.1, 0.01, 0.1, 0.05, 0.1 cycles/m,
    nmax 5 cycles/m, w 2, 2, 1.8, 1.8, 1.6; speed varying smoothly between 7.86
    and 11.28 m/s.

    Returns
    -------
    params : (5, 4) array
    durations : (5,) array [s]
    speed : callable t -> v [m/s]
    """
    prop = np.array([42.08, 4.70, 37.28, 2.92, 13.02])
    durations = 30.0 * prop / prop.sum()
    params = np.array([[16e-6, 2.0, 0.1, 5.0], [256e-6, 2.0, 0.01, 5.0], [256e-6, 1.8, 0.1, 5.0],
                       [1024e-6, 1.8, 0.05, 5.0], [1024e-6, 1.6, 0.1, 5.0]])

    def speed(t):
        return 9.57 - 1.71 * np.cos(2 * np.pi * np.asarray(t) / 30.0)

    return params, durations, speed


class DelayedSimulator:
    """A simulator wrapper that sleeps ``delay_s`` per call (to emulate the cost of
    the Exudyn truck, about 0.3-0.5 s per 30 s drive, in timing studies)."""

    def __init__(self, simulate, delay_s: float):
        self.simulate, self.delay_s = simulate, float(delay_s)

    def __call__(self, params, seed):
        _time.sleep(self.delay_s)
        return self.simulate(params, seed)


def quarter_predict_rms(vehicle: QuarterTruckParams = QuarterTruckParams(), band=(0.2, 20.0),
                        nmin: float = 0.05, nmax: float = 5.0):
    """``predict_rms(Gq_n0, w, speed)`` of the quarter truck's suspension displacement in ``band``."""
    model = QuarterTruck(vehicle)

    def predict(Gq_n0, w, speed):
        return model.predict_rms(Gq_n0, w, speed, "susp_disp", nmin, nmax, f_band=band)
    return predict


def recovery_study(n_cases: int = 20, seed: int = 0, replicates: int = 1, oracle: bool = False,
                   known_noise: bool = False, min_len: float = 3.0, verbose: bool = False,
                   config: InversionConfig = InversionConfig(), spec_kwargs=None,
                   oracle_band: bool = False) -> dict:
    """Blind recovery of random scenarios on the quarter truck.

    Parameters
    ----------
    n_cases : int
        Number of random scenarios (case i uses root seed ``seed + i``).
    seed : int
    replicates : int
        Simulated replicates per evaluation (:class:`FeatureSpec`).
    oracle : bool
        Use the true boundaries (isolates the fit from the segmentation).
    known_noise : bool
        Give the fit the true sensor noise instead of estimating it.
    min_len : float
        Shortest true segment [s].
    verbose : bool
        Print one line per case.
    config : InversionConfig
        Fit settings (its k, feature_spec and seed are set per case).
    spec_kwargs : dict, optional
        Extra :class:`FeatureSpec` settings.
    oracle_band : bool
        With ``oracle``: start nmin and nmax at the truth (a diagnostic of what
        the freedom of the band parameters costs; hold them with a tiny
        ``FitConfig.scale``).

    Returns
    -------
    dict
        Per true segment: 'ln_Gq_err', 'w_err', 'class_ok', 'duration'; per
        boundary: 'boundary_err' [s]; per case: 'wall_s', 'n_sims', 'k_true',
        'k_found'; and 'summary' with medians, 95th percentiles and worst values.
    """
    rows = {"ln_Gq_err": [], "w_err": [], "class_ok": [], "duration": [], "boundary_err": [],
            "wall_s": [], "n_sims": [], "k_true": [], "k_found": [], "nmin_identifiable": [],
            "nmax_identifiable": [], "truth": [], "fitted": []}
    for i in range(n_cases):
        P, dur, speed = random_scenario(seed + i, min_len=min_len)
        drive = make_drive(P, dur, speed=speed, seed=seed + i)
        spec = FeatureSpec(channels=tuple(sorted(drive.channels)), replicates=replicates, **(spec_kwargs or {}))
        cfg = dataclasses.replace(config, k=P.shape[0] if oracle else config.k, feature_spec=spec, seed=seed + i)
        make = quarter_simulator_factory(drive.time, drive.speed, drive.vehicle)
        t0 = _time.perf_counter()
        if oracle:
            pr = quarter_predict_rms(drive.vehicle)
            feats = FeatureSet.from_measurement(drive.time, drive.channels, drive.t_bounds, spec,
                                                noise_psd=drive.noise_psd() if known_noise else None)
            K = P.shape[0]
            p0 = np.empty((K, 4))
            for k in range(K):
                sel = (drive.time >= drive.t_bounds[k]) & (drive.time < drive.t_bounds[k + 1])
                r = math.sqrt(np.mean([np.mean(band_pass(drive.channels[c], drive.fs, 0.2, 20.0)[sel] ** 2)
                                       for c in ("susp_disp_3L", "susp_disp_3R")]))
                p0[k] = (classify(r, float(np.mean(drive.speed[sel])), pr, cfg.w0)[0], cfg.w0, cfg.nmin0, cfg.nmax0)
                if oracle_band:
                    p0[k, 2:] = P[k, 2:]
            prior = p0.copy()
            prior[:, 1:] = (cfg.w_prior, cfg.nmin_prior, cfg.nmax_prior)
            if oracle_band:
                prior[:, 2:] = P[:, 2:]
            fit = fit_segments(make(drive.t_bounds), feats, p0, seed=stream_seed(seed + i, SEED_KEY_FIT),
                               bounds=cfg.bounds.for_record(drive.fs, drive.speed.max()), config=cfg.fit,
                               prior=prior)
            found_tb, fitted, idents = drive.t_bounds, fit.params, [s.identifiable for s in fit.segments]
            n_sims = fit.n_sims
        else:
            inv = invert(drive.time, drive.channels, drive.speed, make,
                         predict_rms=quarter_predict_rms(drive.vehicle), config=cfg)
            found_tb, fitted = inv.t_bounds, inv.fit.params
            idents = [s.identifiable for s in inv.fit.segments]
            n_sims = inv.fit.n_sims
        wall = _time.perf_counter() - t0
        rows["wall_s"].append(wall)
        rows["n_sims"].append(n_sims)
        rows["k_true"].append(P.shape[0])
        rows["k_found"].append(found_tb.size - 1)
        rows["boundary_err"] += segment_errors(drive.t_bounds, found_tb).tolist()
        for k in range(P.shape[0]):
            a, b = drive.t_bounds[k], drive.t_bounds[k + 1]
            overlap = np.minimum(found_tb[1:], b) - np.maximum(found_tb[:-1], a)
            j = int(np.argmax(overlap))
            rows["ln_Gq_err"].append(float(math.log(fitted[j, 0] / P[k, 0])))
            rows["w_err"].append(float(fitted[j, 1] - P[k, 1]))
            rows["class_ok"].append(iso_class(fitted[j, 0]) == iso_class(P[k, 0]))
            rows["duration"].append(float(b - a))
            rows["truth"].append(P[k].tolist())
            rows["fitted"].append(fitted[j].tolist())
            rows["nmin_identifiable"].append(bool(idents[j]["nmin"]))
            rows["nmax_identifiable"].append(bool(idents[j]["nmax"]))
        if verbose:
            print(f"case {i:3d}: K {P.shape[0]} -> {found_tb.size - 1}, wall {wall:5.2f} s, sims {n_sims:4d}, "
                  f"ln Gq err {np.round(rows['ln_Gq_err'][-P.shape[0]:], 2).tolist()}, "
                  f"w err {np.round(rows['w_err'][-P.shape[0]:], 2).tolist()}", flush=True)
    g = np.abs(rows["ln_Gq_err"])
    w = np.abs(rows["w_err"])
    be = np.abs(np.asarray(rows["boundary_err"], dtype=float))
    be = be[np.isfinite(be)]
    rows["summary"] = {
        "cases": n_cases, "segments": int(g.size), "replicates": replicates, "oracle": oracle,
        "abs_ln_Gq_median": float(np.median(g)), "abs_ln_Gq_p95": float(np.percentile(g, 95)),
        "abs_ln_Gq_worst": float(g.max()), "Gq_within_20pct": float(np.mean(g <= math.log(1.2))),
        "abs_w_median": float(np.median(w)), "abs_w_p95": float(np.percentile(w, 95)),
        "abs_w_worst": float(w.max()), "w_within_0.15": float(np.mean(w <= 0.15)),
        "class_accuracy": float(np.mean(rows["class_ok"])),
        "boundary_abs_median_s": float(np.median(be)) if be.size else None,
        "boundary_abs_worst_s": float(be.max()) if be.size else None,
        "k_right": float(np.mean(np.array(rows["k_true"]) == np.array(rows["k_found"]))),
        "nmin_identifiable": float(np.mean(rows["nmin_identifiable"])),
        "nmax_identifiable": float(np.mean(rows["nmax_identifiable"])),
        "wall_s_median": float(np.median(rows["wall_s"])), "n_sims_median": float(np.median(rows["n_sims"])),
    }
    return rows


def luliang_study(seed: int = 0, sim_delay_s: float = 0.0, workers: int = 1,
                  config: InversionConfig = InversionConfig()) -> dict:
    """Invert the luliang-like quarter-truck drive blind and time it.

    Parameters
    ----------
    seed : int
        Root seed of the drive and of the fit.
    sim_delay_s : float
        Extra wall time per simulation [s] (emulates the Exudyn truck).
    workers : int
        Processes for the sampled simulations.
    config : InversionConfig

    Returns
    -------
    dict
        'segments' (fitted rows with the truth), 'wall_s', 'n_sims', 'k_found'.
    """
    P, dur, speed = luliang_like_scenario()
    drive = make_drive(P, dur, speed=speed, seed=seed)
    base = quarter_simulator_factory(drive.time, drive.speed, drive.vehicle)

    def make(tb):
        sim = base(tb)
        return DelayedSimulator(sim, sim_delay_s) if sim_delay_s > 0 else sim

    cfg = dataclasses.replace(config, seed=seed, fit=dataclasses.replace(config.fit, n_workers=workers))
    t0 = _time.perf_counter()
    inv = invert(drive.time, drive.channels, drive.speed, make,
                 predict_rms=quarter_predict_rms(drive.vehicle), config=cfg)
    wall = _time.perf_counter() - t0
    rows = inv.segments()
    for r in rows:
        mid = 0.5 * (r["t_start"] + r["t_end"])
        k = int(np.searchsorted(drive.t_bounds, mid, side="right") - 1)
        r["truth"] = dict(zip(("Gq_n0", "w", "nmin", "nmax"), P[k].tolist()))
    return {"segments": rows, "wall_s": wall, "fit_wall_s": inv.fit.wall_s, "n_sims": inv.fit.n_sims,
            "k_found": inv.segmentation.n_segments, "boundary_err_s": segment_errors(drive.t_bounds, inv.t_bounds).tolist()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m inverse.synthetic",
                                 description="Blind recovery study of the inverse fit on the quarter truck.")
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--replicates", type=int, default=1)
    ap.add_argument("--oracle", action="store_true", help="use the true segment boundaries")
    ap.add_argument("--known-noise", action="store_true", help="give the fit the true sensor noise (oracle only)")
    ap.add_argument("--luliang", action="store_true", help="time the luliang-like five-segment drive instead")
    ap.add_argument("--sim-delay", type=float, default=0.0, help="extra seconds per simulation (--luliang)")
    ap.add_argument("--workers", type=int, default=1, help="processes for sampling (--luliang)")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args(argv)
    if args.luliang:
        print(json.dumps(luliang_study(args.seed, args.sim_delay, args.workers), indent=2))
        return 0
    res = recovery_study(args.cases, args.seed, args.replicates, args.oracle, args.known_noise,
                         verbose=args.verbose)
    print(json.dumps(res["summary"], indent=2))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
