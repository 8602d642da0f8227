"""Exploratory: a low-pass effect's parameter calibrated on the slow and on the fast windows of a
drive, on the road the diagnosis ended with (from its summary). A sensor cutoff is fixed in Hz;
a road feature (or a tyre's enveloping length) is fixed in cycles/m."""
import json, sys, math
import numpy as np
from diagnosis.pipeline import load_measured, windows, candidates, nominal_record, SIM_SOLVER
from diagnosis.truck_model import TruckModel, Fit, Simulate
from diagnosis.road_fit import segment_axle
from diagnosis.which import _Scorer, calibrate

def run(blind, summary, effect, n_windows=8, seed=0):
    s = json.load(open(summary))
    drive, sig = load_measured(blind)
    segs = s["meta"]["road_segments"]
    t0 = float(s["meta"].get("record_t0_s", 0.0))
    bounds = np.array([segs[0]["t_start_s"]] + [g["t_end_s"] for g in segs]) - t0
    bounds[0], bounds[-1] = 0.0, sig.time.size / sig.fs
    veh = s["meta"].get("vehicle") or "dump_truck_8x4"
    from diagnosis.pipeline import noise_std
    model = TruckModel(veh, sig.time, sig.speed, bounds, np.array([g["Gq_n0_m3"] for g in segs]),
                       noise_std(sig, list(sig.channels)), list(sig.channels),
                       ref_axle=segment_axle(list(sig.channels)), w=np.array([g["w"] for g in segs]),
                       nmin=np.array([g["nmin"] for g in segs]), nmax=np.array([g["nmax"] for g in segs]),
                       solver=SIM_SOLVER)
    nominal_record(model, sig, seed)
    cal, held, edges = windows(sig, n_windows)
    allw = sorted(cal + held, key=lambda w: float(np.mean(w.speed)))
    half = len(allw) // 2
    slow, fast = allw[:half], allw[half:]
    cand = [c for c in candidates([effect], veh)][0]
    out = {}
    for tag, ws, other in (("slow", slow, fast), ("fast", fast, slow)):
        sc = _Scorer(Fit(model), Simulate(model), ws, other, seed, 1, 1, None, None)
        c = calibrate([cand], sc.calib_gap, grid=7, refine=10)
        p = cand.params[0].name
        out[tag] = {"v": float(np.mean(np.concatenate([w.speed for w in ws]))), "value": float(c.effects[effect][p]),
                    "gap": c.calib_gap}
    vr = out["fast"]["v"] / out["slow"]["v"]
    pr = out["fast"]["value"] / out["slow"]["value"]
    return out, vr, pr

if __name__ == "__main__":
    blind, summary, effect = sys.argv[1:4]
    out, vr, pr = run(blind, summary, effect)
    print(json.dumps({"case": summary, "effect": effect, **out, "v_ratio": vr, "param_ratio": pr,
                      "ln_param_ratio": math.log(pr), "ln_v_ratio": math.log(vr)}))
