"""The shipped interval constants against a KAPPA set on 100 null drives, on four null sets and two other families
(records of this folder; run from the repository root)."""
import sys; sys.path.insert(0, '.'); sys.path.insert(0, 'benchmarks')
from pathlib import Path
import calibrate_uncertainty as CU
R = 'results/inverse_blind/20261128-boundary-bands'   # run from the repository root
from inverse import uncertainty as U
ship = dict(U.CALIBRATIONS['linear'])
k100 = dict(ship, KAPPA={'ln_Gq_n0': 1.91, 'w': 2.26, 'ln_G_n_best': 2.51})
for name, root in [('null 1-20', R + '/displacement/null'), ('null 21-60', R + '/displacement/null2'),
                   ('null 61-100', R + '/displacement/null3'), ('null 101-140 (fresh)', R + '/displacement/null4'),
                   ('random', R + '/displacement/random'), ('independent', R + '/displacement/second')]:
    rows = CU.load(Path(root))
    a, b = CU.coverage(rows, ship), CU.coverage(rows, k100)
    acc = CU.accuracy(rows)
    print(f"{name:22s} n {a['n']:3d} shipped {' / '.join(f'{a[q][0]*100:.0f}' for q in CU.QUANTITIES)} %  | KAPPA(100 drives) {' / '.join(f'{b[q][0]*100:.0f}' for q in CU.QUANTITIES)} %  | G1 {acc['g1'][0]*100:.0f} %, class {acc['class'][0]*100:.0f} %")
