import glob, os, json
import diagnosis.verdict as V
_orig = V.own_signature_agrees
def _patched(record, z_nominal=None, *a, **k):
    return _orig(record, V.OWN_Z_NOMINAL, *a, **k)
V.own_signature_agrees = _patched
from diagnosis.blind import rescore
roots = sorted({os.path.dirname(p) for p in glob.glob("results/diagnosis_blind/**/blind.json", recursive=True)})
gain = lose = wrong_new = 0; seen=set()
for r in roots:
    try:
        V.OWN_Z_NOMINAL = 2.5; a = rescore(r)["results"]
        V.OWN_Z_NOMINAL = 2.0; b = rescore(r)["results"]
    except Exception as e:
        print("skip", r, type(e).__name__, str(e)[:80]); continue
    for x, y in zip(a, b):
        if (x["verdict"], x["confidence"]) != (y["verdict"], y["confidence"]):
            key=(x.get("seed"), x["effect"], x.get("value"))
            dup = key in seen; seen.add(key)
            print(r.split("diagnosis_blind/")[1], x["case"], x["effect"], x.get("value"), ":", x["verdict"], "->", y["verdict"], y["confidence"], "correct", x["correct"], "->", y["correct"], "(dup)" if dup else "")
            if not dup:
                gain += (not x["correct"]) and y["correct"]; lose += x["correct"] and not y["correct"]
                wrong_new += y["verdict"] not in ("none","unexplained") and y["verdict"] != x["effect"]
print("gain", gain, "lose", lose, "new wrong names", wrong_new)
