"""Measured axle-3 acceleration periodogram over the linear model's expected one at the TRUE road parameters,
per frequency band, on the segments >= 3 s of null seed 101 (python ratio_check.py DATA_ROOT, from the
repository root; DATA_ROOT as made by response_whittle.py, whose periodogram and expected PSD it uses)."""
import sys

import numpy as np

sys.path.insert(0, ".")
sys.path.insert(0, "results/inverse_blind/20261129-response-whittle")
from drives.format import read_drive                                      # noqa: E402
from drives.synth import read_truth                                       # noqa: E402
from response_whittle import CHANNELS, NOISE_PSD, expected_psd, periodograms   # noqa: E402
from vehicles.linear import linear_model                                  # noqa: E402

EDGES = [1.5, 3, 6, 10, 15, 20, 30, 45, 70, 99]
lm = linear_model("dump_truck_8x4")
for seed in (101,):
    ds = f"{sys.argv[1]}/null-{seed}"
    dr, tr = read_drive(ds), read_truth(ds)
    t, v = np.asarray(dr.time), np.asarray(dr.speed)
    acc = [dr.channels[c].to_numpy() for c in CHANNELS]
    for s in tr["segments"]:
        if s["t_end"] - s["t_start"] < 3:
            continue
        m = (t >= s["t_start"]) & (t < s["t_end"])
        vs = v[m]
        f, I = periodograms(acc, m)
        road = {"Gq_n0": s["Gq_n0"], "w": s["w"], "nmin": s["nmin"], "nmax": s["nmax"], "lam": 1.0}
        E = expected_psd(lm, lm.frf(f, CHANNELS), f, road, np.quantile(vs, [1 / 6, .5, 5 / 6])) + NOISE_PSD
        for j, c in enumerate(CHANNELS):
            r = I[j] / E[j]
            print(seed, round(s["t_end"] - s["t_start"], 1), c, "v %.1f-%.1f" % (vs.min(), vs.max()),
                  " ".join("%g-%g:%.2f" % (EDGES[k], EDGES[k + 1], np.mean(r[(f >= EDGES[k]) & (f < EDGES[k + 1])]))
                           for k in range(len(EDGES) - 1)))
