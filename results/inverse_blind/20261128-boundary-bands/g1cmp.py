"""Per set: G(1 cycle/m) within 20 %, its sd, the fit about the true road under its window, n_best, w, class
(python g1cmp.py ROOT [ROOT ...]; segments >= 3 s present in every root)."""
import json, math, sys, numpy as np
def load(root):
    out = {}
    for l in open(f'{root}/results.jsonl'):
        c = json.loads(l)
        if 'skipped' in c: continue
        for i, s in enumerate(c['segments']):
            if s['duration_s'] < 3: continue
            g1t = math.log(s['Gq_true'] * 10 ** -s['w_true'])
            o = s.get('oracle_fit_window'); g1o = math.log(o['Gq'] * 10 ** -o['w']) if o else g1t
            out[(c['seed'], i)] = (s['lnG_1cpm_err'], s['lnG_1cpm_err'] + g1t - g1o, s.get('lnG_n_best_err'), s['w_err'], s['class_true'] == s['class_fit'])
    return out
def main(roots):
    D = [load(r) for r in roots]
    keys = sorted(set.intersection(*[set(d) for d in D]))
    for r, d in zip(roots, D):
        A = np.array([d[k][:4] for k in keys], float); cl = np.mean([d[k][4] for k in keys])
        print(f'{r:30s} n {len(keys)} G1 within20 {np.mean(np.abs(A[:,0])<=math.log(1.2)):.3f} sd {A[:,0].std():.3f} mean {A[:,0].mean():+.3f} | about-window sd {A[:,1].std():.3f} | nbest within20 {np.mean(np.abs(A[:,2])<=math.log(1.2)):.3f} | w sd {A[:,3].std():.3f} | class {cl:.3f}')


if __name__ == '__main__':
    main(sys.argv[1:])
