"""Development re-runs of saved blind cases with the speed test: python dev.py OUT SET/FAM:CASE ..."""
import json, sys
from pathlib import Path
from diagnosis.blind import run_case
R = Path('/work/main/results/diagnosis_blind')
out = Path(sys.argv[1])
for item in sys.argv[2:]:
    sf, c = item.split(':')
    b = json.load(open(R / sf / 'blind.json'))
    r = next(x for x in b['results'] if x['case'] == int(c))
    case = {k: r[k] for k in ('case', 'seed', 'effect', 'param', 'value', 'family', 'scenario') if k in r}
    root = out / sf.replace('/', '_')
    root.mkdir(parents=True, exist_ok=True)
    res = run_case(case, root, settings={"joint_band": True})
    s = json.load(open(root / f"case{int(c):03d}-run" / "summary.json"))
    hz = s.get('signature_hz')
    vd = s.get('verdict_detail', {})
    print(json.dumps({"item": item, "truth": [r['effect'], r['value']], "old": [r['verdict'], r['confidence']],
                      "new": [s['verdict'], s['verdict_confidence']], "ranking": [(e['effect'], round(e['heldout_gap_after'], 3)) for e in s['ranking'][:3]],
                      "hz": None if hz is None else {k: hz[k] for k in ('measured', 'nominal', 'models')},
                      "own": vd.get('signature_own'), "t": res.get('diagnose_s')}), flush=True)
