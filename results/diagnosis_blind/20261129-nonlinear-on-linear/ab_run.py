"""One diagnosis with a chosen integrator: python ab_run.py DATASET OUT exudyn|linear
(the RESULT line: verdict, confidence, the first three ranked models, total time)."""
import time,sys,json
from diagnosis.pipeline import diagnose
src, out, solver = sys.argv[1], sys.argv[2], sys.argv[3]
t0=time.time()
s=diagnose(src,out,force=True,settings={'solver':solver},progress=lambda m: print(f'{time.time()-t0:7.1f} {m}',flush=True))
r=s['ranking'][:3]
print('RESULT', solver, s['verdict'], s['verdict_confidence'], [(e['effect'], e['parameters'], round(e['heldout_gap_after'],4)) for e in r], 'total', s['meta']['timing']['total_s'])
