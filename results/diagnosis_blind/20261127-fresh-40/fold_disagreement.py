import json, math, glob, sys
from pathlib import Path
from diagnosis.verdict import decide
def unit(v, lo, hi, lg):
    if lg: return (math.log(v)-math.log(lo))/(math.log(hi)-math.log(lo))
    return (v-lo)/(hi-lo)
rows=[]
roots=sys.argv[1:] or sorted(glob.glob('results/diagnosis_blind/*/'))
for root in roots:
    root=Path(root)
    if not (root/'blind.json').exists(): continue
    res=json.loads((root/'blind.json').read_text())['results']
    for r in res:
        f=root/f"case{r['case']:03d}-summary.json"
        if not f.exists():
            f=root/f"case{r['case']:03d}-run"/'summary.json'
        if not f.exists(): continue
        s=json.loads(f.read_text())
        try: d=decide(s)
        except Exception as e: continue
        ranges=(s.get('meta') or {}).get('search_ranges') or {}
        worst=(0,None)
        for e in s.get('ranking') or []:
            pf=e.get('parameters_per_fold') or []
            if len(pf)<2 or e['effect']==d['verdict']: continue
            for eff,pp in pf[0].items():
                for pn,v in pp.items():
                    if eff in ranges and pn in ranges[eff]:
                        lo,hi,lg=ranges[eff][pn]
                        us=[unit(fold[eff][pn],lo,hi,lg) for fold in pf]
                        dd=max(us)-min(us)
                        if dd>worst[0]: worst=(dd,f"{eff}.{pn} {[round(fold[eff][pn],3) for fold in pf]}")
        truth=r.get('effect') or r.get('truth')
        rows.append((root.name, r['case'], truth, d['verdict'], d['confidence'], worst[0], worst[1]))
for row in rows:
    if row[4]=='clear':
        print('%-40s %3d truth %-16s verdict %-16s %-9s maxdis %.2f %s'%row)
