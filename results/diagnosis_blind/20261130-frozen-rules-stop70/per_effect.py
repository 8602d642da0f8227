"""Per library effect, how often the diagnosis named it right on a pool of saved blind sets, and what it
answered when not: python per_effect.py DIR [DIR ...]   (re-decided with the code's rules, as decide.py)

Rows: the truth's effect; columns: our truck (ISO roads + measured road) and the independent truck
(every road); "shows" counts drives whose truth passes the benchmark's noise gate (our truck only: the
independent truck has no run of its own effect to measure it on). A miss lists the verdict given."""
import sys
from collections import defaultdict

from decide import truth_model   # this folder's decide.py: our truck or the independent one
from diagnosis.blind import detectable, rescore


def main(dirs):
    table = defaultdict(lambda: {"nominal": [], "second": []})
    for d in dirs:
        for r in rescore(d)["results"]:
            table[r["effect"]][truth_model(r)].append(r)
    print("| truth | our truck: right / drives (the truth shows: right / drives) | misses answered | "
          "independent truck: right / drives | misses answered |")
    print("|---|---|---|---|---|")
    for effect in sorted(table, key=lambda e: (e == "none", e)):
        cells = []
        for truck in ("nominal", "second"):
            rs = table[effect][truck]
            if not rs:
                cells += ["-", ""]
                continue
            right = sum(r["correct"] for r in rs)
            det = [r for r in rs if detectable(r)]
            seen = f" ({sum(r['correct'] for r in det)} / {len(det)})" if truck == "nominal" and effect != "none" else ""
            misses = ", ".join(sorted(r["verdict"] for r in rs if not r["correct"]))
            cells += [f"{right} / {len(rs)}{seen}", misses]
        print(f"| {effect} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
