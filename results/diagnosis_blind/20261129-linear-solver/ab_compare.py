"""Compare the linear-integrator diagnoses (NEW/<family>_<case>/summary.json, ab_run.py) with the
Exudyn ones of stop 57's fresh set (OLD/<family>/<case>-run/summary.json): verdict, confidence,
the first-ranked model, time.  Usage: python ab_compare.py NEW OLD > ab.txt"""
import json, glob, os, sys
NEW, OLD = sys.argv[1], sys.argv[2]
rows=[]
for d in sorted(glob.glob(os.path.join(NEW, '*'))):
    fam, case = os.path.basename(d).split('_')
    new = json.load(open(d+'/summary.json'))
    old = json.load(open(os.path.join(OLD, fam, f'{case}-run', 'summary.json')))
    def top(s):
        r=s['ranking'][0] if s['ranking'] else None
        return (r['effect'], {k:{kk:round(vv,4) for kk,vv in v.items()} for k,v in r['parameters'].items()}, round(r['heldout_gap_after'],4), round(r['heldout_gap_before'],4)) if r else None
    to, tn = old['meta']['timing']['total_s'], new['meta']['timing']['total_s']
    same = (old['verdict'], old['verdict_confidence']) == (new['verdict'], new['verdict_confidence'])
    print(f"{fam:8s} {case} {'SAME' if same else 'DIFF'} old {old['verdict']}({old['verdict_confidence']}) new {new['verdict']}({new['verdict_confidence']})  time {to:.0f} -> {tn:.0f} s  jb {(old['meta'].get('joint_band') or {}).get('chosen')}/{(new['meta'].get('joint_band') or {}).get('chosen')}")
    print('    old', top(old)); print('    new', top(new))
