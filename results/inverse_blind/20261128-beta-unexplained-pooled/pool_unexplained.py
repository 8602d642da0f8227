"""BETA_UNEXPLAINED (the model-form term of the closed loop's 'unexplained' drives, fitted on axle 3's
accelerations) re-chosen by stop 48's rule on every saved loop of the independent truck, then checked on
a fresh set (python results/inverse_blind/20261128-beta-unexplained-pooled/pool_unexplained.py
[FRESH_ROOT ...], from the repository root).

Stop 48 chose the term on two independent-truck sets (seeds 1-20, 41-52) and three friction drives;
two more sets have been run since (seeds 53-72 and 73-84), whose 'unexplained' intervals covered
ln G(n_best) in 94-100 % of their segments with the shipped term (the latter set 100 / 100 / 100 %
over every verdict: too wide). Here the pools hold all four sets.

Rule (unchanged, ../20261128-closest-vehicle-effect/beta_unexplained.py): per quantity the smallest
grid value at which 90 % of the intervals hold in the pooled true segments (synthetic roads; the
measured-road drives' true segments included) AND in the pooled measured-road segments scored
against the profile under each fitted segment; R_REF and KAPPA those of the channel set
(inverse.uncertainty.CALIBRATIONS["linear/axle3_acc"]). Printed: per set the coverage with the open
term, the term stop 48 shipped and the one chosen here, and per quantity a grid scan of the pools.
A FRESH_ROOT (a closed-loop bench_inverse.py root, seeds not in the pools) is scored on its
'unexplained' drives with each."""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-closest-vehicle-effect'))
from beta_unexplained import (GRID, QUANTITIES, U, calibration_sets, coverage, load,  # noqa: E402
                              smallest_holding, unexplained, verdicts)

#: stop 48's term, the one this script re-chose (the package ships the chosen one since)
STOP48 = {'ln_Gq_n0': 0.05, 'w': 0.01, 'ln_G_n_best': 0.1}
LATER = {'independent 53-72': HERE.parent / '20261128-closest-vehicle-effect' / 'fresh-independent-53-72',
         'independent 73-84': HERE.parent / '20261128-beta-diagnosed-pooled' / 'fresh-independent-73-84'}


def pools():
    """The calibration rows: stop 48's sets and the two later ones (true segments; profile segments)."""
    cal, check = calibration_sets()
    for name, root in LATER.items():
        v = verdicts(root)
        cal[name] = unexplained(load(root), v)
        check[f'{name}, profile'] = unexplained(load(root, profile=True), v)
    return cal, check


def choose(pools, const):
    """The rule: per quantity the smallest grid value of the term (scored as BETA on the rows,
    all relabelled 'open') at which 90 % of the intervals hold in every pool."""
    return smallest_holding(pools, const, 'BETA', GRID)


def cells(rows, const):
    cv = coverage(rows, const)
    return ' / '.join(f"{100 * cv[q][0]:.0f}" for q in QUANTITIES)


def main(fresh):
    c0 = {k: v for k, v in U.calibration('linear/axle3_acc').items() if k != 'BETA_UNEXPLAINED'}
    shipped = U.calibration('linear/axle3_acc')['BETA_UNEXPLAINED']
    cal, check = pools()
    pooled, pooled_profile = sum(cal.values(), []), sum(check.values(), [])
    chosen = choose((pooled, pooled_profile), c0)
    print(f"open term (BETA) of linear/axle3_acc: {c0['BETA']}")
    print(f"BETA_UNEXPLAINED of stop 48: {STOP48}")
    print(f"chosen on {len(pooled)} pooled true segments and {len(pooled_profile)} profile segments: {chosen}")
    print(f"the package ships: {shipped} ({'the chosen one' if shipped == chosen else 'NOT the chosen one'})")
    consts = {'open term': c0, 'stop 48': {**c0, 'BETA': STOP48}, 'chosen': {**c0, 'BETA': chosen}}
    print('\n| set | segments | ' + ' | '.join(f"{k}: ln Gq(n0) / w / ln G(n_best) %" for k in consts) + ' |')
    print('|---|---|' + '---|' * len(consts))
    for name, rows in {**cal, 'pooled': pooled, **check, 'pooled, profile': pooled_profile}.items():
        print(f"| {name} | {len(rows)} | " + ' | '.join(cells(rows, c) for c in consts.values()) + ' |')
    for root in fresh:
        v = verdicts(root)
        for label, rows in ((f"{root} (fresh)", unexplained(load(Path(root)), v)),
                            (f"{root} (fresh), profile", unexplained(load(Path(root), profile=True), v))):
            print(f"| {label} | {len(rows)} | " + ' | '.join(cells(rows, c) for c in consts.values()) + ' |')
    print('\nGrid scan of the pools (coverage %, the quantity\'s term at each grid value, the others open):')
    print('| quantity | pool | ' + ' | '.join(f'{b:g}' for b in GRID) + ' |')
    print('|---|---|' + '---|' * len(GRID))
    for q in QUANTITIES:
        for label, rows in (('true segments', pooled), ('profile segments', pooled_profile)):
            covs = [coverage(rows, {**c0, 'BETA': {**c0['BETA'], q: b}})[q][0] for b in GRID]
            print(f"| {q} | {label} | " + ' | '.join(f'{100 * c:.1f}' for c in covs) + ' |')


if __name__ == '__main__':
    main(sys.argv[1:])
