"""The blind check of ``eroad diagnose``: synthetic drives with one withheld effect.

What it is for: make datasets whose truth vehicle is the nominal model plus ONE effect
of the library at a random strength (random road, speed and strength from the case
seed), plus null cases (truth = nominal), diagnose each from a copy WITHOUT
``truth/``, and score:

* **attribution**: top-1 verdict against the truth effect ("none" for null cases);
  a *confident wrong attribution* is a wrong verdict with confidence "clear".  Also
  reported over the *detectable* cases only: those where the truth effect at its true
  strength passes the ranking's gate (positive held-out improvement, more than
  ``Z_PAIRED`` sd above its paired null: the gate every candidate must pass); for the
  others "none" is the answer the diagnosis is built to give;
* **localisation**: a case is a hit when a flagged cell (any segment) lies in a
  band and channel quantity where the effect acts (:data:`ACTS`); for a null case
  when nothing is flagged;
* **how far**: predicted shrink (the verdict's ``shrink_fraction``) against the
  true shrink, the held-out shrink of the truth effect at its true strength on the
  same seeds (:func:`diagnosis.pipeline.heldout_shrink`).

Decision: one-effect cases are made from the ``null`` scenario (``eroad synth
--scenario null --seed S --effect NAME=VALUE``): its truth vehicle is the nominal model
(rigid frame, nominal time step), so the effect is the only model difference.  The
``random`` scenario keeps a flexible 8-segment frame in its truth even with
``--no-default-effects`` (the chassis is not an effect there), which would make
every case a frame_flex + X case.

What it is not: a test (``tests/test_diagnosis_cli.py`` has the slow-marked one) or
a timing benchmark (``benchmarks/bench_diagnosis.py`` runs it and prints times).
"""
from __future__ import annotations

import json
import math
import time as _time
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from diagnosis.pipeline import BUDGET

#: truth strength per effect: (parameter, lo, hi, log, random sign of the change).
#: Rule (docs/diagnosis.md, "Blind strengths"): the weak end is where the effect first
#: changes some third-octave band of one channel quantity by 3 standard errors of a 30 s
#: drive (:func:`effect_size`, median over the quantity's channels, null-scenario roads
#: seeds 500 and 501, mean of the two); the strong end is the largest physically plausible
#: model error.  speed_scale changes no response band: its weak end is 2 % (about 5 standard
#: errors of the front-to-rear delay of a 30 s drive at steady speed), its strong end 10 %
#: (UN R39 allows a speedometer 10 % + 4 km/h high).
STRENGTHS = {
    "frame_flex": ("stiffness_factor", 0.3, 30.0, True, False),    # size 5-12; 100: 2.0
    "leaf_friction": ("force", 500.0, 6000.0, True, False),        # 250 N: 2.9, 500 N: 8.1
    "bump_stop": ("gap", 0.005, 0.02, False, False),               # 0.02 m: 4.0, 0.03 m: 2.8
    "damper_asymmetry": ("ratio", 2.0, 5.0, False, False),         # 1.5: 1.4, 2.0: 3.3
    "payload": ("mass", 7000.0, 12000.0, False, True),             # +6 t: 2.6, +9 t: 3.6, -6 t: 3.7
    "speed_scale": ("factor", 0.02, 0.10, False, True),            # |factor - 1|
    "sensor": ("cutoff", 6.0, 50.0, True, False),                  # 45 Hz: 8.5, 60 Hz: 1.9
    "tyre_enveloping": ("length", 0.15, 0.5, False, False),        # every length >= 0.05 m: > 3
}
#: where each effect acts: (channel quantities, band lo, band hi [Hz]) for the localisation score
ACTS = {
    "frame_flex": (("body_acc",), 3.0, 25.0),
    "leaf_friction": (("body_acc", "susp_disp", "axle_acc"), 1.0, 20.0),
    "bump_stop": (("body_acc", "susp_disp", "axle_acc"), 0.5, 56.0),
    "damper_asymmetry": (("body_acc", "susp_disp", "axle_acc"), 0.5, 56.0),
    "payload": (("body_acc", "susp_disp"), 0.5, 5.0),
    "speed_scale": (("body_acc", "susp_disp", "axle_acc"), 0.5, 56.0),
    "sensor": (("body_acc", "susp_disp", "axle_acc"), None, 56.0),   # lo = cutoff / 2
    "tyre_enveloping": (("axle_acc", "body_acc", "susp_disp"), 4.0, 56.0),
}
#: the acceptance threshold of the ranking (rank_effects' z_paired), for "detectable"
Z_PAIRED = 3.0
#: the ranking budget of the blind run: that of ``eroad diagnose`` itself (the whole
#: library; pairs are off with two folds anyway)
BLIND_SETTINGS = dict(BUDGET, pairs=False)


