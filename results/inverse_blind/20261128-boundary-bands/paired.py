import json, math, sys
def load(root):
    out = {}
    for l in open(f'{root}/results.jsonl'):
        c = json.loads(l)
        if 'skipped' in c: continue
        for i, s in enumerate(c['segments']):
            if s['duration_s'] >= 3: out[(c['seed'], i)] = (abs(s['lnG_1cpm_err']) <= math.log(1.2), s['class_true'] == s['class_fit'])
    return out
a, b = load(sys.argv[1]), load(sys.argv[2]); k = sorted(set(a) & set(b))
for j, name in ((0, 'G1'), (1, 'class')):
    up = sum((not a[x][j]) and b[x][j] for x in k); dn = sum(a[x][j] and not b[x][j] for x in k)
    print(f'{name}: n {len(k)}  gained {up}  lost {dn}')
