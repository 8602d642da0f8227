"""Blind benchmark of ``eroad diagnose`` (issue 7, item 2) and its timing.

Makes ``--n`` synthetic drives (``eroad synth --scenario null --seed S --effect
NAME.PARAM=VALUE``: the nominal truck plus ONE effect at a random strength, random road
and speed; about one in five a null case with no effect), diagnoses each from a copy
without ``truth/`` with the whole effect library, and prints:

* per case: truth, verdict and confidence, predicted and true shrink, localisation hit,
  wall time of the diagnosis;
* the confusion matrix (rows truth, columns verdict), top-1 accuracy, the rate of
  "none" on null cases, confident wrong attributions, localisation hit rate, mean
  |predicted - true shrink|;
* the wall time per diagnosis against a reference measured in the same run (one
  nominal 30 s simulation of the truck), so that the number travels between machines.

Targets (issue 7): >= 30 cases, top-1 >= 90 %, null "none" >= 90 %, no confident wrong
attribution.  Results go to ``OUT/blind.json`` and ``OUT/confusion.txt``; a run can be
resumed (cases already in blind.json are kept).

Usage::

    nice python benchmarks/bench_diagnosis.py --n 30 --out results/diagnosis-blind [--workers 2]
    nice python benchmarks/bench_diagnosis.py --n 10 --seed 1 --null-only --out results/nulls
    nice python benchmarks/bench_diagnosis.py --family nominal --n 22 --n-null 6 --out W1
    nice python benchmarks/bench_diagnosis.py --family second --n 18 --out W2

The last two are the 40-case blind set of the verdict vocabulary (16 one-effect drives of
the Exudyn truck, 6 of it without effect; 18 of the independent truck, 9 with leaf friction
or a payload change, 9 with only its out-of-library differences, 5 of the 18 on the measured
road profile).

Timings are printed, never asserted.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def reference_time() -> float:
    """Wall time of one nominal 30 s simulation of the dump truck (class C, 10 m/s)."""
    from roadlib.segments import RoadSegment, segmented_surface
    from vehicles.simulate import simulate

    road = segmented_surface([RoadSegment(Gq_n0=256e-6, share=330.0)], 330.0, 3.0, 0.05, 0.1, seed=1)
    t = time.perf_counter()
    simulate("dump_truck_8x4", road, 10.0, 30.0)
    return time.perf_counter() - t


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=30, help="number of blind cases (default 30)")
    ap.add_argument("--out", default="results/diagnosis-blind", help="work and result folder")
    ap.add_argument("--seed", type=int, default=0, help="root seed of the cases")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--duration", type=float, default=None, help="record length [s] (default 30)")
    ap.add_argument("--folds", type=int, choices=(1, 2), default=None,
                    help="ranking folds (default: that of diagnosis.blind.BLIND_SETTINGS)")
    ap.add_argument("--n-null", type=int, default=None,
                    help="null cases among them (default: a fifth, families second and measured: half)")
    ap.add_argument("--null-only", action="store_true",
                    help="every case a null drive (the extra null validation: --seed 1)")
    ap.add_argument("--family", choices=("nominal", "second", "measured"), default="nominal",
                    help="truth family: the Exudyn truck plus one effect (nominal), the "
                         "independently written truck with out-of-library differences (second), "
                         "or the Exudyn truck on the measured road profile (measured: no vehicle "
                         "difference, a real road)")
    ap.add_argument("--vehicle", default=None,
                    help="truth and model vehicle of family nominal (built-in id or TOML; default "
                         "the dump truck); payload strengths scaled by its nominal payload, the "
                         "others the dump truck's (diagnosis.blind.make_cases)")
    ap.add_argument("--effects", default=None, metavar="A,B",
                    help="library effects the one-effect cases draw from, in turn (default: all the "
                         "family carries, diagnosis.blind.FAMILIES): a set aimed at some effects")
    ap.add_argument("--rescore", action="store_true",
                    help="re-decide the saved cases of --out with the thresholds given below "
                         "(no simulation) and print the score")
    ap.add_argument("--sweep", metavar="OTHER", default=None,
                    help="set the verdict thresholds on the saved cases of --out (best of "
                         "diagnosis.blind.SWEEP_GRID) and check them on the saved cases of OTHER")
    ap.add_argument("--band-refit", action="store_true",
                    help="refit the road band with the ranking's first effect in the truck "
                         "(diagnosis.road_fit.refit_band); each case keeps the first pass's "
                         "verdict beside the final one")
    ap.add_argument("--joint-band", action="store_true",
                    help="choose the road band jointly with the effect (diagnosis.pipeline."
                         "JOINT_BAND, the default since stop 57; the flag keeps the commands of "
                         "results/diagnosis_blind/20261129-joint-band as they ran): a second pass on "
                         "a road cut where the measured spectrum steps down; each case keeps the "
                         "first pass's verdict beside the final one")
    ap.add_argument("--share-min", type=float, default=None)
    ap.add_argument("--signature-max", type=float, default=None)
    ap.add_argument("--signature-share", type=float, default=None)
    ap.add_argument("--signature-method", choices=("single_input", "two_input"), default=None,
                    help="with --rescore: the transmissibility the verdict checks (default: "
                         "diagnosis.verdict.SIGNATURE_METHOD)")
    ap.add_argument("--signature-null", action="store_true",
                    help="with --rescore: hold the signature to the candidate's own scatter "
                         "(diagnosis.verdict.signature_threshold; not the default)")
    args = ap.parse_args(argv)

    if args.sweep:
        from diagnosis.blind import rescore, sweep, _family_score

        rows = sweep(args.out)
        print(f"set on {args.out}: {len(rows)} threshold triples; the ten best")
        for r in rows[:10]:
            print(f"  {r['thresholds']}  effect top-1 {r['effect_top1']:.2f}  no-effect right "
                  f"{r['no_effect_right']:.2f}  confident wrong {r['confident_wrong']}")
        best = rows[0]["thresholds"]
        chk = rescore(args.sweep, **best)["results"]
        fam = _family_score(chk)
        print(f"checked on {args.sweep} with {best}: effect top-1 {fam['effect_top1']:.2f}, "
              f"no-effect right {fam['no_effect_right']:.2f}, confident wrong "
              f"{sum(r['confident_wrong'] for r in chk)} ({fam['n']} cases)")
        return 0

    if args.rescore:
        from diagnosis.blind import format_confusion, rescore

        th = {k: v for k, v in (("share_min", args.share_min), ("signature_max", args.signature_max),
                                ("signature_share", args.signature_share),
                                ("signature_method", args.signature_method),
                                ("signature_null", args.signature_null or None)) if v is not None}
        out = rescore(args.out, **th)
        print(f"thresholds {th or 'defaults'}")
        print(format_confusion(out["score"]))
        sc = out["score"]
        print(json.dumps({k: sc[k] for k in ("n_cases", "effect_top1_accuracy",
                                            "null_none_or_unexplained_rate", "confident_wrong",
                                            "param_within_1p5_rate", "by_family")}, indent=1))
        return 0

    from diagnosis.blind import format_confusion, run_blind

    ref = reference_time()
    print(f"reference: one nominal 30 s truck simulation {ref:.2f} s", flush=True)
    t = time.perf_counter()
    settings = {**({} if args.folds is None else {"folds": args.folds}),
                **({"band_refit": True} if args.band_refit else {}),
                **({"joint_band": True} if args.joint_band else {})}
    out = run_blind(args.out, args.n, seed=args.seed, workers=args.workers, duration=args.duration,
                    settings=settings or None,
                    n_null=args.n if args.null_only else args.n_null, family=args.family,
                    effects=args.effects.split(",") if args.effects else None,
                    vehicle=args.vehicle, progress=lambda m: print(m, flush=True))
    wall = time.perf_counter() - t
    sc = out["score"]
    res = out["results"]
    print("\nconfusion matrix (rows truth, columns verdict):")
    print(format_confusion(sc))
    d = [r["diagnose_s"] for r in res]
    print(f"\ncases {sc['n_cases']}: top-1 {sc['top1_accuracy']:.2f} (effect cases "
          f"{sc['effect_top1_accuracy']:.2f}), null 'none' {sc['null_none_rate']:.2f}, "
          f"'none' or 'unexplained' {sc['null_none_or_unexplained_rate']:.2f}, parameter within "
          f"x1.5 {sc['param_within_1p5_rate']:.2f}, "
          f"confident wrong {sc['confident_wrong']}, localisation hits on effect cases "
          f"{sc['localisation_hit_rate_effects']:.2f}, flagged cells on null cases "
          f"{sc['null_flagged_cells']}, mean |pred - true shrink| {sc['shrink_mean_abs_diff']}")
    print(f"detectable cases (the truth's effect -- for the independent truck the library's at the true value -- passes the noise gate) {sc['n_detectable']}: top-1 "
          f"{sc['detectable_top1_accuracy']:.2f}; undetectable effect cases answered 'none' "
          f"{sc['undetectable_none_rate']:.2f}")
    print(f"diagnosis wall time: mean {sum(d) / len(d):.1f} s, max {max(d):.1f} s "
          f"({sum(d) / len(d) / ref:.0f} x the reference simulation); whole run {wall:.0f} s")
    Path(args.out, "timing.json").write_text(json.dumps(
        {"reference_sim_s": ref, "diagnose_s": d, "wall_s": wall}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