#: truth families: the scenario a case is made from, and the effects it can carry.
#: ``nominal``: the Exudyn truck itself plus one library effect (null scenario);
#: ``second``: the independently written truck (drives/independent_truck.py, scenario
#: ``second``) with its out-of-library differences (roll centres, anti-roll bars, a cab on
#: mounts, progressive tyres with lift-off, axle-guide geometry), plus one library effect
#: it also models (leaf friction, payload) or none; its null cases carry only the
#: out-of-library differences, and "none" or "unexplained" is the right answer there.
#: ``measured`` (stop 64): the Exudyn truck itself, as ``nominal``, but every drive on the measured
#: road profile (scenario ``null_measured``): no vehicle difference at all, so a gap on its null
#: cases is the real road's misfit with the diagnosis's road model -- what ``second``'s
#: measured-profile drives mix with that truck's structural differences.
FAMILIES = {"nominal": ("null", tuple(STRENGTHS)), "second": ("second", ("leaf_friction", "payload")),
            "measured": ("null_measured", tuple(STRENGTHS))}
#: dataset-seed offset of each family (so that families never share a drive)
FAMILY_SEED_OFFSET = {"nominal": 0, "second": 50000, "measured": 70000}
#: in the ``second`` family every ``MEASURED_EVERY``-th case (case 0, 4, 8, ...) drives the
#: measured road profile (scenario ``second_measured``) instead of a synthetic ISO road
MEASURED_EVERY = 4
#: verdicts that are right where no library effect is in the truth
NO_EFFECT_ANSWERS = ("none", "unexplained")


#: the payload the blind strengths of ``payload`` were set for: the dump truck's [kg]; on another
#: vehicle (``make_cases(vehicle=...)``) a drawn payload change is scaled by that vehicle's
#: nominal payload over this, so it is the same share of what the vehicle carries
STRENGTH_PAYLOAD_KG = 16000.0


def nominal_payload(vehicle) -> float:
    """The nominal payload P [kg] of a vehicle (id or TOML path), as the payload effect knows
    it: its range on that vehicle is [-P, +P] (``vehicles.effects.payload``, -P the empty
    vehicle)."""
    from vehicles.effects import get_effect
    from vehicles.params import load_vehicle

    return -float(get_effect("payload").vehicle_ranges(load_vehicle(vehicle))["mass"][0])


def reported_nmax(summary) -> list | None:
    """The road band of the pass a diagnosis reported, where a band refit or the joint band
    moved it from the first fit (``meta.band_refit`` / ``meta.joint_band``), else None."""
    meta = summary.get("meta") or {}
    joint = meta.get("joint_band") or {}
    if joint.get("chosen") == "cut" and joint.get("nmax_after"):
        return list(joint["nmax_after"])
    refit = meta.get("band_refit") or {}
    if refit.get("changed") and refit.get("nmax_after"):
        return list(refit["nmax_after"])
    return None


def make_cases(n: int, seed: int = 0, n_null: int | None = None, effects=None,
               family: str = "nominal", vehicle=None) -> list[dict]:
    """``n`` blind cases: effects in turn (strength drawn per case), every ``k``-th a null case.

    Parameters
    ----------
    n : int
        Number of cases.
    seed : int
        Root seed; case ``i`` uses dataset seed ``1000 * seed + 100 + i`` and strength stream
        ``SeedSequence(seed, spawn_key=(7, i))``.
    n_null : int, optional
        Null cases among them (default ``round(n / 5)``, at least 1; family ``second``:
        half of them).
    effects : sequence of str, optional
        Effects used (default all the family can carry, :data:`FAMILIES`).
    family : {"nominal", "second", "measured"}
        Truth family (:data:`FAMILIES`); case seeds are offset by :data:`FAMILY_SEED_OFFSET`;
        every :data:`MEASURED_EVERY`-th case of ``second`` drives the measured road profile,
        every case of ``measured``.
    vehicle : str, optional
        Truth and model vehicle (family ``nominal`` only; default the scenario's, the dump
        truck): a payload change is scaled by its nominal payload (``STRENGTH_PAYLOAD_KG``);
        every other strength is the dump truck's, whose weak ends were set on that truck.

    Returns
    -------
    list of dict with ``case``, ``seed``, ``effect`` ("none" for null), ``param``, ``value``.
    """
    if family not in FAMILIES:
        raise ValueError(f"family must be one of {', '.join(FAMILIES)}, got {family!r}")
    scenario, fam_effects = FAMILIES[family]
    if vehicle is not None and family != "nominal":
        raise ValueError("a vehicle other than the scenario's is for the nominal family only "
                         "(the independently written truck is the dump truck)")
    payload_scale = 1.0 if vehicle is None else nominal_payload(vehicle) / STRENGTH_PAYLOAD_KG
    names = list(effects or fam_effects)
    bad = [e for e in names if e not in fam_effects]
    if bad:
        raise ValueError(f"family {family} carries {', '.join(fam_effects)}; not {', '.join(bad)}")
    if n_null is None:
        n_null = max(1, round(n / 5)) if family == "nominal" else n // 2
    off = FAMILY_SEED_OFFSET[family]
    null_at = set(np.linspace(0, n - 1, n_null).round().astype(int).tolist()) if n_null else set()
    cases, k = [], 0
    for i in range(n):
        ds_seed = 1000 * seed + 100 + i + off
        measured = family == "second" and i % MEASURED_EVERY == 0
        tag = dict(family=family, scenario="second_measured" if measured else scenario)
        if vehicle is not None:
            tag["vehicle"] = str(vehicle)
        if i in null_at:
            cases.append(dict(case=i, seed=ds_seed, effect="none", param=None, value=None, **tag))
            continue
        name = names[k % len(names)]
        k += 1
        pname, lo, hi, log, signed = STRENGTHS[name]
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(7, i)))
        u = rng.uniform()
        v = math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))) if log else lo + u * (hi - lo)
        sign = (1.0 if rng.uniform() < 0.5 else -1.0) if signed else 1.0
        v = 1.0 + sign * v if name == "speed_scale" else sign * v
        if name == "payload":
            v *= payload_scale
        cases.append(dict(case=i, seed=ds_seed, effect=name, param=pname, value=float(v), **tag))
    return cases


