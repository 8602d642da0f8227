"""Where the friction loop's G(1 cycle/m) misses come from, per set of 20 (stop 52; from the repository root):
python results/inverse_blind/20261129-calibration-seeds/friction_decomposition.py

Read from records already committed (no simulation): the five friction sets' closed-loop roots (our truck,
leaf friction 2000 N + flexible frame: a gap our code made) and, for seeds 61-80, the same drives inverted
with the TRUE friction (../20261128-effect-profile/records/oracle-true-friction.jsonl). Per set, segments >= 3 s:
* nominal: the same drives inverted without the loop (the gap left in) -- is a set harder for the fit?
* oracle, true segment / fit's window: the one-slope fit to the road itself under the reference axle, over the
  true segment / over the fitted segment it is scored with -- the segmentation's share;
* the loop's error about the road under its own window (lnG_1cpm_err minus the window oracle's) -- the
  estimator's share, whose sd against the no-gap drives' 0.08-0.15 (docs/inverse.md, section 'Left');
* the loop: G(1) within 20 %.
Rows of 1-20 and 21-40 are the roots as run (before stop 48's composition that friction_sets.py applies).
Second table: on the drives corrected with leaf friction, the loop's error about its window's road against
ln(value / 2000 N) of the value it was corrected with, per true class: how much of the value's error reaches
the road, and where. Third: the 90 % intervals of the corrected ('diagnosed') segments per true class, with the
shipped constants (calibrate_uncertainty.coverage). Last line: whether a drive's share of smooth road (true
classes A-B) tells how far its value is off."""
import json
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
R = HERE.parent
sys.path.insert(0, str(R.parents[1] / 'benchmarks'))
sys.path.insert(0, str(R.parents[1]))
from calibrate_uncertainty import coverage, load  # noqa: E402
from scipy.stats import spearmanr  # noqa: E402

import inverse.uncertainty as U  # noqa: E402

ROOTS = {'seeds 1-20': R / '20261128-correct-on-ambiguous' / 'seeds1-20',
         'seeds 21-40': R / '20261128-correct-on-ambiguous' / 'seeds21-40',
         'seeds 41-60': R / '20261128-closest-vehicle-effect' / 'fresh-friction-41-60',
         'seeds 61-80': R / '20261128-beta-diagnosed-pooled' / 'fresh-friction-61-80',
         'seeds 81-100': R / '20261128-effect-profile' / 'fresh-friction-81-100'}
TRUE_FRICTION = R / '20261128-effect-profile' / 'records' / 'oracle-true-friction.jsonl'
L = math.log(1.2)


def ln_g1(gq, w):
    """ln of a one-slope PSD at 1 cycle/m (n0 = 0.1), as bench_inverse.score_case scores the truth."""
    return math.log(gq) - w * math.log(10.0)


def window_error(r):
    """ln G(1) of the road fitted over the row's fitted window (the window oracle) against the truth's."""
    return ln_g1(r['oracle_fit_window']['Gq'], r['oracle_fit_window']['w']) - ln_g1(r['Gq_true'], r['w_true'])


def line(label, rows):
    within = lambda e: float(np.mean(np.abs(e) <= L))
    e = np.array([r['lnG_1cpm_err'] for r in rows])
    if not all(r.get('oracle') and r.get('oracle_fit_window') for r in rows):   # nominal rows carry no oracle
        print(f"| {label} | {len(rows)} | | | | {100 * within(e):.1f} % |")
        return
    tru = [ln_g1(r['Gq_true'], r['w_true']) for r in rows]
    ot = np.array([ln_g1(r['oracle']['Gq'], r['oracle']['w']) - t for r, t in zip(rows, tru)])
    ow = np.array([window_error(r) for r in rows])
    about = e - ow
    print(f"| {label} | {len(rows)} | {100 * within(ot):.0f} % | {100 * within(ow):.0f} % | {about.mean():+.3f} / "
          f"{about.std():.3f} / {np.median(np.abs(about)):.3f} | {100 * within(e):.1f} % |")


def main():
    print('| set | segments | oracle, true segment | oracle, fit window | loop about its window: mean / sd / median abs '
          '| loop G(1) within 20 % |')
    print('|---|---|---|---|---|---|')
    for name, root in ROOTS.items():
        line(f'{name}, nominal (gap left in)', load(root, open_loop=True))
        line(f'{name}, loop', load(root))
    true = [dict(r, seed=c['seed']) for c in map(json.loads, TRUE_FRICTION.read_text().splitlines())
            for r in c['segments'] if r['duration_s'] >= 3.0]
    seeds = {r['seed'] for r in true}
    loop = [r for r in load(ROOTS['seeds 61-80']) if r['seed'] in seeds]
    line(f'seeds 61-80, loop, the {len(seeds)} drives below', loop)
    line(f'seeds 61-80, the same drives at the TRUE friction', true)
    print()
    # one pass over the five sets: the drives corrected with leaf friction, per true class
    by_class, diag, err, smooth = {}, {}, [], []
    for root in ROOTS.values():
        recs = {c['seed']: c for c in map(json.loads, (root / 'results.jsonl').read_text().splitlines())}
        value = {sd: ((c.get('closed_loop') or {}).get('effects') or {}).get('leaf_friction', {}).get('force')
                 for sd, c in recs.items()}
        for r in load(root):
            if value[r['seed']] and r.get('oracle_fit_window'):
                by_class.setdefault(r['class_true'], []).append(
                    (math.log(value[r['seed']] / 2000.0), r['lnG_1cpm_err'] - window_error(r)))
            if r['model_form'] == 'diagnosed':
                diag.setdefault(r['class_true'], []).append(r)
        every = load(root, min_s=0.0)
        for sd in recs:
            if value[sd]:
                rr = [r for r in every if r['seed'] == sd]
                err.append(abs(math.log(value[sd] / 2000.0)))
                smooth.append(sum(r['duration_s'] for r in rr if r['class_true'] in 'AB') / sum(r['duration_s'] for r in rr))
    print('| true class | segments | d(error about the window) / d ln(value): slope | correlation | sd left |')
    print('|---|---|---|---|---|')
    for cl in sorted(by_class):
        x, y = np.array(by_class[cl]).T
        if len(x) < 5:
            continue
        b = np.polyfit(x, y, 1)
        print(f'| {cl} | {len(x)} | {b[0]:+.2f} | {np.corrcoef(x, y)[0, 1]:+.2f} | {np.std(y - np.polyval(b, x)):.3f} |')
    print()
    const = U.calibration('linear')
    print("| true class | corrected segments | 90 % intervals cover ln Gq(n0) / w / ln G(n_best) |")
    print('|---|---|---|')
    for cl in sorted(diag) + ['all']:
        rows = sum(diag.values(), []) if cl == 'all' else diag[cl]
        c = coverage(rows, const)
        print(f"| {cl} | {len(rows)} | {' / '.join(f'{100 * c[q][0]:.0f}' for q in ('ln_Gq_n0', 'w', 'ln_G_n_best'))} % |")
    r, p = spearmanr(smooth, err)
    print(f'\n{len(err)} drives corrected with leaf friction: |ln(value / 2000 N)| against the share of true class A-B '
          f'road: Spearman {r:+.2f} (p {p:.2f})')


if __name__ == '__main__':
    main()
