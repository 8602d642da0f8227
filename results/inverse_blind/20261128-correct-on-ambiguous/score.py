"""The closed loop's correction rule, old against new, on the same friction drives and diagnoses
(python results/inverse_blind/20261128-correct-on-ambiguous/score.py, from the repository root).

`seeds1-20/`: the 20 friction drives (`random`: leaf friction and a flexible frame; seeds 1-20) with
the diagnoses of ../20261128-acceleration-only-fit/closed-loop/ reused (`bench_inverse.py
--effects-auto --diagnoses`), inverted with the new rule; the old rule's records are
../20261128-acceleration-only-fit/closed-loop/axle3/. `seeds21-40/`: fresh drives, the new rule
run once; each record of a corrected drive also holds its nominal inversion
(`nominal`), which is what the old rule reports where only the new one corrects (names short
of 'clear' and not identified; `seeds21-40/identified.json`, written from the run's saved
diagnoses by `score.py ROOT`). Segments >= 3 s."""
import json
import math
import sys
from pathlib import Path

from scipy.stats import binomtest

HERE = Path(__file__).resolve().parent
L = math.log(1.2)


def load(path):
    out = {}
    for line in open(path):
        c = json.loads(line)
        if 'skipped' not in c:
            out[c['seed']] = c
    return out


def long(segs):
    return [s for s in segs if s['duration_s'] >= 3]


def row(s):
    return abs(s['lnG_1cpm_err']) <= L, s['class_true'] == s['class_fit']


def compare(name, pairs):
    """pairs: seed -> (old segments, new segments, verdict, confidence, corrected old, corrected new)."""
    n = g0 = g1 = c0 = c1 = up = dn = cu = cd = 0
    for seed, (a, b, verdict, conf, k0, k1) in sorted(pairs.items()):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            (ga, ca), (gb, cb) = row(x), row(y)
            n += 1; g0 += ga; g1 += gb; c0 += ca; c1 += cb
            up += gb and not ga; dn += ga and not gb; cu += cb and not ca; cd += ca and not cb
        if k0 != k1:
            print(f'  seed {seed}: {verdict} ({conf}) corrected {k0} -> {k1}; ln G(1) error '
                  f'{[round(x["lnG_1cpm_err"], 2) for x in a]} -> {[round(y["lnG_1cpm_err"], 2) for y in b]}')
    p = binomtest(up, up + dn).pvalue if up + dn else float('nan')
    print(f'{name}: {n} segments, G(1 cycle/m) within 20 % {100*g0/n:.1f} -> {100*g1/n:.1f} % '
          f'(paired {up} / {dn}, p {p:.2f}); class right {100*c0/n:.1f} -> {100*c1/n:.1f} % ({cu} / {cd})')


def main():
    old = load(HERE.parent / '20261128-acceleration-only-fit' / 'closed-loop' / 'axle3' / 'results.jsonl')
    new = load(HERE / 'seeds1-20' / 'results.jsonl')
    pairs = {}
    for seed in sorted(set(old) & set(new)):
        co, cn = old[seed]['closed_loop'], new[seed]['closed_loop']
        pairs[seed] = (long(old[seed]['segments']), long(new[seed]['segments']), cn['verdict'],
                       cn.get('confidence'), bool(co['corrected']), bool(cn['corrected']))
    compare('seeds 1-20, same diagnoses', pairs)
    fresh = HERE / 'seeds21-40' / 'results.jsonl'
    ident_file = HERE / 'seeds21-40' / 'identified.json'
    if len(sys.argv) > 1:
        # the bench root of the fresh run: record each diagnosis's verdict_detail.identified (the
        # records keep verdict and confidence only; the old rule also corrected identified names)
        root = Path(sys.argv[1])
        ident = {str(seed): bool(json.load(open(root / f'run-{seed}' / 'diagnose' / 'summary.json'))
                                 .get('verdict_detail', {}).get('identified'))
                 for seed in load(fresh)}
        ident_file.write_text(json.dumps(ident, indent=1) + '\n')
    if fresh.exists():
        identified = json.loads(ident_file.read_text())
        pairs = {}
        for seed, c in load(fresh).items():
            cl = c['closed_loop']
            conf = cl.get('confidence')
            corrected_new = bool(cl['corrected'])
            corrected_old = corrected_new and (conf == 'clear' or identified[str(seed)])
            segs = long(c['segments'])
            old_segs = long(c['nominal']) if corrected_new and not corrected_old else segs
            pairs[seed] = (old_segs, segs, cl['verdict'], conf, corrected_old, corrected_new)
        compare('seeds 21-40, fresh', pairs)


if __name__ == '__main__':
    sys.path.insert(0, str(HERE.parents[2]))
    main()
