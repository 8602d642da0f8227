"""The effect profile's evidence, from the records of this folder (python
results/inverse_blind/20261128-effect-profile/score_profile.py [CONFIRM BASELINE], from the
repository root; CONFIRM and BASELINE are bench roots or their results.jsonl, by default the records here).

1. Friction drives 61-80 (our truck, leaf friction 2000 N and a flexible frame; loop closed, records
   in ../20261128-beta-diagnosed-pooled/fresh-friction-61-80/) against the same drives inverted with
   the TRUE leaf friction (records/oracle-true-friction.jsonl; make_oracle.py) and, for five drives, with
   the true friction and the truth's flexible frame (records/oracle-true-friction-and-frame.jsonl).
2. The profile (diagnosis.effect_profile) on the 17 corrected drives: each value tried
   (records/profile-runs.jsonl; k = 0 is the loop's own record), the search as it ran
   (records/profiles.jsonl; reach up to four steps), and the same runs with the search capped at one
   and at two steps (chosen after seeing these drives: in-sample).
3. The confirmatory comparison: CONFIRM (a bench_inverse.py --effects-auto run with the profile capped
   at two steps, friction seeds 41-60, records/confirm-41-60-profiled.jsonl) against BASELINE (the same
   drives and diagnoses at the diagnosis's value, records/confirm-41-60-baseline.jsonl).
Segments >= 3 s; G(1) "within 20 %" = |ln G(1 cycle/m) error| <= ln 1.2 (issue 14); intervals with
today's constants of the linear axle-3 fit (benchmarks/calibrate_uncertainty.py)."""
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.stats import binomtest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import QUANTITIES, coverage  # noqa: E402

from inverse import uncertainty as U  # noqa: E402

L = math.log(1.2)
LOOP = HERE.parent / '20261128-beta-diagnosed-pooled' / 'fresh-friction-61-80' / 'results.jsonl'


def jsonl(path):
    return [json.loads(line) for line in Path(path).read_text().splitlines() if line.strip()]


def rows(case, form=None):
    out = []
    for s in case['segments']:
        if s['duration_s'] >= 3 and 'lnG_1cpm_err' in s:
            s = dict(s, model_form=form or (case.get('closed_loop') or {}).get('model_form') or 'diagnosed')
            s.setdefault('sd_laplace', {'ln_Gq_n0': s['sd_ln_Gq_n0'], 'w': s['sd_w']})
            s.setdefault('sd_ln_G_n_best_laplace', s.get('sd_ln_G_n_best'))
            out.append(s)
    return out


def g1(rs):
    return np.array([abs(s['lnG_1cpm_err']) <= L for s in rs])


def klass(rs):
    return np.array([s['class_true'] == s['class_fit'] for s in rs])


def cover(rs):
    cv = coverage(rs, U.calibration('linear'))
    return ' / '.join(f"{100 * cv[q][0]:.0f}" for q in QUANTITIES)


def gains_losses(a, b):
    """Paired segments whose G(1) within 20 % ``b`` gains over ``a``, and loses."""
    ga, gb = g1(a), g1(b)
    return int(np.sum(gb & ~ga)), int(np.sum(ga & ~gb))


def paired(a, b):
    ga, gb = g1(a), g1(b)
    gain, loss = gains_losses(a, b)
    p = binomtest(gain, gain + loss, 0.5, alternative='greater').pvalue if gain + loss else 1.0
    return (f"{len(a)} segments: G(1) within 20 % {100 * ga.mean():.1f} -> {100 * gb.mean():.1f} % "
            f"(+{gain} / -{loss}, one-sided sign test p = {p:.3f}); class {100 * klass(a).mean():.1f} -> "
            f"{100 * klass(b).mean():.1f} %; intervals {cover(a)} -> {cover(b)} %")


