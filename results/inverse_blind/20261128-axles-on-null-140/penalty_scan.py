"""Segmentation alone at several BIC penalty multipliers against the truth: true boundaries found within
0.5 s and fitted boundaries more than 1 s from any true one (python penalty_scan.py DATA_ROOT ...;
DATA_ROOT as made by benchmarks/bench_inverse.py --data-root; run from the repository root)."""
import glob, json, sys
import numpy as np
sys.path.insert(0, '.')
import inverse.segmentation as S
from drives.format import read_drive
roots = sys.argv[1:]
items = []
for root in roots:
    for d in sorted(glob.glob(f'{root}/*-*')):
        if '/blind-' in d or not glob.glob(f'{d}/truth/truth.json'):
            continue
        tr = json.load(open(f'{d}/truth/truth.json')); dr = read_drive(d)
        items.append((tr, dr.time, {c: dr.channels[c].to_numpy() for c in ('susp_disp_3L', 'susp_disp_3R')}, np.asarray(dr.speed)))
print(len(items), 'drives')
for pen in (1.0, 0.75, 0.5, 0.35, 0.25):
    kr = kl = kh = 0; found = ntrue = spur = nfit = 0; dur_spur = []
    for tr, t, ch, v in items:
        tf = S.segment(t, ch, v, penalty=pen).t_bounds
        ts = tr['segments']; tt = np.array([s['t_end'] for s in ts[:-1]])
        K, Kf = len(ts), len(tf) - 1
        kr += K == Kf; kl += Kf < K; kh += Kf > K
        fb = np.asarray(tf[1:-1])
        for b in tt:
            ntrue += 1; found += fb.size > 0 and np.min(np.abs(fb - b)) < 0.5
        for b in fb:
            nfit += 1; spur += tt.size == 0 or np.min(np.abs(tt - b)) > 1.0
    print(f'penalty {pen}: K right {kr} low {kl} high {kh}; true boundaries found within 0.5 s {found}/{ntrue}; fitted boundaries {nfit}, of them > 1 s from any true one {spur}')
