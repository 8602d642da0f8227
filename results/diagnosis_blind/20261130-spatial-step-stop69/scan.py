"""Every saved blind summary (deduplicated) whose fitted road band cut a segment: was there a step in
the spatial spectrum (meta.joint_band.step, max >= band_edge.STEP_MIN = 1.0)? Counts by (step seen,
family, road, truth effect, verdict right), then the drives without a step: python scan.py"""
import glob, collections
from pathlib import Path
from diagnosis.blind import saved_cases, judge
from diagnosis.verdict import decide
roots = sorted({str(Path(p).parent) for p in glob.glob("results/diagnosis_blind/*/**/blind.json", recursive=True)})
seen=set(); rows=[]
for root in roots:
    for r, s in saved_cases(root):
        key=(r.get("seed"), r["effect"], str(r.get("value")), r.get("family"), r.get("scenario"))
        if key in seen: continue
        seen.add(key)
        m = s.get("meta") or {}
        rs = m.get("road_segments") or []
        jb = m.get("joint_band") or {}
        if not rs or not jb or "step" not in jb: continue
        cut = [x["nmax"] < 5 for x in rs]
        if not any(cut): continue
        step = max(v for v in jb["step"].values() if v is not None)
        d = decide(s)
        ok = judge(r, d["verdict"], d["confidence"])["correct"]
        rows.append((step >= 1.0, r.get("family","nominal"), "meas" if "measured" in (r.get("scenario") or "") else "iso", r["effect"], round(r["value"],2) if isinstance(r.get("value"),float) else r.get("value"), sum(cut), len(cut), round(step,2), d["verdict"], ok))
c = collections.Counter((x[0], x[1], x[2], x[3], x[-1]) for x in rows)
for k, n in sorted(c.items(), key=lambda kv: (kv[0][0], kv[0][1], kv[0][2], kv[0][3])): print(k, n)
print()
for x in rows:
    if not x[0]: print(x)
