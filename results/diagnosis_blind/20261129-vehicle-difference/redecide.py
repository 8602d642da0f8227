"""python redecide.py [ROOT ...]  (default: results/diagnosis_blind; a bench --out folder works too)

Re-decide saved blind summaries with the vehicle-difference rule on (default) and off
(vehicle_share=None); print every drive whose verdict changes, and the counts."""
import json, glob, os, sys, collections
from diagnosis import verdict as V
roots = sys.argv[1:] or ["results/diagnosis_blind"]
n = 0; cnt = collections.Counter(); lines = []
for root in roots:
    for bj in sorted(set(glob.glob(f"{root}/**/blind.json", recursive=True))):
        d = os.path.dirname(bj)
        try: b = json.load(open(bj))
        except Exception: continue
        for r in b.get("results", []):
            sp = f"{d}/case{r['case']:03d}-summary.json"          # a committed set
            if not os.path.exists(sp):
                sp = f"{d}/case{r['case']:03d}-run/summary.json"  # a bench work folder
            if not os.path.exists(sp): continue
            s = json.load(open(sp))
            try:
                on = V.decide(s); off = V.decide(s, vehicle_share=None)
            except Exception as e:
                continue
            n += 1
            if on["verdict"] == off["verdict"] and on["confidence"] == off["confidence"]: continue
            truth = r["effect"] if r["effect"] not in (None, "none") else "-"
            kind = ("gained" if on["verdict"] == truth else
                    "lost" if off["verdict"] == truth else
                    "wrong name (no effect)" if truth == "-" else "wrong name")
            cnt[(r.get("family"), kind)] += 1
            lines.append(f"{d}: case {r['case']} {r.get('family')} truth {truth} {r.get('value')}: "
                         f"{off['verdict']} -> {on['verdict']} ({on['confidence']}), share "
                         f"{on['explained_share']:.2f} [{kind}]")
print(n, "summaries re-decided")
for l in lines: print(l)
print(dict(cnt))
