"""The loop closed: diagnose a drive, then invert it with the effect the diagnosis names.

What this module is for: ``eroad invert DATASET --effects auto`` and ``eroad reproduce``.
An inversion with the nominal model on a drive whose vehicle differs from it puts the
difference into the road (the leaf-friction gap of the embedded dataset moved its levels
by a factor 0.3-1.4); the diagnosis finds the difference but, until now, nothing used it.
Here the diagnosis runs first (nominal model, its own cheap road fit), and where it names
an effect whose calibration is an estimate (not on its search range's edge) the drive is
inverted twice, with the nominal model and with the named effect at its calibrated value,
side by side; the corrected inversion is the run's result (its road goes on to Figure 11
and the chassis study). Where the verdict is ``none``, or the named effect calibrates at a
range edge, the nominal inversion is the result and the report says why no correction was
made. An ``unexplained`` verdict is corrected only with a closest effect that changes the
vehicle itself and explains most of the gap (:func:`closest_vehicle_effect`).

Why a name with confidence ``ambiguous`` is used too (2026-11-28): the confidence says
whether the data single the effect out (a rival within noise, a transmissibility the
effect cannot confirm, a remainder beside it), not whether the name is right: re-decided
with today's rules, the names this rule adds to the corrected ones were right in 72 of 74 on
the twelve saved 40-case blind sets of both trucks (wrong: a damper asymmetry on a drive
without an effect, a tyre enveloping for a sensor low-pass) and in 93 of 98 over every saved
blind summary, older sets and reruns included. Leaving a right name out leaves its bias in
the road: on 20 friction drives with the loop closed, the four named ``ambiguous`` carried
errors of -0.86 to -1.53 in ln G(1 cycle/m) with the nominal model and +0.31 at most
corrected (results/inverse_blind/20261128-correct-on-ambiguous/).

What it is not: a diagnosis or an inversion of its own; it calls
:func:`diagnosis.pipeline.diagnose` and :func:`inverse.run.run_inversion`, and writes::

    RUN/                 the chosen inversion's run folder (summary.json, tables, figures, road)
    RUN/diagnose/        the diagnosis (report.md, summary.json, figures)
    RUN/nominal/         the nominal inversion, where a corrected one was made
    RUN/tables/table1_nominal_vs_corrected.{csv,md}
    summary.json         gains ``closed_loop``: verdict, confidence, effects used, reason,
                         and the nominal segments beside the corrected ones
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd

from eroad.errors import EroadInputError


def effects_from_diagnosis(summary: dict, action: str = "inverted") -> tuple[dict | None, str]:
    """The effects to invert with, from a diagnosis summary, and why.

    Parameters
    ----------
    summary : dict
        ``diagnose``'s summary.json.
    action : str
        What the caller does with the effects, for the reason line ("inverted",
        "reconstructed").

    Returns
    -------
    effects : dict or None
        ``{effect: {parameter: value}}`` (the calibrated candidate's parameters) when the
        verdict names an effect (any confidence) whose calibration is not at an edge of its
        search range (``verdict_detail.edge`` empty: an edge value is a bound, not an
        estimate), or when it is ``unexplained`` and its closest effect qualifies
        (:func:`closest_vehicle_effect`); None otherwise.
    reason : str
        One line for the report.
    """
    verdict = summary.get("verdict", "none")
    conf = summary.get("verdict_confidence", "none")
    detail = summary.get("verdict_detail") or {}
    if verdict == "unexplained":
        closest = closest_vehicle_effect(summary)
        if closest is None:
            return None, "the diagnosis answered 'unexplained': the nominal model is kept"
        params, share = closest
        name = next(iter(params))
        why = ("its road-independent signature does not agree" if detail.get("signature_agrees") is False
               else "the verdict's other tests did not single it out")
        return params, (f"the diagnosis answered 'unexplained' (no library effect passed all of its tests), but "
                        f"its closest effect, {name}, changes the vehicle itself and explains "
                        f"{100 * share:.0f} % of the held-out gap with a clear ranking; {action} with {_describe(params)} "
                        f"as the nearest description of the vehicle ({why}: something beyond it may remain)")
    if verdict in ("none", None):
        return None, f"the diagnosis answered '{verdict}': the nominal model is kept"
    identified = bool(detail.get("identified"))
    edge = list(detail.get("edge") or [])
    if edge:
        return None, (f"the diagnosis named {verdict} but it calibrates at the edge of its search range "
                      f"({', '.join(map(str, edge))}): the value is a bound, not an estimate, so the "
                      f"nominal model is kept")
    params = _ranking_parameters(summary, verdict)
    fb = (summary.get("meta") or {}).get("force_balance") or {}
    if params is None and detail.get("named_on") == "force_balance" and fb.get("available"):
        params = {"leaf_friction": {"force": float(fb["force_N"])}}
    if params is None:
        return None, f"the diagnosis named {verdict} but recorded no calibrated parameters: nominal model kept"
    text = _describe(params)
    how = ("confidence clear" if conf == "clear" else "identified; a difference beyond it remains"
           if identified else f"confidence '{conf}': not singled out, the nearest library effect")
    return params, f"the diagnosis named {verdict} ({how}); {action} with {text}"


#: the share of the held-out gap (``verdict_detail.explained_share``) the closest library effect
#: of an ``unexplained`` verdict must explain, with a clear ranking and an effect on the vehicle
#: itself, for the loop to correct with it (:func:`closest_vehicle_effect`). Chosen on the saved
#: blind diagnoses (2026-11-28; results/inverse_blind/20261128-closest-vehicle-effect/
#: closest_names.py): of the 155 `unexplained` verdicts, the 12 whose closest effect acts on the
#: vehicle (suspension terms or masses), explained >= 0.6 of the gap with a clear ranking and
#: calibrated inside its range were all the planted effect; at >= 0.5 one more came in, wrong
#: (a damper asymmetry for a leaf friction of the independent truck). The 15 such verdicts whose
#: closest effect acts on the road input or the recorded channels (sensor, tyre enveloping) were
#: right in 3: the independent truck on a band-limited road looks like a sensor low-pass.
CLOSEST_SHARE_MIN = 0.6


#: the loop's leaf-friction force from the body's force balance (:mod:`diagnosis.force_balance`,
#: no road) instead of the diagnosis's calibrated value, where the balance is available and
#: detects friction.  Stated and tested at stop 74 (results/diagnosis_blind/20261201-force-balance/)
FRICTION_FROM_BALANCE = True


def friction_from_balance(effects: dict | None, reason: str, dataset) -> tuple[dict | None, str, dict | None]:
    """Where the effects to invert with hold a leaf friction: its force from the body's force
    balance, road-independent, where the diagnosis's calibration went through a fitted road
    (its value scatters by about 0.25 in ln, docs/inverse.md).  Kept as calibrated where the
    balance is not available (channels missing, a poor balance) or does not see friction.

    Returns ``(effects, reason, balance)``: the effects (a copy when changed), the reason line
    with what was done, the balance's result (None where no leaf friction is used).
    """
    if not FRICTION_FROM_BALANCE or not effects or "leaf_friction" not in effects:
        return effects, reason, None
    from diagnosis.force_balance import describe, leaf_friction
    from drives.format import read_drive

    fb = leaf_friction(read_drive(dataset))
    old = effects["leaf_friction"].get("force")
    if not fb.get("available"):
        return effects, f"{reason}; {describe(fb)}: the calibrated force kept", fb
    if not fb["detected"]:
        return effects, (f"{reason}; the body's force balance does not see the friction ({fb['force_N']:.0f} N, "
                         f"sd {fb['sd_N']:.0f} N): the calibrated force kept"), fb
    new = {k: dict(v) for k, v in effects.items()}
    new["leaf_friction"]["force"] = float(fb["force_N"])
    lo, hi = fb["interval_90_N"]
    was = f"; the diagnosis's calibration gave {old:.0f} N" if isinstance(old, (int, float)) else ""
    return new, (f"{reason.replace(_describe(effects), _describe(new))} (the friction force from the body's "
                 f"force balance, no road needed: 90 % {max(lo, 0):.0f}-{hi:.0f} N{was})"), fb


def closest_vehicle_effect(summary: dict) -> tuple[dict, float] | None:
    """An ``unexplained`` verdict's closest library effect, when the loop corrects with it.

    The verdict says no library effect passed both tests (a share of the held-out gap AND a
    road-independent signature that agrees). Where the closest effect still explains at least
    :data:`CLOSEST_SHARE_MIN` of the gap with a clear ranking, calibrates inside its search range
    and changes the vehicle itself (``Effect.acts_on_vehicle``: suspension terms or masses, which
    the road's spectrum cannot mimic), it is the nearest description of the vehicle the library
    has: on our truck with leaf friction and a flexible frame (signature off because of the
    frame) the three such drives of 40 went from ln G(1 cycle/m) errors of -0.5 to -1.8 in 6 of
    11 segments to 1 of 11 outside 20 %. An effect on the road input or the recorded channels is
    never used here: corrected with its closest sensor low-pass, three measured-road drives of the
    independent truck moved from +0.15..+0.65 to +1.3..+2.0 in ln G(1).

    Returns ``({effect: {parameter: value}}, explained share)`` or None.
    """
    from diagnosis.verdict import acts_on_vehicle

    if summary.get("verdict") != "unexplained":
        return None
    detail = summary.get("verdict_detail") or {}
    name = detail.get("closest")
    share = detail.get("explained_share")
    if (not acts_on_vehicle(name) or detail.get("ranking_confidence") != "clear"
            or share is None or share < CLOSEST_SHARE_MIN or detail.get("edge")):
        return None
    params = _ranking_parameters(summary, name)
    return None if params is None else (params, float(share))


def _ranking_parameters(summary: dict, effect: str) -> dict | None:
    """The calibrated parameters of ``effect``'s own ranking entry, ``{effect: {parameter: value}}``."""
    entry = next((r for r in summary.get("ranking", []) if r.get("effect") == effect), None)
    if entry is None or not entry.get("parameters"):
        return None
    return {str(k): {str(p): float(v) for p, v in d.items()} for k, d in entry["parameters"].items()}


def _describe(params: dict) -> str:
    """``effect.parameter=value, ...`` for the reason line."""
    return ", ".join(f"{k}." + ", ".join(f"{p}={v:.4g}" for p, v in d.items()) for k, d in params.items())


#: the channels the closed loop fits where the diagnosis answers ``none`` and the caller chose
#: none (:func:`inverse.run.axles_channels`): where the model explains the drive, every axle's
#: accelerations average the noise and the road's realisation over more stations (on 20 fresh
#: blind null drives, 18 answered 'none': G(1 cycle/m) within 20 % in 86 % of the segments
#: against 77 % for axle 3, class right 88 % against 86 %), while
#: a vehicle difference left in the model reaches more channels and biases the road further
#: (friction drives, loop closed: 63 % against 80 %), so every other verdict keeps axle 3.
#: results/inverse_blind/20261124-channels-all-axles/ and .../20261124-axles-when-none/
CHANNELS_WHEN_NONE = "axles"
#: the channels the closed loop fits where the diagnosis answers ``unexplained`` and the caller
#: chose none: axle 3's axle accelerations alone (its suspension displacements still segment the
#: drive). A gap no library effect explains is a vehicle the model does not describe; the
#: displacements carry the body's motion at 0.5-3 Hz, where such a difference shows most, while
#: the axle accelerations are dominated by the tyre and the road around the wheel hop. Measured
#: (2026-11-28, results/inverse_blind/20261128-correct-on-ambiguous/): on the independently
#: written truck (20 drives, closed loop, 14 'unexplained') G(1 cycle/m) within 20 % 75.9 ->
#: 81.0 % of 58 segments (paired 5 / 2), class 82.8 -> 86.2 %; on its measured-road drives 2 -> 5
#: of 12 fitted segments against the profile; on the friction drives the one 'unexplained' drive
#: lost 2 segments by 0.01 in ln G. Only where axle 3 is the drive's reference axle (the set with
#: its own interval constants, inverse.uncertainty.CALIBRATIONS["linear/axle3_acc"]).
CHANNELS_WHEN_UNEXPLAINED = "axle3_acc"


def loop_channels(verdict: str | None, channels=None, available=None) -> tuple:
    """The fitted channels of a closed loop's inversions and the phrase that says why.

    ``channels`` given by the caller are kept (the phrase is empty); None: ``axles``
    (:data:`CHANNELS_WHEN_NONE`) where the verdict is ``none``, ``axle3_acc``
    (:data:`CHANNELS_WHEN_UNEXPLAINED`) where it is ``unexplained`` and axle 3 is the drive's
    reference axle with both axle accelerations logged, else None: the inversion's default,
    axle 3 (or the reference axle of a drive logged elsewhere, ``inverse.run.reference_axle``).
    ``available`` (the drive's channel names): where ``axles`` holds no more than the default
    (a drive logged on one axle), the default is kept and the phrase says so. Without
    ``available`` the drive is taken to log axle 3.
    """
    if channels is not None:
        return channels, ""
    if verdict == "unexplained":
        if available is not None:
            from inverse.run import PREFERRED_AXLE, axle_channels, reference_axle
            acc = {c for c in axle_channels(PREFERRED_AXLE) if c.startswith("axle_acc_")}
            if (reference_axle(available) != PREFERRED_AXLE
                    or not acc <= set(available)):
                return None, ""
        return CHANNELS_WHEN_UNEXPLAINED, ("a gap no library effect fully explains, so axle 3's axle accelerations "
                                           "alone are fitted (channel set 'axle3_acc'; the suspension "
                                           "displacements, where the body's motion shows, only segment the drive)")
    if verdict == "none":
        if available is not None:
            from inverse.run import fit_channels
            if set(fit_channels(available, CHANNELS_WHEN_NONE)) == set(fit_channels(available, None)):
                return None, ("no gap beyond noise; the drive logs one axle's accelerations, so its default "
                              "channels are fitted")
        return CHANNELS_WHEN_NONE, ("no gap beyond noise, so the accelerations of every axle are fitted "
                                    "(channel set 'axles')")
    return None, ""


def loop_verdict(summary: dict) -> str | None:
    """The verdict the loop chooses its channels and model form by: the diagnosis's, except that
    an effect named as a vehicle difference (``verdict_detail.named_on == "vehicle_share"``:
    a vehicle effect explaining most of the gap whose transmissibility does not confirm it,
    ``diagnosis.verdict.VEHICLE_SHARE_MIN``) is fitted as the ``unexplained`` drive it was
    before the verdict named it: axle 3's accelerations, the unexplained model-form term. The
    effect and its value are the same either way (:func:`closest_vehicle_effect` corrected with
    it), so the loop's inversions of those drives are unchanged."""
    if (summary.get("verdict_detail") or {}).get("named_on") == "vehicle_share":
        return "unexplained"
    return summary.get("verdict")


def singled_out(summary: dict) -> bool:
    """Whether the diagnosis singled its named effect out: confidence ``clear``, or
    ``identified`` (a remainder beside an undisputed effect)."""
    return (summary.get("verdict_confidence") == "clear"
            or bool((summary.get("verdict_detail") or {}).get("identified")))


def model_form(verdict: str | None, corrected: bool, singled: bool = True) -> str:
    """The model-form state of a closed loop's reported inversion
    (:data:`inverse.uncertainty.MODEL_FORMS`): "diagnosed" where the diagnosis found no gap
    beyond noise (``none``) or named an effect it singled out (``singled``,
    :func:`singled_out`) that the inversion then carries (``corrected``); "unexplained" where
    the gap is one no library effect fully explains, corrected or not (its own term where the
    fitted channels have one, ``BETA_UNEXPLAINED`` of axle 3's accelerations, set on the saved
    loops' unexplained drives with the measured-road segments as a second check; else the open
    term -- the diagnosed one covered ln G(n_best) in 6 of 10 measured-road segments, docs/inverse.md
    section 11); "open" where a vehicle difference may be left unaccounted for: an effect named at
    an edge of its search range (not carried, :func:`effects_from_diagnosis`), or a correction with a name
    short of that (``ambiguous``: the nearest library effect, which may leave part of the
    difference in the road -- on 20 fresh friction drives with a flexible frame the smaller
    term covered ln G(n_best) in 82 % of the segments, the open one on those corrections in
    86 %; results/inverse_blind/20261128-correct-on-ambiguous/)."""
    if verdict == "unexplained":
        return "unexplained"
    return "diagnosed" if verdict == "none" or (corrected and singled) else "open"


def _start(out, force: bool) -> tuple[Path, Path]:
    """A closed loop's output folder (refused if non-empty unless ``force``) and the
    temporary work folder beside it that is renamed into place at the end."""
    from drives.format import temp_folder_beside
    from inverse.run import check_out

    out = Path(out)
    check_out(out, force)
    out.parent.mkdir(parents=True, exist_ok=True)
    return out, temp_folder_beside(out)


def _diagnosis_summary(dataset, work: Path, diagnosis, copy: bool, workers: int, quick: bool, seed: int,
                       progress, out: Path | None = None) -> dict:
    """The diagnosis of a closed loop: a given run folder's summary (copied to work/diagnose
    when ``copy``), or a fresh diagnosis written there."""
    if diagnosis is not None:
        if not (Path(diagnosis) / "summary.json").is_file():
            raise EroadInputError(f"{diagnosis}: not a diagnosis run folder (no summary.json)")
        if copy:
            shutil.copytree(diagnosis, work / "diagnose")
        return json.loads((Path(diagnosis) / "summary.json").read_text())
    from diagnosis.pipeline import diagnose

    progress("closed loop: diagnosing the nominal model's gap ...")
    # the diagnosis's own lines go where the loop's go (none with --quiet); it writes into the
    # loop's temporary folder, which becomes the run folder: name that one

    def say(msg: str) -> None:
        progress(str(msg).replace(str(work), str(out)) if out is not None else msg)
    return diagnose(dataset, work / "diagnose", workers=workers, quick=quick, force=True, seed=seed,
                    progress=say)


def still_poor_message(fit_quality: dict, effects: dict) -> str:
    """The gate's one line for a corrected fit that is still poor: the advice to run the
    diagnosis has been followed, so say what is left instead."""
    names = ", ".join(effects)
    segs = ", ".join(str(i) for i in fit_quality.get("poor_segments", []))
    return (f"segment(s) {segs} exceed the fit-quality gate even with {names} at its calibrated value: "
            f"what the model still lacks there is not that effect alone (another difference of the "
            f"vehicle, or a segment the stationary model does not hold); read their numbers with "
            f"their wide intervals")


def compare_table(nominal: list, corrected: list) -> pd.DataFrame:
    """Table 1 nominal beside corrected (:func:`inverse.report.table1` rows of each fit,
    labelled by model; the two segmentations may differ, so rows are by fit): segment,
    times, class, Gq(n0), w, the 90 % interval of Gq(n0) and the fit-quality gate."""
    from inverse.report import table1

    cols = ["model", "segment", "t_start_s", "t_end_s", "class", "Gq_n0_1e-6m3", "w",
            "Gq_n0_90pct_1e-6m3", "fit", "misfit_per_feature"]
    parts = [table1(segs).assign(model=label) for label, segs in (("nominal", nominal), ("corrected", corrected))
             if segs]
    if not parts:
        return pd.DataFrame(columns=cols)
    df = pd.concat(parts, ignore_index=True)
    return df[[c for c in cols if c in df.columns]]


def invert_closed_loop(dataset, out, *, workers: int = 2, seed: int = 0, quick: bool = False,
                       force: bool = False, argv=None, diagnosis=None, progress=print, **inversion) -> dict:
    """Diagnose ``dataset``, then invert it nominal and, on a clear verdict, corrected.

    Parameters
    ----------
    dataset, out : str or Path
        Dataset folder; run folder to create (refused if non-empty unless ``force``).
    workers, seed, quick : see :func:`inverse.run.run_inversion`.
    diagnosis : str or Path, optional
        An existing diagnosis run folder of this dataset to use instead of diagnosing again.
    progress : callable
        One-line progress messages.
    **inversion
        Further keyword arguments of :func:`inverse.run.run_inversion` (not ``effects``);
        ``channels`` None or absent: chosen by the verdict (:func:`loop_channels`).

    Returns
    -------
    dict
        The chosen inversion's summary with ``closed_loop`` added.
    """
    from drives.format import swap_into_place
    from eroad.archive import write_json_atomic
    from inverse.report import write_table
    from inverse.run import dataset_path, relocate, run_inversion

    if "effects" in inversion:
        raise EroadInputError("--effects auto and explicit --effect values cannot be combined")
    out, work = _start(out, force)
    try:
        dsum = _diagnosis_summary(dataset, work, diagnosis, True, workers, quick, seed, progress, out)
        effects, reason = effects_from_diagnosis(dsum)
        effects, reason, balance = friction_from_balance(effects, reason, dataset)
        from drives.format import read_drive
        inversion["channels"], why = loop_channels(loop_verdict(dsum), inversion.get("channels"),
                                                   read_drive(dataset).channel_names)
        reason = f"{reason}; {why}" if why else reason
        progress(f"closed loop: {reason}")
        progress("closed loop: nominal inversion ...")
        nominal = run_inversion(dataset, work / "nominal", workers=workers, seed=seed, quick=quick,
                                argv=argv, model_form=model_form(loop_verdict(dsum), False), **inversion)
        if effects:
            progress("closed loop: corrected inversion ...")
            chosen = run_inversion(dataset, work / "corrected", workers=workers, seed=seed, quick=quick,
                                   effects=effects, argv=argv,
                                   model_form=model_form(loop_verdict(dsum), True, singled_out(dsum)),
                                   **inversion)
            main = work / "corrected"
            (work / "nominal").rename(main / "nominal")
            fq = chosen.get("fit_quality", {})
            if fq.get("status") == "poor":   # the named effect did not make the model explain it
                fq["message"] = still_poor_message(fq, effects)
                from inverse.report import table1, table1_note
                fit = chosen["fit"]
                write_table(table1(chosen["segments"]), main / "tables" / "table1",
                            note=table1_note(fq, segments=chosen["segments"], model_form=fit["model_form"],
                                             channels=(fit["channel_set"], fit["uncertainty_calibrated_for_channels"])))
        else:
            chosen, main = nominal, work / "nominal"
        (work / "diagnose").rename(main / "diagnose")
        chosen["closed_loop"] = {
            "verdict": dsum.get("verdict"), "confidence": dsum.get("verdict_confidence"),
            "effects": effects or {}, "corrected": bool(effects), "reason": reason,
            "model_form": chosen.get("fit", {}).get("model_form"),
            "channel_set": chosen.get("fit", {}).get("channel_set"),
            "diagnosis": "diagnose/summary.json",
            "force_balance": balance,
            "nominal_segments": nominal["segments"] if effects else None,
            "nominal_fit_quality": nominal.get("fit_quality") if effects else None}
        write_table(compare_table(nominal["segments"], chosen["segments"] if effects else []),
                    main / "tables" / "table1_nominal_vs_corrected",
                    note=f"Closed loop: {reason}.")
        chosen.setdefault("dataset", {})["path"] = dataset_path(dataset, out)
        write_json_atomic(main / "summary.json", chosen)
        swap_into_place(main, out)
        relocate(out, dataset)
        if (out / "nominal").is_dir():
            relocate(out / "nominal", dataset)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return chosen


def replica_closed_loop(dataset, out, *, workers: int = 2, seed: int = 0, quick: bool = False,
                        force: bool = False, argv=None, diagnosis=None, copy_diagnosis: bool = True,
                        progress=print, **replica) -> dict:
    """``eroad replica DATASET --effects auto``: diagnose, then reconstruct the road with the
    effect the diagnosis names (the same rule as :func:`invert_closed_loop`: only a
    ``clear`` or identified verdict changes the model; otherwise the nominal one is used
    and the reason is recorded).

    Writes RUN (the replica's run folder, :func:`inverse.replica.run_replica`) with
    ``RUN/diagnose/`` and ``summary.json`` ``closed_loop``.  ``diagnosis``: an existing
    diagnosis run folder of this dataset to use instead of diagnosing again.
    """
    from drives.format import swap_into_place
    from eroad.archive import write_json_atomic
    from inverse.replica import run_replica

    if "effects" in replica:
        raise EroadInputError("--effects auto and explicit effect values cannot be combined")
    out, work = _start(out, force)
    try:
        dsum = _diagnosis_summary(dataset, work, diagnosis, copy_diagnosis, workers, quick, seed, progress, out)
        effects, reason = effects_from_diagnosis(dsum, action="reconstructed")
        # one friction value per drive in a run: the inversion's (measured for the inversion, stop 74;
        # not benchmarked on the replica separately)
        effects, reason, balance = friction_from_balance(effects, reason, dataset)
        progress(f"closed loop: {reason}")
        summary = run_replica(dataset, work / "replica", effects=effects, argv=argv, progress=progress, **replica)
        main = work / "replica"
        if (work / "diagnose").is_dir():
            (work / "diagnose").rename(main / "diagnose")
            where = "diagnose/summary.json"
        else:
            import os
            where = os.path.relpath(Path(diagnosis).resolve() / "summary.json", out.resolve())
        summary["closed_loop"] = {"verdict": dsum.get("verdict"), "confidence": dsum.get("verdict_confidence"),
                                  "effects": effects or {}, "corrected": bool(effects), "reason": reason,
                                  "diagnosis": where, "force_balance": balance}
        from inverse.run import dataset_path
        summary["dataset"]["path"] = dataset_path(dataset, out)      # as recorded from the final folder
        write_json_atomic(main / "summary.json", summary)
        import tomllib

        import tomli_w
        cfg = tomllib.loads((main / "config.toml").read_text())
        cfg["dataset"] = summary["dataset"]["path"]
        (main / "config.toml").write_text(tomli_w.dumps(cfg))
        swap_into_place(main, out)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return summary
