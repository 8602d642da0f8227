"""Pair the two solvers' closed-loop inversions segment by segment (segments >= 3 s):
python ab_compare.py LIN/results.jsonl EXU/results.jsonl"""
import json
import sys

import numpy as np


def load(p):
    return {r["seed"]: r for r in map(json.loads, open(p))}


a, b = load(sys.argv[1]), load(sys.argv[2])
seeds = sorted(set(a) & set(b))
rows = []
for s in seeds:
    for x, y in zip(a[s]["segments"], b[s]["segments"]):
        if x["duration_s"] >= 3.0:
            rows.append((s, x, y))
g1a = np.array([x["lnG_1cpm_err"] for _, x, _ in rows])
g1b = np.array([y["lnG_1cpm_err"] for _, _, y in rows])
cla = [x["class_fit"] == x["class_true"] for _, x, _ in rows]
clb = [y["class_fit"] == y["class_true"] for _, _, y in rows]
same = sum(x["class_fit"] == y["class_fit"] for _, x, y in rows)
d = np.abs(g1a - g1b)
print(f"{len(seeds)} drives ({sys.argv[1]} against {sys.argv[2]}), {len(rows)} segments >= 3 s")
print(f"solvers: {a[seeds[0]].get('solver')} / {b[seeds[0]].get('solver')}; "
      f"corrected inversions {sum(bool((a[s].get('closed_loop') or {}).get('corrected')) for s in seeds)}"
      f" / {sum(bool((b[s].get('closed_loop') or {}).get('corrected')) for s in seeds)}")
print(f"same class: {same}/{len(rows)} = {same / len(rows):.1%}")
print(f"class right: {sum(cla)} / {sum(clb)}")
print(f"G(1 cycle/m) within 20 %: {int(np.sum(np.abs(g1a) <= np.log(1.2)))} / {int(np.sum(np.abs(g1b) <= np.log(1.2)))}")
print(f"|ln G(1)_first - ln G(1)_second|: median {np.median(d):.4f}, 90 % {np.quantile(d, 0.9):.4f}, max {d.max():.4f}")
print(f"wall per drive (bench): median {np.median([a[s]['wall_s'] for s in seeds]):.1f} / "
      f"{np.median([b[s]['wall_s'] for s in seeds]):.1f} s")
