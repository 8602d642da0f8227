"""(The script as it ran, 2026-11-28 19:00-19:30 UTC, from /tmp/s50; data of friction seeds 61-80 in /tmp/s49/data-random61.)
Friction drives 61-80 inverted with the TRUE effects (oracle corrections): leaf friction at its
true value (F), and leaf friction plus the truth's flexible frame (FF). Scored as bench_inverse.py."""
import json, sys, time
from pathlib import Path
sys.path.insert(0, '/work/main'); sys.path.insert(0, '/work/main/benchmarks')
from bench_inverse import score_run
from drives.synth import read_truth
from inverse.run import run_inversion

DATA = Path('/tmp/s49/data-random61')
OUT = Path('/tmp/s50/oracle')
variants = sys.argv[1].split(',')
seeds = range(int(sys.argv[2]), int(sys.argv[3]) + 1)
for seed in seeds:
    ds = DATA / f'random-{seed}'
    t = read_truth(ds)
    eff = t['vehicle']['simulate_kwargs']['effects']
    nseg = t['vehicle']['simulate_kwargs'].get('frame_segments', 8)
    for v in variants:
        res = OUT / f'{v}.jsonl'
        if res.is_file() and any(json.loads(l)['seed'] == seed for l in res.read_text().splitlines()):
            continue
        effects = dict(eff)
        if v == 'FF':
            effects['frame_flex'] = {'stiffness_factor': 1.0, 'segments': float(nseg)}
        t0 = time.perf_counter()
        summ = run_inversion(DATA / f'blind-random-{seed}', OUT / f'{v}-{seed}', workers=1, seed=0, candidates=0,
                             force=True, effects=effects, model_form='diagnosed')
        case = score_run(ds, 'random', summ)
        case.update(seed=seed, scenario='random', wall_s=time.perf_counter() - t0, variant=v, effects=effects)
        with res.open('a') as f:
            f.write(json.dumps(case) + '\n')
        print(seed, v, [round(r['lnG_1cpm_err'], 2) for r in case['segments']], round(case['wall_s']), flush=True)
