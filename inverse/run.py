"""One inversion run: a measured drive in, a run folder out (what ``eroad invert`` runs).

What this module is for: :func:`run_inversion` wires the dataset reader, the truck
simulator (``inverse.truck``), the pipeline (``inverse.pipeline``), the
realisation selection (``inverse.realisation``) and the report writer
(``inverse.report``) into one run folder, and records it with the run archive
(:mod:`eroad.archive`).  It reads the dataset's channels, speed and meta only --
never ``truth/``.  What it is not: the command line (``inverse.cli`` parses the
options and prints) or the method (``inverse.pipeline``).

RUN (written into a temporary sibling folder and renamed into place when
complete; an existing non-empty RUN is refused unless ``force``)::

    summary.json        segments (Table 1 rows), response errors (Table 2), selection, fit, history
    config.toml         the resolved settings
    run.json            the archive's record (eroad.archive.run_info): command, git, versions, host,
                        seed, start/end, status
    history.json        the fit's iteration history
    tables/table1.{csv,md}, tables/table2.{csv,md}, tables/candidates.csv
    figures/figure6_segmentation, figure8_time_compare, figure9_amplitude_distributions (.png, .pdf)
    road.npz, road.crg  the global road: fitted segments, smoothed junctions, selected phases

Paths recorded in the run (the dataset) are relative to the run folder.
"""
from __future__ import annotations

import json
import math
import os
import re
import shutil
import time as _time
from pathlib import Path

import numpy as np

from eroad.archive import finish_run_info, run_info, write_json_atomic, write_run_json
from eroad.errors import EroadInputError

__all__ = ["run_inversion", "fit_channels", "fit_plan", "axles_channels", "channel_set", "CHANNEL_SETS", "noise_psd_from_sd", "check_out", "headline",
           "AXLE3_CHANNELS", "RUN_FORMAT", "axle_channels", "reference_axle", "paired_axles"]

#: run-folder format version
RUN_FORMAT = 1


def noise_psd_from_sd(noise_sd: dict, channels, fs: float, src: str = "--noise") -> dict:
    """White-noise PSDs [unit^2/Hz] = sd^2 / (fs / 2) per channel from sd per channel or quantity.

    A key matches a channel by its full name or by its quantity (the name without the
    station suffix, e.g. ``axle_acc`` for ``axle_acc_3L``); a key that matches no
    channel is refused.
    """
    out = {}
    for key, sd in noise_sd.items():
        hit = [c for c in channels if c == key or c.rsplit("_", 1)[0] == key]
        if not hit:
            raise EroadInputError(f"{src} {key}: matches no channel of the drive "
                                  f"({', '.join(sorted(channels))})")
        for c in hit:
            out[c] = float(sd) ** 2 / (0.5 * fs)
    return out


def axle_channels(axle: int) -> tuple:
    """The fitted channels of one axle: its suspension displacement and axle acceleration,
    both sides."""
    return (f"susp_disp_{axle}L", f"susp_disp_{axle}R", f"axle_acc_{axle}L", f"axle_acc_{axle}R")


#: the axle the default inversion fits where the drive logs it: axle 3, the paper's Table 2 axle
PREFERRED_AXLE = 3
#: the default fitted channels where axle 3 is logged: both sides of axle 3
AXLE3_CHANNELS = axle_channels(PREFERRED_AXLE)


#: the named channel sets of ``--channels`` besides a comma list ('axle<N>' names any axle;
#: 'axle<N>_acc' and 'axles_acc' fit the axle accelerations of those sets alone)
CHANNEL_SETS = ("axle3", "axles", "all", "axle3_acc", "axles_acc")
#: an acceleration set's name: the set whose axle accelerations alone are fitted
_ACC_SET = re.compile(r"(axle\d+|axles)_acc")


def paired_axles(names) -> list:
    """The axles whose suspension displacement is among ``names`` on both sides, ascending."""
    got = set(names)
    found = set()
    for c in got:
        m = re.fullmatch(r"susp_disp_(\d+)[LR]", c)
        if m and {f"susp_disp_{m.group(1)}L", f"susp_disp_{m.group(1)}R"} <= got:
            found.add(int(m.group(1)))
    return sorted(found)