def localisation_hit(summary: dict, effect: str, value=None) -> bool:
    """Did the diagnosis flag a cell where ``effect`` acts (nothing flagged for "none")?"""
    flagged = [c for c in summary.get("localization", []) if c.get("significant")]
    if effect == "none":
        return not flagged
    quants, lo, hi = ACTS[effect]
    if lo is None:
        lo = 0.5 * float(value)
    for c in flagged:
        b0, b1 = c["band_hz"]
        if c["channel"].startswith(quants) and b1 >= lo and b0 <= hi:
            return True
    return False


def run_case(case: dict, root, *, workers: int = 2, settings=None, duration=None,
             progress=print) -> dict:
    """Make, blind-copy, diagnose and score one case.

    Returns
    -------
    dict: the case, verdict, confidence, predicted and true shrink, localisation hit, times.
    """
    from diagnosis.pipeline import diagnose, heldout_shrink
    from drives.synth import copy_without_truth, read_truth, synth_command
    from eroad.errors import EroadInputError

    root = Path(root)
    ds = root / f"case{case['case']:03d}"
    blind = root / f"case{case['case']:03d}-blind"
    run = root / f"case{case['case']:03d}-run"
    eff_items = [] if case["effect"] == "none" else [f"{case['effect']}.{case['param']}={case['value']!r}"]
    t0 = _time.perf_counter()
    if not (ds / "truth" / "summary.json").is_file():
        # a very rough random road can drive the truth outside the plausible range of the
        # measurement format (e.g. |axle_acc| > 200 m/s^2): redraw road and speed
        for attempt in range(6):
            try:
                synth_command(scenario=case.get("scenario", "null"), seed=case["seed"],
                              effects=eff_items, out=ds, vehicle=case.get("vehicle"),
                              force=True, duration=duration)
                break
            except EroadInputError as exc:
                if attempt == 5:
                    raise
                progress(f"case {case['case']}: seed {case['seed']} not usable ({exc}); redrawn")
                case["seed"] += 7919
    if not blind.exists():
        copy_without_truth(ds, blind)
    t1 = _time.perf_counter()
    settings = dict(BLIND_SETTINGS, **(settings or {}))
    summ = diagnose(blind, run, workers=workers, force=True, settings=settings,
                    progress=lambda m: None)
    t2 = _time.perf_counter()
    # scoring only from here: truth is read
    truth = read_truth(ds)
    truth_eff, oracle_kind = oracle_effects(case, truth)
    case = dict(case, seed=int(truth.get("seed", case["seed"])))   # the seed actually used
    verdict = summ["verdict"]
    entry = next((e for e in summ.get("ranking", []) if e["effect"] == verdict), None)
    pred_shrink = float(entry["shrink_fraction"]) if entry else 0.0
    true_shrink = true_z = None
    if truth_eff:
        hs = heldout_shrink(blind, truth_eff, n_seeds=settings["n_seeds"], n_null=settings["n_null"],
                            nmax=reported_nmax(summ))
        true_shrink, true_z = hs["shrink_fraction"], hs["paired_z"]
    t3 = _time.perf_counter()
    detail = summ.get("verdict_detail") or {}
    res = dict(case, verdict=verdict, confidence=summ.get("verdict_confidence"),
               **judge(case, verdict, summ.get("verdict_confidence")),
               param_ratio=param_ratio(case, entry),
               ranking_verdict=detail.get("ranking_verdict"),
               gap_side=(detail.get("gap_side") or {}).get("side"),
               explained_share=detail.get("explained_share"),
               signature=summ.get("signature"), summary=str(run / "summary.json"),
               localisation_hit=localisation_hit(summ, case["effect"], case["value"]),
               n_flagged=sum(1 for c in summ.get("localization", []) if c.get("significant")),
               predicted_shrink=pred_shrink, true_shrink=true_shrink, true_paired_z=true_z,
               oracle=oracle_kind if true_shrink is not None else None,
               best_parameters=entry["parameters"] if entry else None,
               heldout_gap_before=float(summ["nominal"]["heldout_gap"]),
               null_sd=float(summ["nominal"]["null_gap_std"]),
               synth_s=round(t1 - t0, 1), diagnose_s=round(t2 - t1, 1), oracle_s=round(t3 - t2, 1),
               band_refit=first_pass_result(case, summ),
               joint_band=first_pass_result(case, summ, "joint_band"))
    progress(f"case {case['case']:3d} truth {case['effect']:>16s} "
             f"{'' if case['value'] is None else format(case['value'], '.4g'):>8s} -> "
             f"{verdict:>16s} ({res['confidence']}) shrink pred {pred_shrink:.2f} "
             f"true {'-' if true_shrink is None else format(true_shrink, '.2f')}  "
             f"loc {'hit' if res['localisation_hit'] else 'miss'}  {t2 - t1:.0f} s")
    return res


