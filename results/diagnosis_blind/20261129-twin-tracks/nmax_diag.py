"""fit_nmax's statistics (d, e; diagnosis.pipeline.fit_nmax) on blind drives made by twin_check.py.

Usage: [NMAXQ=axle_acc_1,axle_acc_2] python nmax_diag.py WORK SEED ...   (NMAXQ: the channels pooled, default all axle accelerations)
"""
import sys, numpy as np
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from diagnosis import pipeline as P
import os
if os.environ.get("NMAXQ"): P.NMAX_QUANTITIES = tuple(os.environ["NMAXQ"].split(","))
np.set_printoptions(precision=2, suppress=True, linewidth=200)
for seed in sys.argv[2:]:
    drive, sig = P.load_measured(Path(sys.argv[1]) / f"{seed}-blind")
    bounds = P.road_segments(sig)
    calib, held, edges = P.windows(sig, 4)
    cal_edges = [(float(edges[i]), float(edges[i + 1])) for i in range(4) if i % 2 == 0]
    noise = P.noise_std(sig, list(sig.channels))
    model = P.TruckModel("dump_truck_8x4", sig.time, sig.speed, bounds, np.full(len(bounds) - 1, P.GQ_REF), noise,
                         list(sig.channels), ref_axle=P.segment_axle(list(sig.channels)))
    gq, w = P.fit_road(model, sig, cal_edges, 0)
    diag = {}
    model.nmax = None
    P.fit_nmax(model, sig, gq, 0, diag=diag)
    print(seed, "bounds", np.round(bounds, 1), "w", np.round(w, 2))
    print("  d (rows NMAX_GRID", P.NMAX_GRID, ")\n", diag["d"])
    print("  e\n", diag["e"])
    print("  vmax", diag["vmax"], "rolloff", diag["rolloff"], "vetoed", diag["vetoed"], "nmax", model.nmax)
