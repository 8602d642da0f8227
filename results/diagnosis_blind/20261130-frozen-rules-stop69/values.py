"""Values within x1.5 of the truth among right names, and diagnosis times, per folder:
python values.py DIR [DIR ...]   (re-decided with the code's rules, as pool.py)"""
import json
import sys
from pathlib import Path

from diagnosis.blind import rescore

for d in sys.argv[1:]:
    rs = rescore(d)["results"]
    right = [r for r in rs if r["correct"] and r["effect"] != "none" and r.get("param_ratio") is not None]
    ok = sum(1 / 1.5 <= r["param_ratio"] <= 1.5 for r in right)
    t = [r.get("diagnose_s") for r in json.loads((Path(d) / "blind.json").read_text())["results"]]
    t = [x for x in t if x is not None]
    print(f"{d}: values within x1.5 {ok}/{len(right)}" + (f"; diagnosis time mean {sum(t) / len(t):.1f} s, max {max(t):.1f} s" if t else ""))