def oracle_effects(case: Mapping, truth: Mapping) -> tuple[dict, str]:
    """The effects the oracle puts in the nominal model to measure whether a case's truth shows
    its effect (:func:`detectable`), and what they are.

    Our own truck (families ``nominal``, ``measured``): the truth's own effects (``"truth"``; a
    sensor without its noise floor, which the nominal model carries already).  The independently
    written truck (``second``): its effects are its own model, not ours, so the oracle is the
    LIBRARY's effect at the truth's strength (``"library"``): whether the data show the effect
    through the library at all, read by the same gate (stop 71; its earlier sets ran no oracle).
    No effect: ``{}``.
    """
    if case.get("family", "nominal") == "second":
        if case.get("effect", "none") == "none":
            return {}, "library"
        return {case["effect"]: {case["param"]: case["value"]}}, "library"
    eff = (truth.get("vehicle", {}).get("truth", {}) or {}).get("effects") or {}
    oracle = {k: dict(v) for k, v in eff.items()}
    if "sensor" in oracle:        # the nominal model carries the measured noise floor
        oracle["sensor"].update(acc_noise=0.0, disp_noise=0.0)
    return oracle, "truth"


def first_pass_result(case: dict, summ: dict, key: str = "band_refit") -> dict | None:
    """Where the diagnosis made a second pass on another road band (``key``: ``"band_refit"``,
    ``settings["band_refit"]``, or ``"joint_band"``, ``settings["joint_band"]``): the band before
    and after and the first pass's verdict scored as the final one is, so one run compares
    both rules on the same drives; None where the option was not asked or not run."""
    rec = (summ.get("meta") or {}).get(key)
    if not rec:
        return None
    out = {k: rec.get(k) for k in ("effect", "parameters", "nmax_before", "nmax_after", "changed",
                                    "time_s", "first_pass_s", "trial_cut", "step", "gap_fitted",
                                    "gap_cut", "chosen") if k in rec}
    first = rec.get("first_pass")
    if first is None:           # band unchanged: the first pass is the final one
        verdict, conf = summ["verdict"], summ.get("verdict_confidence")
        entry = next((e for e in summ.get("ranking", []) if e["effect"] == verdict), None)
    else:
        verdict, conf = first["verdict"], first.get("verdict_confidence")
        entry = next((e for e in first.get("ranking") or [] if e["effect"] == verdict), None)
    out.update(verdict=verdict, confidence=conf, **judge(case, verdict, conf),
               param_ratio=param_ratio(case, entry))
    return out


def two_rule_counts(results: list[dict], key: str, which: str = "final") -> dict:
    """Counts of one rule on cases scored by :func:`run_case`: ``which`` "final" (the verdict
    reported) or "first" (the first pass kept under ``key``, :func:`first_pass_result`; where it
    is absent the first pass was the final one).  Keys: ``named`` (library cases named right),
    ``library``, ``no_effect_right``, ``no_effect``, ``wrong`` (an effect named that is not the
    truth's), ``clear_wrong``, ``within_1p5`` (values within x1.5 among right names with a
    value), ``valued``."""
    def get(r):
        f = r.get(key) if which == "first" else None
        f = f or r
        return f["verdict"], f["correct"], f["confident_wrong"], f.get("param_ratio")
    g = [(r, get(r)) for r in results]
    lib = [x for r, x in g if r["effect"] != "none"]
    nul = [x for r, x in g if r["effect"] == "none"]
    vals = [x[3] for x in lib if x[1] and x[3] is not None]
    return {"named": sum(x[1] for x in lib), "library": len(lib),
            "no_effect_right": sum(x[1] for x in nul), "no_effect": len(nul),
            "wrong": sum(1 for r, x in g if wrong_name(r, x[0])),
            "clear_wrong": sum(x[2] for _, x in g),
            "within_1p5": sum(1 for v in vals if 1 / 1.5 <= v <= 1.5), "valued": len(vals)}


