"""The whole joint-band rule on design drives: diagnose(settings=BLIND_SETTINGS + joint_band) on each
WORK/<seed> dataset (made by step_design.py), blind copy WORK/<seed>-blind, run WORK/runs/<seed>.

Usage: python design_runs.py WORK SEED ...   (one line per drive: final verdict, confidence, first two
ranked models, meta.joint_band without the other pass, the other pass's verdict, wall s); the lines of
design_runs.txt were made by this with WORK = /tmp/jb (the same code as a scratch copy, one.py).
"""
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))


def main(argv):
    from diagnosis.blind import BLIND_SETTINGS
    from diagnosis.pipeline import diagnose
    from drives.synth import copy_without_truth

    work = Path(argv[0])
    for s in argv[1:]:
        ds, blind = work / s, work / f"{s}-blind"
        if not blind.exists():
            copy_without_truth(ds, blind)
        t = time.perf_counter()
        summ = diagnose(blind, work / "runs" / s, workers=2, force=True,
                        settings=dict(BLIND_SETTINGS, joint_band=True), progress=lambda m: None)
        jb = summ["meta"]["joint_band"] or {}
        print(s, summ["verdict"], summ["verdict_confidence"],
              [(e["effect"], e["parameters"]) for e in summ["ranking"][:2]],
              json.dumps({k: v for k, v in jb.items() if k not in ("first_pass", "cut_pass")}),
              jb.get("first_pass", {}).get("verdict"), jb.get("cut_pass", {}).get("verdict"),
              round(time.perf_counter() - t, 1), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
