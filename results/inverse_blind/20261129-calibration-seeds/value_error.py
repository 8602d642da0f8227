"""The leaf-friction value's error and its folds' disagreement, per calibration setting (stop 52):
python results/inverse_blind/20261129-calibration-seeds/value_error.py  (from the repository root).

Arms: the diagnosis's own calibration (refine 3, one road-phase seed; ../20261128-refined-value/diagnosis_folds.json),
stop 51's refine 8 with one seed (../20261128-refined-value/values.jsonl) and this folder's values-*.jsonl.
Truth: 2000 N (our truck, `random` scenario, seeds 81-100; the 17 drives the diagnosis named leaf friction on)."""
import json
import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
STOP51 = HERE.parent / '20261128-refined-value'
L = math.log(1.2)


def arms():
    dg = json.loads((STOP51 / 'diagnosis_folds.json').read_text())
    out = {'diagnosis (refine 3, 1 seed)': {int(s): (d['force'], d['per_fold']) for s, d in dg.items()}}

    def jl(p):
        return {r['seed']: (r['force'], r['per_fold']) for r in map(json.loads, p.read_text().splitlines())}
    out['refine 8, 1 seed (stop 51)'] = jl(STOP51 / 'values.jsonl')
    for p in sorted(HERE.glob('values-refine*.jsonl')):
        out[p.stem.replace('values-', '').replace('-', ', ')] = jl(p)
    return out


def summary(a, only=None):
    print('| arm | drives | rms ln(value / 2000 N) | mean | median abs | within x1.2 | folds differ: sd ln | equal |')
    print('|---|---|---|---|---|---|---|---|')
    for name, v in a.items():
        seeds = sorted(v) if only is None else sorted(only)
        if not set(seeds) <= set(v):
            continue
        e = np.array([math.log(v[s][0] / 2000.0) for s in seeds])
        f = np.array([math.log(v[s][1][0] / v[s][1][1]) for s in seeds])
        print(f'| {name} | {len(seeds)} | {np.sqrt(np.mean(e ** 2)):.3f} | {e.mean():+.3f} | {np.median(np.abs(e)):.3f} '
              f'| {int(np.sum(np.abs(e) <= L))} | {f.std():.3f} | {int(np.sum(np.abs(f) < 1e-9))} |')


def main():
    a = arms()
    summary(a)
    big = [set(v) for v in a.values() if len(v) >= 8]
    common = set.intersection(*big)
    if any(len(b) != len(common) for b in big):
        print(f'\nThe same {len(common)} drives in every arm of at least 8:')
        summary(a, common)
    print()
    names = list(a)
    print('| seed | ' + ' | '.join(names) + ' |')
    print('|---|' + '---|' * len(names))
    for s in sorted(set.union(*(set(v) for v in a.values()))):
        cells = [f"{a[n][s][0]:.0f} ({' / '.join(f'{x:.0f}' for x in a[n][s][1])})" if s in a[n] else '' for n in names]
        print(f'| {s} | ' + ' | '.join(cells) + ' |')
    print()
    # does a drive's fold disagreement tell how far its value is off? (Spearman over the drives)
    from scipy.stats import spearmanr
    for name, v in a.items():
        seeds = sorted(v)
        if len(seeds) < 8:
            continue
        err = [abs(math.log(v[s][0] / 2000.0)) for s in seeds]
        dis = [abs(math.log(v[s][1][0] / v[s][1][1])) for s in seeds]
        r, p = spearmanr(dis, err)
        print(f'{name}: |ln fold ratio| against |ln(value / 2000 N)| over {len(seeds)} drives: Spearman {r:+.2f} (p {p:.2f})')


if __name__ == '__main__':
    main()