def main(argv):
    loop = {c['seed']: c for c in jsonl(LOOP)}
    print('1. The loop at the diagnosis\'s value against the true effects (friction seeds 61-80)')
    for name, f in (('true leaf friction', 'oracle-true-friction.jsonl'),
                    ('true leaf friction and flexible frame', 'oracle-true-friction-and-frame.jsonl')):
        orc = {c['seed']: c for c in jsonl(HERE / 'records' / f)}
        seeds = sorted(orc)
        a = sum((rows(loop[s], 'diagnosed') for s in seeds), [])
        b = sum((rows(orc[s], 'diagnosed') for s in seeds), [])
        print(f"   {name}, {len(seeds)} drives: {paired(a, b)}")
    orc = {c['seed']: c for c in jsonl(HERE / 'records' / 'oracle-true-friction.jsonl')}
    ff = {c['seed']: c for c in jsonl(HERE / 'records' / 'oracle-true-friction-and-frame.jsonl')}
    a = sum((rows(orc[s], 'diagnosed') for s in sorted(ff)), [])
    print(f"   the frame added to the true friction ({len(ff)} drives): {paired(a, sum((rows(ff[s], 'diagnosed') for s in sorted(ff)), []))}")

    runs = {(c['seed'], c['k']): c for c in jsonl(HERE / 'records' / 'profile-runs.jsonl')}
    profs = {p['seed']: p for p in jsonl(HERE / 'records' / 'profiles.jsonl')}
    print(f"\n2. The profile on the {len(profs)} corrected drives (values tried per drive: "
          f"{np.mean([len(p['values']) for p in profs.values()]):.1f} as it ran)")
    print('   | seed | diagnosis [N] | objective per step k (value x 1.3^k) | chosen as run [N] | capped at 2 [N] |')
    print('   |---|---|---|---|---|')
    for seed, p in sorted(profs.items()):
        objs = {k: o for k, o in zip(p['k'], p['objectives']) if abs(k) <= 2}
        steps = ', '.join(f"{k}: {o:.1f}" for k, o in sorted(zip(p['k'], p['objectives'])))
        print(f"   | {seed} | {p['values'][0]:.0f} | {steps} | {p['values'][p['best']]:.0f} | "
              f"{p['values'][0] * 1.3 ** min(objs, key=objs.get):.0f} |")
    for cap, label in ((None, 'as it ran (reach 4 steps)'), (1, 'capped at 1 step'), (2, 'capped at 2 steps')):
        a, b, err0, err1 = [], [], [], []
        for seed, p in sorted(profs.items()):
            objs = {k: o for k, o in zip(p['k'], p['objectives']) if cap is None or abs(k) <= cap}
            kb = min(objs, key=objs.get)
            a += rows(loop[seed])
            b += rows(loop[seed] if kb == 0 else dict(runs[(seed, kb)], closed_loop=loop[seed]['closed_loop']))
            err0.append(math.log(p['values'][0] / 2000.0))
            err1.append(math.log(p['values'][0] * 1.3 ** kb / 2000.0))
        e0, e1 = np.abs(err0), np.abs(err1)
        print(f"   {label}: {paired(a, b)}; friction value |ln error| median {np.median(e0):.3f} -> "
              f"{np.median(e1):.3f}, within x1.2 {int(np.sum(e0 <= L))} -> {int(np.sum(e1 <= L))} of {len(e0)}")
    if not argv:
        argv = [HERE / 'records' / 'confirm-41-60-profiled.jsonl', HERE / 'records' / 'confirm-41-60-baseline.jsonl']
    if len(argv) == 2:
        conf, base = ({c['seed']: c for c in jsonl(Path(r) / 'results.jsonl' if Path(r).is_dir() else r)}
                      for r in argv)
        seeds = sorted(s for s in conf if conf[s].get('closed_loop', {}).get('profile'))
        a = sum((rows(base[s]) for s in seeds), [])
        b = sum((rows(conf[s]) for s in seeds), [])
        print(f"\n3. Confirmatory set ({len(seeds)} drives profiled): {paired(a, b)}")
        ch = [(conf[s]['closed_loop']['profile']['diagnosis_value'], conf[s]['closed_loop']['profile']['chosen'])
              for s in seeds]
        e0 = np.abs([math.log(d / 2000.0) for d, _ in ch])
        e1 = np.abs([math.log(c / 2000.0) for _, c in ch])
        print(f"   friction value |ln error| median {np.median(e0):.3f} -> {np.median(e1):.3f}, within x1.2 "
              f"{int(np.sum(e0 <= L))} -> {int(np.sum(e1 <= L))} of {len(ch)}")
        allc = sorted(set(conf) & set(base))
        a = sum((rows(base[s]) for s in allc), [])
        b = sum((rows(conf[s]) for s in allc), [])
        print(f"   whole set ({len(allc)} drives, every verdict): {paired(a, b)}")


if __name__ == '__main__':
    main(sys.argv[1:])
