"""Segmentation alone against the truth: python seg_only.py DATA_ROOT [DATA_ROOT ...]
(DATA_ROOT as made by benchmarks/bench_inverse.py --data-root; run from the repository root)."""
import glob, json, sys
import numpy as np
sys.path.insert(0, '.')
import inverse.segmentation as S
from drives.format import read_drive

def cases(roots):
    for root in roots:
        for d in sorted(glob.glob(f'{root}/*-*')):
            if '/blind-' in d or not glob.glob(f'{d}/truth/truth.json'):
                continue
            yield json.load(open(f'{d}/truth/truth.json')), read_drive(d)

def score(items, fn):
    kr = kl = kh = matched = n3 = 0; errs = []
    for tr, dr in items:
        tf = fn(dr); ts = tr['segments']
        tt = np.array([ts[0]['t_start']] + [s['t_end'] for s in ts]); K, Kf = len(ts), len(tf) - 1
        kr += K == Kf; kl += Kf < K; kh += Kf > K
        for s in ts:
            if s['t_end'] - s['t_start'] < 3:
                continue
            n3 += 1
            ov = [max(0, min(s['t_end'], b) - max(s['t_start'], a)) for a, b in zip(tf[:-1], tf[1:])]
            i = int(np.argmax(ov))
            # matched: one fitted segment holds >= 80 % of the true one and is >= 80 % made of it
            matched += ov[i] >= 0.8 * (s['t_end'] - s['t_start']) and ov[i] >= 0.8 * (tf[i + 1] - tf[i])
        errs += [np.min(np.abs(tf[1:-1] - b)) if Kf > 1 else 99 for b in tt[1:-1]]
    errs = np.array(errs)
    return (f'K right {kr}/{len(items)} low {kl} high {kh}; matched >= 3 s {matched}/{n3}; '
            f'boundaries found within 0.5 s {np.sum(errs < 0.5)}/{errs.size}')

items = list(cases(sys.argv[1:]))
ch = lambda dr, names: {c: dr.channels[c].to_numpy() for c in names}
D, A = ('susp_disp_3L', 'susp_disp_3R'), ('axle_acc_3L', 'axle_acc_3R')
print('displacement (default)', score(items, lambda dr: S.segment(dr.time, ch(dr, D), dr.speed).t_bounds))
acc = lambda dr: S.segment(dr.time, ch(dr, D), dr.speed, boundary_channels=ch(dr, A)).t_bounds
print('axle_acc, cut          ', score(items, acc))
S.BOUNDARY_NMAX = 1e6
print('axle_acc, uncut        ', score(items, acc))
