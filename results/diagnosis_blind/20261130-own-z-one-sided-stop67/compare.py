"""Old (own signature at z 2.0) against new (one-sided 5 %, z 1.645, diagnosis.verdict.OWN_Z_NOMINAL
since stop 67) verdicts on the same drives:  python compare.py DIR [DIR ...]

Each DIR holds blind.json and caseNNN-summary.json (a committed set) or caseNNN-run/summary.json
(a bench work folder).  Prints each changed drive and a line per folder and for all."""
import json
import sys
from pathlib import Path

from diagnosis import verdict
from diagnosis.verdict import decide

OLD_Z = 2.0


def summary_of(d: Path, case: int):
    for p in (d / f"case{case:03d}-summary.json", d / f"case{case:03d}-run" / "summary.json"):
        if p.is_file():
            return json.load(open(p))
    return None


def both(s):
    new = decide(s)
    orig = verdict.own_signature_agrees
    verdict.own_signature_agrees = lambda rec, z_nominal=OLD_Z, **k: orig(rec, z_nominal=z_nominal, **k)
    try:
        old = decide(s)
    finally:
        verdict.own_signature_agrees = orig
    return old, new


def right(dd, truth):
    return dd["verdict"] == truth if truth != "none" else dd["verdict"] in ("none", "unexplained")


def main(dirs):
    keys = ("damper", "effect", "null")
    total = {k: [0, 0, 0] for k in keys} | {"wrong": [0, 0], "clear_wrong": [0, 0], "changed": 0, "drives": 0}
    for d in map(Path, dirs):
        b = json.load(open(d / "blind.json"))
        c = {k: [0, 0, 0] for k in keys} | {"wrong": [0, 0], "clear_wrong": [0, 0], "changed": 0, "drives": 0}
        for r in b["results"]:
            s = summary_of(d, r["case"])
            if s is None:
                continue
            truth = r["effect"]
            old, new = both(s)
            c["drives"] += 1
            key = "null" if truth == "none" else "effect"
            for i, dd in ((0, old), (1, new)):
                c[key][i] += right(dd, truth)
                if truth == "damper_asymmetry":
                    c["damper"][i] += right(dd, truth)
                wrong = dd["verdict"] not in ("none", "unexplained") and dd["verdict"] != truth
                c["wrong"][i] += wrong
                c["clear_wrong"][i] += wrong and dd["confidence"] == "clear"
            c[key][2] += 1
            c["damper"][2] += truth == "damper_asymmetry"
            if (old["verdict"], old["confidence"]) != (new["verdict"], new["confidence"]):
                c["changed"] += 1
                print(f"  {d} case {r['case']} truth {truth} {r.get('value')}: {old['verdict']} "
                      f"({old['confidence']}) -> {new['verdict']} ({new['confidence']})")
        print(f"{d}: drives {c['drives']}; library effects right {c['effect'][0]} -> {c['effect'][1]} "
              f"of {c['effect'][2]} (damper_asymmetry {c['damper'][0]} -> {c['damper'][1]} of "
              f"{c['damper'][2]}); no effect none/unexplained {c['null'][0]} -> {c['null'][1]} of "
              f"{c['null'][2]}; wrong names {c['wrong'][0]} -> {c['wrong'][1]} (clear "
              f"{c['clear_wrong'][0]} -> {c['clear_wrong'][1]}); changed {c['changed']}")
        for k in total:
            if isinstance(total[k], list):
                total[k] = [a + b for a, b in zip(total[k], c[k])]
            else:
                total[k] += c[k]
    print(f"ALL: drives {total['drives']}; library effects right {total['effect'][0]} -> "
          f"{total['effect'][1]} of {total['effect'][2]} (damper_asymmetry {total['damper'][0]} -> "
          f"{total['damper'][1]} of {total['damper'][2]}); no effect {total['null'][0]} -> "
          f"{total['null'][1]} of {total['null'][2]}; wrong names {total['wrong'][0]} -> "
          f"{total['wrong'][1]} (clear {total['clear_wrong'][0]} -> {total['clear_wrong'][1]}); "
          f"changed {total['changed']}")


if __name__ == "__main__":
    main(sys.argv[1:])
