"""Where the intervals and G(1 cycle/m) fail: true segments alone in their fitted segment against
true segments that share one fitted segment with a neighbour (the segmentation merged them), on
every saved blind set (python results/inverse_blind/20261128-beta-diagnosed-pooled/merges.py
[NAME=ROOT ...], from the repository root; extra closed-loop roots are added as sets).

A true segment 'shares' when another true segment of the same drive (of any length) got the same
fitted values (same fitted Gq_n0). Each row's 90 % interval uses the constants of its channel set and model form
(closed loop: 'none' -> linear/axles, 'unexplained' -> linear/axle3_acc, else linear, as
diagnosis.closed_loop.loop_channels chooses; open-loop sets: the key given below). Segments >= 3 s."""
import json
import math
import sys
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import coverage, load  # noqa: E402

from inverse import uncertainty as U  # noqa: E402

B = HERE.parent
L = math.log(1.2)
OPEN = {   # open-loop sets: root, calibration key (our truck without a gap, and the independent truck)
    'null 1-20 (axle 3)': (B / '20261124-linear-null-20', 'linear'),
    'null 1-20 (axles)': (B / '20261128-axles-on-null-140/axles/null', 'linear/axles'),
    'null 21-60 (axles)': (B / '20261128-axles-on-null-140/axles/null2', 'linear/axles'),
    'null 61-100 (axles)': (B / '20261128-axles-on-null-140/axles/null3', 'linear/axles'),
    'null 101-140 (axles)': (B / '20261128-axles-on-null-140/axles/null4', 'linear/axles'),
}
LOOPS = {  # closed-loop sets (bench_inverse.py --effects-auto)
    'friction 41-60 (loop)': B / '20261128-closest-vehicle-effect/fresh-friction-41-60',
    'independent 53-72 (loop)': B / '20261128-closest-vehicle-effect/fresh-independent-53-72',
}
KEY = {'none': 'linear/axles', 'unexplained': 'linear/axle3_acc'}


def sharing(rows):
    """How many true pieces got each fitted segment's values, keyed (seed, fitted Gq_n0); pass the
    rows of every length (load(..., min_s=0)): a piece is merged where its count is above 1."""
    return Counter((r['seed'], r['Gq_fit']) for r in rows)


def tagged(rows, root):
    n = sharing(load(Path(root), min_s=0.0))     # a neighbour of any length counts
    for r in rows:
        r['shares'] = n[(r['seed'], r['Gq_fit'])] > 1
    return rows


def groups_of(root, key=None):
    rows = tagged(load(Path(root)), root)
    if key:
        return {key: rows}
    verdict = {json.loads(li)['seed']: (json.loads(li).get('closed_loop') or {}).get('verdict')
               for li in (Path(root) / 'results.jsonl').read_text().splitlines()}
    out = {}
    for r in rows:
        out.setdefault(KEY.get(verdict[r['seed']], 'linear'), []).append(r)
    return out


def score(groups, shares):
    tot = {q: [0, 0] for q in ('ln_Gq_n0', 'w', 'ln_G_n_best')}
    g1, cl = [], []
    for key, rows in groups.items():
        rows = [r for r in rows if r['shares'] == shares]
        if not rows:
            continue
        c = coverage(rows, U.calibration(key))
        for q in tot:
            tot[q][0] += round(c[q][0] * c[q][2])
            tot[q][1] += c[q][2]
        g1 += [abs(r['lnG_1cpm_err']) <= L for r in rows]
        cl += [r['class_true'] == r['class_fit'] for r in rows]
    n = len(g1)
    if not n:
        return '| 0 | | | |'
    cov = ' / '.join(f'{100 * a / max(m, 1):.0f}' for a, m in tot.values())
    return f'| {n} | {100 * sum(g1) / n:.0f} % | {100 * sum(cl) / n:.0f} % | {cov} % |'


def main(extra):
    sets = {name: groups_of(root, key) for name, (root, key) in OPEN.items()}
    sets.update({name: groups_of(root) for name, root in {**LOOPS, **extra}.items()})
    print('| set | alone: segments | G(1) within 20 % | class right | 90 % cover ln Gq(n0) / w / ln G(n_best) '
          '| shared: segments | G(1) within 20 % | class right | 90 % cover |')
    print('|---|---|---|---|---|---|---|---|---|')
    for name, g in sets.items():
        print(f'| {name} ' + score(g, False) + score(g, True)[1:])


if __name__ == '__main__':
    main(dict(a.split('=', 1) for a in sys.argv[1:]))