def two_rule_lines(results: list[dict], key: str) -> tuple[list[str], list[str]]:
    """The first pass (kept under ``key``) against the final verdict, as text: the counts of
    :func:`two_rule_counts` per rule, and the time per diagnosis per rule (the first pass's is
    the whole diagnosis less the second pass's ``time_s``)."""
    score = []
    for lab, which in (("first pass", "first"), ("final", "final")):
        c = two_rule_counts(results, key, which)
        score.append(f"  {lab:10s}: library effects named right {c['named']}/{c['library']}, no-effect "
                     f"right {c['no_effect_right']}/{c['no_effect']}, wrong names {c['wrong']}, clear "
                     f"wrong {c['clear_wrong']}, values within x1.5 {c['within_1p5']}/{c['valued']}")
    t_final = [r["diagnose_s"] for r in results]
    t_first = [r["diagnose_s"] - ((r.get(key) or {}).get("time_s") or 0.0) for r in results]
    times = [f"  time {lab}: mean {sum(t) / len(t):.1f} s, max {max(t):.1f} s, over 120 s: "
             f"{sum(x > 120 for x in t)}" for lab, t in (("first pass", t_first), ("final", t_final))]
    return score, times


def judge(case: dict, verdict: str, confidence) -> dict:
    """``correct`` and ``confident_wrong`` of one verdict: right is the truth effect, or
    "none" / "unexplained" where the truth carries no library effect; a confident wrong
    answer names another effect with confidence "clear"."""
    if case["effect"] == "none":
        correct = verdict in NO_EFFECT_ANSWERS
    else:
        correct = verdict == case["effect"]
    wrong = wrong_name(case, verdict)
    return {"correct": bool(correct), "confident_wrong": bool(wrong and confidence == "clear")}


def wrong_name(case: dict, verdict: str) -> bool:
    """The verdict names a library effect that is not the truth's."""
    return verdict not in NO_EFFECT_ANSWERS and verdict != case["effect"]


def param_ratio(case: dict, entry) -> float | None:
    """Calibrated over true value of the effect's parameter (same sign asked; None where
    the verdict is not the truth effect).  speed_scale: ratio of the deviations from 1."""
    if entry is None or case["effect"] == "none" or entry.get("effect") != case["effect"]:
        return None
    got = (entry.get("parameters") or {}).get(case["effect"], {}).get(case["param"])
    if got is None:
        return None
    got, true = float(got), float(case["value"])
    if case["effect"] == "speed_scale":
        got, true = got - 1.0, true - 1.0
    return got / true if true else None


def saved_cases(root):
    """Each case of ``root/blind.json`` with its saved summary, ``(case result, summary)``: the
    summary where the run recorded it, else ``caseNNN-run/summary.json`` (a bench work folder),
    else ``caseNNN-summary.json`` (an archived results folder); cases without one are skipped."""
    root = Path(root)
    for r in json.loads((root / "blind.json").read_text())["results"]:
        tries = [Path(r["summary"])] if r.get("summary") else []
        tries += [root / f"case{r['case']:03d}-run" / "summary.json",
                  root / f"case{r['case']:03d}-summary.json"]
        p = next((t for t in tries if t.is_file()), None)
        if p is not None:
            yield r, json.loads(p.read_text())


def rescore(root, **thresholds) -> dict:
    """Re-decide every case of ``root/blind.json`` from its saved summary with other
    thresholds of :func:`diagnosis.verdict.decide`; returns ``{"results", "score"}``."""
    from diagnosis.verdict import decide

    results = []
    for r, summ in saved_cases(root):
        d = decide(summ, **thresholds)
        entry = next((e for e in summ.get("ranking", []) if e["effect"] == d["verdict"]), None)
        results.append(dict(r, verdict=d["verdict"], confidence=d["confidence"],
                            **judge(r, d["verdict"], d["confidence"]),
                            param_ratio=param_ratio(r, entry)))
    return {"results": results, "score": score(results)}


def _paired_blank() -> dict:
    return {"focus": [0, 0, 0], "effect": [0, 0, 0], "null": [0, 0, 0], "wrong": [0, 0],
            "clear_wrong": [0, 0], "right_to_wrong": 0, "changed": 0, "drives": 0}


def _paired_line(name: str, c: Mapping, focus: str) -> str:
    return (f"{name}: drives {c['drives']}; library effects right {c['effect'][0]} -> {c['effect'][1]} "
            f"of {c['effect'][2]} ({focus} {c['focus'][0]} -> {c['focus'][1]} of {c['focus'][2]}); "
            f"no effect none/unexplained {c['null'][0]} -> {c['null'][1]} of {c['null'][2]}; wrong "
            f"names {c['wrong'][0]} -> {c['wrong'][1]} (clear {c['clear_wrong'][0]} -> "
            f"{c['clear_wrong'][1]}); right -> wrong {c['right_to_wrong']}; changed {c['changed']}")


