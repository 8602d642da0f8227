"""The force balance on every drive of the saved standard blind sets (development for a verdict rule).

    python pool_signatures.py --tmp /work/pool74 --out pool_signatures.jsonl SET_DIR ...

Each case of SET_DIR/{nominal,second,measured}/blind.json is made again exactly as diagnosis.blind.run_case
made it (scenario, the seed actually used, the effect at its value; `eroad synth` is deterministic), the
force balance is read (diagnosis.force_balance.leaf_friction), the dataset deleted; one JSON line per case with
the saved verdict, confidence, ranking shares and the balance's numbers.
"""
import argparse
import json
import shutil
import sys
from pathlib import Path

from diagnosis.force_balance import leaf_friction
from drives.format import read_drive
from drives.synth import synth_command


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--tmp", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("sets", nargs="+")
    a = ap.parse_args(argv)
    tmp = Path(a.tmp)
    tmp.mkdir(parents=True, exist_ok=True)
    done = set()
    outp = Path(a.out)
    if outp.is_file():
        done = {(r["set"], r["family"], r["case"]) for r in map(json.loads, outp.read_text().splitlines())}
    for sdir in a.sets:
        for fam in ("nominal", "second", "measured"):
            bj = Path(sdir) / fam / "blind.json"
            if not bj.is_file():
                continue
            for r in json.loads(bj.read_text())["results"]:
                key = (Path(sdir).name, fam, r["case"])
                if key in done:
                    continue
                eff = [] if r["effect"] == "none" else [f"{r['effect']}.{r['param']}={r['value']!r}"]
                ds = tmp / "ds"
                synth_command(scenario=r.get("scenario", "null"), seed=r["seed"], effects=eff, out=ds,
                              vehicle=r.get("vehicle"), force=True)
                fb = leaf_friction(read_drive(ds))
                shutil.rmtree(ds, ignore_errors=True)
                summ = {}
                sp = Path(sdir) / fam / f"case{r['case']:03d}-summary.json"
                if sp.is_file():
                    summ = json.loads(sp.read_text())
                rank = {e["effect"]: {k: e.get(k) for k in ("shrink_fraction", "accepted", "parameters")}
                        for e in summ.get("ranking", [])}
                row = {"set": key[0], "family": fam, "case": r["case"], "seed": r["seed"], "scenario": r.get("scenario"),
                       "effect": r["effect"], "value": r["value"], "verdict": r["verdict"],
                       "confidence": r["confidence"], "correct": r["correct"], "oracle": r.get("oracle"),
                       "explained_share": r.get("explained_share"),
                       "edge": (summ.get("verdict_detail") or {}).get("edge"), "ranking": rank,
                       "fb": {k: fb.get(k) for k in ("available", "force_N", "sd_N", "interval_90_N", "detected", "r2",
                                                      "rigid_body_residual_share", "frame_rigid", "reason")}}
                with outp.open("a") as f:
                    f.write(json.dumps(row) + "\n")
                print(key, r["effect"], r["value"], r["verdict"], f"F {fb.get('force_N', float('nan')):.0f}",
                      f"rb {fb.get('rigid_body_residual_share', float('nan')):.5f}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
