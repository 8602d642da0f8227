import sys, math
import numpy as np, pandas as pd
from drives.synth import load_scenario, plan_drive, resolve_scenario
from vehicles.params import load_vehicle
from inverse.segmentation import segment
cfg, _ = load_scenario("null")
AX = [float(a.x) for a in load_vehicle(cfg["scenario"]["vehicle"]).axles]
ROOT = "/work/gqb/data"
tot = {}
miss = {}
for seed in range(181, 221):
    df = pd.read_csv(f"{ROOT}/blind-null-{seed}/channels.csv")
    t = df["time"].to_numpy(); v = df["speed"].to_numpy()
    truth = plan_drive(resolve_scenario(cfg, seed), AX)["segments"]
    d3 = {c: df[c].to_numpy() for c in ("susp_disp_3L", "susp_disp_3R")}
    a3 = {c: df[c].to_numpy() for c in ("axle_acc_3L", "axle_acc_3R")}
    both = dict(a3)
    runs = {"default": segment(t, d3, v).t_bounds,
            "axle_acc": segment(t, d3, v, boundary_channels=a3).t_bounds,
            "axle_acc+disp bands 3-6": segment(t, d3, v, boundary_channels={**a3, **d3},
                                               boundary_bands=((3, 6), (6, 12), (12, 24), (24, 48))).t_bounds}
    for k, tb in runs.items():
        true_b = [s["t_end"] for s in truth[:-1]]
        f = sum(any(abs(b - x) <= 0.5 for x in tb[1:-1]) for b in true_b)
        fa = sum(all(abs(x - b) > 1.0 for b in true_b) for x in tb[1:-1])
        c = tot.setdefault(k, [0, 0, 0]); c[0] += f; c[1] += len(true_b); c[2] += fa
        for a, b in zip(truth[:-1], truth[1:]):
            if not any(abs(a["t_end"] - x) <= 0.5 for x in tb[1:-1]):
                g1 = abs((math.log(a["Gq_n0"]) - a["w"] * math.log(10)) - (math.log(b["Gq_n0"]) - b["w"] * math.log(10)))
                miss.setdefault(k, []).append(round(g1, 2))
for k, (f, n, fa) in tot.items():
    m = miss.get(k, [])
    print(f"{k:26s} found {f}/{n}, false {fa}; missed with |d ln G(1)| > 0.18: {sum(x > 0.18 for x in m)} of {len(m)}")
