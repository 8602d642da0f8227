"""Per library effect, how often the diagnosis named it right on a pool of saved blind sets, and what it
answered when not: python per_effect.py DIR [DIR ...]   (re-decided with the code's rules, as decide.py)

Rows: the truth's effect; columns: our truck (ISO roads + measured road) and the independent truck
(every road); "shows" counts drives whose truth passes the benchmark's noise gate (our truck only: the
independent truck has no run of its own effect to measure it on). A miss lists the verdict given."""
import sys
from collections import defaultdict

from diagnosis.blind import Z_PAIRED, rescore


def shows(r):
    """The score's 'detectable' (diagnosis.blind.score): the truth's own effect at its true value improves
    the held-out gap by more than Z_PAIRED sd of its paired noise."""
    return (r.get("true_paired_z") is not None and (r.get("true_shrink") or 0) > 0
            and r["true_paired_z"] > Z_PAIRED)


def main(dirs):
    table = defaultdict(lambda: {"nominal": [], "second": []})
    for d in dirs:
        for r in rescore(d)["results"]:
            truck = "second" if r.get("family") == "second" else "nominal"
            table[r["effect"]][truck].append(r)
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
            det = [r for r in rs if shows(r)]
            seen = f" ({sum(r['correct'] for r in det)} / {len(det)})" if truck == "nominal" and effect != "none" else ""
            misses = ", ".join(sorted(r["verdict"] for r in rs if not r["correct"]))
            cells += [f"{right} / {len(rs)}{seen}", misses]
        print(f"| {effect} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
