"""Prototype: boundaries from axle 3's displacements (default) against all four axles'
displacements aligned in road position on axle 3's clock. Null drives seeds 181-220 (our truck)."""
import sys, json
import numpy as np
import pandas as pd
from drives.synth import load_scenario, plan_drive, resolve_scenario
from vehicles.params import load_vehicle
from inverse.segmentation import segment

cfg, _ = load_scenario("null")
veh = load_vehicle(cfg["scenario"]["vehicle"])
AX = [float(a.x) for a in veh.axles]
ROOT = sys.argv[1] if len(sys.argv) > 1 else "/work/gqb/data"
SEEDS = range(181, 221)


def aligned(t, v, df, axles=(1, 2, 3, 4), ref=3):
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    out = {}
    for side in "LR":
        base = df[f"susp_disp_{ref}{side}"].to_numpy()
        for a in axles:
            y = df[f"susp_disp_{a}{side}"].to_numpy()
            d = AX[a - 1] - AX[ref - 1]
            ta = np.interp(s - d, s, t, left=np.nan, right=np.nan)
            ya = np.interp(ta, t, y)
            ok = np.isfinite(ta)
            out[f"{a}{side}"] = np.where(ok, ya, base)
    return out


def score(tb, truth, tol=0.5, far=1.0):
    true_b = [s["t_end"] for s in truth[:-1]]
    fit_b = list(tb[1:-1])
    found = sum(any(abs(b - f) <= tol for f in fit_b) for b in true_b)
    false = sum(all(abs(f - b) > far for b in true_b) for f in fit_b)
    return found, len(true_b), false


variants = {"default": None}
for pen in (1.0, 0.7, 0.5):
    variants[f"aligned p{pen}"] = pen
tot = {k: [0, 0, 0] for k in variants}
tot.update({f"default p{p}": [0, 0, 0] for p in (0.7, 0.5)})
for seed in SEEDS:
    df = pd.read_csv(f"{ROOT}/blind-null-{seed}/channels.csv")
    t = df["time"].to_numpy(); v = df["speed"].to_numpy()
    truth = plan_drive(resolve_scenario(cfg, seed), AX)["segments"]
    res = {}
    d3 = {c: df[c].to_numpy() for c in ("susp_disp_3L", "susp_disp_3R")}
    for pen in (1.0, 0.7, 0.5):
        name = "default" if pen == 1.0 else f"default p{pen}"
        res[name] = score(segment(t, d3, v, penalty=pen).t_bounds, truth)
    al = aligned(t, v, df)
    for pen in (1.0, 0.7, 0.5):
        res[f"aligned p{pen}"] = score(segment(t, al, v, penalty=pen).t_bounds, truth)
    for k, r in res.items():
        tot[k] = [x + y for x, y in zip(tot[k], r)]
    print(seed, {k: r for k, r in res.items()}, flush=True)
for k, (f, n, fa) in tot.items():
    print(f"{k:14s} found {f}/{n} within 0.5 s, false {fa}")

# the boundaries the default misses: how far apart are the two pieces' roads?
import math
rows = []
for seed in SEEDS:
    df = pd.read_csv(f"{ROOT}/blind-null-{seed}/channels.csv")
    t = df["time"].to_numpy(); v = df["speed"].to_numpy()
    truth = plan_drive(resolve_scenario(cfg, seed), AX)["segments"]
    tb = segment(t, {c: df[c].to_numpy() for c in ("susp_disp_3L", "susp_disp_3R")}, v).t_bounds
    for a, b in zip(truth[:-1], truth[1:]):
        hit = any(abs(a["t_end"] - f) <= 0.5 for f in tb[1:-1])
        g1 = [math.log(s["Gq_n0"]) - s["w"] * math.log(10.0) for s in (a, b)]
        # ln of the 3-20 Hz-dominant wavelength's power (0.3 cycles/m) -- what the statistic sees
        g03 = [math.log(s["Gq_n0"]) - s["w"] * math.log(3.0) for s in (a, b)]
        rows.append((hit, abs(g1[0] - g1[1]), abs(g03[0] - g03[1]), min(a["t_end"] - a["t_start"], b["t_end"] - b["t_start"])))
miss = [r for r in rows if not r[0]]
print(f"\nmissed true boundaries: {len(miss)} of {len(rows)}")
for q, lab in ((1, "|d ln G(1 cycle/m)|"), (2, "|d ln G(0.3 cycles/m)|"), (3, "shorter piece [s]")):
    vals = sorted(r[q] for r in miss)
    print(f"  {lab}: " + ", ".join(f"{x:.2f}" for x in vals))
found = [r for r in rows if r[0]]
print(f"found boundaries, |d ln G(0.3)| median {np.median([r[2] for r in found]):.2f}, "
      f"|d ln G(1)| median {np.median([r[1] for r in found]):.2f}")
print(f"missed with |d ln G(1)| > 0.18 (a merge that puts G(1) of one piece outside 20 %): "
      f"{sum(r[1] > 0.18 for r in miss)} of {len(miss)}")
