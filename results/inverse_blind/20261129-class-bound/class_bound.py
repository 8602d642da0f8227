"""How often can ANY estimator get the ISO class of a `null` segment right?  (issue 14, stop 54)

For each true segment >= 3 s of the `null` drives of a seed range, the road's own information about
its level: the Fisher information of the Whittle likelihood of the exact road profile's
periodogram for theta = (ln Gq(n0), w), G(n) = Gq (n / n0)^-w, over the segment's true band
[nmin, nmax] (known: more than any inversion knows), one unit of information for ln G per
periodogram bin n_k = k / L (L the segment's length under the reference axle), both wheel tracks
counted as independent (they are not: the scenario's isotropic surface makes them coherent at long
waves, so this over-counts the information).  The Cramer-Rao sd of ln Gq(n0) is
sqrt([I^-1]_11) with w unknown, 1 / sqrt(I_11) with w known exactly.

An estimator with that sd and no bias gets the class right (roadlib.psd.class_of: classes four
times wide, A open below) with probability P = Phi((ln hi - mu) / sd) - Phi((ln lo - mu) / sd) at
the true mu = ln Gq.  The scenario draws ln Gq uniformly across classes A-E, so with a flat prior
the Bayes rule is the class the estimate falls in, and P is what the best rule reaches per segment.
Averaged over the same segments as the committed inversion records, beside the exact-road oracle's
rate (the Whittle fit of the true road, bench_inverse.oracle_fits) and the inversion's.

Run from the repository root:
    python results/inverse_blind/20261129-class-bound/class_bound.py > results/inverse_blind/20261129-class-bound/class_bound.txt
"""
import glob
import json
import math
import sys

import numpy as np
from scipy.stats import norm

sys.path.insert(0, ".")
from drives.synth import load_scenario, plan_drive, resolve_scenario   # noqa: E402
from roadlib.psd import ISO_CLASSES, N0, class_of                      # noqa: E402
from vehicles.params import load_vehicle                               # noqa: E402

RECORDS = "results/inverse_blind/20261128-axles-on-null-140/axles/null*/results.jsonl"


def info(L: float, nmin: float, nmax: float, tracks: int = 2) -> np.ndarray:
    k = np.arange(math.ceil(nmin * L), math.floor(nmax * L) + 1)
    n = k / L
    g = np.stack([np.ones_like(n), -np.log(n / N0)])
    return tracks * g @ g.T


def p_right(mu: float, sd: float) -> float:
    c = ISO_CLASSES[class_of(math.exp(mu))]
    lo = -np.inf if c.lower == 0 else math.log(c.lower)
    hi = np.inf if math.isinf(c.upper) else math.log(c.upper)
    return float(norm.cdf((hi - mu) / sd) - norm.cdf((lo - mu) / sd))


def main() -> None:
    cfg, _ = load_scenario("null")
    axle_x = [float(a.x) for a in load_vehicle(cfg["scenario"]["vehicle"]).axles]
    rows = []
    for fn in sorted(glob.glob(RECORDS)):
        for line in open(fn):
            r = json.loads(line)
            plan = plan_drive(resolve_scenario(cfg, r["seed"]), axle_x)
            truth = plan["segments"]
            assert len(truth) == r["K_true"], (r["seed"], len(truth), r["K_true"])
            for s, rec in zip(truth, r["segments"]):
                dur = s["t_end"] - s["t_start"]
                assert abs(dur - rec["duration_s"]) < 0.01 and abs(s["Gq_n0"] / rec["Gq_true"] - 1) < 1e-9
                if dur < 3.0:
                    continue
                I = info(s["x_end"] - s["x_start"], s["nmin"], s["nmax"])
                sd_free = math.sqrt(np.linalg.inv(I)[0, 0])
                sd_known = 1.0 / math.sqrt(I[0, 0])
                sd_one = math.sqrt(np.linalg.inv(info(s["x_end"] - s["x_start"], s["nmin"], s["nmax"], 1))[0, 0])
                mu = math.log(s["Gq_n0"])
                g1 = np.array([1.0, -math.log(1.0 / N0)])
                sd_g1 = math.sqrt(g1 @ np.linalg.inv(I) @ g1)
                fit_w_err = rec["w_fit"] - s["w"]
                rows.append(dict(seed=r["seed"], dur=dur, L=s["x_end"] - s["x_start"], sd_free=sd_free,
                                 sd_known=sd_known, p_free=p_right(mu, sd_free), p_known=p_right(mu, sd_known), p_one=p_right(mu, sd_one),
                                 sd_free_w=math.sqrt(np.linalg.inv(I)[1, 1]), fit_w_err=fit_w_err,
                                 p_g1=float(2 * norm.cdf(math.log(1.2) / sd_g1) - 1),
                                 g1_fit=abs(rec["lnG_1cpm_err"]) <= math.log(1.2),
                                 oracle=class_of(rec["oracle"]["Gq"]) == rec["class_true"],
                                 fit=rec["class_fit"] == rec["class_true"]))
    print(f"records: {RECORDS}")
    print("segments >= 3 s; class right [%]: Cramer-Rao bound with w free / w known exactly / w free and "
          "one track's information only | "
          "exact-road oracle | the inversion (closed loop's `axles` fit)")
    for lo, hi, name in ((1, 20, "seeds 1-20"), (21, 60, "seeds 21-60"), (61, 100, "seeds 61-100"),
                         (101, 140, "seeds 101-140"), (1, 140, "all 140")):
        sub = [x for x in rows if lo <= x["seed"] <= hi]
        print(f"{name:14s} {len(sub):4d} segments: bound {100 * np.mean([x['p_free'] for x in sub]):5.1f} / "
              f"{100 * np.mean([x['p_known'] for x in sub]):5.1f} / {100 * np.mean([x['p_one'] for x in sub]):5.1f} | "
              f"oracle {100 * np.mean([x['oracle'] for x in sub]):5.1f} | fit {100 * np.mean([x['fit'] for x in sub]):5.1f}")
    print("G(1 cycle/m) within 20 % [%], all 140: Cramer-Rao bound (w free, two tracks) "
          f"{100 * np.mean([x['p_g1'] for x in rows]):.1f} | fit {100 * np.mean([x['g1_fit'] for x in rows]):.1f}")
    print("w: Cramer-Rao sd (w free, two tracks), median over segments "
          f"{np.median([x['sd_free_w'] for x in rows]):.3f}; the fit's w error against the truth: sd "
          f"{np.std([x['fit_w_err'] for x in rows]):.3f}")
    print("by duration (all 140 drives):")
    for lo, hi in ((3, 5), (5, 8), (8, 15), (15, 31)):
        sub = [x for x in rows if lo <= x["dur"] < hi]
        print(f"  {lo:2d}-{hi:2d} s {len(sub):4d}: median length {np.median([x['L'] for x in sub]):5.1f} m, "
              f"CR sd ln Gq(n0) {np.median([x['sd_free'] for x in sub]):.3f} (w known {np.median([x['sd_known'] for x in sub]):.3f}); "
              f"bound {100 * np.mean([x['p_free'] for x in sub]):5.1f} / {100 * np.mean([x['p_known'] for x in sub]):5.1f} / "
              f"{100 * np.mean([x['p_one'] for x in sub]):5.1f} | "
              f"oracle {100 * np.mean([x['oracle'] for x in sub]):5.1f} | fit {100 * np.mean([x['fit'] for x in sub]):5.1f}")


if __name__ == "__main__":
    main()
