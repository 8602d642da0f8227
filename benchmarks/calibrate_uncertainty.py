"""Calibrate and check the inversion's reported uncertainty (inverse.uncertainty) on blind drives.

Reads the per-case records of ``benchmarks/bench_inverse.py`` (``ROOT/results.jsonl``;
each true segment with its signed errors, the fit's Laplace sd and the fitted segment's
misfit) and

* with ``--calibrate SET``: derives from that set (correctly modelled drives, e.g. the
  ``null`` scenario) R_REF (median misfit per feature of the fitted segments), R_GATE
  (5 R_REF) and, per quantity, KAPPA: the 90th percentile of
  |error| / (1.645 sd_laplace sqrt(max(1, r / R_REF))) over segments >= 3 s, i.e. the
  factor at which 90 % of those intervals hold;
* for every set given: the coverage of the 90 % intervals (segments >= 3 s) with the
  constants in ``inverse/uncertainty.py`` (or the freshly calibrated ones), for
  ln Gq(n0), w and ln G(n_best), the share flagged 'poor' by the gate, and the coverage
  of the noise-only Laplace intervals for comparison.

With ``--by-scenario`` a set whose drives come from several scenarios (the second truth
family: ``second`` on synthetic roads, ``second_measured`` on the measured profile) is
also scored per scenario; with ``--profile`` the measured-road drives are also scored
segment by segment against the profile under each FITTED segment (the records'
``profile`` rows: the window's ISO fit and its periodogram at n_best), as
``NAME/profile``.  A second table gives the accuracy targets: G(1 cycle/m) within 20 %
and class right.

Usage::

    python benchmarks/calibrate_uncertainty.py null=/tmp/cal/null random=/tmp/cal/random \
        [--calibrate null] [--by-scenario] [--profile]

Nothing is written; the printout is what results/inverse_blind/<run>/README.md quotes.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from inverse import uncertainty as U

QUANTITIES = {"ln_Gq_n0": ("lnGq_err", lambda r: r["sd_laplace"]["ln_Gq_n0"]),
              "w": ("w_err", lambda r: r["sd_laplace"]["w"]),
              "ln_G_n_best": ("lnG_n_best_err", lambda r: r["sd_ln_G_n_best_laplace"])}


def profile_rows(case: dict, min_s: float = 3.0) -> list:
    """A measured-road drive's fitted segments as scoring rows against the profile under them."""
    import math

    from roadlib.psd import class_of

    rows = []
    for r in case.get("profile", []):
        if r["duration_s"] < min_s or "Gq_prof" not in r or "lnG_n_best_err" not in r:
            continue
        rows.append(dict(r, lnGq_err=math.log(r["Gq_fit"] / r["Gq_prof"]), w_err=r["w_fit"] - r["w_prof"],
                         class_true=class_of(r["Gq_prof"]), class_fit=class_of(r["Gq_fit"])))
    return rows


def redecided_loops(diag_root: Path) -> dict:
    """Per seed, the closed loop as today's verdict rules would run it: ``{seed: (verdict,
    corrected, singled out)}`` from the saved diagnoses of a blind folder (``blind.json`` and
    ``caseNNN-summary.json``, re-decided by ``diagnosis.verdict.decide``; corrected as
    ``diagnosis.closed_loop.effects_from_diagnosis`` decides, singled out as
    ``diagnosis.closed_loop.singled_out``)."""
    from diagnosis.closed_loop import effects_from_diagnosis, singled_out
    from diagnosis.verdict import decide

    out = {}
    for r in json.loads((diag_root / "blind.json").read_text())["results"]:
        summ = json.loads((diag_root / f"case{r['case']:03d}-summary.json").read_text())
        d = decide(summ)
        summ = dict(summ, verdict=d["verdict"], verdict_confidence=d["confidence"], verdict_detail=d)
        out[int(r["seed"])] = (d["verdict"], effects_from_diagnosis(summ)[0] is not None, singled_out(summ))
    return out


