"""The variant tried first (2026-11-28, worktree of main at bb8925d): an unexplained drive corrected with its closest
effect whatever it acts on, fitted on axle 3 (the verdict rewritten to the closest name, confidence ambiguous)."""
import json, shutil, sys, time
from pathlib import Path
sys.path.insert(0, '/tmp/wt48/benchmarks'); sys.path.insert(0, '/tmp/wt48')
from bench_inverse import score_run
from diagnosis.closed_loop import invert_closed_loop

def main(name, data_root, diag_root, out_root, seeds, scen_fn, channels):
    out_root = Path(out_root); out_root.mkdir(parents=True, exist_ok=True)
    res = out_root / 'results.jsonl'
    for seed in seeds:
        scen = scen_fn(seed)
        src = Path(diag_root) / f'run-{seed}' / 'diagnose'
        dg = out_root / 'diag' / f'run-{seed}' / 'diagnose'
        if dg.exists(): shutil.rmtree(dg)
        shutil.copytree(src, dg)
        s = json.loads((dg / 'summary.json').read_text())
        d = s['verdict_detail']
        s['verdict'] = d['closest']; s['verdict_confidence'] = 'ambiguous'
        (dg / 'summary.json').write_text(json.dumps(s))
        ds = Path(data_root) / f'{scen}-{seed}'; blind = Path(data_root) / f'blind-{scen}-{seed}'
        t0 = time.perf_counter()
        inv = dict(workers=2, seed=0, candidates=0, max_iter=10, channels=channels, force=True, polish=True,
                   noise_sd=None, fit_model='linear', segment_on='displacement')
        summ = invert_closed_loop(blind, out_root / f'run-{seed}', progress=lambda _m: None, diagnosis=dg, **inv)
        case = score_run(ds, scen, summ)
        case.update(seed=seed, scenario=scen, wall_s=time.perf_counter() - t0)
        with res.open('a') as f: f.write(json.dumps(case) + '\n')
        print(name, seed, summ['closed_loop']['reason'][:120], round(time.perf_counter() - t0), 's', flush=True)

if __name__ == '__main__':
    ch = None if sys.argv[1] == 'axle3' else sys.argv[1]
    tag = sys.argv[1]
    main('fric1-20', '/tmp/s45/data-random', '/tmp/s46/cl-axle3', f'/tmp/s48/closest-{tag}/fric1-20', [12], lambda s: 'random', ch)
    main('fric21-40', '/tmp/s47/data-random21', '/tmp/s47/fresh-random', f'/tmp/s48/closest-{tag}/fric21-40', [37, 38], lambda s: 'random', ch)
    main('ind1-20', '/tmp/s45/data-second', '/tmp/s47/cl-second', f'/tmp/s48/closest-{tag}/ind1-20', [13], lambda s: 'second_measured' if (s - 1) % 4 == 0 else 'second', ch)
    main('ind41-52', '/tmp/s47/data-second41', '/tmp/s47/fresh-second', f'/tmp/s48/closest-{tag}/ind41-52', [41, 45], lambda s: 'second_measured' if (s - 41) % 4 == 0 else 'second', ch)
