import sys, json, math
sys.path.insert(0, '/work/main')
import numpy as np
from diagnosis.pipeline import load_measured, prepare, signature_seeds, _phase_runs, own_signature_stats
from diagnosis.compare import OWN_STATISTICS
stat = 'stroke_velocity_l_skewness'
case = sys.argv[1]
drive, sig = load_measured(case + '-blind')
tr = json.load(open(case + '/truth/summary.json'))
eff = tr['effects']
ctx = prepare(sig, drive.vehicle, seed=0, workers=1)
m = ctx.model; T = sig.time.size / sig.fs; seeds = signature_seeds(0)[:3]
print('fitted: bounds', np.round(m.bounds,1), 'gq', m.gq, 'w', m.w, 'nmin', m.nmin, 'nmax', m.nmax)
print('fitted road: cand', np.round(own_signature_stats(m, sig, _phase_runs(m, eff, T, seeds), seeds, stat),4))
S = tr['segments']
m.bounds = np.array([0.0] + [x['t_end'] for x in S]); m.bounds[-1] = T
m.gq = np.array([x['Gq_n0'] for x in S]); m.w = np.array([x['w'] for x in S])
m.nmin = np.array([x['nmin'] for x in S]); m.nmax = np.array([x['nmax'] for x in S])
m._roads.clear()
print('true params: nominal', np.round(own_signature_stats(m, sig, _phase_runs(m, {}, T, seeds), seeds, stat),4), 'cand', np.round(own_signature_stats(m, sig, _phase_runs(m, eff, T, seeds), seeds, stat),4))
print('measured', OWN_STATISTICS[stat](sig))
