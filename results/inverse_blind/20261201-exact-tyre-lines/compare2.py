"""decision2.txt's bar: paired non-inferiority of B2 (exact tyre lines) against A2 (grid mix).

    python compare2.py ROOT_A2 ROOT_B2     # --root folders of benchmarks/bench_inverse.py (or results.jsonl)"""
import math
import sys

import numpy as np
from scipy.stats import beta

from compare import Z90, rows, score

MARGIN = -0.03


def paired_lower(ok_a, ok_b, conf=0.95):
    """One-sided lower confidence bound of mean(ok_b) - mean(ok_a) from the discordant pairs."""
    g = int(np.sum(~ok_a & ok_b))
    lo = int(np.sum(ok_a & ~ok_b))
    d, n = g + lo, ok_a.size
    if d == 0:
        return 0.0, g, lo
    p_l = 0.0 if g == 0 else float(beta.ppf(1 - conf, g, d - g + 1))
    return d * (2 * p_l - 1) / n, g, lo


def main(ra, rb):
    a, b = rows(ra), rows(rb)
    keys = [k for k in sorted(set(a) & set(b)) if abs(a[k]["duration_s"] - b[k]["duration_s"]) < 1e-6]
    print(f"A2: {len(a)} segments >= 3 s, B2: {len(b)}, shared {len(keys)}")
    for name, r in (("A2", a), ("B2", b)):
        s = score(r)
        print(f"  {name}: G(1) within 20 % {100 * s['g1_within20']:.1f} %, class {100 * s['class_right']:.1f} %, "
              f"cover " + " / ".join(f"{100 * c:.1f}" for c in s["cover"])
              + f" %, ln G(1) error mean {s['g1_mean_signed']:+.3f}, w median {s['w_median_signed']:+.3f}")
    ok = True
    for label, f in (("G(1) within 20 %", lambda x: abs(x["lnG_1cpm_err"]) <= math.log(1.2)),
                     ("class right", lambda x: x["class_fit"] == x["class_true"])):
        oa = np.array([f(a[k]) for k in keys])
        ob = np.array([f(b[k]) for k in keys])
        low, g, lo = paired_lower(oa, ob)
        good = low > MARGIN
        ok &= good
        print(f"(i) {label}: A2 {oa.sum()} -> B2 {ob.sum()} of {len(keys)} (gained {g}, lost {lo}); 95 % lower "
              f"bound of the difference {100 * low:+.1f} points (bar > {100 * MARGIN:.0f}): {'holds' if good else 'FAILS'}")
    for q, (e, sd) in zip(("ln Gq(n0)", "w", "ln G(n_best)"),
                          (("lnGq_err", "sd_ln_Gq_n0"), ("w_err", "sd_w"), ("lnG_n_best_err", "sd_ln_G_n_best"))):
        ca = float(np.mean([abs(a[k][e]) <= Z90 * a[k][sd] for k in keys]))
        cb = float(np.mean([abs(b[k][e]) <= Z90 * b[k][sd] for k in keys]))
        out_a = max(0.0, 0.85 - ca, ca - 0.95)
        out_b = max(0.0, 0.85 - cb, cb - 0.95)
        good = out_b == 0.0 or out_b <= out_a + 0.03
        ok &= good
        print(f"(ii) coverage {q}: A2 {100 * ca:.1f} %, B2 {100 * cb:.1f} %: {'holds' if good else 'FAILS'}")
    d = np.array([b[k]["lnG_1cpm_err"] - a[k]["lnG_1cpm_err"] for k in keys])
    good = abs(d.mean()) < 0.02
    ok &= good
    print(f"(iii) paired change of the signed ln G(1) error: mean {d.mean():+.4f} (sd {d.std():.3f}): "
          f"{'holds' if good else 'FAILS'}")
    print("decision2.txt's bar:", "HOLDS -- the change is applied again" if ok else "FAILS -- the change stays out")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
