"""Bump stops left out against linearised per block (decision_bump_stop.txt).

    python compare_bump_stop.py CACHE OUT.txt SEED [SEED ...]

Each `random` drive with `--effect bump_stop.gap=0.012` (made in CACHE if absent) is replicated twice with
the truth's effects: without the bump stop (leaf_friction=2000, frame_flex=1: what the replica did before,
when bump stops were left out) and with it (bump_stop gap 0.012 m, linearised per block).  Per 5 s block:
the bump stop's equivalent stiffness in the new model, ln(replica PSD / truth PSD) at 0.5-2 m on the side
tracks and the band-passed (0.5-20 m) correlation, scored as compare.py."""
import json
import sys
from pathlib import Path

import numpy as np

from benchmarks.bench_replica import response_channels, true_tracks
from drives.format import read_drive
from drives.synth import synth_command
from inverse.replica import BlockModel, FRICTION_BLOCK_S, reconstruct, replica_linear_model
from vehicles.effects import parse_effects

sys.path.insert(0, str(Path(__file__).parent))
from compare import blocks_of  # noqa: E402  (the same per-block scoring)

BASE = ["leaf_friction=2000", "frame_flex=1"]


def main(cache, out, seeds):
    cache = Path(cache)
    rows = []
    for seed in seeds:
        ds = cache / f"random-bump-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario="random", seed=int(seed), out=ds, force=True, effects=["bump_stop.gap=0.012"])
        d = read_drive(ds)
        names = response_channels(d.channel_names)
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        res = {}
        for key, eff in (("left out", BASE), ("per block", BASE + ["bump_stop.gap=0.012"])):
            lm, left, notes = replica_linear_model(d.vehicle, parse_effects(eff), ch, d.sample_rate_hz,
                                                   t0=float(d.time[0]))
            rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
            res[key] = (blocks_of(d, rep, true_tracks(ds, rep.x, lm.contacts), ""), lm, notes)
        lm = res["per block"][1]
        n = int(round(FRICTION_BLOCK_S * d.sample_rate_hz))
        for bo, bn in zip(res["left out"][0], res["per block"][0]):
            if isinstance(lm, BlockModel):
                i = max(j for j, (k0, _) in enumerate(lm.pieces) if k0 <= bo["block"] * n)
                keq = lm.values["bump_stop"][i]
            else:
                keq = None
            rows.append({"seed": int(seed), "block": bo["block"], "k_eq": keq, "old_ln_psd": bo["ln_psd"],
                         "new_ln_psd": bn["ln_psd"], "old_corr": bo["corr"], "new_corr": bn["corr"]})
        print(f"seed {seed}: {[n_ for n_ in res['per block'][2] if n_.startswith('bump_stop')]}", flush=True)
    lines = [f"random seeds {' '.join(map(str, seeds))} with bump_stop.gap=0.012; blocks of 5 s"]
    for lab, sel in (("k_eq >= 50 kN/m", lambda x: (x["k_eq"] or 0.0) >= 5e4), ("all", lambda x: True)):
        r = [x for x in rows if sel(x)]
        if not r:
            lines.append(f"{lab}: no block")
            continue
        med = {k: float(np.median([x[k] for x in r])) for k in ("old_ln_psd", "new_ln_psd", "old_corr", "new_corr")}
        mabs = {k: float(np.median([abs(x[k]) for x in r])) for k in ("old_ln_psd", "new_ln_psd")}
        lines.append(f"{lab}: {len(r)} blocks; correlation median {med['old_corr']:.3f} -> {med['new_corr']:.3f}; "
                     f"ln PSD 0.5-2 m median {med['old_ln_psd']:+.2f} -> {med['new_ln_psd']:+.2f} (median abs "
                     f"{mabs['old_ln_psd']:.2f} -> {mabs['new_ln_psd']:.2f})")
    lines.append("per block (seed/block k_eq kN/m: corr old -> new, ln PSD old -> new): " + "; ".join(
        f"{x['seed']}/{x['block']} {0 if x['k_eq'] is None else x['k_eq'] / 1e3:.0f}: {x['old_corr']:.3f}->"
        f"{x['new_corr']:.3f}, {x['old_ln_psd']:+.2f}->{x['new_ln_psd']:+.2f}" for x in rows))
    Path(out).write_text("\n".join(lines) + "\n")
    Path(out).with_suffix(".jsonl").write_text("".join(json.dumps(x) + "\n" for x in rows))
    print("\n".join(lines[:3]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]])
