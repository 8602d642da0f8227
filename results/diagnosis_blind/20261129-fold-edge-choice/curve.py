"""Each fold's calibration gap of one candidate over a value grid (stop 60, exploration):
python curve.py DATASET EFFECT PARAM V1,V2,... [FIXED_JSON]; the folds as diagnose makes them (seed 0)."""
import sys, json, numpy as np
from diagnosis.pipeline import load_measured, prepare, Fit, Simulate, gap_terms, _set_terms
from diagnosis.which import _Scorer
ds, eff, par = sys.argv[1], sys.argv[2], sys.argv[3]
vals = [float(v) for v in sys.argv[4].split(",")]
extra = json.loads(sys.argv[5]) if len(sys.argv) > 5 else {}
drive, sig = load_measured(ds)
ctx = prepare(sig, drive.vehicle, seed=0, n_windows=4)
terms = gap_terms(ctx.model, sig)
for fold, (cal, held, seed) in enumerate([(ctx.calib, ctx.held, 0), (ctx.held, ctx.calib, 1)]):
    sc = _Scorer(Fit(ctx.model), Simulate(ctx.model), cal, held, seed, 1, 4, None, None)
    _set_terms(sc, terms, 12)
    g0 = sc.calib_gap({})
    row = []
    for v in vals:
        e = {eff: dict(extra, **{par: v})}
        row.append(sc.calib_gap(e))
    print(f"fold {fold}: nominal {g0:.4f} | " + "  ".join(f"{v:g}:{g:.4f}" for v, g in zip(vals, row)), flush=True)
