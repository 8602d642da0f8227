"""The named leaf friction calibrated again with other ranking settings (stop 52, design set; decision.txt).

    PYTHONPATH=. nice python results/inverse_blind/20261129-calibration-seeds/calibrate_values.py SETTINGS SEEDS DATA OUT

SETTINGS: JSON merged into the diagnosis's BUDGET (e.g. '{"n_calib_seeds": 3}'); SEEDS: comma-separated
friction seeds; DATA: a folder of blind-random-SEED datasets (no truth read); OUT: one diagnosis folder per
seed and values.jsonl (the calibrated force, per fold, evaluations, wall). Only the one candidate is ranked
(diagnose(effects=['leaf_friction'])): the candidates are calibrated independently of each other, so this is
the diagnosis's own calibration of it with the settings changed."""
import json
import sys
import time
from pathlib import Path

from diagnosis.pipeline import diagnose


def main(settings, seeds, data, out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for s in seeds:
        t = time.perf_counter()
        d = diagnose(Path(data) / f'blind-random-{s}', out / f'run-{s}', effects=['leaf_friction'],
                     settings=settings, force=True, progress=lambda m: None)
        r = next(x for x in d['ranking'] if x['effect'] == 'leaf_friction')
        rec = {'seed': s, 'settings': settings, 'force': r['parameters']['leaf_friction']['force'],
               'per_fold': [p['leaf_friction']['force'] for p in r['parameters_per_fold']],
               'n_evaluations': r['n_evaluations'], 'wall_s': time.perf_counter() - t}
        print(json.dumps(rec), flush=True)
        with open(out / 'values.jsonl', 'a') as f:
            f.write(json.dumps(rec) + '\n')


if __name__ == '__main__':
    main(json.loads(sys.argv[1]), [int(x) for x in sys.argv[2].split(',')], sys.argv[3], sys.argv[4])
