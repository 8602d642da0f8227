"""The friction drives with the loop closed (`bench_inverse.py --effects-auto`): axle 3's
accelerations alone against the default axle 3 on the same diagnoses (run from the repository
root: python results/inverse_blind/20261128-acceleration-only-fit/closed_loop_score.py)."""
import math
import sys
from pathlib import Path

sys.path.insert(0, '.'); sys.path.insert(0, 'benchmarks')
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-boundary-bands'))
import calibrate_uncertainty as CU  # noqa: E402
from g1cmp import load  # noqa: E402
from inverse import uncertainty as U  # noqa: E402

A, V = HERE / 'closed-loop' / 'axle3', HERE / 'closed-loop' / 'axle3-acc'
a, v = load(A), load(V)
keys = sorted(set(a) & set(v))
ok = lambda r: (abs(r[0]) <= math.log(1.2), r[4])  # noqa: E731
for name, d in (('axle 3 (default)', a), ('axle 3 accelerations alone', v)):
    n = len(keys)
    print(f'{name:28s} segments >= 3 s {n}: G(1) within 20 % {100 * sum(ok(d[k])[0] for k in keys) / n:.1f} %, '
          f'class right {100 * sum(ok(d[k])[1] for k in keys) / n:.1f} %')
up = sum(ok(v[k])[0] and not ok(a[k])[0] for k in keys); dn = sum(ok(a[k])[0] and not ok(v[k])[0] for k in keys)
cu = sum(ok(v[k])[1] and not ok(a[k])[1] for k in keys); cd = sum(ok(a[k])[1] and not ok(v[k])[1] for k in keys)
print(f'paired: G(1) {up} gained / {dn} lost, class {cu} / {cd}')
for name, root, key in (('axle 3', A, 'linear'), ('axle 3 accelerations', V, 'linear/axle3_acc')):
    rows = CU.load(root)
    c = CU.coverage(rows, U.CALIBRATIONS[key])
    forms = {f: sum(r.get('model_form') == f for r in rows) for f in U.MODEL_FORMS}
    print(f'{name}: 90 % intervals cover ' + ' / '.join(f'{100 * c[q][0]:.0f}' for q in CU.QUANTITIES)
          + f' % (ln Gq(n0) / w / ln G(n_best)) of {c["n"]} segments; model form {forms}')
