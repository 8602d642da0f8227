"""The friction's damper: Gaussian form against the measured velocity distribution (decision_empirical.txt).

    python compare_empirical.py CACHE OUT.txt SCENARIO SYNTH_EFFECT REPLICA_EFFECTS SEED [SEED ...]
    e.g. ... random - "leaf_friction=2000 frame_flex=1" 121 ... 130
         ... second leaf_friction=2500 leaf_friction=2500 311 ... 320

Each drive (made in CACHE as compare.py makes it; SYNTH_EFFECT '-' for none) replicated per block twice:
inverse.replica.FRICTION_EMPIRICAL False (c = F sqrt(2/pi) / RMS) and True (c = F mean|v| / mean(v^2)).
Per 5 s block ln(replica PSD / truth PSD) at 0.5-2 m and the band-passed correlation, scored as compare.py."""
import json
import sys
from pathlib import Path

import numpy as np

import inverse.replica as replica
from benchmarks.bench_replica import response_channels, true_tracks
from drives.format import read_drive
from drives.synth import synth_command
from vehicles.effects import parse_effects

sys.path.insert(0, str(Path(__file__).parent))
from compare import blocks_of  # noqa: E402  (the same per-block scoring)


def main(cache, out, scen, synth_effect, effects, seeds):
    cache = Path(cache)
    rows = []
    for seed in seeds:
        ds = cache / f"{scen}-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=scen, seed=int(seed), out=ds, force=True,
                          effects=[] if synth_effect == "-" else [synth_effect])
        d = read_drive(ds)
        names = response_channels(d.channel_names)
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        res = {}
        for flag in (False, True):
            replica.FRICTION_EMPIRICAL = flag
            lm, _, notes = replica.replica_linear_model(d.vehicle, parse_effects(effects.split()), ch, d.sample_rate_hz)
            rep = replica.reconstruct(lm, d.time, d.speed, ch, lines="tyre")
            res[flag] = (blocks_of(d, rep, true_tracks(ds, rep.x, lm.contacts), ""), notes)
        replica.FRICTION_EMPIRICAL = False
        for bo, bn in zip(res[False][0], res[True][0]):
            rows.append({"seed": int(seed), "block": bo["block"], "old_ln_psd": bo["ln_psd"], "new_ln_psd": bn["ln_psd"],
                         "old_corr": bo["corr"], "new_corr": bn["corr"]})
        print(f"seed {seed}: {res[True][1][-1]}", flush=True)
    med = {k: float(np.median([x[k] for x in rows])) for k in ("old_ln_psd", "new_ln_psd", "old_corr", "new_corr")}
    mabs = {k: float(np.median([abs(x[k]) for x in rows])) for k in ("old_ln_psd", "new_ln_psd")}
    lines = [f"{scen} seeds {' '.join(map(str, seeds))} (synth {synth_effect}, replica {effects}); blocks of 5 s",
             f"all {len(rows)} blocks: ln PSD ratio 0.5-2 m median Gaussian form {med['old_ln_psd']:+.2f}, empirical "
             f"{med['new_ln_psd']:+.2f} (median abs {mabs['old_ln_psd']:.3f} -> {mabs['new_ln_psd']:.3f}); correlation "
             f"median {med['old_corr']:.4f} -> {med['new_corr']:.4f}",
             "per block (seed/block: Gaussian -> empirical): " + "; ".join(
                 f"{x['seed']}/{x['block']} {x['old_ln_psd']:+.2f}->{x['new_ln_psd']:+.2f}" for x in rows)]
    Path(out).write_text("\n".join(lines) + "\n")
    Path(out).with_suffix(".jsonl").write_text("".join(json.dumps(x) + "\n" for x in rows))
    print("\n".join(lines[:2]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5], [int(s) for s in sys.argv[6:]])