def load(root: Path, min_s: float = 3.0, profile: bool = False, open_loop: bool = False,
         loops: dict | None = None) -> list:
    """Rows of segments >= ``min_s`` (true segments; with ``profile`` the measured-road drives'
    fitted segments against the profile instead, :func:`profile_rows`; with ``open_loop`` the
    nominal inversion's rows where a closed-loop run (``bench_inverse.py --effects-auto``)
    corrected the drive, i.e. the same drives inverted without the loop).

    Each row gets ``model_form`` (``inverse.uncertainty.MODEL_FORMS``) as
    ``diagnosis.closed_loop.model_form`` decides it from the record's ``closed_loop``
    (records without one: "open"), or the record's own ``closed_loop.model_form`` where it holds
    one (records made after 2026-11-28: a correction with an 'ambiguous' name is "open"). ``loops``
    (``{seed: (verdict, corrected, singled out)}``,
    :func:`redecided_loops`) replaces the recorded verdicts: a drive corrected then and not
    now is scored on its nominal rows (with ``profile``, left out: the records keep the
    profile rows of the corrected inversion only)."""
    from diagnosis.closed_loop import model_form

    rows = []
    # a set re-scored after a change of the scoring (bench_inverse.py --rescore) is read re-scored
    res = root / "results-rescored.jsonl"
    for line in (res if res.is_file() else root / "results.jsonl").read_text().splitlines():
        case = json.loads(line)
        loop = case.get("closed_loop")
        nominal_rows = open_loop and bool(case.get("nominal"))
        if loop and loops is not None and case["seed"] in loops:
            verdict, corrected, singled = loops[case["seed"]]
            if corrected and not loop.get("corrected"):
                raise SystemExit(f"{root}: seed {case['seed']} would be corrected now and has no corrected record")
            nominal_rows = nominal_rows or (loop.get("corrected") and not corrected)
            loop = {"verdict": verdict, "corrected": corrected,
                    "model_form": model_form(verdict, corrected, singled)}
        form = "open" if not loop or (nominal_rows and loop.get("corrected")) else \
            loop.get("model_form") or model_form(loop.get("verdict"), bool(loop.get("corrected")))
        if loop and loop.get("verdict") == "unexplained" and not nominal_rows:
            form = "unexplained"      # today's state (records before stop 48 hold "open")
        if profile:
            was_corrected = bool((case.get("closed_loop") or {}).get("corrected"))
            segs = [] if nominal_rows and was_corrected else profile_rows(case, min_s)
        else:
            segs = case.get("nominal") if nominal_rows and case.get("nominal") else case.get("segments", [])
        for r in segs:
            if r["duration_s"] >= min_s and "lnGq_err" in r:
                r["seed"] = case["seed"]
                r["scenario"] = case.get("scenario", "")
                r["model_form"] = form
                # records made before the pipeline reported honest sd hold the Laplace ones
                r.setdefault("sd_laplace", {"ln_Gq_n0": r["sd_ln_Gq_n0"], "w": r["sd_w"]})
                r.setdefault("sd_ln_G_n_best_laplace", r.get("sd_ln_G_n_best"))
                rows.append(r)
    return rows


def misfit(r) -> float:
    return r["objective"] / max(r["n_features"], 1)


def calibrate(rows: list) -> dict:
    rs = np.array([misfit(r) for r in rows])
    r_ref = float(np.median(rs))
    # the gate: 5x the reference misfit (see inverse/uncertainty.py R_GATE); the printout also
    # gives the share of the calibration set above it
    out = {"R_REF": r_ref, "R_GATE": 5.0 * r_ref, "misfit_p90": float(np.percentile(rs, 90)), "KAPPA": {},
           "BETA": {q: 0.0 for q in QUANTITIES}}
    for q, (err, sd) in QUANTITIES.items():   # KAPPA with no model-form term (a correct model)
        z = [abs(r[err]) / (U.Z90 * sd(r) * np.sqrt(max(1.0, misfit(r) / r_ref)))
             for r in rows if r.get(err) is not None and sd(r)]
        out["KAPPA"][q] = float(np.percentile(z, 90))
    return out


def reported_sd(r, q, sd_lap, const) -> float:
    """inverse.uncertainty's formula with the constants in ``const`` (BETA_DIAGNOSED and, where the
    set has one, FLOOR_DIAGNOSED for a row whose model form is "diagnosed", BETA_UNEXPLAINED where
    the set has one for an "unexplained" row)."""
    return U.state_sd(sd_lap, misfit(r), q, const, r.get("model_form") or "open")


