"""Can the fit see that its segment merged two roads? Misfit per feature and the between-channel-kind
consistency excess (summary.json 'consistency') of merged against alone true pieces >= 3 s
(python results/inverse_blind/20261128-beta-diagnosed-pooled/fit_statistics.py ROOT ...)."""
import sys
from collections import Counter
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[3] / 'benchmarks'))
from calibrate_uncertainty import load
import numpy as np
for root in sys.argv[1:]:
    rows0 = load(Path(root), min_s=0.0)
    n = Counter((r['seed'], r['Gq_fit']) for r in rows0)
    rows = [r for r in rows0 if r['duration_s'] >= 3 and 'ln_Gq_n0' in (r.get('consistency') or {}).get('excess', {})]
    if not rows: print(root, 'no consistency'); continue
    for q in ('ln_Gq_n0', 'ln_G_n_best', 'w'):
        m = [r['consistency']['excess'][q] for r in rows if n[(r['seed'], r['Gq_fit'])] > 1]
        a = [r['consistency']['excess'][q] for r in rows if n[(r['seed'], r['Gq_fit'])] == 1]
        print(f"{root[-45:]:45s} {q:12s} merged n={len(m)} median {np.median(m):.3f} p75 {np.percentile(m,75):.3f} | alone n={len(a)} median {np.median(a):.3f} p75 {np.percentile(a,75):.3f}")
    # misfit too
    m = [r['objective']/r['n_features'] for r in rows if n[(r['seed'], r['Gq_fit'])] > 1]
    a = [r['objective']/r['n_features'] for r in rows if n[(r['seed'], r['Gq_fit'])] == 1]
    print(f"{'':45s} misfit       merged median {np.median(m):.3f} | alone {np.median(a):.3f}")
