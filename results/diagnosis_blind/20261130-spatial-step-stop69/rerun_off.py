"""The fresh test of NMAX_SPATIAL_STEP: every drive of the seed-659 sets whose summary says the rule fired
(meta.road_high_band.unstepped) re-diagnosed from its blind copy with the rule OFF, same settings;
verdicts paired (the drives where it did not fire are the same either way)."""
import json, sys
from pathlib import Path
from diagnosis import road_fit
from diagnosis.blind import BLIND_SETTINGS, judge, wrong_name
from diagnosis.pipeline import diagnose
from diagnosis.verdict import decide

road_fit.NMAX_SPATIAL_STEP = False
tot = {"fired": 0, "right_on": 0, "right_off": 0, "wrong_on": 0, "wrong_off": 0, "right_to_wrong": 0, "drives": 0}
for root in sys.argv[1:]:
    root = Path(root)
    for r in json.loads((root / "blind.json").read_text())["results"]:
        tot["drives"] += 1
        k = f"case{r['case']:03d}"
        s_on = json.loads((root / f"{k}-run" / "summary.json").read_text())
        hb = (s_on.get("meta") or {}).get("road_high_band") or {}
        if not hb.get("unstepped"):
            continue
        tot["fired"] += 1
        s_off = diagnose(root / f"{k}-blind", root / f"{k}-off", workers=2, force=True,
                         settings=dict(BLIND_SETTINGS, joint_band=True), progress=lambda m: None)
        a, b = decide(s_off), decide(s_on)
        ja, jb = judge(r, a["verdict"], a["confidence"]), judge(r, b["verdict"], b["confidence"])
        tot["right_off"] += ja["correct"]; tot["right_on"] += jb["correct"]
        tot["wrong_off"] += wrong_name(r, a["verdict"]); tot["wrong_on"] += wrong_name(r, b["verdict"])
        tot["right_to_wrong"] += ja["correct"] and not jb["correct"]
        print(f"{root.name} {k} truth {r['effect']} {r.get('value')}: off {a['verdict']} ({a['confidence']}) -> "
              f"on {b['verdict']} ({b['confidence']}); nmax off {[x['nmax'] for x in s_off['meta']['road_segments']]}", flush=True)
print(tot)
