"""The leaf-friction value's error with the diagnosis's search and with the refined one (stop 51):
python results/inverse_blind/20261128-refined-value/value_error.py  (from the repository root).

The diagnosis's values, and each fold's, are in diagnosis_folds.json (copied from the saved diagnoses'
summary.json, ranking entry leaf_friction: the value handed to the loop); the refined ones are
values.jsonl here (refine_values.py 8). Truth: 2000 N (our truck, `random` scenario)."""
import json
import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
L = math.log(1.2)


def main():
    dg = json.loads((HERE / 'diagnosis_folds.json').read_text())
    diag = {int(s): d['force'] for s, d in dg.items()}
    ref = {r['seed']: r for r in map(json.loads, (HERE / 'values.jsonl').read_text().splitlines())}
    seeds = sorted(set(diag) & set(ref))
    print('| seed | diagnosis (refine 3) [N] | refined (refine 8) [N] | per fold [N] |')
    print('|---|---|---|---|')
    for s in seeds:
        print(f"| {s} | {diag[s]:.0f} | {ref[s]['force']:.0f} | {' / '.join(f'{v:.0f}' for v in ref[s]['per_fold'])} |")
    e0 = np.array([math.log(diag[s] / 2000.0) for s in seeds])
    e1 = np.array([math.log(ref[s]['force'] / 2000.0) for s in seeds])
    fold = np.array([math.log(ref[s]['per_fold'][0] / ref[s]['per_fold'][1]) for s in seeds])
    for name, e in (('diagnosis, refine 3', e0), ('refined, refine 8', e1)):
        print(f"{name}: {len(e)} drives, ln(value / 2000 N) mean {e.mean():+.3f}, rms {np.sqrt(np.mean(e ** 2)):.3f}, "
              f"median |.| {np.median(np.abs(e)):.3f}, within x1.2 {int(np.sum(np.abs(e) <= L))}")
    print(f"refined: the two folds' values differ by sd {fold.std():.3f} in ln; if the folds are independent, one "
          f"fold's value scatters by {fold.std() / math.sqrt(2):.3f} and their mean (the value handed on) by "
          f"{fold.std() / 2:.3f} -- against its rms error {np.sqrt(np.mean(e1 ** 2)):.3f}")
    fd = np.array([math.log(dg[str(s)]['per_fold'][0] / dg[str(s)]['per_fold'][1]) for s in seeds])
    print(f"the diagnosis's own folds (refine 3, diagnosis_folds.json, copied from the saved diagnoses): differ by "
          f"sd {fd.std():.3f} in ln; equal in {int(np.sum(np.abs(fd) < 1e-9))} of {len(fd)} (the same grid point)")
    print(f"wall per refined calibration (one candidate, two folds): median "
          f"{np.median([ref[s]['wall_s'] for s in seeds]):.0f} s")


if __name__ == '__main__':
    main()
