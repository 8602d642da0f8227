"""Option 1 of the stated test, checked on its mechanism first: two measured-profile friction
drives of the independent truck diagnosed with settings["band_refit"] (diagnosis.pipeline.refit_band).

Usage: python refit_check.py WORK SEED:SCENARIO:EFFECT:PARAM=VALUE ...   (one JSON line per drive)
"""
import json, sys, time
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from diagnosis.blind import BLIND_SETTINGS
from diagnosis.pipeline import diagnose
from drives.synth import copy_without_truth, synth_command
work = Path(sys.argv[1])
work.mkdir(parents=True, exist_ok=True)
for spec in sys.argv[2:]:
    seed, scen, eff, pv = spec.split(":")
    ds, blind = work / f"{seed}", work / f"{seed}-blind"
    if not (ds / "truth" / "summary.json").is_file():
        synth_command(scenario=scen, seed=int(seed), effects=[f"{eff}.{pv}"], out=ds, force=True, duration=None)
    if not blind.exists():
        copy_without_truth(ds, blind)
    t = time.perf_counter()
    summ = diagnose(blind, work / f"{seed}-run", workers=2, force=True,
                    settings=dict(BLIND_SETTINGS, band_refit=True), progress=print)
    br = summ["meta"]["band_refit"]
    print(json.dumps({"seed": seed, "truth": pv, "verdict": summ["verdict"], "conf": summ["verdict_confidence"],
                      "rank": [(e["effect"], e["parameters"], round(e["shrink_fraction"], 3)) for e in summ["ranking"][:3]],
                      "refit": {k: v for k, v in (br or {}).items() if k != "first_pass"},
                      "first": None if not br or not br.get("first_pass") else
                      (br["first_pass"]["verdict"], br["first_pass"]["verdict_confidence"]),
                      "wall": round(time.perf_counter() - t, 1)}), flush=True)
