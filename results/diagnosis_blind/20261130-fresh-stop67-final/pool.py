"""Pooled counts over saved blind sets, each summary re-decided with the code's verdict rules:
python pool.py DIR [DIR ...]

Per family (nominal, second, with "/measured" for drives over the measured road profile): library
effects named right, the same on drives whose truth passes the noise gate (the truth's own effect at its
true value improves the held-out gap by more than 2 sd of its paired noise), no-effect drives answered
none/unexplained, wrong names and clear wrong names."""
import json
import sys
from pathlib import Path

from diagnosis.redecide import right, summary_of, wrong_name
from diagnosis.verdict import decide


def main(dirs):
    agg = {}
    for d in map(Path, dirs):
        for r in json.loads((d / "blind.json").read_text())["results"]:
            s = summary_of(d, r["case"])
            if s is None:
                continue
            key = r.get("family", "nominal") + ("/measured" if "measured" in r.get("scenario", "") else "")
            v = decide(s)
            a = agg.setdefault(key, {"effects": [0, 0], "gate": [0, 0], "no_effect": [0, 0],
                                     "wrong": 0, "clear_wrong": 0})
            t = r["effect"]
            if t == "none":
                a["no_effect"][0] += right(v, t)
                a["no_effect"][1] += 1
            else:
                a["effects"][0] += right(v, t)
                a["effects"][1] += 1
                if (r.get("true_paired_z") or 0) > 2 and (r.get("true_shrink") or 0) > 0:
                    a["gate"][0] += right(v, t)
                    a["gate"][1] += 1
            a["wrong"] += wrong_name(v, t)
            a["clear_wrong"] += wrong_name(v, t) and v["confidence"] == "clear"
    for k, a in sorted(agg.items()):
        print(k, a)


if __name__ == "__main__":
    main(sys.argv[1:])
