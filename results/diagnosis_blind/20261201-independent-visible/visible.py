"""Does the independent truck's data show its library effect (decision.txt)?

    python visible.py WORK OUT.jsonl SET_DIR [SET_DIR ...]

Each library-effect drive of the sets' blind.json is made again (drives/synth.py, its recorded seed and
effect), copied blind, and scored with diagnosis.pipeline.heldout_shrink: the library effect at the
truth's strength in our nominal model, the set's n_seeds / n_null, the reported road band.  One JSON line
per drive (appended, so a stopped run resumes).  Needs the repository on PYTHONPATH.
"""
import json
import sys
import time
from pathlib import Path

import numpy as np


from diagnosis.blind import Z_PAIRED, reported_nmax
from diagnosis.pipeline import heldout_shrink, load_measured
from drives.synth import copy_without_truth, synth_command


def main(work, out, sets):
    work, out = Path(work), Path(out)
    done = set()
    if out.is_file():
        done = {(r["set"], r["case"]) for r in map(json.loads, out.read_text().splitlines())}
    for sd in sets:
        sd = Path(sd)
        blind = json.loads((sd / "blind.json").read_text())
        settings = blind["settings"]
        for r in blind["results"]:
            if r["effect"] == "none" or (str(sd), r["case"]) in done:
                continue
            t0 = time.perf_counter()
            tag = f"{sd.parent.name}-{sd.name}-case{r['case']:03d}"
            ds, bl = work / tag, work / (tag + "-blind")
            synth_command(scenario=r["scenario"], seed=r["seed"], force=True, out=ds,
                          effects=[f"{r['effect']}.{r['param']}={r['value']!r}"])
            if bl.exists():
                import shutil
                shutil.rmtree(bl)
            copy_without_truth(ds, bl)
            summ = json.loads((sd / f"case{r['case']:03d}-summary.json").read_text())
            hs = heldout_shrink(bl, {r["effect"]: {r["param"]: r["value"]}},
                                n_seeds=settings["n_seeds"], n_null=settings["n_null"],
                                nmax=reported_nmax(summ))
            # the regeneration check: the saved diagnosis's nominal gap and noise estimate
            drive, sig = load_measured(bl)
            v = np.asarray(sig.speed, float)
            speed_now = {"p05": float(np.percentile(v, 5)), "mean": float(v.mean()), "max": float(v.max())}
            speed_saved = summ["meta"]["speed_mps"]
            same = all(abs(speed_now[k] - speed_saved[k]) <= 1e-9 * abs(speed_saved[k]) for k in speed_now)
            rec = dict(set=str(sd), case=r["case"], scenario=r["scenario"], effect=r["effect"],
                       value=r["value"], verdict=r["verdict"], confidence=r["confidence"],
                       correct=r["correct"], explained_share=r.get("explained_share"),
                       saved_gap=summ["nominal"]["heldout_gap"], before=hs["before"],
                       after=hs["after"], shrink=hs["shrink_fraction"], paired_z=hs["paired_z"],
                       shows=bool(hs["shrink_fraction"] > 0 and hs["paired_z"] > Z_PAIRED),
                       same_drive=same, speed_saved=speed_saved, speed_now=speed_now,
                       wall_s=round(time.perf_counter() - t0, 1))
            with out.open("a") as f:
                f.write(json.dumps(rec) + "\n")
            print(f"{tag}: {r['effect']} {r['value']:.4g} -> {r['verdict']} ({r['confidence']}); "
                  f"same drive {same}; shrink {rec['shrink']:.2f} "
                  f"z {rec['paired_z']:.1f} shows {rec['shows']}  {rec['wall_s']} s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
