"""Does the library's own version of the truth's effect, at the truth's value, explain a drive
of the independent truck?

The blind benchmark (`benchmarks/bench_diagnosis.py`) computes the true shrink of a case only
for our own truck, where the Exudyn model with the effect IS the truth. On the independent
truck (`drives/independent_truck.py`) the effect is written independently, so the library's
effect at the truth's value is not the truth -- but whether it explains the drive is the
ceiling of any ranking over the library: where it does not shrink the held-out gap, naming the
effect would take a calibration away from the truth's value, and `unexplained` is an honest
answer for this library.

For every case of a `bench_diagnosis.py --family second` work folder (ROOT/blind.json and the
ROOT/caseNNN-blind datasets it leaves) that carries a library effect, this drives the nominal
model with that effect at the truth's value over the diagnosis's held-out windows and seeds
(`diagnosis.pipeline.heldout_shrink`, the same budget as the blind run) and prints, per road
and effect: the drives, those on which the library effect at the truth's value shrinks the
held-out gap beyond the paired noise (improvement > 0 and paired z > `blind.Z_PAIRED`), and
the verdicts that named it. About 40 s a case on 2 cores.

    python benchmarks/diagnosis_library_oracle.py ROOT [ROOT ...] --out FILE.jsonl

Scoring only: it reads the truth, so run it after the blind run, never before.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from diagnosis.blind import BLIND_SETTINGS, Z_PAIRED  # noqa: E402
from diagnosis.pipeline import heldout_shrink  # noqa: E402


def oracle_row(root: Path, r: dict) -> dict:
    """One case's row: the truth, the verdict, the ranking winner's held-out gap and the held-out
    gaps of the nominal model and of the library effect at the truth's value."""
    summ = json.loads(Path(r["summary"]).read_text()) if r.get("summary") and \
        Path(r["summary"]).exists() else {}
    win = next((e for e in summ.get("ranking", []) if e["effect"] == r.get("ranking_verdict")),
               None)
    t = time.perf_counter()
    hs = heldout_shrink(root / f"case{r['case']:03d}-blind",
                        {r["effect"]: {r["param"]: float(r["value"])}},
                        n_seeds=BLIND_SETTINGS["n_seeds"], n_null=BLIND_SETTINGS["n_null"])
    return dict(root=str(root), case=r["case"], scenario=r.get("scenario"), effect=r["effect"],
                param=r["param"], value=r["value"], verdict=r["verdict"],
                ranking=r.get("ranking_verdict"),
                winner_after=win["heldout_gap_after"] if win else None,
                winner_parameters=win.get("parameters") if win else None,
                helps=bool(hs["improvement"] > 0 and hs["paired_z"] > Z_PAIRED),
                **hs, seconds=round(time.perf_counter() - t, 1))


def table(rows: list[dict]) -> str:
    """Per road and effect: drives, library effect at the truth's value helps, named right."""
    groups = defaultdict(list)
    for r in rows:
        groups[(r["scenario"], r["effect"])].append(r)
    out = ["| road | effect | drives | library effect at the truth's value shrinks the gap "
           "| named right | named right where it shrinks | where it does not |",
           "|---|---|---|---|---|---|---|"]
    for (scen, eff), rs in sorted(groups.items()):
        helps = [r for r in rs if r["helps"]]
        right = [r for r in rs if r["verdict"] == r["effect"]]
        rh = [r for r in helps if r["verdict"] == r["effect"]]
        rn = [r for r in rs if not r["helps"] and r["verdict"] == r["effect"]]
        out.append(f"| {scen} | {eff} | {len(rs)} | {len(helps)} | {len(right)} | "
                   f"{len(rh)} of {len(helps)} | {len(rn)} of {len(rs) - len(helps)} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("roots", nargs="+", help="bench_diagnosis.py --family second work folders")
    ap.add_argument("--out", required=True, help="jsonl file the rows are appended to")
    ap.add_argument("--table-only", action="store_true",
                    help="print the table of the rows already in --out, simulate nothing")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if not a.table_only:
        with out.open("a") as fh:
            for root in map(Path, a.roots):
                for r in json.loads((root / "blind.json").read_text())["results"]:
                    if not r.get("effect") or r["effect"] == "none":
                        continue
                    row = oracle_row(root, r)
                    fh.write(json.dumps(row) + "\n")
                    fh.flush()
                    print(f"{root.name} case {row['case']:3d} {row['scenario']:16s} "
                          f"{row['effect']} {row['value']:.4g}: held-out gap "
                          f"{row['before']:.3f} -> {row['after']:.3f} (paired z "
                          f"{row['paired_z']:.1f}); verdict {row['verdict']}", flush=True)
    rows = [json.loads(line) for line in out.read_text().splitlines() if line.strip()]
    print(table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
