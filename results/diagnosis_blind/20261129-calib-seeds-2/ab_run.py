"""One diagnosis with settings: python ab_run.py DATASET OUT JSON_SETTINGS"""
import time,sys,json
from diagnosis.pipeline import diagnose
src, out, st = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
t0=time.time()
s=diagnose(src,out,force=True,settings=st,progress=lambda m: print(f'{time.time()-t0:7.1f} {m}',flush=True))
r=s['ranking'][:3]
print('RESULT', st, s['verdict'], s['verdict_confidence'], [(e['effect'], e['parameters'], round(e['heldout_gap_after'],4)) for e in r], 'total', s['meta']['timing']['total_s'])