def choose_beta(rows: list, const: dict, grid=(0.0, 0.01, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5)) -> dict:
    """Per quantity, the grid value after which the coverage on ``rows`` stops rising by 2 points."""
    out = {}
    for q in QUANTITIES:
        covs = [coverage(rows, {**const, "BETA": {**const["BETA"], q: b}})[q][0] for b in grid]
        best = grid[-1]
        for i, b in enumerate(grid[:-1]):
            if max(covs[i + 1:]) - covs[i] < 0.02 + 1e-9:
                best = b
                break
        out[q] = best
    return out


def smallest_holding(pools, const: dict, term: str, grid, level: float = 0.90) -> dict:
    """Per quantity, the smallest grid value of the model-form term ``term`` (a key of ``const``,
    e.g. "BETA_DIAGNOSED") at which ``level`` of the 90 % intervals hold in every one of ``pools``
    (lists of rows); the last grid value if none does. The rule behind every model-form constant
    chosen on blind drives since 2026-11-24."""
    out = {}
    for q in QUANTITIES:
        out[q] = next((v for v in grid
                       if all(coverage(rows, {**const, term: {**const.get(term, {}), q: v}})[q][0] >= level - 1e-9
                              for rows in pools)), grid[-1])
    return out


def choose_beta_diagnosed(rows: list, const: dict, grid=(0.0, 0.01, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5)) -> dict:
    """Per quantity, the smallest grid value of BETA_DIAGNOSED at which 90 % of the intervals
    of ``rows`` (their "diagnosed" rows) hold; the last grid value if none does."""
    return smallest_holding([[r for r in rows if r.get("model_form") == "diagnosed"]], const, "BETA_DIAGNOSED", grid)


def choose_floor_diagnosed(rows: list, const: dict,
                           grid=(0.0, 0.005, 0.01, 0.02, 0.03, 0.05, 0.08, 0.1, 0.15, 0.2)) -> dict:
    """Per quantity, the smallest grid value of FLOOR_DIAGNOSED (a model-form variance that does
    not scale with the misfit, added to the reported sd^2 of "diagnosed" rows, BETA_DIAGNOSED kept)
    at which 90 % of the intervals of ``rows`` (their "diagnosed" rows) hold; the last grid value
    if none does."""
    return smallest_holding([[r for r in rows if r.get("model_form") == "diagnosed"]], const, "FLOOR_DIAGNOSED", grid)


def coverage(rows: list, const: dict) -> dict:
    res = {"n": len(rows), "poor": float(np.mean([misfit(r) > const["R_GATE"] for r in rows]))}
    for q, (err, sd) in QUANTITIES.items():
        ok, lap = [], []
        for r in rows:
            if r.get(err) is None or not sd(r):
                continue
            s = reported_sd(r, q, sd(r), const)
            ok.append(abs(r[err]) <= U.Z90 * s)
            lap.append(abs(r[err]) <= U.Z90 * sd(r))
        res[q] = (float(np.mean(ok)), float(np.mean(lap)), len(ok))
    return res


