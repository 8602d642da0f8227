import json, math, sys, collections
import numpy as np
def load(fn, var):
    out = {}
    for line in open(fn):
        r = json.loads(line)
        if var in r: out[r['case']] = (r, r[var])
    return out
variants = [a.split(':') for a in sys.argv[1:]]   # file:var:label
data = {lab: load(fn, var) for fn, var, lab in variants}
common = set.intersection(*[set(d) for d in data.values()])
print('drives', len(common))
for n in (0.3, 1.0):
    for lab, d in data.items():
        es, cs, effs = [], [], []
        for case in sorted(common):
            r, f = d[case]; ts = r['truth']; b = f['bounds']
            for i in range(len(b) - 1):
                a, e = b[i], b[i+1]; L = e - a
                ov = [max(0, min(e, x['t_end']) - max(a, x['t_start'])) for x in ts]
                j = int(np.argmax(ov))
                if ov[j] < 0.9 * L or L < 2: continue
                x = ts[j]
                es.append(math.log(f['gq'][i] * (n/0.1)**-f['w'][i] / (x['Gq_n0'] * (n/0.1)**-x['w'])))
                nb = [f['gq'][k] for k in (i-1, i+1) if 0 <= k < len(f['gq'])]
                cs.append(math.log(max(nb) / x['Gq_n0']) if nb else -9)
                effs.append(','.join(r['effects'] or {}) or 'none')
        e = np.array(es); c = np.array(cs); effs = np.array(effs)
        line = f'n={n} {lab:8s} segs {len(e)} median|e| {np.median(abs(e)):.3f} x1.5 {np.mean(abs(e)<math.log(1.5)):.3f} sd {e.std():.2f} |'
        for lo, hi in [(-20, 1), (1, 3), (3, 20)]:
            m = (c >= lo) & (c < hi); line += f' c{lo}..{hi}: {e[m].mean():+.2f}/{np.mean(abs(e[m])<math.log(1.5)):.2f}'
        m = effs == 'none'; line += f' | none sd {e[m].std():.2f} x1.5 {np.mean(abs(e[m])<math.log(1.5)):.2f}'
        print(line)
