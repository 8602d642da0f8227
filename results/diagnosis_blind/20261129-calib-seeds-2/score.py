import json, glob, os, sys
"""python score.py OUT > score.txt: each diagnosis in OUT/<family>_caseNNN/summary.json (ab_run.py with
{"n_calib_seeds": 2}) against the truth and the stop-58 summary of the same drive."""
root = sys.argv[1]
OLD = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "20261129-linear-fresh-40")
truth = {}
for fam in ("nominal", "second"):
    for c in json.load(open(f"{OLD}/{fam}/blind.json"))["results"]:
        truth[(fam, "case%03d" % c["case"])] = c
for d in sorted(glob.glob(f"{root}/*_case*/summary.json")):
    fam, case = os.path.basename(os.path.dirname(d)).split("_")
    s = json.load(open(d)); t = truth[(fam, case)]
    old = json.load(open(f"{OLD}/{fam}/{case}-summary.json"))
    def val(summ):
        r = [e for e in summ.get("ranking") or [] if e["effect"] == summ["verdict"]]
        if not r or t["param"] is None: return None
        eff, par = t["effect"], t["param"]
        v = r[0]["parameters"][eff].get(par) if eff in r[0]["parameters"] else None
        return None if v is None else round(v / t["value"], 3)
    right = lambda v: v == t["effect"] or (t["effect"] == "none" and v in ("none", "unexplained"))
    print(f"{fam:8s} {case} truth {t['effect']}={t['value']}  old {old['verdict']}({old['verdict_confidence']}) x{val(old)} {'OK' if right(old['verdict']) else '--'}  new {s['verdict']}({s['verdict_confidence']}) x{val(s)} {'OK' if right(s['verdict']) else '--'}  t {old['meta']['timing']['total_s']:.0f}->{s['meta']['timing']['total_s']:.0f}")
