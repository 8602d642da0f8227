"""The named leaf friction calibrated again with a finer search (stop 51, design set; decision.txt).

    PYTHONPATH=. nice python results/inverse_blind/20261128-refined-value/refine_values.py REFINE SEEDS DATA OUT

REFINE: golden-section steps after the grid (the diagnosis's BUDGET has 3); SEEDS: comma-separated friction
seeds; DATA: the bench's data root (blind-random-SEED folders, no truth read); OUT: one diagnosis folder per
seed and values.jsonl (the calibrated force, per fold, evaluations, wall). Only the one candidate is ranked
(diagnose(effects=['leaf_friction'])): the candidates are calibrated independently, so its search is the
diagnosis's own with more steps."""
import json
import sys
import time
from pathlib import Path

from diagnosis.pipeline import diagnose


def calibrate(settings, seeds, data, out, tag):
    """The one candidate calibrated with ``settings`` (merged into the diagnosis's BUDGET) on each seed's blind
    dataset; one record per seed, ``tag`` (the fields naming the settings) after the seed. Also used by
    ../20261129-calibration-seeds/calibrate_values.py."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for s in seeds:
        t = time.perf_counter()
        d = diagnose(Path(data) / f'blind-random-{s}', out / f'run-{s}', effects=['leaf_friction'],
                     settings=settings, force=True, progress=lambda m: None)
        r = next(x for x in d['ranking'] if x['effect'] == 'leaf_friction')
        rec = {'seed': s, **tag, 'force': r['parameters']['leaf_friction']['force'],
               'per_fold': [p['leaf_friction']['force'] for p in r['parameters_per_fold']],
               'n_evaluations': r['n_evaluations'], 'wall_s': time.perf_counter() - t}
        print(json.dumps(rec), flush=True)
        with open(out / 'values.jsonl', 'a') as f:
            f.write(json.dumps(rec) + '\n')


def main(refine, seeds, data, out):
    calibrate({'refine': refine}, seeds, data, out, {'refine': refine})


if __name__ == '__main__':
    main(int(sys.argv[1]), [int(x) for x in sys.argv[2].split(',')], sys.argv[3], sys.argv[4])