def decide_with(**settings) -> Callable[[dict], dict]:
    """``summary -> decision``: :func:`diagnosis.verdict.decide` with module settings of
    :mod:`diagnosis.verdict` (e.g. ``LOWPASS_TWO_INPUT=False``) in force for the call and restored
    after it -- the two sides of :func:`paired` for a rule switched by a module constant."""
    from diagnosis import verdict

    unknown = [k for k in settings if not hasattr(verdict, k)]
    if unknown:
        raise ValueError(f"diagnosis.verdict has no setting {', '.join(unknown)}")

    def run(summary: dict) -> dict:
        # every verdict function reads its settings when called (verdict._or_setting), so the
        # module constants set here are the ones in force, keyword defaults included
        keep = {k: getattr(verdict, k) for k in settings}
        try:
            for k, v in settings.items():
                setattr(verdict, k, v)
            return verdict.decide(summary)
        finally:
            for k, v in keep.items():
                setattr(verdict, k, v)
    return run


def paired(folders, old: Callable[[dict], dict], new: Callable[[dict], dict], focus: str,
           out=print) -> dict:
    """The paired re-decision of saved blind sets: every saved case of ``folders``
    (:func:`saved_cases`) decided by two verdict rules ``old`` and ``new`` (summary -> decision),
    so a rule that needs no new record is judged on the SAME drives, with no simulation noise
    between the columns.  Prints each drive whose verdict or confidence changed, a line per folder
    and one for all (``focus``: the effect whose count is shown apart).  Returns the totals:
    ``[old, new, cases]`` for ``effect``, ``null`` and ``focus``, ``[old, new]`` for ``wrong`` and
    ``clear_wrong``, and the counts ``right_to_wrong``, ``changed``, ``drives``."""
    total = _paired_blank()
    for d in folders:
        c = _paired_blank()
        for r, s in saved_cases(d):
            a, b = old(s), new(s)
            ja, jb = judge(r, a["verdict"], a["confidence"]), judge(r, b["verdict"], b["confidence"])
            key = "null" if r["effect"] == "none" else "effect"
            c["drives"] += 1
            for i, j in enumerate((ja, jb)):
                c[key][i] += j["correct"]
                c["focus"][i] += r["effect"] == focus and j["correct"]
                c["wrong"][i] += wrong_name(r, (a, b)[i]["verdict"])
                c["clear_wrong"][i] += j["confident_wrong"]
            c[key][2] += 1
            c["focus"][2] += r["effect"] == focus
            c["right_to_wrong"] += ja["correct"] and not jb["correct"]
            if (a["verdict"], a["confidence"]) != (b["verdict"], b["confidence"]):
                c["changed"] += 1
                out(f"  {d} case {r['case']} truth {r['effect']} {r.get('value')}: {a['verdict']} "
                    f"({a['confidence']}) -> {b['verdict']} ({b['confidence']})")
        out(_paired_line(str(d), c, focus))
        for k, v in c.items():
            total[k] = [x + y for x, y in zip(total[k], v)] if isinstance(v, list) else total[k] + v
    out(_paired_line("ALL", total, focus))
    return total


#: threshold grid of :func:`sweep` (the committed values are on it)
SWEEP_GRID = {"share_min": (0.2, 0.3, 0.4, 0.5, 0.6),
              "signature_max": (1.5, 2.0, 3.0, 5.0),
              "signature_share": (0.05, 0.1, 0.15, 0.3)}


def sweep(root, grid=None) -> list[dict]:
    """Re-decide the saved cases of ``root`` at every threshold triple of ``grid``
    (default :data:`SWEEP_GRID`).

    Returns
    -------
    list of dict, best first: ``thresholds``, ``effect_top1``, ``no_effect_right``,
    ``confident_wrong``, ``balanced`` (mean of the two rates).  Order: no confident
    wrong answer first, then the balanced rate, then the smaller distance (in grid
    steps) from the committed thresholds -- the rule by which the thresholds are set
    on one family before they are checked on the other.
    """
    import itertools

    from diagnosis import verdict as V

    grid = dict(SWEEP_GRID, **(grid or {}))
    committed = {"share_min": V.SHARE_MIN, "signature_max": V.SIGNATURE_CHI2_MAX,
                 "signature_share": V.SIGNATURE_SHARE_MIN}
    rows = []
    for combo in itertools.product(*grid.values()):
        th = dict(zip(grid, combo))
        rs = rescore(root, **th)["results"]
        fam = _family_score(rs)
        e, n = fam["effect_top1"], fam["no_effect_right"]
        bal = float(np.nanmean([e, n])) if not (math.isnan(e) and math.isnan(n)) else float("nan")
        dist = sum(abs(grid[k].index(th[k]) - grid[k].index(committed[k]))
                   if committed[k] in grid[k] else 0 for k in grid)
        rows.append(dict(thresholds=th, effect_top1=e, no_effect_right=n,
                         confident_wrong=int(sum(r["confident_wrong"] for r in rs)),
                         balanced=bal, distance=dist))
    rows.sort(key=lambda r: (r["confident_wrong"] > 0, -r["balanced"], r["distance"]))
    return rows


