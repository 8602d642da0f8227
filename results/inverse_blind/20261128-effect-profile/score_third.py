"""The third set's test (decision.txt, stated at stop 51 before its drives existed), from the repository
root: python results/inverse_blind/20261128-effect-profile/score_third.py [PROFILED BASELINE]

PROFILED: a bench_inverse.py --effects-auto run with the profile capped at two steps (worktree at 4f67d65),
friction seeds 81-100 (records/third-81-100-profiled.jsonl by default); BASELINE: the same drives and the
same saved diagnoses at the diagnosis's value (--no-profile --diagnoses PROFILED;
fresh-friction-81-100/results.jsonl, the shipped loop's records). Truth: our own Exudyn truck with leaf friction 2000 N and a flexible
frame (a gap our code made). Segments >= 3 s, drives the loop corrected (and so profiled).

Adopt only if (a) on 81-100 G(1)-within-20 % gains > losses, (b) pooled over 41-60 and 81-100 (the two
sets the capped code was not designed on) the one-sided sign test gives p < 0.05, (c) the corrected
drives' coverage on 81-100 stays >= 85 % in each of ln Gq(n0) / w / ln G(n_best)."""
import sys
from pathlib import Path

from scipy.stats import binomtest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
from calibrate_uncertainty import QUANTITIES, coverage  # noqa: E402
from score_profile import gains_losses, jsonl, paired, rows  # noqa: E402

from inverse import uncertainty as U  # noqa: E402


def load(r):
    r = Path(r)
    return {c['seed']: c for c in jsonl(r / 'results.jsonl' if r.is_dir() else r)}


def corrected_pairs(prof, base, flag='profile'):
    """The seeds whose ``prof`` record's closed loop has ``flag`` set (profiled; or 'corrected') and
    that ``base`` holds, with both records' segment rows in that order."""
    seeds = sorted(s for s in prof if (prof[s].get('closed_loop') or {}).get(flag) and s in base)
    return seeds, sum((rows(base[s]) for s in seeds), []), sum((rows(prof[s]) for s in seeds), [])


def main(argv):
    rec = HERE / 'records'
    if not argv:
        argv = [rec / 'third-81-100-profiled.jsonl', HERE / 'fresh-friction-81-100']
    prof, base = load(argv[0]), load(argv[1])
    seeds, a, b = corrected_pairs(prof, base)
    g3, l3 = gains_losses(a, b)
    print(f"Third set, seeds 81-100 ({len(seeds)} drives corrected and profiled): {paired(a, b)}")
    cv = coverage(b, U.calibration('linear'))
    cov = {q: 100 * cv[q][0] for q in QUANTITIES}
    s1, a1, b1 = corrected_pairs(load(rec / 'confirm-41-60-profiled.jsonl'), load(rec / 'confirm-41-60-baseline.jsonl'))
    g1_, l1 = gains_losses(a1, b1)
    gp, lp = g3 + g1_, l3 + l1
    p = binomtest(gp, gp + lp, 0.5, alternative='greater').pvalue if gp + lp else 1.0
    print(f"Pooled out-of-sample (41-60: {len(s1)} drives +{g1_} / -{l1}; 81-100: +{g3} / -{l3}): "
          f"+{gp} / -{lp}, one-sided sign test p = {p:.4f}")
    ok_a, ok_b = g3 > l3, p < 0.05
    ok_c = all(v >= 85 for v in cov.values())
    print(f"(a) gains > losses on 81-100: {'yes' if ok_a else 'NO'} (+{g3} / -{l3})")
    print(f"(b) pooled p < 0.05: {'yes' if ok_b else 'NO'} (p = {p:.4f})")
    print(f"(c) coverage >= 85 % on 81-100's corrected drives: {'yes' if ok_c else 'NO'} ("
          + ' / '.join(f"{v:.0f}" for v in cov.values()) + " %)")
    print(f"Decision by the stated test: {'ADOPT' if ok_a and ok_b and ok_c else 'NOT ADOPTED'}")
    print(f"Whole set ({len(set(prof) & set(base))} drives, every verdict): {paired(*whole_set(prof, base))}")


def whole_set(prof, base):
    """Both records' segment rows over every seed the two hold."""
    allc = sorted(set(prof) & set(base))
    return sum((rows(base[s]) for s in allc), []), sum((rows(prof[s]) for s in allc), [])


if __name__ == '__main__':
    main(sys.argv[1:])
