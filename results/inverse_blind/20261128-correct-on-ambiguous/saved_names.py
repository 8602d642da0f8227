"""Saved blind diagnoses re-decided with today's rules: which named verdicts the closed loop corrects
under the old rule (clear or identified) and under the new one (any name whose value is not at a range
edge), and whether the name was right. Run from the repository root."""
import collections, glob, json, sys
sys.path.insert(0, '.')
import diagnosis.verdict as V
from diagnosis.closed_loop import effects_from_diagnosis

def load():
    out = []
    for f in sorted(glob.glob('results/diagnosis_blind/2026112*/*/blind.json')) + sorted(glob.glob('results/diagnosis_blind/2026112*/blind.json')):
        base = f.rsplit('/', 1)[0]
        for c in json.load(open(f))['results']:
            try:
                s = json.load(open(f"{base}/case{c['case']:03d}-summary.json"))
            except OSError:
                continue
            out.append((base, c, s))
    return out

rows = load()
T = collections.Counter()
for b, c, s in rows:
    v = V.decide(s)
    s2 = dict(s, verdict=v['verdict'], verdict_confidence=v['confidence'], verdict_detail=v)
    new = effects_from_diagnosis(s2)[0] is not None
    old = new and (v['confidence'] == 'clear' or v.get('identified'))
    named = v['verdict'] not in ('none', 'unexplained')
    right = v['verdict'] == c['effect']
    fam = c['family']
    T[(fam, 'drives')] += 1
    if named:
        T[(fam, 'named', 'right' if right else 'wrong')] += 1
        T[(fam, 'corrected, old rule', 'right' if right else 'wrong')] += old
        T[(fam, 'corrected, new rule', 'right' if right else 'wrong')] += new
        if new and not old:
            T[(fam, 'added by the new rule', 'right' if right else f"wrong: {v['verdict']} for {c['effect']}")] += 1
for k, n in sorted(T.items()):
    print(n, ' / '.join(k))
