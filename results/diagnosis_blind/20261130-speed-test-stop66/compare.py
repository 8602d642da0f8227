"""Old (no speed test) against new verdicts on the same drives:
python compare.py [--rule replace|powered] DIR [DIR ...]

Each DIR holds blind.json and caseNNN-summary.json (a committed set) or caseNNN-run/summary.json
(a bench work folder).  "old" re-decides each summary with its `signature_hz` record removed; "new"
re-decides it with the speed test under --rule (diagnosis.verdict.HZ_RULES; default the code's
HZ_RULE; the fresh test of this folder ran "replace")."""
import json
import sys
from pathlib import Path

from diagnosis import verdict
from diagnosis.verdict import decide


def summary_of(d: Path, case: int):
    for p in (d / f"case{case:03d}-summary.json", d / f"case{case:03d}-run" / "summary.json"):
        if p.is_file():
            return json.load(open(p))
    return None


def main(dirs):
    tot = {}
    for d in map(Path, dirs):
        b = json.load(open(d / "blind.json"))
        rows = []
        for r in b["results"]:
            s = summary_of(d, r["case"])
            if s is None:
                continue
            old = decide({k: v for k, v in s.items() if k != "signature_hz"})
            new = decide(s)
            truth = r["effect"]
            hz = s.get("signature_hz")
            rows.append((r, truth, old, new, hz))
        fam = d.name
        c = {"sensor": [0, 0, 0], "tyre_enveloping": [0, 0, 0], "effect": [0, 0, 0], "null": [0, 0, 0],
             "wrong": [0, 0], "clear_wrong": [0, 0], "changed": 0, "hz_records": 0, "max_s": 0.0}
        for r, truth, old, new, hz in rows:
            c["hz_records"] += hz is not None
            c["max_s"] = max(c["max_s"], r.get("diagnose_s") or 0.0)
            for i, dd in ((0, old), (1, new)):
                right = dd["verdict"] == truth if truth != "none" else dd["verdict"] in ("none", "unexplained")
                named_wrong = dd["verdict"] not in ("none", "unexplained") and dd["verdict"] != truth
                key = "null" if truth == "none" else "effect"
                c[key][i] += right
                if truth in ("sensor", "tyre_enveloping"):
                    c[truth][i] += right
                c["wrong"][i] += named_wrong
                c["clear_wrong"][i] += named_wrong and dd["confidence"] == "clear"
            for key in ("null", "effect", "sensor", "tyre_enveloping"):
                if (key == "null" and truth == "none") or (key == "effect" and truth != "none") or key == truth:
                    c[key][2] += 1
            if (old["verdict"], old["confidence"]) != (new["verdict"], new["confidence"]):
                c["changed"] += 1
                print(f"  {fam} case {r['case']} truth {truth} {r.get('value')}: {old['verdict']} "
                      f"({old['confidence']}) -> {new['verdict']} ({new['confidence']})")
        print(f"{fam}: library effects right old {c['effect'][0]}/{c['effect'][2]} new {c['effect'][1]}/{c['effect'][2]}"
              f" (sensor {c['sensor'][0]}->{c['sensor'][1]} of {c['sensor'][2]}, tyre {c['tyre_enveloping'][0]}->"
              f"{c['tyre_enveloping'][1]} of {c['tyre_enveloping'][2]}); no effect none/unexplained old "
              f"{c['null'][0]}/{c['null'][2]} new {c['null'][1]}/{c['null'][2]}; wrong names old {c['wrong'][0]} new "
              f"{c['wrong'][1]} (clear {c['clear_wrong'][0]} / {c['clear_wrong'][1]}); changed {c['changed']}; "
              f"speed-test records {c['hz_records']}/{len(rows)}; max diagnosis {c['max_s']:.1f} s")
        tot[fam] = c
    return tot


if __name__ == "__main__":
    args = sys.argv[1:]
    if args and args[0] == "--rule":
        verdict.HZ_RULE = args[1]
        args = args[2:]
    print(f"rule: {verdict.HZ_RULE}")
    main(args)
