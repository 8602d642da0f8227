"""Fits without the suspension-displacement features against the same drives fitted with them
(python results/inverse_blind/20261128-acceleration-only-fit/score.py, from the repository root).

Variants (records in this folder): `axle3-acc` = axle 3's two axle accelerations only;
`axles-acc` = the axle accelerations of every axle (8 channels). Baselines: `axle3` = the default
(../20261128-boundary-bands/displacement/), `axles` = the closed loop's set for `none` verdicts
(../20261128-axles-on-null-140/axles/). The segmentation is the same in all (axle 3's suspension
displacements); only the fitted features differ. Segments >= 3 s; G(1 cycle/m) within 20 %, class
right, and the paired count (segments that became / stopped being right) against the baseline."""
import math
import sys
from pathlib import Path

from scipy.stats import binomtest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-boundary-bands'))
from g1cmp import load  # noqa: E402

BASE = {'axle3': HERE.parent / '20261128-boundary-bands' / 'displacement',
        'axles': HERE.parent / '20261128-axles-on-null-140' / 'axles'}
PAIRS = [('axle3', 'axle3-acc'), ('axles', 'axles-acc')]
SETS = ['null', 'null2', 'null3', 'null4', 'random', 'second']
NAMES = {'null': 'null 1-20', 'null2': 'null 21-60', 'null3': 'null 61-100', 'null4': 'null 101-140',
         'random': 'friction + flexible frame 1-20 (open loop)', 'second': 'independent truck 1-20'}


def ok(row):
    return abs(row[0]) <= math.log(1.2), row[4]


def main():
    print('| set | baseline -> variant | segments | G(1) within 20 % | class right | paired G(1) gained / lost | paired class |')
    print('|---|---|---|---|---|---|---|')
    for b, v in PAIRS:
        pool = {'n': 0, 'g': [0, 0], 'c': [0, 0], 'pg': [0, 0], 'pc': [0, 0]}
        for s in SETS:
            pa, pv = BASE[b] / s, HERE / v / s
            if not (pa / 'results.jsonl').exists() or not (pv / 'results.jsonl').exists():
                continue
            A, V = load(pa), load(pv)
            keys = sorted(set(A) & set(V))
            ga = sum(ok(A[k])[0] for k in keys); gv = sum(ok(V[k])[0] for k in keys)
            ca = sum(ok(A[k])[1] for k in keys); cv = sum(ok(V[k])[1] for k in keys)
            up = sum(ok(V[k])[0] and not ok(A[k])[0] for k in keys); dn = sum(ok(A[k])[0] and not ok(V[k])[0] for k in keys)
            cu = sum(ok(V[k])[1] and not ok(A[k])[1] for k in keys); cd = sum(ok(A[k])[1] and not ok(V[k])[1] for k in keys)
            n = len(keys)
            print(f'| {NAMES[s]} | {b} -> {v} | {n} | {100*ga/n:.1f} -> {100*gv/n:.1f} % | {100*ca/n:.1f} -> {100*cv/n:.1f} % | {up} / {dn} | {cu} / {cd} |')
            if s.startswith('null'):
                pool['n'] += n; pool['g'][0] += ga; pool['g'][1] += gv; pool['c'][0] += ca; pool['c'][1] += cv
                pool['pg'][0] += up; pool['pg'][1] += dn; pool['pc'][0] += cu; pool['pc'][1] += cd
        n = pool['n']
        if n:
            pg = binomtest(pool['pg'][0], sum(pool['pg'])).pvalue if sum(pool['pg']) else float('nan')
            pc = binomtest(pool['pc'][0], sum(pool['pc'])).pvalue if sum(pool['pc']) else float('nan')
            print(f"| null pooled | {b} -> {v} | {n} | {100*pool['g'][0]/n:.1f} -> {100*pool['g'][1]/n:.1f} % | "
                  f"{100*pool['c'][0]/n:.1f} -> {100*pool['c'][1]/n:.1f} % | {pool['pg'][0]} / {pool['pg'][1]} (p {pg:.2f}) | "
                  f"{pool['pc'][0]} / {pool['pc'][1]} (p {pc:.2f}) |")


if __name__ == '__main__':
    main()
