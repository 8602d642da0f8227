"""Score the stated test (decision.txt) from the fresh set's blind.json files: the first pass
(today's rules, same drives, same seeds) against the final verdict with the joint road band.

Usage: python compare.py W/second W/nominal
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from diagnosis.blind import two_rule_lines  # noqa: E402


def rows(folder):
    return json.loads((Path(folder) / "blind.json").read_text())["results"]


def first(r):
    """(verdict, confidence, value ratio) of the first pass (today's rules)."""
    f = r.get("joint_band") or r
    return f["verdict"], f["confidence"], f.get("param_ratio")


def _x(v):
    return "-" if v is None else f"x{v:.2f}"


def main(folders):
    for f in folders:
        rs = rows(f)
        print(f"{f}: {len(rs)} cases")
        score, times = two_rule_lines(rs, "joint_band")
        print("\n".join(score))
        for r in rs:
            j = r.get("joint_band") or {}
            if j.get("gap_cut") is None:
                continue
            v, c, p = first(r)
            print(f"  case {r['case']:2d} {r['scenario']:15s} {r['effect']:15s} trial cut {j['trial_cut']:g}: "
                  f"gap fitted {j['gap_fitted']:.3g} cut {j['gap_cut']:.3g} ({j['gap_cut'] / j['gap_fitted']:.2f}) "
                  f"-> {j['chosen']}; first pass {v} ({c}, value {_x(p)}) -> final {r['verdict']} "
                  f"({r['confidence']}, value {_x(r.get('param_ratio'))})")
        print(f"  trial cut on {sum((r.get('joint_band') or {}).get('trial_cut') is not None for r in rs)} "
              f"drive(s) with a gap; second pass on "
              f"{sum((r.get('joint_band') or {}).get('gap_cut') is not None for r in rs)}")
        print("\n".join(times))


if __name__ == "__main__":
    main(sys.argv[1:])