def _rate(flags) -> float:
    return float(np.mean(flags)) if flags else float("nan")


def _family_score(rs: list[dict]) -> dict:
    """Cases, top-1 on library-effect cases, and the right-answer rate without one."""
    return {"n": len(rs), "effect_top1": _rate([r["correct"] for r in rs if r["effect"] != "none"]),
            "no_effect_right": _rate([r["correct"] for r in rs if r["effect"] == "none"])}


def detectable(r: dict) -> bool:
    """Whether a blind case's truth shows its own effect: the truth effect at its true strength
    passes the ranking's gate (a positive held-out improvement, paired z above ``Z_PAIRED``).
    Cases of our own truck carry the truth's effect as the oracle; the independent truck's
    (``oracle == "library"``, sets run since stop 71) the library's effect at the truth's
    strength, which says whether the data show it through the library; cases without
    ``true_paired_z`` (that truck's older sets) are never detectable."""
    return (r.get("true_paired_z") is not None and (r.get("true_shrink") or 0) > 0
            and r["true_paired_z"] > Z_PAIRED)


def score(results: list[dict]) -> dict:
    """Confusion matrix (truth rows x verdict columns) and the target metrics."""
    labels = sorted({r["effect"] for r in results} | {r["verdict"] for r in results},
                    key=lambda s: (s == "none", s))
    idx = {l: i for i, l in enumerate(labels)}
    cm = np.zeros((len(labels), len(labels)), int)
    for r in results:
        cm[idx[r["effect"]], idx[r["verdict"]]] += 1
    eff = [r for r in results if r["effect"] != "none"]
    nul = [r for r in results if r["effect"] == "none"]
    det = [r for r in eff if detectable(r)]
    pairs = [(r["predicted_shrink"], r["true_shrink"]) for r in eff
             if r["correct"] and r["true_shrink"] is not None]
    return {
        "n_cases": len(results),
        "top1_accuracy": float(np.mean([r["correct"] for r in results])) if results else float("nan"),
        "effect_top1_accuracy": float(np.mean([r["correct"] for r in eff])) if eff else float("nan"),
        "n_detectable": len(det),
        "detectable_top1_accuracy": float(np.mean([r["correct"] for r in det])) if det else float("nan"),
        "undetectable_none_rate": float(np.mean([r["verdict"] == "none" for r in eff if r not in det]))
        if len(det) < len(eff) else float("nan"),
        "null_none_rate": float(np.mean([r["verdict"] == "none" for r in nul])) if nul else float("nan"),
        "null_none_or_unexplained_rate": float(np.mean([r["verdict"] in NO_EFFECT_ANSWERS
                                                        for r in nul])) if nul else float("nan"),
        "param_within_1p5_rate": (float(np.mean([1 / 1.5 <= r["param_ratio"] <= 1.5 for r in eff
                                                 if r["correct"] and r.get("param_ratio") is not None]))
                                  if any(r["correct"] and r.get("param_ratio") is not None for r in eff)
                                  else float("nan")),
        "by_family": {f: _family_score([r for r in results if r.get("family", "nominal") == f])
                      for f in sorted({r.get("family", "nominal") for r in results})},
        "confident_wrong": int(sum(r["confident_wrong"] for r in results)),
        "localisation_hit_rate": float(np.mean([r["localisation_hit"] for r in results]))
        if results else float("nan"),
        "localisation_hit_rate_effects": float(np.mean([r["localisation_hit"] for r in eff]))
        if eff else float("nan"),
        "null_flagged_cells": [int(r["n_flagged"]) for r in nul],
        "shrink_pred_vs_true": [[float(a), float(b)] for a, b in pairs],
        "shrink_mean_abs_diff": float(np.mean([abs(a - b) for a, b in pairs])) if pairs else None,
        "labels": labels,
        "confusion": cm.tolist(),
    }


def format_confusion(sc: dict) -> str:
    """The confusion matrix as a text table (rows truth, columns verdict)."""
    labels = sc["labels"]
    w = max(len(l) for l in labels) + 1
    short = [l[:8] for l in labels]
    lines = ["truth \\ verdict".ljust(w) + " ".join(s.rjust(8) for s in short)]
    for l, row in zip(labels, sc["confusion"]):
        lines.append(l.ljust(w) + " ".join(str(v).rjust(8) for v in row))
    return "\n".join(lines)


