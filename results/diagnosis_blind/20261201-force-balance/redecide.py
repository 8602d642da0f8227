"""Development: the saved verdicts of the standard blind sets re-decided with force-balance rules.

    python redecide.py pool_signatures.jsonl [--f-min N] [--rb-min X] [--rules F,R,Fr,Rr]

Rules (each applied after the saved verdict, in this order):
  F   a verdict other than leaf_friction becomes leaf_friction where the balance is available, detects
      friction and reads at least F_MIN;
  Fr  a leaf_friction verdict becomes `unexplained` where the balance is available and does not detect it;
  R   a verdict other than frame_flex becomes frame_flex where the rigid-body residual share exceeds RB_MIN
      (the balance available);
  Rr  a frame_flex verdict becomes `unexplained` where the residual share is at most RB_MIN.
Groups as stop 70's pool counted them: our truck (nominal family) on ISO roads, our truck on the measured
road (measured family), the independent truck on ISO roads and on the measured road; library-effect drives
right when the verdict is the effect, no-effect drives when it is none or unexplained.
"""
import argparse
import json
from collections import Counter


def group(r):
    if r["family"] == "nominal":
        g = "ours ISO"
    elif r["family"] == "measured":
        g = "ours measured"
    else:
        g = "independent measured" if r["scenario"] == "second_measured" else "independent ISO"
    return g + (" no-effect" if r["effect"] == "none" else "")


def right(r, verdict):
    return verdict in ("none", "unexplained") if r["effect"] == "none" else verdict == r["effect"]


def redecide(r, rules, f_min, rb_min):
    v, fb = r["verdict"], r["fb"]
    ok = bool(fb.get("available"))
    why = ""
    if "F" in rules and ok and v != "leaf_friction" and fb["detected"] and fb["force_N"] >= f_min:
        v, why = "leaf_friction", "F"
    elif "Fr" in rules and ok and v == "leaf_friction" and not fb["detected"]:
        v, why = "unexplained", "Fr"
    if "R" in rules and ok and v != "frame_flex" and fb["rigid_body_residual_share"] > rb_min:
        v, why = "frame_flex", "R"
    elif "Rr" in rules and ok and v == "frame_flex" and fb["rigid_body_residual_share"] <= rb_min:
        v, why = "unexplained", "Rr"
    return v, why


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("jsonl")
    ap.add_argument("--f-min", type=float, default=300.0)
    ap.add_argument("--rb-min", type=float, default=0.002)
    ap.add_argument("--rules", default="F,Fr,R,Rr")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args()
    rules = set(a.rules.split(",")) if a.rules else set()
    rows = [json.loads(x) for x in open(a.jsonl)]
    before, after, n = Counter(), Counter(), Counter()
    changes = []
    for r in rows:
        g = group(r)
        n[g] += 1
        before[g] += right(r, r["verdict"])
        v, why = redecide(r, rules, a.f_min, a.rb_min)
        after[g] += right(r, v)
        if v != r["verdict"]:
            changes.append((r["set"], r["family"], r["case"], r["effect"], r["value"], r["verdict"], v, why,
                            round(r["fb"].get("force_N") or 0), round(r["fb"].get("rigid_body_residual_share") or 0, 5)))
    print(f"rules {sorted(rules)}, F_MIN {a.f_min:g} N, RB_MIN {a.rb_min:g}; {len(rows)} drives")
    print("| group | n | right before | right after |")
    print("|---|---|---|---|")
    for g in sorted(n):
        print(f"| {g} | {n[g]} | {before[g]} ({100 * before[g] / n[g]:.1f} %) | {after[g]} ({100 * after[g] / n[g]:.1f} %) |")
    good = sum(right(dict(effect=c[3]), c[6]) and not right(dict(effect=c[3]), c[5]) for c in changes)
    bad = sum(right(dict(effect=c[3]), c[5]) and not right(dict(effect=c[3]), c[6]) for c in changes)
    print(f"changed {len(changes)}: wrong -> right {good}, right -> wrong {bad}")
    if a.list:
        for c in changes:
            print("  ", c)


if __name__ == "__main__":
    main()
