"""python score_pair.py W ONE > pair.txt: the fresh set's drives diagnosed with n_calib_seeds = 2
(W/<family>/blind.json and its case summaries, bench_diagnosis.py) against the same blind datasets
diagnosed with n_calib_seeds = 1 (ONE/<family>_caseNNN/summary.json, ab_run.py), both judged by
diagnosis.blind.judge / param_ratio against the same truth; per family and per drive."""
import json
import os
import sys

import numpy as np

from diagnosis.blind import judge, param_ratio

W, ONE = sys.argv[1], sys.argv[2]


def entry_of(summ):
    return next((e for e in summ.get("ranking", []) if e["effect"] == summ["verdict"]), None)


def row(case, summ):
    j = judge(case, summ["verdict"], summ.get("verdict_confidence"))
    pr = param_ratio(case, entry_of(summ))
    return dict(verdict=summ["verdict"], conf=summ.get("verdict_confidence"), ratio=pr,
                time=float(summ["meta"]["timing"]["total_s"]), **j)


tot = {"two": 0, "one": 0}
for fam in ("second", "nominal"):
    res = json.load(open(os.path.join(W, fam, "blind.json")))["results"]
    rows = {"two": [], "one": []}
    lines = []
    for c in res:
        f2 = os.path.join(W, fam, f"case{c['case']:03d}-summary.json")        # an archived set
        if not os.path.exists(f2):
            f2 = os.path.join(W, fam, f"case{c['case']:03d}-run", "summary.json")   # the work folder
        two = json.load(open(f2))
        f1 = os.path.join(ONE, f"{fam}_case{c['case']:03d}", "summary.json")
        if not os.path.exists(f1):
            continue
        one = json.load(open(f1))
        a, b = row(c, two), row(c, one)
        rows["two"].append((c, a))
        rows["one"].append((c, b))
        fmt = lambda r: (f"{r['verdict']}({r['conf']})" + (f" x{r['ratio']:.2f}" if r["ratio"] is not None else "")
                         + f" {'OK' if r['correct'] else '--'} {r['time']:.0f}s")
        mark = "" if a["correct"] == b["correct"] else ("  <- 2 seeds right" if a["correct"] else "  <- 1 seed right")
        lines.append(f"  case {c['case']:2d} {c['scenario']:16s} {c['effect']:>16s} "
                     f"{'' if c['value'] is None else format(c['value'], '.4g'):>9s}: 2 seeds {fmt(a)} | 1 seed {fmt(b)}{mark}")
    print(f"{fam}: {len(rows['two'])} drives")
    for k, name in (("two", "n_calib_seeds 2"), ("one", "n_calib_seeds 1")):
        rs = rows[k]
        eff = [r for c, r in rs if c["effect"] != "none"]
        non = [r for c, r in rs if c["effect"] == "none"]
        wrong = sum(1 for c, r in rs if r["verdict"] not in ("none", "unexplained") and r["verdict"] != c["effect"])
        vals = [r for r in eff if r["correct"] and r["ratio"] is not None]
        within = sum(1 for r in vals if 1 / 1.5 <= r["ratio"] <= 1.5)
        t = np.array([r["time"] for c, r in rs])
        right = sum(r["correct"] for r in eff) + sum(r["correct"] for r in non)
        tot[k] += right
        print(f"  {name}: library effects named right {sum(r['correct'] for r in eff)}/{len(eff)}, "
              f"none/unexplained {sum(r['correct'] for r in non)}/{len(non)}, wrong names {wrong} "
              f"(clear {sum(r['confident_wrong'] for c, r in rs)}), values within x1.5 {within}/{len(vals)}, "
              f"time mean {t.mean():.1f} s, max {t.max():.1f} s, over 120 s {int((t > 120).sum())}")
    print("\n".join(lines))
print(f"right answers over both families: n_calib_seeds 2 {tot['two']}, n_calib_seeds 1 {tot['one']}")
