"""Can the fit see that its segment merged two roads? Misfit per feature and the between-channel-kind
consistency excess (summary.json 'consistency') of merged against alone true pieces >= 3 s
(python results/inverse_blind/20261128-beta-diagnosed-pooled/fit_statistics.py ROOT ...)."""
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE))
from calibrate_uncertainty import load  # noqa: E402
from merges import sharing  # noqa: E402


def main(roots):
    for root in roots:
        rows0 = load(Path(root), min_s=0.0)
        n = sharing(rows0)
        rows = [r for r in rows0
                if r['duration_s'] >= 3 and 'ln_Gq_n0' in (r.get('consistency') or {}).get('excess', {})]
        if not rows:
            print(root, 'no consistency')
            continue
        merged = [r for r in rows if n[(r['seed'], r['Gq_fit'])] > 1]
        alone = [r for r in rows if n[(r['seed'], r['Gq_fit'])] == 1]
        for q in ('ln_Gq_n0', 'ln_G_n_best', 'w'):
            m = [r['consistency']['excess'][q] for r in merged]
            a = [r['consistency']['excess'][q] for r in alone]
            print(f"{root[-45:]:45s} {q:12s} merged n={len(m)} median {np.median(m):.3f} p75 {np.percentile(m, 75):.3f}"
                  f" | alone n={len(a)} median {np.median(a):.3f} p75 {np.percentile(a, 75):.3f}")
        m = [r['objective'] / r['n_features'] for r in merged]
        a = [r['objective'] / r['n_features'] for r in alone]
        print(f"{'':45s} misfit       merged median {np.median(m):.3f} | alone {np.median(a):.3f}")


if __name__ == '__main__':
    main(sys.argv[1:])
