"""The closed loop with axle 3's accelerations alone where the verdict is 'unexplained', composed from
fits already made (python results/inverse_blind/20261128-correct-on-ambiguous/compose_unexplained.py
[--profile] [CL_ROOT ACC_ROOT], from the repository root).

A closed-loop set gives each drive's verdict and its fits (axle 3, or 'axles' where the verdict is
'none'); an open-loop set of the same drives fitted on 'axle3_acc' gives the rows an 'unexplained'
drive gets with the new choice. Each row's 90 % interval is recomputed with the constants of its
channel set (inverse.uncertainty.CALIBRATIONS) and model form. Defaults: the independent truck,
independent-cl/ (this folder) and ../20261128-acceleration-only-fit/axle3-acc/second/; the friction
drives: seeds1-20/ and ../20261128-acceleration-only-fit/axle3-acc/random/. --profile scores the
measured-road drives' fitted segments against the profile. Segments >= 3 s."""
import json
import math
import sys
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import accuracy, coverage, load  # noqa: E402

from inverse import uncertainty as U  # noqa: E402

L = math.log(1.2)
ACC = HERE.parent / '20261128-acceleration-only-fit' / 'axle3-acc'


def g1(r):
    e = r['lnG_1cpm_err'] if 'lnG_1cpm_err' in r else r.get('dlnG_1cpm')
    return e is not None and abs(e) <= L


def cov(groups):
    tot = {q: [0.0, 0] for q in ('ln_Gq_n0', 'w', 'ln_G_n_best')}
    for key, rows in groups.items():
        if rows:
            c = coverage(rows, U.calibration(key))
            for q in tot:
                tot[q][0] += c[q][0] * c[q][2]
                tot[q][1] += c[q][2]
    return ' / '.join(f'{100 * a / max(n, 1):.0f}' for a, n in tot.values())


def compose(cl_root, acc_root, profile):
    verdict = {json.loads(l)['seed']: json.loads(l)['closed_loop']['verdict']
               for l in (cl_root / 'results.jsonl').read_text().splitlines()}
    rows_cl, rows_acc = load(cl_root, profile=profile), load(acc_root, profile=profile)
    today = {'linear/axles': [r for r in rows_cl if verdict[r['seed']] == 'none'],
             'linear': [r for r in rows_cl if verdict[r['seed']] != 'none']}
    new = {'linear/axles': today['linear/axles'],
           'linear': [r for r in rows_cl if verdict[r['seed']] not in ('none', 'unexplained')],
           'linear/axle3_acc': [r for r in rows_acc if verdict.get(r['seed']) == 'unexplained']}
    print(f"{cl_root.name} ({'fitted segments against the profile' if profile else 'true segments'}); "
          f"verdicts {dict(Counter(verdict.values()))}")
    res = {}
    for name, d in (('axle 3 where unexplained', today), ('axle3_acc where unexplained', new)):
        rows = sum(d.values(), [])
        a = accuracy(rows)
        res[name] = {(r['seed'], round(r['duration_s'], 3)): r for r in rows}
        print(f"  {name}: {len(rows)} segments; G(1 cycle/m) within 20 % {100 * a['g1'][0]:.1f} %, class right "
              f"{100 * a['class'][0]:.1f} %; 90 % intervals cover {cov(d)} % (ln Gq(n0) / w / ln G(n_best))")
    A, B = res.values()
    ks = sorted(set(A) & set(B))
    print(f"  paired G(1): {sum(g1(B[k]) and not g1(A[k]) for k in ks)} gained / "
          f"{sum(g1(A[k]) and not g1(B[k]) for k in ks)} lost of {len(ks)}")


def main():
    args = [a for a in sys.argv[1:] if a != '--profile']
    profile = '--profile' in sys.argv
    if args:
        compose(Path(args[0]), Path(args[1]), profile)
        return
    compose(HERE / 'independent-cl', ACC / 'second', profile)
    if not profile:
        compose(HERE / 'seeds1-20', ACC / 'random', False)


if __name__ == '__main__':
    main()
