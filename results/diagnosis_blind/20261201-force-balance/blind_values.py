"""Test 2 of decision.txt: the force-balance friction on fresh drives of both truck models.

    python blind_values.py --out /work/fb74/V > blind_values.txt

Independent truck (`second`, drives/independent_truck.py: not our model) seeds 981-992 with leaf friction
drawn log-uniform 500-6000 N (diagnosis.blind.STRENGTHS), 993-996 without; our truck (`null`) seeds 1001-1012
with the same draw, 1013-1016 without.  The truth's value is read from truth/scenario.toml, for scoring only.
"""
import argparse
import math
import tomllib
from pathlib import Path

import numpy as np

from diagnosis.blind import STRENGTHS
from diagnosis.force_balance import leaf_friction
from drives.format import read_drive
from drives.synth import synth_command


def draw(seed: int) -> float:
    _, lo, hi, _, _ = STRENGTHS["leaf_friction"]
    u = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(74,))).uniform()
    return float(math.exp(math.log(lo) + u * (math.log(hi) - math.log(lo))))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    root = Path(a.out)
    plan = ([("second", s, draw(s)) for s in range(981, 993)] + [("second", s, 0.0) for s in range(993, 997)]
            + [("null", s, draw(s)) for s in range(1001, 1013)] + [("null", s, 0.0) for s in range(1013, 1017)])
    print("| truck | seed | truth F [N] | estimate [N] | ratio | 90 % interval [N] | covered | detected | R^2 | rigid-body residual |")
    print("|---|---|---|---|---|---|---|---|---|---|", flush=True)
    rows = []
    for scen, seed, force in plan:
        ds = root / f"{scen}-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=scen, seed=seed, effects=(f"leaf_friction.force={force:.1f}",) if force else (),
                          out=ds, force=True)
        eff = tomllib.loads((ds / "truth" / "scenario.toml").read_text())["truth"].get("effects") or {}
        truth = float(eff.get("leaf_friction", {}).get("force", 0.0))
        fb = leaf_friction(read_drive(ds))
        lo, hi = fb["interval_90_N"]
        cov = lo <= truth <= hi
        ratio = fb["force_N"] / truth if truth else float("nan")
        rows.append((scen, truth, ratio, cov, fb["detected"]))
        print(f"| {'independent' if scen == 'second' else 'ours'} | {seed} | {truth:.0f} | {fb['force_N']:.0f} | "
              f"{ratio:.3f} | {lo:.0f}-{hi:.0f} | {cov} | {fb['detected']} | {fb['r2']:.4f} | "
              f"{fb['rigid_body_residual_share']:.5f} |", flush=True)
    print()
    for scen, name in (("second", "independent truck"), ("null", "our truck")):
        fr = [r for r in rows if r[0] == scen and r[1] > 0]
        no = [r for r in rows if r[0] == scen and r[1] == 0]
        ln = np.log([r[2] for r in fr])
        print(f"{name}: friction drives {len(fr)}: ratio median {np.median([r[2] for r in fr]):.3f}, "
              f"rms ln error {np.sqrt(np.mean(ln ** 2)):.3f}, within x1.2 {sum(abs(x) <= math.log(1.2) for x in ln)}/{len(fr)}, "
              f"covered {sum(r[3] for r in fr)}/{len(fr)}, detected {sum(r[4] for r in fr)}/{len(fr)}; "
              f"without friction: covered (0 N) {sum(r[3] for r in no)}/{len(no)}, detected {sum(r[4] for r in no)}/{len(no)}")


if __name__ == "__main__":
    main()
