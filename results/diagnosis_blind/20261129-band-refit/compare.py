"""Score the stated test (decision.txt) from the fresh set's blind.json files: the first pass
(today's rules, same drives, same seeds) against the final verdict with the band refitted.

Usage: python compare.py W/second W/nominal
"""
import json
import sys
from pathlib import Path


def rows(folder):
    return json.loads((Path(folder) / "blind.json").read_text())["results"]


def count(rs, which):
    """(right names on library cases, library cases, right on no-effect drives, no-effect drives,
    wrong names, clear wrong, values within x1.5 of right names, right names with a value)."""
    def get(r):
        if which == "final":
            return r["verdict"], r["confidence"], r["correct"], r["confident_wrong"], r.get("param_ratio")
        b = r.get("band_refit")
        if b is None:        # refit not made (no gap): the first pass is the final one
            return r["verdict"], r["confidence"], r["correct"], r["confident_wrong"], r.get("param_ratio")
        return b["verdict"], b["confidence"], b["correct"], b["confident_wrong"], b.get("param_ratio")
    lib = [r for r in rs if r["effect"] != "none"]
    nul = [r for r in rs if r["effect"] == "none"]
    c_lib = sum(get(r)[2] for r in lib)
    c_nul = sum(get(r)[2] for r in nul)
    wrong = sum(1 for r in rs if get(r)[0] not in ("none", "unexplained") and get(r)[0] != r["effect"])
    clear = sum(get(r)[3] for r in rs)
    vals = [get(r)[4] for r in lib if get(r)[2] and get(r)[4] is not None]
    within = sum(1 for v in vals if 1 / 1.5 <= v <= 1.5)
    return c_lib, len(lib), c_nul, len(nul), wrong, clear, within, len(vals)


def main(folders):
    for f in folders:
        rs = rows(f)
        print(f"{f}: {len(rs)} cases")
        for which in ("first pass", "final"):
            c = count(rs, "final" if which == "final" else "first")
            print(f"  {which:10s}: library effects named right {c[0]}/{c[1]}, no-effect right {c[2]}/{c[3]}, "
                  f"wrong names {c[4]}, clear wrong {c[5]}, values within x1.5 {c[6]}/{c[7]}")
        ch = [r for r in rs if (r.get("band_refit") or {}).get("changed")]
        print(f"  band moved on {len(ch)} drive(s): " + "; ".join(
            f"case {r['case']} ({r['effect']}, refit with {r['band_refit']['effect']}): "
            f"{r['band_refit']['verdict']} -> {r['verdict']}" for r in ch))
        t_final = [r["diagnose_s"] for r in rs]
        # the first pass's time: the diagnosis without the refit step (and without a second pass)
        t_first = [r["diagnose_s"] - ((r.get("band_refit") or {}).get("time_s") or 0.0) for r in rs]
        for lab, t in (("first pass", t_first), ("final", t_final)):
            print(f"  time {lab}: mean {sum(t) / len(t):.1f} s, max {max(t):.1f} s, over 120 s: "
                  f"{sum(x > 120 for x in t)}")


if __name__ == "__main__":
    main(sys.argv[1:])
