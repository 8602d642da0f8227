"""(The script as it ran, 2026-11-28 19:30-20:03 UTC, from /tmp/s50, with diagnosis/effect_profile.py as in commit 4f67d65
(reverted at c58bc99: read it with `git show 4f67d65:diagnosis/effect_profile.py`) before its
reach was capped, i.e. up to four steps; refine_exp.py had made the k = -1, +1 runs of seeds 62-65 the same way.)
The profile algorithm (diagnosis.effect_profile.profile) on the friction drives 61-80, with
the runs of refine_exp.py cached; missing runs are made."""
import json, math, sys, time
from pathlib import Path
sys.path.insert(0, '/work/main'); sys.path.insert(0, '/work/main/benchmarks')
from bench_inverse import score_run
from inverse.run import run_inversion
from diagnosis.effect_profile import profile, profiled_parameter, STEP

DATA = Path('/tmp/s49/data-random61')
OUT = Path('/tmp/s50/refine')
res = OUT / 'runs.jsonl'
loop = {json.loads(l)['seed']: json.loads(l)['closed_loop'] for l in
        open('/work/main/results/inverse_blind/20261128-beta-diagnosed-pooled/fresh-friction-61-80/results.jsonl')}
cache = {}
for l in res.read_text().splitlines():
    c = json.loads(l); cache[(c['seed'], c['k'])] = c['objective']
seeds = [int(s) for s in sys.argv[1].split(',')]
out = open(OUT / 'profiles.jsonl', 'a')
for seed in seeds:
    cl = loop[seed]
    if not cl['corrected']:
        continue
    name, par, c, bounds = profiled_parameter(cl['effects'])
    cache[(seed, 0)] = json.load(open(f'/tmp/s49/fresh-random/run-{seed}/summary.json'))['fit']['objective']
    def obj(v):
        k = round(math.log(v / c) / math.log(STEP))
        if abs(c * STEP ** k - v) > 1e-6 * v:
            raise SystemExit(f'off grid {v}')
        if (seed, k) not in cache:
            eff = {name: dict(cl['effects'][name], **{par: v})}
            t0 = time.perf_counter()
            summ = run_inversion(DATA / f'blind-random-{seed}', OUT / f'run-{seed}-{k}', workers=1, seed=0, candidates=0,
                                 force=True, effects=eff, model_form=cl.get('model_form') or 'diagnosed')
            case = score_run(DATA / f'random-{seed}', 'random', summ)
            case.update(seed=seed, k=k, force=v, objective=summ['fit']['objective'],
                        n_features=summ['fit']['n_features'], wall_s=time.perf_counter() - t0)
            with res.open('a') as f:
                f.write(json.dumps(case) + '\n')
            print(seed, k, round(v), round(case['objective'], 2), [round(r['lnG_1cpm_err'], 2) for r in case['segments']], flush=True)
            cache[(seed, k)] = case['objective']
        return cache[(seed, k)]
    p = profile(obj, c, bounds)
    p['seed'] = seed; p['k'] = [round(math.log(v / c) / math.log(STEP)) for v in p['values']]
    out.write(json.dumps(p) + '\n'); out.flush()
    print('profile', seed, p['k'], [round(o, 1) for o in p['objectives']], 'best k', p['k'][p['best']], flush=True)
