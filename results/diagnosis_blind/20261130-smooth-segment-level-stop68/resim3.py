import sys, json, tomllib
sys.path.insert(0, '/work/main')
import numpy as np
import drives.synth as DS
from vehicles.params import load_vehicle
from vehicles.simulate import SpeedProfile, simulate
from diagnosis.pipeline import load_measured
from diagnosis.signals import Signals
from diagnosis.compare import OWN_STATISTICS
from roadlib.segments import RoadSegment, segmented_surface
stat = OWN_STATISTICS['stroke_velocity_l_skewness']
case = sys.argv[1]
drive, sig = load_measured(case + '-blind')
cfg = tomllib.load(open(case + '/truth/scenario.toml', 'rb'))
vp = load_vehicle(cfg['scenario']['vehicle'])
plan = DS.plan_drive(cfg, [a.x for a in vp.axles])
road = cfg['road']
segs = [RoadSegment(Gq_n0=float(s["Gq_n0"]), share=float(length), w=float(s["w"]), nmin=float(s["nmin"]), nmax=float(s["nmax"]), lam=1.0) for s, length in zip(road["segments"], plan["seg_lengths"])]
fs = 200.0; n_rec, n_run = plan['n_record'], plan['n_runin']
def st(ch, mask):
    idx = np.nonzero(mask)[0]
    return stat(Signals(sig.time[idx], {c: v[idx] for c, v in ch.items()}, dict(sig.units), sig.speed[idx], {}))
rows = []
for rs in [DS._int_seed(cfg['scenario']['seed'], DS.STREAM_ROAD), 1, 2, 3, 4, 5, 6, 7]:
    r = segmented_surface(segs, plan["road_length"], 3.0, 0.025, 0.1, seed=rs)
    out = []
    for eff in ({}, cfg['truth']['effects']):
        res = simulate(vp, r, speed=SpeedProfile(plan['t_sim'], plan['v_sim']), duration=(n_run+n_rec)/fs, fs_out=fs, x_start=plan['x_front0'], y_offset=0.0, seed=0, effects=eff, solver='linear')
        t = np.asarray(res.time); idx = np.searchsorted(t, n_run/fs - 0.25/fs)
        ch = {c: np.asarray(res.channels[c])[idx:idx+n_rec] for c in sig.channels}
        off = np.asarray(res.extra['tyre_off'])[idx:idx+n_rec].astype(bool)
        # mask: 1 s around any lift-off sample
        k = int(fs)
        near = np.convolve(off.astype(float), np.ones(2*k+1), 'same') > 0
        full = np.ones(n_rec, bool)
        out += [round(st(ch, full), 4), round(st(ch, ~near), 4), round((~near).mean(), 2)]
    print('seed', rs, 'nominal full/masked/kept', out[:3], 'effect', out[3:])
