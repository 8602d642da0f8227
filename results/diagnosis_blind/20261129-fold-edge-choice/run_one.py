"""One blind diagnosis as bench_diagnosis runs it (BLIND_SETTINGS, joint band), with the
fold-edge choice on or off: python run_one.py DATASET OUT on|off
Prints RESULT: verdict, confidence, the winner's value and folds, the fold choice, time."""
import json
import sys
import time

from diagnosis.blind import BLIND_SETTINGS
from diagnosis.pipeline import diagnose

src, out, flag = sys.argv[1], sys.argv[2], sys.argv[3]
t0 = time.time()
s = diagnose(src, out, workers=2, force=True,
             settings=dict(BLIND_SETTINGS, joint_band=True, fold_edge_choice=flag == "on"),
             progress=lambda m: None)
rd = s.get("ranking_decision") or {}
win = next((e for e in s["ranking"] if e["effect"] == rd.get("verdict")), None)
print("RESULT", flag, src, s["verdict"], s["verdict_confidence"],
      json.dumps(win and {"effect": win["effect"], "value": win["parameters"],
                          "folds": win.get("parameters_per_fold"), "choice": win.get("fold_choice")}),
      f"{time.time() - t0:.1f} s", flush=True)
