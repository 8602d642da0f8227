"""Mean errors of committed independent-truck inversions on measured-profile segments against
synthetic-road segments (segments >= 3 s; run from the repository root)."""
import json

import numpy as np

for fn in ["results/inverse_blind/20261128-boundary-bands/displacement/second/results.jsonl",
           "results/inverse_blind/20261128-correct-on-ambiguous/independent-41-52-axle3/results.jsonl",
           "results/inverse_blind/20261128-acceleration-only-fit/axle3-acc/second/results.jsonl"]:
    rows = {"measured profile": [], "synthetic roads": []}
    for line in open(fn):
        r = json.loads(line)
        for s in r["segments"]:
            if s["duration_s"] < 3 or "lnG_1cpm_err" not in s:
                continue
            key = "measured profile" if r.get("scenario") == "second_measured" else "synthetic roads"
            rows[key].append((s["lnG_1cpm_err"], s["w_err"]))
    for k, v in rows.items():
        v = np.array(v, float)
        print(f"{fn.split('/')[2]}/{fn.split('/')[3]} {k:16s} {len(v):3d} segments: ln G(1) error mean {v[:, 0].mean():+.3f} "
              f"(sd {v[:, 0].std():.3f}), w error mean {v[:, 1].mean():+.3f}")
