"""Acceleration-only drives: friction left out against friction from the accelerations (decision_accelerations.txt).

    python compare_accelerations.py CACHE OUT.txt SEED [SEED ...]

Each `second` drive (the independent truck, `--effect leaf_friction=2500`, made in CACHE if absent) with its
susp_disp columns dropped is replicated twice: the linear model without leaf friction (what a drive without
displacements got before) and with leaf_friction=2500 linearised per block from the accelerations.  Per 5 s
block: ln(replica PSD / truth PSD) at 0.5-2 m on the side tracks (mean of both sides) and the band-passed
(0.5-20 m) correlation, scored as compare.py."""
import json
import sys
from pathlib import Path

import numpy as np

from benchmarks.bench_replica import response_channels, true_tracks
from drives.format import read_drive
from drives.synth import synth_command
from inverse.replica import reconstruct, replica_linear_model
from vehicles.effects import parse_effects

sys.path.insert(0, str(Path(__file__).parent))
from compare import blocks_of  # noqa: E402  (the same per-block scoring)


def main(cache, out, seeds):
    cache = Path(cache)
    rows = []
    for seed in seeds:
        ds = cache / f"second-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario="second", seed=int(seed), out=ds, force=True, effects=["leaf_friction=2500"])
        d = read_drive(ds)
        names = [c for c in response_channels(d.channel_names) if not c.startswith("susp_disp_")]
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        res = {}
        for key, eff in (("left out", None), ("from accelerations", ["leaf_friction=2500"])):
            lm, left, notes = replica_linear_model(d.vehicle, parse_effects(eff) if eff else None, ch,
                                                   d.sample_rate_hz, t0=float(d.time[0]))
            rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
            res[key] = (blocks_of(d, rep, true_tracks(ds, rep.x, lm.contacts), ""), notes)
        for bo, bn in zip(res["left out"][0], res["from accelerations"][0]):
            rows.append({"seed": int(seed), "block": bo["block"], "old_ln_psd": bo["ln_psd"], "new_ln_psd": bn["ln_psd"],
                         "old_corr": bo["corr"], "new_corr": bn["corr"]})
        print(f"seed {seed}: {res['from accelerations'][1][-1] if res['from accelerations'][1] else ''}", flush=True)
    med = {k: float(np.median([x[k] for x in rows])) for k in ("old_ln_psd", "new_ln_psd", "old_corr", "new_corr")}
    mabs = {k: float(np.median([abs(x[k]) for x in rows])) for k in ("old_ln_psd", "new_ln_psd")}
    lines = [f"second seeds {' '.join(map(str, seeds))} (leaf friction 2500 N), susp_disp dropped; blocks of 5 s",
             f"all {len(rows)} blocks: ln PSD ratio 0.5-2 m median friction left out {med['old_ln_psd']:+.2f}, from "
             f"accelerations {med['new_ln_psd']:+.2f} (median abs {mabs['old_ln_psd']:.2f} -> {mabs['new_ln_psd']:.2f}); "
             f"correlation median {med['old_corr']:.3f} -> {med['new_corr']:.3f}",
             "per block (seed/block: left out -> from accelerations): " + "; ".join(
                 f"{x['seed']}/{x['block']} {x['old_ln_psd']:+.2f}->{x['new_ln_psd']:+.2f}" for x in rows)]
    Path(out).write_text("\n".join(lines) + "\n")
    Path(out).with_suffix(".jsonl").write_text("".join(json.dumps(x) + "\n" for x in rows))
    print("\n".join(lines[:2]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]])
