"""Counts of a bench_diagnosis work folder W (measured/, second/, nominal/ blind.json): python summarise.py W"""
import json, sys, collections
W = sys.argv[1]
for fam in ['measured', 'second', 'nominal']:
    try:
        b = json.load(open(f'{W}/{fam}/blind.json'))
    except FileNotFoundError:
        continue
    rs = b['results']
    null = [r for r in rs if r['effect'] == 'none']
    eff = [r for r in rs if r['effect'] != 'none']
    nu = sum(r['verdict'] in ('none', 'unexplained') for r in null)
    right = sum(r['correct'] for r in eff)
    cw = sum(r['confident_wrong'] for r in rs)
    wrong = sum((not r['correct']) and r['verdict'] not in ('none', 'unexplained') for r in rs)
    pr = [r['param_ratio'] for r in rs if r.get('param_ratio') is not None and r['correct']]
    pin = sum(1 / 1.5 <= p <= 1.5 for p in pr)
    ts = [r['diagnose_s'] for r in rs]
    side = collections.Counter((r['effect'] == 'none', r.get('gap_side')) for r in rs if r['verdict'] == 'unexplained')
    print(f"{fam}: n {len(rs)}; none/unexplained {nu}/{len(null)} ({collections.Counter(r['verdict'] for r in null)}); "
          f"effects right {right}/{len(eff)}; wrong names {wrong} (clear {cw}); values {pin}/{len(pr)} "
          f"({min(pr) if pr else None:.2f}-{max(pr) if pr else 0:.2f}); time mean {sum(ts)/len(ts):.1f} max {max(ts):.1f} over120 {sum(t>120 for t in ts)}; gap side {dict(side)}")
    for r in rs:
        if not r['correct']:
            print('   miss', r['case'], r.get('scenario'), r['effect'], r['value'], '->', r['verdict'], r['confidence'], 'oracle', r.get('true_shrink'))