def reference_axle(names, where: str = "the drive") -> int:
    """The axle whose two suspension displacements segment the drive and locate the segments
    on the road: axle 3 (:data:`PREFERRED_AXLE`) where both its sides are among ``names``,
    else the lowest-numbered axle with both sides (a logger on the front axle only)."""
    axles = paired_axles(names)
    if not axles:
        have = ", ".join(sorted(c for c in names if c.split("_")[0] in ("susp", "axle", "body"))) or "none"
        raise EroadInputError(f"{where}: the inversion needs the suspension displacement of both sides of one "
                              f"axle (susp_disp_<a>L and susp_disp_<a>R, e.g. susp_disp_3L and susp_disp_3R); "
                              f"response channels present: {have}")
    return PREFERRED_AXLE if PREFERRED_AXLE in axles else axles[0]


def axles_channels(available) -> list:
    """The ``axles`` set: the suspension displacement of the reference axle (axle 3 where
    logged; :func:`reference_axle`), both sides, and the axle accelerations of every axle the
    drive carries (both sides). Every axle sees the same tracks a few metres apart, so their
    accelerations average the noise and the road's realisation over more stations; the
    suspension displacements of the other axles are left out because they carry the body's
    motion, where a vehicle difference (a flexible frame) shows most
    (results/inverse_blind/20261124-channels-all-axles/)."""
    ref = reference_axle(available)
    return [f"susp_disp_{ref}L", f"susp_disp_{ref}R"] + sorted(c for c in available if c.startswith("axle_acc_"))


def channel_set(names, available) -> str:
    """The name of a FITTED channel list (:func:`fit_plan`'s second list): 'axle<N>' (e.g.
    'axle3'), 'axles', 'all', 'axle<N>_acc', 'axles_acc' when it is that set of the drive
    ``available``, else 'custom' (the key of its uncertainty calibration,
    :func:`inverse.uncertainty.calibration_key`)."""
    got = set(names)
    resp = [c for c in available if c.split("_")[0] in ("susp", "axle", "body")]
    axles = paired_axles(resp)
    for spec in [f"axle{a}" for a in axles] + ["axles", "all"] + [f"axle{a}_acc" for a in axles] + ["axles_acc"]:
        fitted = fit_plan(available, spec)[1]
        if fitted and got == set(fitted):
            return spec
    return "custom"


def fit_plan(available, spec) -> tuple[list, list]:
    """The simulated and the fitted channels of ``--channels spec``.

    The simulated list is :func:`fit_channels`'s (it always holds one axle's suspension
    displacement on both sides: the segmentation's).  The fitted list -- the channels whose
    features the fit compares -- is the same, except for 'axle<N>_acc' and 'axles_acc' (the
    axle accelerations of 'axle<N>' or 'axles' alone) and a comma list, whose channels are
    fitted as listed: a displacement pair added for the segmentation is simulated, not fitted.
    """
    sim = fit_channels(available, spec)
    acc = _ACC_SET.fullmatch(spec) if isinstance(spec, str) else None
    if acc:
        fitted = [c for c in sim if c.startswith("axle_acc_")]
        if not fitted:
            raise EroadInputError(f"--channels {spec}: the drive logs no axle acceleration of "
                                  f"{'that axle' if acc.group(1) != 'axles' else 'any axle'}")
        return sim, fitted
    if isinstance(spec, str) and (spec in CHANNEL_SETS or re.fullmatch(r"axle\d+", spec)) or spec is None:
        return sim, list(sim)
    listed = [c.strip() for c in (spec.split(",") if isinstance(spec, str) else spec) if c.strip()]
    return sim, [c for c in sim if c in listed]


