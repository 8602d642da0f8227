"""The model-form term of the closed loop's 'unexplained' drives (fitted on axle 3's accelerations):
chosen on the saved loops, checked on fresh ones (python
results/inverse_blind/20261128-closest-vehicle-effect/beta_unexplained.py [FRESH_ROOT ...], from the
repository root).

Calibration rows (segments >= 3 s): the 'unexplained' drives of the independent truck's two saved
closed loops (seeds 1-20: their axle3_acc fits, ../20261128-acceleration-only-fit/axle3-acc/second;
seeds 41-52: ../20261128-correct-on-ambiguous/independent-41-52) and the three friction drives the
closest-effect rule corrects (same-drives/), and the measured-road drives' fitted segments
scored against the profile under them (the truth closest to a user's road). Rule (as for
BETA_DIAGNOSED, benchmarks/calibrate_uncertainty.py --beta-diagnosed-from, with the real-road rows
as a second pool): per quantity the smallest grid value at which 90 % of the intervals hold in the
pooled true segments AND in the pooled profile segments; R_REF and KAPPA stay those of the channel
set (inverse.uncertainty.CALIBRATIONS["linear/axle3_acc"]). Printed: coverage per set with the open
term (today) and the chosen one. A FRESH_ROOT (a closed-loop bench_inverse.py root) is scored on
its 'unexplained' drives with both."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import QUANTITIES, coverage, load, smallest_holding  # noqa: E402

from inverse import uncertainty as U  # noqa: E402

AMB = HERE.parent / '20261128-correct-on-ambiguous'
ACC = HERE.parent / '20261128-acceleration-only-fit' / 'axle3-acc'
GRID = (0.0, 0.01, 0.03, 0.05, 0.1, 0.2, 0.3, 0.5)


def verdicts(root):
    return {json.loads(l)['seed']: (json.loads(l).get('closed_loop') or {}).get('verdict')
            for l in (Path(root) / 'results.jsonl').read_text().splitlines()}


def unexplained(rows, v):
    """The rows of 'unexplained' drives, each scored with the constants' BETA (the candidate)."""
    return [dict(r, model_form='open') for r in rows if v.get(r['seed']) == 'unexplained']


def calibration_sets():
    v1, v2 = verdicts(AMB / 'independent-cl'), verdicts(AMB / 'independent-41-52')
    fric = [dict(r, model_form='open') for r in
            load(HERE / 'same-drives' / 'seeds1-20') + load(HERE / 'same-drives' / 'seeds21-40')]
    return ({'independent 1-20': unexplained(load(ACC / 'second'), v1),
             'independent 41-52': unexplained(load(AMB / 'independent-41-52'), v2),
             'friction, closest corrected': fric},
            {'independent 1-20, profile': unexplained(load(ACC / 'second', profile=True), v1),
             'independent 41-52, profile': unexplained(load(AMB / 'independent-41-52', profile=True), v2)})


def choose(pools, const):
    """The rule: per quantity the smallest grid value of the term (scored as BETA on the rows,
    all relabelled 'open') at which 90 % of the intervals hold in every pool."""
    return smallest_holding(pools, const, 'BETA', GRID)


def show(name, rows, consts):
    cells = []
    for label, c in consts.items():
        cv = coverage(rows, c)
        cells.append(' / '.join(f"{100 * cv[q][0]:.0f}" for q in QUANTITIES))
    print(f"| {name} | {len(rows)} | " + ' | '.join(cells) + ' |')


def main(fresh):
    c0 = {k: v for k, v in U.calibration('linear/axle3_acc').items() if k != 'BETA_UNEXPLAINED'}
    shipped = U.calibration('linear/axle3_acc').get('BETA_UNEXPLAINED')
    cal, check = calibration_sets()
    pooled = sum(cal.values(), [])
    pooled_profile = sum(check.values(), [])
    chosen = choose((pooled, pooled_profile), c0)
    print(f"open term (BETA) of linear/axle3_acc: {c0['BETA']}")
    print(f"chosen on {len(pooled)} pooled true segments and {len(pooled_profile)} profile segments: {chosen}")
    consts = {'open term': c0, 'chosen': {**c0, 'BETA': chosen}}
    if shipped is not None:
        consts['shipped BETA_UNEXPLAINED'] = {**c0, 'BETA': shipped}
    print('\n| set | segments | ' + ' | '.join(f"{k}: ln Gq(n0) / w / ln G(n_best) %" for k in consts) + ' |')
    print('|---|---|' + '---|' * len(consts))
    for name, rows in {**cal, 'pooled': pooled, **check, 'pooled, profile': pooled_profile}.items():
        show(name, rows, consts)
    for root in fresh:
        v = verdicts(root)
        show(f"{root} (fresh)", unexplained(load(Path(root)), v), consts)
        show(f"{root} (fresh), profile", unexplained(load(Path(root), profile=True), v), consts)


if __name__ == '__main__':
    main(sys.argv[1:])
