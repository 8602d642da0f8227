"""Score bench_inverse roots of the independent truck on ISO roads (scenario 'second'), segments >= 3 s,
and pair two roots on the same seeds:   python score.py ROOT_NEW ROOT_OLD   (or their results.jsonl:
python score.py exact-results.jsonl before-results.jsonl)"""
import json
import math
import sys
from pathlib import Path

import numpy as np

Z90, L20 = 1.645, math.log(1.2)


def rows(root):
    out = {}
    path = Path(root) if str(root).endswith(".jsonl") else Path(root, "results.jsonl")
    for line in path.read_text().splitlines():
        r = json.loads(line)
        if r.get("scenario") != "second":
            continue
        for i, s in enumerate(r["segments"]):
            if s["duration_s"] >= 3.0:
                out[(r["seed"], i)] = s
    return out


def line(name, rs):
    s = list(rs.values())
    g = np.array([x["lnG_1cpm_err"] for x in s])
    cov = [np.mean([abs(x[e]) <= Z90 * x[sd] for x in s]) for e, sd in
           (("lnGq_err", "sd_ln_Gq_n0"), ("w_err", "sd_w"), ("lnG_n_best_err", "sd_ln_G_n_best"))]
    print(f"{name}: {len(s)} ISO-road segments >= 3 s; G(1 cycle/m) within 20 % {100 * np.mean(np.abs(g) <= L20):.0f} %, "
          f"class right {100 * np.mean([x['class_fit'] == x['class_true'] for x in s]):.0f} %, ln G(1) error mean "
          f"{g.mean():+.3f} sd {g.std():.3f}; 90 % cover " + " / ".join(f"{100 * c:.0f}" for c in cov) + " %")


def main(new, old):
    a, b = rows(old), rows(new)
    line("before (grid mix)", a)
    line("exact lines", b)
    keys = [k for k in sorted(set(a) & set(b)) if abs(a[k]["duration_s"] - b[k]["duration_s"]) < 1e-6]
    d = np.array([b[k]["lnG_1cpm_err"] - a[k]["lnG_1cpm_err"] for k in keys])
    oa = np.array([abs(a[k]["lnG_1cpm_err"]) <= L20 for k in keys])
    ob = np.array([abs(b[k]["lnG_1cpm_err"]) <= L20 for k in keys])
    print(f"paired on {len(keys)} shared segments: G(1) within 20 % gained {int(np.sum(~oa & ob))}, lost "
          f"{int(np.sum(oa & ~ob))}; ln G(1) error moved by mean {d.mean():+.3f} (sd {d.std():.3f})")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
