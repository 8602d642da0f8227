import sys, json, math, glob, os, time
sys.path.insert(0, '/work/main')
import numpy as np
import diagnosis.road_fit as RF
from diagnosis.pipeline import load_measured, prepare
out = open(sys.argv[1], 'a')
for d in [a for a in sys.argv[2:] if not a.startswith("--")]:
    for case in sorted(glob.glob(d + '/case[0-9][0-9][0-9]')):
        tp = case + '/truth/summary.json'
        if not os.path.exists(tp): continue
        t = json.load(open(tp))
        if t.get('truth_model', {}).get('model') != 'exudyn': continue
        drive, sig = load_measured(case + '-blind')
        rec = {'case': case, 'truth': t['segments'], 'effects': t.get('effects')}
        for flag in ((True,) if "--split-only" in sys.argv else (False, True)):
            RF.NEIGHBOUR_SPLIT = flag
            ctx = prepare(sig, drive.vehicle, seed=0, workers=1)
            rec['split' if flag else 'old'] = {'bounds': list(map(float, ctx.bounds)), 'gq': list(map(float, ctx.model.gq)), 'w': list(map(float, ctx.model.w))}
        out.write(json.dumps(rec) + '\n'); out.flush()
