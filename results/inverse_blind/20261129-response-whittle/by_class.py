"""Errors of the response-Whittle fit by true class (python by_class.py RECORDS.jsonl; run from this folder)."""
import json
import sys

import numpy as np

rows = [json.loads(line) for line in open(sys.argv[1])]
for c in "ABCDE":
    r = [x for x in rows if x["class_true"] == c]
    ew = np.array([x["w_fit"] - x["w_true"] for x in r])
    e1 = np.array([x["lnG1_err"] for x in r])
    ok = np.mean([x["class_fit"] == x["class_true"] for x in r])
    print(f"{c} {len(r):3d} segments: w error mean {ew.mean():+.3f} sd {ew.std():.3f} | ln G(1) error mean "
          f"{e1.mean():+.3f} sd {e1.std():.3f} | within 20 % {100 * np.mean(np.abs(e1) <= np.log(1.2)):.0f} % | class right {100 * ok:.0f} %")
