"""Development drives of the force-balance friction estimate (stop 74): what set its floors.

    python development.py /work/ff74 /work/fl74/D > development.txt

/work/ff74: seeds 951-972 made by make_development.py (our truck `null` with one effect each, the
independent truck `second`, both on the measured road); /work/fl74/D: the `random` drives 801-808 (our truck,
leaf friction 2000 N, flexible frame) of the monitor set.
"""
import glob
import sys
import tomllib
from pathlib import Path

from diagnosis.force_balance import leaf_friction
from drives.format import read_drive


def main(*roots):
    print("| drive | truth effects (scenario.toml) | F [N] | sd [N] | bootstrap sd | R^2 | rigid-body residual | detected |")
    print("|---|---|---|---|---|---|---|---|")
    for root in roots:
        for ds in sorted(glob.glob(f"{root}/*-9[5-7]*") + glob.glob(f"{root}/random-80[1-8]")):
            if not Path(ds, "truth", "summary.json").is_file():
                continue
            cfg = tomllib.loads(Path(ds, "truth", "scenario.toml").read_text())
            eff = cfg.get("truth", {}).get("effects") or cfg.get("effects") or {}
            fb = leaf_friction(read_drive(ds))
            print(f"| {Path(ds).name} | {eff} | {fb['force_N']:.0f} | {fb['sd_N']:.0f} | {fb['sd_bootstrap_N']:.0f} | "
                  f"{fb['r2']:.4f} | {fb['rigid_body_residual_share']:.5f} | {fb['detected']} |")


if __name__ == "__main__":
    main(*sys.argv[1:])
