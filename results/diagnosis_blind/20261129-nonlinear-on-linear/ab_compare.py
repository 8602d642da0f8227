"""python ab_compare.py OUT > ab.txt: each A/B diagnosis in OUT/<family>_caseNNN/summary.json
against the same drive's summary in the stop-58 fresh set (results/diagnosis_blind/
20261129-linear-fresh-40/<family>/caseNNN-summary.json): verdict, confidence, time, and the
first-ranked model (effect, value, held-out gap after, before)."""
import glob
import json
import os
import sys

OLD = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "20261129-linear-fresh-40")
for d in sorted(glob.glob(os.path.join(sys.argv[1], "*_case*", "summary.json"))):
    tag = os.path.basename(os.path.dirname(d))
    fam, case = tag.split("_")
    new = json.load(open(d))
    old = json.load(open(os.path.join(OLD, fam, f"{case}-summary.json")))

    def top(s):
        r = s.get("ranking") or []
        if not r:
            return None
        return (r[0]["effect"], {k: round(v, 4) for k, v in list(r[0]["parameters"].values())[0].items()},
                round(r[0]["heldout_gap_after"], 4), round(r[0]["heldout_gap_before"], 4))
    same = (new["verdict"], new["verdict_confidence"]) == (old["verdict"], old["verdict_confidence"])
    print(f"{fam:8s} {case} {'SAME' if same else 'DIFF'} old {old['verdict']}({old['verdict_confidence']}) "
          f"new {new['verdict']}({new['verdict_confidence']})  time {old['meta']['timing']['total_s']:.0f} -> "
          f"{new['meta']['timing']['total_s']:.0f} s  jb {(old['meta'].get('joint_band') or {}).get('chosen')}/"
          f"{(new['meta'].get('joint_band') or {}).get('chosen')}")
    print("    old", top(old))
    print("    new", top(new))