def run_blind(root, n: int = 30, *, seed: int = 0, workers: int = 2, duration=None, settings=None,
              n_null: int | None = None, family: str = "nominal", effects=None, vehicle=None,
              progress=print) -> dict:
    """Run ``n`` blind cases under ``root``; write ``root/blind.json`` and ``root/confusion.txt``.
    ``effects``: the library effects the one-effect cases draw from (:func:`make_cases`).

    Cases already scored in ``root/blind.json`` are reused (the run can be resumed).
    """
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    done_file = root / "blind.json"
    done = {}
    if done_file.is_file():
        done = {r["case"]: r for r in json.loads(done_file.read_text()).get("results", [])}
    results = []
    t0 = _time.perf_counter()
    # case ids are stable; a redrawn road changes a case's dataset seed (recorded in results)
    for case in make_cases(n, seed, n_null=n_null, family=family, effects=effects, vehicle=vehicle):
        r = done.get(case["case"])
        if r is None or r.get("value") != case["value"]:
            r = run_case(case, root, workers=workers, settings=settings, duration=duration,
                         progress=progress)
        results.append(r)
        sc = score(results)
        done_file.write_text(json.dumps({"results": results, "score": sc,
                                         "settings": dict(BLIND_SETTINGS, **(settings or {})),
                                         "wall_s": _time.perf_counter() - t0}, indent=1))
    sc = score(results)
    (root / "confusion.txt").write_text(format_confusion(sc) + "\n")
    return {"results": results, "score": sc}


def effect_size(effect: str, param: str, value: float, seed: int, *, duration: float = 30.0,
                extra: dict | None = None) -> dict:
    """How much one effect at one strength changes a 30 s drive, in standard errors.

    The ``null`` scenario drive of ``seed`` (road, speed, sensor noise levels) is simulated
    with the nominal truck and with the effect, on the SAME road and with the same noise
    realisation (so the difference is the effect only).  Per channel and third-octave band
    (0.5-50 Hz, whole record) ``d = ln(P_effect / P_nominal)``; its yardstick is the
    standard error of the log band-power difference of two INDEPENDENT 30 s drives,
    ``se = sqrt(2 trigamma(nu / 2))`` (``nu`` the band EDOF).  Per channel quantity
    (susp_disp, axle_acc, body_acc) and band the median over the quantity's channels of
    ``|d| / se`` is taken (one odd channel does not count); the effect size is the
    largest of these.

    ``extra``: other parameters of the effect (e.g. the sensor's noise switched off, to size
    the low-pass alone).

    Returns
    -------
    dict with ``size`` (max median |d|/se), ``quantity`` and ``band_hz`` where it occurs.
    """
    from drives.synth import build_road, load_scenario, plan_drive, resolve_scenario
    from vehicles.params import load_vehicle
    from vehicles.simulate import SpeedProfile, simulate

    from diagnosis.bandpower import band_powers, var_log_power

    cfg, path = load_scenario("null")
    cfg = resolve_scenario(cfg, seed, duration=duration, src=path)
    vp = load_vehicle(cfg["scenario"]["vehicle"])
    plan = plan_drive(cfg, [float(a.x) for a in vp.axles])
    road = build_road(cfg, plan)
    fs = float(cfg["scenario"]["sample_rate_hz"])
    n_run, n_rec = plan["n_runin"], plan["n_record"]
    noise = cfg["noise"]
    eff = {} if effect == "none" else {effect: {param: float(value), **(extra or {})}}
    out = []
    for e in ({}, eff):
        res = simulate(vp, road, speed=SpeedProfile(plan["t_sim"], plan["v_sim"]),
                       duration=(n_run + n_rec) / fs, fs_out=fs, x_start=plan["x_front0"],
                       effects=e or None, seed=seed)
        ch = {}
        for k, c in enumerate(sorted(c for c in res.channels
                                     if c.startswith(("susp_disp_", "axle_acc_", "body_acc_")))):
            x = np.asarray(res.channels[c], float)[n_run:n_run + n_rec]
            sd = noise["susp_disp_m"] if c.startswith("susp_disp_") else \
                noise["axle_acc_mps2"] if c.startswith("axle_acc_") else noise["body_acc_mps2"]
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(11, k)))
            ch[c] = x + sd * rng.standard_normal(x.size)
        out.append(ch)
    names = list(out[0])
    b0 = band_powers(np.array([out[0][c] for c in names]), fs)
    b1 = band_powers(np.array([out[1][c] for c in names]), fs, nperseg=b0.nperseg)
    with np.errstate(all="ignore"):
        z = np.abs(np.log(b1.power / b0.power)) / np.sqrt(2.0 * var_log_power(b0.nu))
    best = (0.0, None, None)
    for q in ("susp_disp_", "axle_acc_", "body_acc_"):
        rows = [i for i, c in enumerate(names) if c.startswith(q)]
        with np.errstate(all="ignore"):
            med = np.nanmedian(z[rows], axis=0)
        if np.isfinite(med).any():
            b = int(np.nanargmax(med))
            if med[b] > best[0]:
                best = (float(med[b]), q.rstrip("_"), [float(b0.bands[b, 0]), float(b0.bands[b, 2])])
    return {"effect": effect, "param": param, "value": float(value), "seed": int(seed),
            "size": best[0], "quantity": best[1], "band_hz": best[2]}
