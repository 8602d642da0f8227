"""Re-decide saved blind summaries with the damper asymmetry's own-signature threshold at 2.5 and at
2.0 (diagnosis.verdict.OWN_Z_NOMINAL; the search side, OWN_Z_SIDE, is not involved: verdict only):
python redecide_own_z.py [ROOT ...]  (default: every results/diagnosis_blind/**/blind.json; run from
the repository root).  Prints each drive whose verdict or confidence changes and the counts (a drive
seen in several saved sets is counted once)."""
import glob
import os
import sys

sys.path.insert(0, ".")
import diagnosis.verdict as V  # noqa: E402
from diagnosis.blind import rescore  # noqa: E402

_orig = V.own_signature_agrees


def _patched(record, z_nominal=None, *a, **k):      # the threshold of the moment, not the default
    return _orig(record, V.OWN_Z_NOMINAL, *a, **k)


V.own_signature_agrees = _patched
roots = sys.argv[1:] or sorted({os.path.dirname(p) for p in
                                glob.glob("results/diagnosis_blind/**/blind.json", recursive=True)})
gain = lose = wrong_new = n = 0
seen = set()
for r in roots:
    V.OWN_Z_NOMINAL = 2.5
    a = rescore(r)["results"]
    V.OWN_Z_NOMINAL = 2.0
    b = rescore(r)["results"]
    n += len(a)
    for x, y in zip(a, b):
        if (x["verdict"], x["confidence"]) == (y["verdict"], y["confidence"]):
            continue
        key = (x.get("seed"), x["effect"], x.get("value"))
        dup = key in seen
        seen.add(key)
        print(r, x["case"], x["effect"], x.get("value"), ":", f"{x['verdict']}({x['confidence']})", "->",
              f"{y['verdict']}({y['confidence']})", "right", x["correct"], "->", y["correct"], "(seen before)" if dup else "")
        if not dup:
            gain += (not x["correct"]) and y["correct"]
            lose += x["correct"] and not y["correct"]
            wrong_new += y["verdict"] not in ("none", "unexplained") and y["verdict"] != x["effect"]
print(f"{n} drives re-decided; right answers gained {gain}, lost {lose}; new wrong names {wrong_new}")
