import sys, json, math, time
sys.path.insert(0, '/work/main')
import numpy as np
import diagnosis.road_fit as RF
from diagnosis.pipeline import load_measured, prepare, signature_seeds, _phase_runs, own_signature_stats
from diagnosis.compare import OWN_STATISTICS
stat = 'stroke_velocity_l_skewness'
for case in sys.argv[1:]:
    drive, sig = load_measured(case + '-blind')
    s = json.load(open(case + '-run/summary.json'))
    eff = s['ranking'][0]['parameters']
    tr = json.load(open(case + '/truth/summary.json'))
    print(case, 'winner', eff, 'truth', tr['effects'], 'measured', round(OWN_STATISTICS[stat](sig), 4))
    for split in (False, True):
        RF.NEIGHBOUR_SPLIT = split
        ctx = prepare(sig, drive.vehicle, seed=0, workers=1)
        m = ctx.model; T = sig.time.size / sig.fs; seeds = signature_seeds(0)
        g0 = m.gq.copy()
        nom = own_signature_stats(m, sig, _phase_runs(m, {}, T, seeds), seeds, stat)
        cand = own_signature_stats(m, sig, _phase_runs(m, eff, T, seeds), seeds, stat)
        gc = RF.relevel_road(m, sig, ctx.cal_edges, g0, 0, effects=eff)
        m.gq = gc
        cand2 = own_signature_stats(m, sig, _phase_runs(m, eff, T, seeds), seeds, stat)
        tg = [x['Gq_n0'] for x in tr['segments']]
        print(f'  split={split} gq nominal {np.round(g0*1e6,1)} cand-relevel {np.round(gc*1e6,1)} truth {np.round(np.array(tg)*1e6,1)}')
        print(f'    nominal stat {np.mean(nom):+.4f}  cand on nominal road {np.mean(cand):+.4f}  cand on own road {np.mean(cand2):+.4f}')
