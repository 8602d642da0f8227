"""The named leaf friction calibrated again with other ranking settings (stop 52, design set; decision.txt).

    PYTHONPATH=. nice python results/inverse_blind/20261129-calibration-seeds/calibrate_values.py SETTINGS SEEDS DATA OUT

SETTINGS: JSON merged into the diagnosis's BUDGET (e.g. '{"n_calib_seeds": 3}'); SEEDS: comma-separated
friction seeds; DATA: a folder of blind-random-SEED datasets (no truth read); OUT: one diagnosis folder per
seed and values.jsonl (the calibrated force, per fold, evaluations, wall). Only the one candidate is ranked
(diagnose(effects=['leaf_friction'])): the candidates are calibrated independently of each other, so this is
the diagnosis's own calibration of it with the settings changed."""
import json
import sys
from pathlib import Path

# the loop is stop 51's (refine_values.calibrate), with any settings instead of refine alone
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / '20261128-refined-value'))
from refine_values import calibrate  # noqa: E402


def main(settings, seeds, data, out):
    calibrate(settings, seeds, data, out, {'settings': settings})


if __name__ == '__main__':
    main(json.loads(sys.argv[1]), [int(x) for x in sys.argv[2].split(',')], sys.argv[3], sys.argv[4])