def accuracy(rows: list) -> dict:
    """Shares of segments with G(1 cycle/m) within 20 % and with the class right."""
    import math

    g1 = [abs(r["lnG_1cpm_err"]) if "lnG_1cpm_err" in r else r.get("dlnG_1cpm") for r in rows]
    g1 = np.array([g for g in g1 if g is not None], float)
    cl = [r["class_true"] == r["class_fit"] for r in rows if "class_true" in r]
    return {"n": len(rows), "g1": (float(np.mean(g1 <= math.log(1.2))) if g1.size else float("nan"), g1.size),
            "class": (float(np.mean(cl)) if cl else float("nan"), len(cl))}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sets", nargs="+", metavar="NAME=ROOT")
    ap.add_argument("--calibrate", default=None, metavar="NAME", help="derive the constants from this set")
    ap.add_argument("--min-s", type=float, default=3.0, help="shortest true segment scored [s]")
    ap.add_argument("--beta-from", default=None, metavar="NAME",
                    help="choose the model-form term BETA on this set (drives with a model gap)")
    ap.add_argument("--by-scenario", action="store_true",
                    help="also score each set's scenarios apart (NAME/SCENARIO)")
    ap.add_argument("--profile", action="store_true",
                    help="also score measured-road drives per fitted segment against the profile (NAME/profile)")
    ap.add_argument("--open-loop", action="store_true",
                    help="for closed-loop sets (bench_inverse.py --effects-auto), also score the same "
                         "drives' nominal inversions (NAME/open-loop)")
    ap.add_argument("--beta-scan", action="store_true",
                    help="print each set's coverage for a grid of the level terms' BETA "
                         "(ln Gq(n0) and ln G(n_best) alike; w keeps its constant): does one value "
                         "serve every set?")
    ap.add_argument("--verdicts", action="append", default=[], metavar="NAME=DIAG_ROOT",
                    help="re-decide the closed-loop verdicts of set NAME with today's rules from the saved "
                         "diagnoses of a blind folder (results/diagnosis_blind/...): which drives would be "
                         "corrected and which model-form term their intervals carry")
    ap.add_argument("--beta-diagnosed-from", default=None, metavar="NAME[,NAME...]",
                    help="choose BETA_DIAGNOSED (the model-form term of drives the diagnosis checked) on "
                         "these closed-loop sets pooled: per quantity the smallest grid value at which 90 %% "
                         "of their diagnosed segments' intervals hold; with two or more sets, each set "
                         "alone is also used to calibrate and the others scored out of sample")
    a = ap.parse_args(argv)
    loops = {}
    for item in a.verdicts:
        name, _, droot = item.partition("=")
        loops[name] = redecided_loops(Path(droot))
    sets = {}
    for item in a.sets:
        name, _, root = item.partition("=")
        sets[name] = load(Path(root), a.min_s, loops=loops.get(name))
    extra = {}
    for name in list(sets):
        root = Path(dict(i.partition("=")[::2] for i in a.sets)[name])
        if a.by_scenario:
            scens = sorted({r["scenario"] for r in sets[name]})
            if len(scens) > 1:
                for sc in scens:
                    extra[f"{name}/{sc}"] = [r for r in sets[name] if r["scenario"] == sc]
        if a.open_loop and any(json.loads(li).get("nominal") for li in (root / "results.jsonl").read_text().splitlines()):
            extra[f"{name}/open-loop"] = load(root, a.min_s, open_loop=True, loops=loops.get(name))
        if a.profile:
            pr = load(root, a.min_s, profile=True, loops=loops.get(name))
            if pr:
                extra[f"{name}/profile"] = pr
    # the constants of the fit that made the records (each record's fit_model; older records
    # without it came from the simulation fit)
    roots = [Path(i.partition("=")[2]) for i in a.sets]
    models = {json.loads(li).get("fit_model") or "simulation"
              for r in roots for li in (r / "results.jsonl").read_text().splitlines() if li.strip()}
    if len(models) != 1 and not a.calibrate:
        ap.error(f"the sets come from different fit models ({', '.join(sorted(models))}); score them apart")
    fit_model = models.pop() if len(models) == 1 else "mixed"
    const = {k: (dict(v) if isinstance(v, dict) else v)
             for k, v in U.calibration(fit_model if fit_model != "mixed" else "simulation").items()}
    if a.calibrate:
        const = calibrate(sets[a.calibrate])
        print(f"calibrated on '{a.calibrate}' ({len(sets[a.calibrate])} segments >= {a.min_s:g} s): "
              f"R_REF = {const['R_REF']:.3f}, R_GATE = 5 R_REF = {const['R_GATE']:.3f} (misfit 90th "
              f"percentile {const['misfit_p90']:.2f}), KAPPA = "
              + ", ".join(f"{k} {v:.2f}" for k, v in const["KAPPA"].items()))
        if a.beta_from:
            const["BETA"] = choose_beta(sets[a.beta_from], const)
            print(f"BETA chosen on '{a.beta_from}': " + ", ".join(f"{k} {v:g}" for k, v in const["BETA"].items()))
        const["BETA_DIAGNOSED"] = dict(const["BETA"])
    else:
        print(f"constants of inverse/uncertainty.py for the {fit_model} fit: R_REF {const['R_REF']}, R_GATE {const['R_GATE']}, "
              f"KAPPA {const['KAPPA']}, BETA {const['BETA']}, BETA_DIAGNOSED {const['BETA_DIAGNOSED']}")
    cross = []
    if a.beta_diagnosed_from:
        names = a.beta_diagnosed_from.split(",")
        const["BETA_DIAGNOSED"] = choose_beta_diagnosed([r for n in names for r in sets[n]], const)
        print(f"BETA_DIAGNOSED chosen on {' + '.join(names)} pooled: "
              + ", ".join(f"{k} {v:g}" for k, v in const["BETA_DIAGNOSED"].items()))
        for n in names if len(names) > 1 else []:
            bd = choose_beta_diagnosed(sets[n], const)
            for m in names:
                if m != n:
                    cross.append((f"{m}, BETA_DIAGNOSED from {n} alone ("
                                  + ", ".join(f"{v:g}" for v in bd.values()) + ")",
                                  coverage(sets[m], {**const, "BETA_DIAGNOSED": bd})))
    print("\n| set | segments >= %g s | flagged poor | 90 %% cover ln Gq(n0) | w | ln G(n_best) | "
          "noise-only sd: ln Gq(n0) | w | ln G(n_best) |" % a.min_s)
    print("|---|---|---|---|---|---|---|---|---|")
    def line(name, c):
        print(f"| {name} | {c['n']} | {100 * c['poor']:.0f} % | "
              + " | ".join(f"{100 * c[q][0]:.0f} %" for q in QUANTITIES) + " | "
              + " | ".join(f"{100 * c[q][1]:.0f} %" for q in QUANTITIES) + " |")

    scored = {**sets, **extra}
    for name, rows in scored.items():
        line(name, coverage(rows, const))
    for name, c in cross:
        line(name, c)
    print("\nmodel-form term per set (segments): " + "; ".join(
        f"{name} {sum(r.get('model_form') == 'diagnosed' for r in rows)} diagnosed / "
        f"{sum(r.get('model_form') != 'diagnosed' for r in rows)} open" for name, rows in scored.items()))
    print("\n| set | segments >= %g s | G(1 cycle/m) within 20 %% | class right |" % a.min_s)
    print("|---|---|---|---|")
    for name, rows in scored.items():
        c = accuracy(rows)
        print(f"| {name} | {c['n']} | {100 * c['g1'][0]:.0f} % | {100 * c['class'][0]:.0f} % |")
    if a.beta_scan:
        print("\n| BETA (ln Gq(n0), ln G(n_best)) | " + " | ".join(scored) + " |")
        print("|---|" + "---|" * len(scored))
        for b in (0.0, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0):
            c = {**const, **{k: {**const[k], "ln_Gq_n0": b, "ln_G_n_best": b} for k in ("BETA", "BETA_DIAGNOSED")}}
            cells = []
            for rows in scored.values():
                cv = coverage(rows, c)
                cells.append(f"{100 * cv['ln_Gq_n0'][0]:.0f} / {100 * cv['ln_G_n_best'][0]:.0f} %")
            print(f"| {b:g} | " + " | ".join(cells) + " |")
    if a.calibrate:   # out of sample on the calibration family: odd seeds calibrate even ones and back
        rows = sets[a.calibrate]
        for part, other in ((1, 0), (0, 1)):
            train = [r for r in rows if r["seed"] % 2 == part]
            test = [r for r in rows if r["seed"] % 2 == other]
            c = {**calibrate(train), "BETA": const["BETA"]}
            line(f"{a.calibrate}, {'even' if other == 0 else 'odd'} seeds with KAPPA from the "
                 f"{'odd' if part == 1 else 'even'} ones", coverage(test, c))
            if a.beta_from:
                rb = sets[a.beta_from]
                cb = {**const, "BETA": choose_beta([r for r in rb if r["seed"] % 2 == part], const)}
                line(f"{a.beta_from}, {'even' if other == 0 else 'odd'} seeds with BETA from the "
                     f"{'odd' if part == 1 else 'even'} ones", coverage([r for r in rb if r["seed"] % 2 == other], cb))
    return 0


if __name__ == "__main__":
    sys.exit(main())