def fit_channels(available, spec) -> list:
    """Simulated channels from ``spec``: None (the default: both sides of the reference axle,
    :func:`reference_axle`, i.e. axle 3 where logged), 'axle<N>' (axle N's suspension
    displacement and axle acceleration), 'axles', 'all', 'axle<N>_acc' / 'axles_acc' (as
    'axle<N>' / 'axles'; only the accelerations are fitted, :func:`fit_plan`) or a comma
    list / sequence. The list always holds one axle's suspension displacement on both sides
    (the segmentation's)."""
    resp = [c for c in available if c.split("_")[0] in ("susp", "axle", "body")]
    acc = _ACC_SET.fullmatch(spec) if isinstance(spec, str) else None
    if acc:
        spec = acc.group(1)
    one = re.fullmatch(r"axle(\d+)", spec) if isinstance(spec, str) else None
    if spec is None:
        names = [c for c in axle_channels(reference_axle(resp)) if c in resp]
    elif one:
        a = int(one.group(1))
        if a not in paired_axles(resp):
            raise EroadInputError(f"--channels {spec}: the drive has no suspension displacement of both sides of "
                                  f"axle {a} (susp_disp_{a}L, susp_disp_{a}R); axles with both: "
                                  f"{', '.join(map(str, paired_axles(resp))) or 'none'}")
        names = [c for c in axle_channels(a) if c in resp]
    elif spec == "axles":
        names = [c for c in axles_channels(resp) if c in resp]
    elif spec == "all":
        names = list(resp)
    else:
        names = [c.strip() for c in (spec.split(",") if isinstance(spec, str) else spec) if c.strip()]
        bad = [c for c in names if c not in resp]
        if bad:
            raise EroadInputError(f"--channels: {', '.join(bad)} not among the drive's response channels "
                                  f"({', '.join(resp)})")
    if not paired_axles(names):
        ref = reference_axle(resp)
        pair = [f"susp_disp_{ref}L", f"susp_disp_{ref}R"]
        names = pair + [c for c in names if c not in pair]
    return names


