"""Score the stated test (decision.txt) from the fresh set's blind.json files: the first pass
(today's rules, same drives, same seeds) against the final verdict with the band refitted.

Usage: python compare.py W/second W/nominal
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))


def rows(folder):
    return json.loads((Path(folder) / "blind.json").read_text())["results"]


def main(folders):
    from diagnosis.blind import two_rule_lines

    for f in folders:
        rs = rows(f)
        print(f"{f}: {len(rs)} cases")
        score, times = two_rule_lines(rs, "band_refit")
        print("\n".join(score))
        ch = [r for r in rs if (r.get("band_refit") or {}).get("changed")]
        print(f"  band moved on {len(ch)} drive(s): " + "; ".join(
            f"case {r['case']} ({r['effect']}, refit with {r['band_refit']['effect']}): "
            f"{r['band_refit']['verdict']} -> {r['verdict']}" for r in ch))
        print("\n".join(times))


if __name__ == "__main__":
    main(sys.argv[1:])
