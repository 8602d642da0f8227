"""Re-diagnose the saved drives whose fitted band cut a segment without a spatial step, with
road_fit.NMAX_SPATIAL_STEP on, the blind benchmark's settings (joint band on)."""
import json, sys, time
from diagnosis import road_fit
from diagnosis.blind import BLIND_SETTINGS
from diagnosis.pipeline import diagnose
from diagnosis.verdict import decide
road_fit.NMAX_SPATIAL_STEP = True
CASES = [("frozen69-n18 sensor 6.84", "/work/fresh69/nominal/case018-blind"),
         ("measured64-m12 sensor 6.09", "/work/f64m/measured/case012-blind"),
         ("stop64-n19 sensor 9.02", "/work/f64/nominal/case019-blind"),
         ("tractor409-17 sensor 34.3", "/work/tractor409/tractor/case017-blind")]
for name, blind in CASES:
    t0 = time.time()
    s = diagnose(blind, f"/work/exp69/step/{name.split()[0]}", workers=2, force=True,
                 settings=dict(BLIND_SETTINGS, joint_band=True), progress=lambda m: None)
    d = decide(s)
    hb = s["meta"].get("road_high_band")
    print(name, "->", d["verdict"], d["confidence"], "| nmax", [r["nmax"] for r in s["meta"]["road_segments"]],
          "w", [round(r["w"], 2) for r in s["meta"]["road_segments"]], hb,
          "| value", json.dumps(next((e["parameters"] for e in s["ranking"] if e["effect"] == d["verdict"]), None)),
          f"{time.time() - t0:.0f} s", flush=True)