def check_out(out: Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise EroadInputError(f"{out}: exists and is not a folder")
    if out.exists() and any(out.iterdir()) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; choose another --out or use --force")


def run_inversion(dataset, out, *, segments=None, workers: int = 2, seed: int = 0, quick: bool = False,
                  force: bool = False, candidates=None, max_iter=None, effects=None, chassis: str = "rigid",
                  channels=None, argv=None, polish: bool = True, noise_sd=None,
                  fit_model: str = "linear", selection: str = "linear", bar=None,
                  road_model: str = "auto", model_form: str = "open", segment_on: str = "displacement",
                  solver: str | None = None) -> dict:
    """Invert a dataset into the run folder ``out`` (see the module docstring).

    Parameters
    ----------
    dataset : str or Path
        Dataset folder.
    out : str or Path
        Run folder to create.
    segments : int, optional
        K; default chosen by the segmentation.
    workers : int
        Processes (1 = serial).
    seed : int
        Root seed.
    quick : bool
        3 iterations, 6 candidates.
    force : bool
        Replace ``out``.
    candidates, max_iter : int, optional
        Override the selection size and the iteration cap.
    effects : dict, optional
        Effects of the nominal model.
    chassis : str
    channels : str or sequence of str
        Fitted (and simulated) channels: 'axle3' (default; also for None), 'axles'
        (:func:`axles_channels`), 'all', 'axle<N>_acc' / 'axles_acc' (those sets' axle
        accelerations fitted, the segmentation's displacements only simulated) or names
        (fitted as listed; :func:`fit_plan`). The reported intervals take the
        uncertainty calibration of the fit model and this channel set where there is one
        (``summary["fit"]["uncertainty_calibration"]`` says which, and whether it was
        calibrated for these channels).
    argv : list of str, optional
        Command line recorded in run.json.
    noise_sd : dict, optional
        Known white sensor noise: channel or quantity (``axle_acc``) -> standard
        deviation [SI unit of the channel]; the rest is estimated.
    fit_model : {"linear", "simulation"}
        The fit's model (:class:`inverse.pipeline.InversionConfig`); recorded in
        ``summary["fit"]["model"]`` and config.toml.  Default "linear" (linear-model
        features corrected by a few time simulations; 3x faster than "simulation", as
        accurate on the blind sets, its own uncertainty calibration; docs/inverse.md 12).
    selection : {"linear", "simulation"}
        How the candidate realisations are scored: "linear" (default) by the linear
        truck's time response corrected by the simulated ones, only the fit's and the
        most promising candidates simulated
        (:func:`inverse.realisation.select_realisation_linear`); "simulation" every
        candidate a time simulation (:func:`inverse.realisation.select_realisation`).
    polish : bool
        The fit's final polishing step over several road realisations
        (:class:`inverse.sensitivity.FitConfig` ``polish_replicates``); off only to
        compare.
    road_model : {"auto", "one"}
        Per segment, one ISO slope or two chosen by BIC ("auto") or one slope
        everywhere ("one"); new segment fields ``road_model``, ``w_low``, ``w_high``,
        ``n_break``, ``ic_delta`` (:mod:`inverse.road_model`, docs/road_model.md).
    bar : tqdm.tqdm, optional
        Progress bar (:func:`eroad.progress.progress_bar`), advanced per fit
        iteration and per candidate realisation.
    model_form : {"open", "diagnosed", "unexplained"}
        The model-form term of the reported intervals (:data:`inverse.uncertainty.MODEL_FORMS`):
        "open" unless the diagnosis found no gap on this drive or named and singled out the effect
        this fit carries ("diagnosed"), or found a gap no library effect fully explains
        ("unexplained"); ``diagnosis.closed_loop.model_form`` sets it; recorded in
        ``summary["fit"]["model_form"]``.
    segment_on : {"displacement", "axle_acc"}
        What the segment boundaries are located on (:class:`inverse.pipeline.InversionConfig`):
        the reference axle's suspension displacements in 3-20 Hz (default) or the octave bands
        of its axle accelerations; recorded in ``summary["segmentation"]["boundaries_from"]``.
    solver : {"linear", "exudyn"}, optional
        Integrator of the time simulations (:data:`inverse.truck.SIM_SOLVER` when None);
        recorded in config.toml and ``summary["timing"]["solver"]``.

    Returns
    -------
    dict
        The summary (also ``out/summary.json``).
    """
    from drives.format import read_drive
    from inverse.pipeline import SEED_KEY_FIT, InversionConfig, invert, stream_seed
    from inverse.realisation import candidate_seeds, select_channels, select_realisation, select_realisation_linear
    from inverse.report import table1, table1_note, table2, table2_channels, table2_note, write_figures, write_table
    from inverse.uncertainty import overall_fit_quality
    from inverse.sensitivity import FitConfig
    from inverse.spectral import ParamBounds
    from inverse.truck import SIM_DX, SIM_SOLVER, TruckPredictRms, make_truck_simulator, nmax_cap
    from inverse.validation import response_table

    t0 = _time.perf_counter()
    out = Path(out)
    record = run_info("invert", run_id=out.name, command=argv or ["run_inversion"], seed=seed)
    for name, v, lo in (("--workers", workers, 1), ("--seed", seed, 0)):
        if not isinstance(v, int) or v < lo:
            raise EroadInputError(f"{name} must be an integer >= {lo}, got {v!r}")
    if segments is not None and not (isinstance(segments, int) and segments >= 1):
        raise EroadInputError(f"--segments must be an integer >= 1, got {segments!r}")
    check_out(out, force)
    drive = read_drive(dataset)
    from drives.cut import require_road_record
    from drives.rate import for_road_methods
    drive, resampled = for_road_methods(drive)   # above the vehicle's solver rate: to 200 Hz
    from drives.format import CHANNELS_FILE
    reference_axle(drive.channel_names, f"{drive.path / CHANNELS_FILE}: eroad invert")
    require_road_record(drive, "eroad invert")   # the road methods run in distance
    n_cand = int(candidates if candidates is not None else (6 if quick else 16))
    iters = int(max_iter if max_iter is not None else (3 if quick else 12))
    if n_cand < 0 or iters < 1:
        raise EroadInputError("--candidates must be >= 0 (0: keep the fit's phases) and --max-iter >= 1")
    if selection not in ("linear", "simulation"):
        raise EroadInputError(f"--selection must be 'linear' or 'simulation', got {selection!r}")

    time = np.asarray(drive.time, float)
    sim_names, fitted = fit_plan(drive.channel_names, channels)
    chans = {c: drive.channels[c].to_numpy(float) for c in sim_names}
    speed = np.asarray(drive.speed, float)
    # the axle whose displacements segment the drive and place the segments on the road:
    # axle 3 where fitted, else the fitted pair (a logger on another axle)
    ref = reference_axle(list(chans))
    seg_disp = [f"susp_disp_{ref}L", f"susp_disp_{ref}R"]
    fit_cfg = FitConfig(max_iter=iters, n_workers=1, **({} if polish else {"polish_replicates": 0}))
    bounds = ParamBounds(nmax=(1.0, nmax_cap(SIM_DX)))
    fs = 1.0 / float(np.median(np.diff(time)))
    noise_psd = noise_psd_from_sd(noise_sd, list(drive.channel_names), fs) if noise_sd else None
    from inverse.uncertainty import calibration_key
    cset = channel_set(fitted, drive.channel_names)
    ckey, calibrated = calibration_key(fit_model, cset)
    from inverse.features import FeatureSpec
    # the features of the fitted channels (the segmentation's displacements may be simulated only)
    spec = FeatureSpec(channels=tuple(sorted(fitted)))
    icfg = InversionConfig(k=segments, fit=fit_cfg, bounds=bounds, seed=seed, noise_psd=noise_psd,
                           fit_model=fit_model, model_form=model_form, calibration=ckey, segment_on=segment_on,
                           feature_spec=spec)
    solver = SIM_SOLVER if solver is None else str(solver)
    make_sim = make_truck_simulator(drive, effects=effects, chassis=chassis, channels=list(chans), ref_axle=ref,
                                    solver=solver)
    predict = TruckPredictRms(drive.vehicle, tuple(seg_disp), chassis=chassis, effects=effects)

    pool = None
    map_fn = map
    if workers > 1:
        from eroad.threads import process_pool
        pool = process_pool(workers, initializer=_warm_worker)
        pool.submit(int)       # start the workers now: their imports overlap the segmentation
        map_fn = pool.map
    timing = {}
    if bar is not None:
        bar.reset(total=iters + 2)   # the start, the iterations, the polish (an early stop ends short)
        bar.set_description("invert: fit")
    try:
        t1 = _time.perf_counter()
        inv = invert(time, chans, speed, make_sim, predict_rms=predict, config=icfg, map_fn=map_fn,
                     segment_channels=seg_disp,
                     progress=None if bar is None else (lambda entry: bar.update(1)))
        timing["fit_s"] = _time.perf_counter() - t1
        sim = make_sim(inv.t_bounds)
        params = inv.fit.params
        fit_seed = stream_seed(seed, SEED_KEY_FIT)
        seeds = [fit_seed] + candidate_seeds(seed, n_cand)
        labels = ["fit"] + [f"c{i}" for i in range(n_cand)]
        table_ch = [c for c in table2_channels(ref) if c in chans]
        sel_ch = select_channels(ref)
        sel_map = map_fn
        if bar is not None:
            # linear: the fit's simulation, every candidate's linear response, usually one round of 2
            bar.reset(total=len(seeds) + (3 if selection == "linear" and n_cand else 0))
            bar.set_description("invert: road realisations")

            def sel_map(func, items):   # one step per finished candidate simulation
                for r in map_fn(func, items):
                    bar.update(1)
                    yield r
        from drives.format import swap_into_place, temp_folder_beside

        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = temp_folder_beside(out)
        (tmp / "tables").mkdir()

        def select_and_draw():
            """The realisation selection, then the figures (in a worker when there is a pool)."""
            t = _time.perf_counter()
            # one seed for both tracks: a per-side choice by the reported RMS would tune Table 2 to itself
            if selection == "linear" and n_cand > 0:
                from inverse.linear_response import LinearRealisation

                sel = select_realisation_linear(sim, LinearRealisation(sim), road_p, chans, seeds,
                                                channels=sel_ch,
                                                table_channels=table_ch, map_fn=sel_map, labels=labels,
                                                per_round=max(1, workers))
            else:
                sel = select_realisation(sim, road_p, chans, seeds, channels=sel_ch,
                                         table_channels=table_ch, map_fn=sel_map, labels=labels, sides=False)
                sel.update(method="simulation", n_simulated=len(seeds), fit_simulated=sel.pop("simulated_all")[0])
            timing["selection_s"] = _time.perf_counter() - t
            timing["selection_sims"] = int(sel["n_simulated"])
            if bar is not None:
                bar.set_description("invert: report")
            fig_kw = dict(time=time, measured=chans, simulated=sel["simulated"], segmentation=inv.segmentation,
                          seg_signal=chans[seg_disp[0]], title=f"({drive.name})", axle=ref)
            # Figures 8 and 9 need the chosen realisation: one pool worker each
            figures = ([pool.submit(write_figures, tmp / "figures", which=w, **fig_kw) for w in "89"]
                       if pool is not None else None)
            return sel, fig_kw, figures

        # the road model of each segment, one ISO slope or two (inverse.road_model), first:
        # the road the selection realises and road.npz holds is the one the report describes
        t = _time.perf_counter()
        segs = inv.segments()
        from inverse.road_model import add_road_models, road_params, select_road_models
        add_road_models(segs, select_road_models(inv, sim, speed, road_model, map_fn=map_fn))
        road_p = road_params(params, segs)
        timing["road_model_s"] = _time.perf_counter() - t
        sel_thread = None
        try:
            # Figure 6 needs the fit only: drawn now (in a pool worker: the selection leaves the
            # workers mostly idle, its 3 simulations aside)
            fig6_kw = dict(time=time, measured=chans, simulated=None, segmentation=inv.segmentation,
                           seg_signal=chans[seg_disp[0]], title=f"({drive.name})", which="6", axle=ref)
            fig6 = None
            if pool is None:
                write_figures(tmp / "figures", **fig6_kw)
            else:
                fig6 = pool.submit(write_figures, tmp / "figures", **fig6_kw)
            # With a pool, the selection (and then the figures) run from a thread of this process
            # on the pool's workers, while this process computes what needs the fit only: the
            # lateral-structure sensitivity.
            if pool is not None:
                from concurrent.futures import ThreadPoolExecutor
                sel_thread = ThreadPoolExecutor(1)
                sel_job = sel_thread.submit(select_and_draw)
            from inverse.lateral import note_line, run_summary

            t = _time.perf_counter()
            lateral = run_summary(drive.vehicle, segs, time, speed, list(chans), effects=effects, chassis=chassis)
            timing["lateral_s"] = _time.perf_counter() - t
            if sel_thread is None:
                sel, fig_kw, figures = select_and_draw()
            else:
                try:
                    sel, fig_kw, figures = sel_job.result()
                finally:
                    sel_thread.shutdown()
            simulated = sel["simulated"]
            rows = response_table(chans, simulated, table_ch)
            fit_rows = response_table(chans, sel["fit_simulated"], table_ch) if sel["label"] != "fit" else rows
            inv_summary = inv.summary()
            summary = {
                "format": RUN_FORMAT,
                "dataset": {"name": drive.name, "path": dataset_path(dataset, out), "vehicle": str(drive.vehicle),
                            "duration_s": drive.duration_s, "sample_rate_hz": drive.sample_rate_hz,
                            "warnings": list(drive.warnings), "resampled": resampled,
                            "speed_check": drive.speed_check},
                "segments": segs,
                "fit_quality": overall_fit_quality(segs),
                "table2": rows,
                "errors": headline(rows, sel["spread"]),
                "selection": {"n_candidates": len(seeds), "selected": sel["label"], "seed": sel["seed"],
                              "statistic": f"sum of w_c ln(rms_sim/rms_meas)^2 over axle_acc_{ref}L/R (w 1) and "
                                           f"susp_disp_{ref}L/R (w 0.25), plus ln(mean_abs ratio)^2 of "
                                           f"axle_acc_{ref}L/R",
                              "method": sel["method"], "n_simulated": sel["n_simulated"],
                              "rounds": sel.get("rounds"), "correction": sel.get("correction"),
                              "per_side": bool(sel.get("sides")), "mismatch": sel["mismatch"],
                              "sides_rejected": sel.get("sides_rejected"),
                              "spread": sel["spread"],
                              "candidates": sel["candidates"],
                              "fit_phases_errors": headline(fit_rows)},
                "fit": {**inv_summary["fit"], "channels": list(fitted), "simulated_channels": list(chans),
                        "channel_set": cset, "reference_axle": ref,
                        "uncertainty_calibration": ckey, "uncertainty_calibrated_for_channels": calibrated},
                "segmentation": inv_summary["segmentation"],
                "road": {"file": "road.npz", "crg": "road.crg", "seed": sel["seed"], "dx": SIM_DX,
                         "seg_lengths_m": [float(v) for v in sim.layout()["seg_lengths"]]},
            }
            summary["lateral"] = lateral
            write_table(table1(segs), tmp / "tables" / "table1",
                        note=table1_note(summary["fit_quality"], segments=summary["segments"], model_form=model_form,
                                         channels=(cset, calibrated)) + "\n\n" + note_line(summary["lateral"]))
            basis = ""
            if sel["method"] == "linear":
                basis = (f" Realisations: {sel['n_simulated']} of {len(seeds)} simulated in time, the others the "
                         "linear truck's time response on the same road corrected by the mean log ratio "
                         "simulated / linear of the simulated ones (tables/candidates.csv, column basis).")
            write_table(table2(rows, sel["spread"]), tmp / "tables" / "table2", note=table2_note(ref) + basis)
            import pandas as pd
            pd.DataFrame([{"label": c["label"], "seed": c["seed"], "mismatch": c["mismatch"],
                           "basis": c.get("basis", "simulated"),
                           **{f"rms_err_{k}": v for k, v in c["rms_err"].items()}} for c in sel["candidates"]]
                         ).to_csv(tmp / "tables" / "candidates.csv", index=False)
            road = sim.road(road_p, sel["seed"])
            road.save(tmp / "road.npz")
            road.save(tmp / "road.crg")
            write_json_atomic(tmp / "history.json", inv.fit.history)
            import tomli_w
            cfg = {"dataset": dataset_path(dataset, out),
                   "segments": segments if segments is not None else "auto",
                   "noise_sd": dict(noise_sd or {}), "polish": bool(polish),
                   "workers": workers, "seed": seed, "quick": quick, "candidates": n_cand, "max_iter": iters,
                   "chassis": chassis, "channels": list(fitted), "simulated_channels": list(chans),
                   "effects": json.dumps(effects or {}),
                   "fit_model": fit_model, "selection": selection, "model_form": model_form, "solver": solver,
                   "channel_set": cset, "uncertainty_calibration": ckey,
                   "simulator": {"dx_m": SIM_DX, "nmax_cap_cpm": nmax_cap(SIM_DX)},
                   "bounds": {k: list(getattr(bounds, k)) for k in ("Gq_n0", "w", "nmin", "nmax")}}
            (tmp / "config.toml").write_text(tomli_w.dumps(cfg))
            if figures is None:
                write_figures(tmp / "figures", which="89", **fig_kw)
            else:
                for f in [fig6, *figures]:
                    f.result()
            timing["total_s"] = _time.perf_counter() - t0
            # the wall the report adds after the selection (the road model and the lateral
            # summary ran during the selection when there was a pool)
            timing["report_s"] = timing["total_s"] - timing["fit_s"] - timing["selection_s"]
            timing["n_sims"] = int(inv.fit.n_sims + sel["n_simulated"])
            timing["workers"] = workers
            timing["solver"] = solver
            summary["timing"] = timing
            summary["history"] = inv.fit.history
            write_json_atomic(tmp / "summary.json", summary)
            write_run_json(tmp, finish_run_info(record, "complete", wall_s=timing["total_s"]))
            swap_into_place(tmp, out)   # an old RUN (--force) is removed only once the new one is in place
        except BaseException:
            if sel_thread is not None:
                sel_thread.shutdown(wait=False, cancel_futures=True)
            shutil.rmtree(tmp, ignore_errors=True)
            raise
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)
    return summary


