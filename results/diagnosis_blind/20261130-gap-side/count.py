"""Count what diagnosis.verdict.gap_side reads on every saved blind drive answered 'unexplained'
(one count per drive): python results/diagnosis_blind/20261130-gap-side/count.py results/diagnosis_blind"""
import json, glob, os, sys, collections
from diagnosis.verdict import gap_side
root = sys.argv[1]
res = collections.defaultdict(collections.Counter)
seen = set()
for bj in sorted(glob.glob(f'{root}/**/blind.json', recursive=True)):
    d = os.path.dirname(bj)
    try:
        b = json.load(open(bj))
    except Exception:
        continue
    for r in b.get('results', []):
        f = f"{d}/case{r['case']:03d}-summary.json"
        if not os.path.exists(f):
            continue
        s = json.load(open(f))
        if s['verdict'] != 'unexplained':
            continue
        g = gap_side(s)
        if g is None:
            continue
        key = (r.get('family', 'nominal'), r['seed'], r['effect'], r.get('value'))
        if key in seen:
            continue
        seen.add(key)
        fam = r.get('family', 'nominal')
        truck = 'ours' if fam in ('nominal', 'measured') else 'independent'
        res[(truck, 'no effect' if r['effect'] == 'none' else 'library effect')][g['side']] += 1
for k in sorted(res):
    print(k, dict(res[k]))
