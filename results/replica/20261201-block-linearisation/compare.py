"""One damper for the drive against a damper per 5 s block, on the same drives (decision.txt).

    python compare.py CACHE OUT.txt SEED [SEED ...]

Each `random` drive (made in CACHE as benchmarks/bench_replica.py makes it, if absent) is replicated
twice with the truth's effects (leaf_friction=2000, frame_flex=1): per_block=False (stop 71: one
statistically linearised damper, a warning where a block would need one > 3x stiffer) and
per_block=True.  Per 5 s block: warned by the stop-71 rule or not; ln(replica PSD / truth PSD) at
0.5-2 m (side tracks: the mean of each side's tyre lines, the truth's likewise; mean of both sides); band-passed (0.5-20 m) correlation with the truth."""
import json
import sys
from pathlib import Path

import numpy as np
from scipy.signal import welch

from benchmarks.bench_replica import response_channels, true_tracks
from drives.format import read_drive
from drives.synth import synth_command
from inverse.replica import (FRICTION_BLOCK_S, band_correlation, reconstruct,
                             replica_linear_model)
from vehicles.effects import parse_effects

EFFECTS = ["leaf_friction=2000", "frame_flex=1"]
#: the family the drives are made from and the effects added to its truth (compare_family.py sets them)
SCENARIO = "random"
SYNTH_EFFECTS = []


def blocks_of(d, rep, truth, warn):
    s_t = np.concatenate([[0.0], np.cumsum(0.5 * (d.speed[1:] + d.speed[:-1]) * np.diff(d.time))])
    dx = float(rep.x[1] - rep.x[0])
    nb = int(len(d.time) // round(FRICTION_BLOCK_S * d.sample_rate_hz))
    out = []
    for b in range(nb):
        ta, tb = d.time[0] + b * FRICTION_BLOCK_S, d.time[0] + (b + 1) * FRICTION_BLOCK_S
        xa, xb = np.interp([ta, tb], d.time, s_t)
        sel = (rep.x >= xa) & (rep.x < xb) & rep.covered
        if sel.sum() < 64:
            continue
        lr, cr = [], []
        for s, est in (("L", rep.z_left), ("R", rep.z_right)):
            f, pe = welch(est[sel] - est[sel].mean(), fs=1 / dx, nperseg=min(256, int(sel.sum())))
            _, pt = welch(truth[s][sel] - truth[s][sel].mean(), fs=1 / dx, nperseg=min(256, int(sel.sum())))
            m = (f >= 0.5) & (f <= 2.0)
            lr.append(float(np.log(pe[m].mean() / pt[m].mean())))
            cr.append(band_correlation(est[sel], truth[s][sel], dx))
        out.append({"block": b, "warned": f"{ta:.0f}-{tb:.0f} s" in warn, "ln_psd": float(np.mean(lr)),
                    "corr": float(np.mean(cr))})
    return out


def main(cache, out, seeds):
    cache = Path(cache)
    rows = []
    for seed in seeds:
        ds = cache / f"{SCENARIO}-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=SCENARIO, seed=int(seed), out=ds, force=True, effects=SYNTH_EFFECTS)
        d = read_drive(ds)
        names = response_channels(d.channel_names)
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        res = {}
        for key, pb in (("old", False), ("new", True)):
            lm, _, notes = replica_linear_model(d.vehicle, parse_effects(EFFECTS), ch, d.sample_rate_hz,
                                                t0=float(d.time[0]), per_block=pb)
            warn = next((n for n in notes if n.startswith("WARNING")), "")
            rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
            truth = true_tracks(ds, rep.x, lm.contacts)
            res[key] = (blocks_of(d, rep, truth, warn), notes,
                        float(np.median([np.sqrt(np.mean((rep.fitted[c] - ch[c] + ch[c].mean()) ** 2))
                                         / np.std(ch[c]) for c in names])))
        warned = [b["warned"] for b in res["old"][0]]
        for bo, bn, w in zip(res["old"][0], res["new"][0], warned):
            rows.append({"seed": int(seed), "block": bo["block"], "warned": w,
                         "old_ln_psd": bo["ln_psd"], "new_ln_psd": bn["ln_psd"],
                         "old_corr": bo["corr"], "new_corr": bn["corr"]})
        print(f"seed {seed}: {sum(warned)} of {len(warned)} blocks warned; fit nrmse (median channel) old "
              f"{res['old'][2]:.3f} new {res['new'][2]:.3f}; {res['new'][1][-1] if res['new'][1] else ''}",
              flush=True)
    lines = [f"{SCENARIO} seeds {' '.join(map(str, seeds))}; blocks of {FRICTION_BLOCK_S} s"]
    for lab, sel in (("warned", True), ("unwarned", False)):
        r = [x for x in rows if x["warned"] == sel]
        if not r:
            lines.append(f"{lab} blocks: none")
            continue
        med = {k: float(np.median([x[k] for x in r])) for k in ("old_ln_psd", "new_ln_psd", "old_corr", "new_corr")}
        mabs = {k: float(np.median([abs(x[k]) for x in r])) for k in ("old_ln_psd", "new_ln_psd")}
        lines.append(f"{lab} blocks: {len(r)}; ln PSD ratio 0.5-2 m median old {med['old_ln_psd']:+.2f} new "
                     f"{med['new_ln_psd']:+.2f} (median |.| old {mabs['old_ln_psd']:.2f} new {mabs['new_ln_psd']:.2f}, "
                     f"new 10-90 % {np.percentile([x['new_ln_psd'] for x in r], 10):+.2f}.."
                     f"{np.percentile([x['new_ln_psd'] for x in r], 90):+.2f}); correlation 0.5-20 m median old "
                     f"{med['old_corr']:.3f} new {med['new_corr']:.3f}")
    lines.append("per block (seed/block[W warned]: old -> new ln PSD ratio): " + "; ".join(
        f"{x['seed']}/{x['block']}{'W' if x['warned'] else ''} {x['old_ln_psd']:+.2f}->{x['new_ln_psd']:+.2f}"
        for x in rows))
    Path(out).write_text("\n".join(lines) + "\n")
    Path(out).with_suffix(".jsonl").write_text("".join(json.dumps(x) + "\n" for x in rows))
    print("\n".join(lines[:3]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]])