def _warm_worker() -> None:
    """Pool initializer: the imports a worker will need (the simulator, the figures)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401

    import vehicles.simulate  # noqa: F401


def dataset_path(dataset, run) -> str:
    """The dataset folder as recorded in a run: relative to the run folder ``run``
    (``/``-separated), so the record holds when both move together."""
    return Path(os.path.relpath(Path(dataset).resolve(), Path(run).resolve())).as_posix()


def relocate(run, dataset) -> None:
    """Re-record the dataset path of an inversion run folder that was moved to ``run``
    (summary.json's ``dataset.path``, config.toml's ``dataset``, run.json's ``run_id``)."""
    import tomllib

    import tomli_w

    run = Path(run)
    rel = dataset_path(dataset, run)
    sf = run / "summary.json"
    if sf.is_file():
        summary = json.loads(sf.read_text())
        summary.setdefault("dataset", {})["path"] = rel
        write_json_atomic(sf, summary)
    rf = run / "run.json"
    if rf.is_file():
        write_json_atomic(rf, {**json.loads(rf.read_text()), "run_id": run.name})
    cf = run / "config.toml"
    if cf.is_file():
        cfg = tomllib.loads(cf.read_text())
        cfg["dataset"] = rel
        cf.write_text(tomli_w.dumps(cfg))


def headline(rows: list, spread: dict | None = None) -> dict:
    """Per channel relative errors [-] of the RMS and the rectified mean.

    With ``spread`` (over the candidate realisations) ``rms_err`` and ``mean_err`` are the
    MEDIANS over the realisations, with their 16th/84th percentiles beside them, and the
    selected realisation's values under ``selected``; without it (the selected
    realisation's rows only) they are that realisation's, as ``basis`` says.  ``mean_err``
    is the error of the RECTIFIED mean (Table 2's rect_mean); the same values are also
    under ``rect_mean_err*``, the name that says so.
    """
    out = {}
    for r in _headline_rows(rows, spread):
        out[r[0]] = r[1]
    return out


def _with_rect_names(d: dict) -> dict:
    """``mean_err*`` (kept for scripts written against it) is the relative error of the
    RECTIFIED mean, mean |y - mean y|; the same values also under ``rect_mean_err*``."""
    return {**d, **{k.replace("mean_err", "rect_mean_err"): v for k, v in d.items()
                    if k.startswith("mean_err")}}


def _headline_rows(rows: list, spread: dict | None):
    for r in rows:
        if math.isnan(r["rms_err"]):
            continue
        sel = {"rms_err": r["rms_err"], "mean_err": r["mean_abs_err"],
               "rmse_eq6_norm": r["rmse_eq6_norm"], "wasserstein": r["wasserstein"]}
        sp = (spread or {}).get(r["channel"])
        if sp and "mean_abs_median" in sp:
            row = {"rms_err": sp["median"], "rms_err_p16": sp["p16"], "rms_err_p84": sp["p84"],
                   "mean_err": sp["mean_abs_median"], "mean_err_p16": sp["mean_abs_p16"],
                   "mean_err_p84": sp["mean_abs_p84"],
                   "rmse_eq6_norm": r["rmse_eq6_norm"], "wasserstein": r["wasserstein"],
                   "basis": f"median over {sp['n']} realisations"}
            yield r["channel"], _with_rect_names({**row, "selected": _with_rect_names(sel)})
        else:
            yield r["channel"], _with_rect_names({**sel, "basis": "selected realisation"})
