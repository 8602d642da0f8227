"""Summarise visible.py's records:  python summarise.py OUT.jsonl"""
import json
import sys
from collections import defaultdict


def main(path):
    rs = [json.loads(l) for l in open(path)]
    bad = [r for r in rs if not r["same_drive"]]
    rs = [r for r in rs if r["same_drive"]]
    print(f"{len(rs)} drives regenerated identically (speed profile), {len(bad)} not "
          + ("(" + ", ".join(f"{r['set']} case {r['case']}" for r in bad) + ")" if bad else ""))
    by = defaultdict(list)
    for r in rs:
        by[r["effect"]].append(r)
    print("| effect | drives | the data show it (library effect at the true value passes the gate) "
          "| named right: all / where shown | misses: value, answer, shrink, paired z |")
    print("|---|---|---|---|---|")
    for eff, g in sorted(by.items()):
        shown = [r for r in g if r["shows"]]
        miss = [r for r in g if not r["correct"]]
        print(f"| {eff} | {len(g)} | {len(shown)} | {sum(r['correct'] for r in g)} / "
              f"{sum(r['correct'] for r in shown)} of {len(shown)} | "
              + "; ".join(f"{r['value']:.0f} {r['verdict']} ({'shown' if r['shows'] else 'not shown'}, "
                          f"{r['shrink']:.2f}, {r['paired_z']:.1f})" for r in miss) + " |")
    iso = [r for r in rs if r["scenario"] == "second"]
    for name, g in (("ISO roads", iso), ("every road", rs)):
        shown = [r for r in g if r["shows"]]
        print(f"{name}: named right {sum(r['correct'] for r in g)} of {len(g)}; "
              f"the data show {len(shown)}, of them named right {sum(r['correct'] for r in shown)}")
    lo = sorted((r for r in rs if r["effect"] == "leaf_friction"), key=lambda r: r["value"])
    print("leaf frictions by value (N: shrink, paired z, answer):")
    print("  " + "; ".join(f"{r['value']:.0f}: {r['shrink']:.2f}, {r['paired_z']:.1f}, "
                           f"{'right' if r['correct'] else r['verdict']}" for r in lo))


if __name__ == "__main__":
    main(sys.argv[1])
