"""Experiment (not part of eroad): the linear fit of one drive as `eroad invert --fit linear` runs it
(K by BIC, 12 iterations, seed 0, axle-3 channels), the road-model selection with the sourced w bounds
(1.5-3.5), then again with both waviness exponents allowed up to 5.8 ("wide" lines).

    python results/road_model/20261124-check/wide_bounds_experiment.py DATASET

Output of the three second_measured drives: wide_bounds_experiment.txt (the machine's load was
about 14 on 2 cores, so its timings are not representative).
"""
import sys, time, pickle, json
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[3]))
from drives.format import read_drive
from inverse.pipeline import InversionConfig, invert
from inverse.sensitivity import FitConfig
from inverse.spectral import ParamBounds
from inverse.truck import SIM_DX, TruckPredictRms, make_truck_simulator, nmax_cap
from inverse.run import fit_channels
from inverse.road_model import select_road_models

ds = sys.argv[1]
drive = read_drive(ds)
time_ = np.asarray(drive.time, float)
chans = {c: drive.channels[c].to_numpy(float) for c in fit_channels(drive.channel_names, "axle3")}
speed = np.asarray(drive.speed, float)
icfg = InversionConfig(fit=FitConfig(max_iter=12, n_workers=1), bounds=ParamBounds(nmax=(1.0, nmax_cap(SIM_DX))), seed=0, fit_model="linear")
make_sim = make_truck_simulator(drive, channels=list(chans))
predict = TruckPredictRms(drive.vehicle, ("susp_disp_3L", "susp_disp_3R"))
from concurrent.futures import ProcessPoolExecutor
with ProcessPoolExecutor(2) as pool:
    t0 = time.perf_counter()
    inv = invert(time_, chans, speed, make_sim, predict_rms=predict, config=icfg, map_fn=pool.map)
    print("fit", time.perf_counter() - t0)
sim = make_sim(inv.t_bounds)
t0 = time.perf_counter()
rm = select_road_models(inv, sim, speed)
print("road model", time.perf_counter() - t0)
for s, r in zip(inv.segments(), rm):
    f = r.get("road_model_fit", {})
    print(round(s["t_start"],1), round(s["t_end"],1), "%.3g" % s["Gq_n0"], round(s["w"], 2), round(s["nmin"],3), round(s["nmax"],2), r["road_model"],
          "ic %.2f" % (r["ic_delta"] if r["ic_delta"] is not None else float("nan")),
          json.dumps({k: (round(v, 4) if isinstance(v, float) else v) for k, v in f.items() if k not in ("one_slope", "two_slope")}),
          json.dumps({k: round(v, 6) for k, v in f.get("two_slope", {}).items()}), json.dumps({k: round(v, 6) for k, v in f.get("one_slope", {}).items()}))

# experiment: the two-slope exponents allowed up to 5.8 (beyond the sourced 3.5)
from inverse.road_model import select_segment, linear_features_for
wide = ParamBounds(w=(1.5, 5.8), nmax=(1.0, nmax_cap(SIM_DX))).for_record(200.0, float(speed.max()))
lin = linear_features_for(inv, sim, speed)
for k in range(inv.fit.params.shape[0]):
    r = select_segment(lin, inv.features, k, inv.fit.params[k], wide)
    f = r.get("road_model_fit", {}); c = f.get("two_slope", {}); o = f.get("one_slope", {})
    print("wide", k + 1, r["road_model"], "ic %.2f" % (r["ic_delta"] if r["ic_delta"] is not None else float("nan")),
          "one Gq %.1f w %.2f" % (1e6 * o.get("Gq_n0", float("nan")), o.get("w", float("nan"))),
          "two Gd(n0) %.1f wl %.2f wh %.2f nb %.3f" % (1e6 * c.get("Gd_n0", float("nan")), c.get("w_low", float("nan")), c.get("w_high", float("nan")), c.get("n_break", float("nan"))))
