"""Score the arms of decision.txt (this folder) from their bench_inverse results.jsonl.

    python compare.py W/A W/B W/C     # each a --root of benchmarks/bench_inverse.py (or its results.jsonl)
    python compare.py A-results.jsonl B-results.jsonl C-results.jsonl   # the committed copies

Per arm, segments >= 3 s: G(1 cycle/m) within 20 %, class right, the 90 % coverage of ln Gq(n0) /
w / ln G(n_best) (|error| <= 1.645 reported sd), the mean signed ln G(1 cycle/m) error and the
median signed w error (fit - truth), and the true-road oracle's mean signed ln G(1 cycle/m) error
against the ISO truth (its one-slope fit to the road under the reference axle).  Paired per
(seed, segment) where two arms share their segments."""
import json
import math
import sys
from pathlib import Path

import numpy as np

Z90 = 1.645
LN10 = math.log(10.0)     # ln(n / n0) at n = 1 cycle/m, n0 = 0.1


def rows(root):
    out = {}
    path = Path(root) if str(root).endswith(".jsonl") else Path(root, "results.jsonl")
    for line in path.read_text().splitlines():
        r = json.loads(line)
        for i, s in enumerate(r["segments"]):
            if s["duration_s"] >= 3.0:
                out[(r["seed"], i)] = s
    return out


def score(rs):
    s = list(rs.values())
    g1 = np.array([x["lnG_1cpm_err"] for x in s])
    cov = [np.mean([abs(x[e]) <= Z90 * x[sd] for x in s])
           for e, sd in (("lnGq_err", "sd_ln_Gq_n0"), ("w_err", "sd_w"), ("lnG_n_best_err", "sd_ln_G_n_best"))]
    orc = np.array([math.log(x["oracle"]["Gq"] / x["Gq_true"]) - (x["oracle"]["w"] - x["w_true"]) * LN10
                    for x in s if x.get("oracle")])
    return {"n": len(s), "g1_within20": float(np.mean(np.abs(g1) <= math.log(1.2))),
            "class_right": float(np.mean([x["class_fit"] == x["class_true"] for x in s])),
            "cover": [float(c) for c in cov], "g1_mean_signed": float(np.mean(g1)), "g1_sd": float(np.std(g1)),
            "w_median_signed": float(np.median([x["w_err"] for x in s])),
            "oracle_g1_mean_signed": float(np.mean(orc)) if orc.size else float("nan")}


def main(argv):
    arms = {Path(a).name.replace("-results.jsonl", ""): rows(a) for a in argv}
    for name, rs in arms.items():
        s = score(rs)
        print(f"{name}: n {s['n']}, G(1) within 20 % {100 * s['g1_within20']:.1f} %, class right "
              f"{100 * s['class_right']:.1f} %, 90 % cover ln Gq(n0) / w / ln G(n_best) "
              + " / ".join(f"{100 * c:.0f}" for c in s["cover"])
              + f" %, ln G(1) error mean {s['g1_mean_signed']:+.3f} (sd {s['g1_sd']:.3f}), w error median "
              f"{s['w_median_signed']:+.3f}, true-road oracle ln G(1) against ISO mean {s['oracle_g1_mean_signed']:+.3f}")
    names = list(arms)
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            a, b = arms[names[i]], arms[names[j]]
            common = sorted(set(a) & set(b))
            same = [k for k in common if abs(a[k]["duration_s"] - b[k]["duration_s"]) < 1e-6]
            ok_a = np.array([abs(a[k]["lnG_1cpm_err"]) <= math.log(1.2) for k in same])
            ok_b = np.array([abs(b[k]["lnG_1cpm_err"]) <= math.log(1.2) for k in same])
            d = np.array([b[k]["lnG_1cpm_err"] - a[k]["lnG_1cpm_err"] for k in same])
            print(f"{names[i]} -> {names[j]}: {len(same)} common segments; G(1) within 20 % gained "
                  f"{int(np.sum(~ok_a & ok_b))}, lost {int(np.sum(ok_a & ~ok_b))}; ln G(1) error moved by "
                  f"mean {np.mean(d):+.3f} (sd {np.std(d):.3f})" if same else f"{names[i]} -> {names[j]}: none common")


if __name__ == "__main__":
    main(sys.argv[1:])
