"""The replica's friction warning on drives its threshold was not set on (decision_blind.txt).

    python blind_check.py CACHE OUT.txt SEED [SEED ...]

Each `random` drive (made in CACHE as benchmarks/bench_replica.py makes it) replicated with the truth's
effects (leaf_friction=2000, frame_flex=1); per 5 s block: warned or not (inverse.replica's own rule),
ln(replica PSD / truth PSD) at 0.5-2 m on both sides' front tyre lines."""
import sys
from pathlib import Path

import numpy as np
from scipy.signal import welch

from benchmarks.bench_replica import response_channels, true_tracks
from drives.format import read_drive
from drives.synth import synth_command
from inverse.replica import FRICTION_BLOCK_RATIO, FRICTION_BLOCK_S, reconstruct, replica_linear_model
from vehicles.effects import parse_effects


def main(cache, out, seeds):
    cache = Path(cache)
    rows = []
    for seed in seeds:
        ds = cache / f"random-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario="random", seed=int(seed), out=ds, force=True)
        d = read_drive(ds)
        names = response_channels(d.channel_names)
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        lm, _, notes = replica_linear_model(d.vehicle, parse_effects(["leaf_friction=2000", "frame_flex=1"]), ch,
                                            d.sample_rate_hz, t0=float(d.time[0]))
        warn = next((n for n in notes if n.startswith("WARNING")), "")
        rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
        truth = true_tracks(ds, rep.x, lm.contacts)
        # the road position of axle 1 at each sample: the replica's x of time t
        s_t = np.concatenate([[0.0], np.cumsum(0.5 * (d.speed[1:] + d.speed[:-1]) * np.diff(d.time))])
        dx = float(rep.x[1] - rep.x[0])
        nb = int(len(d.time) // round(FRICTION_BLOCK_S * d.sample_rate_hz))
        for b in range(nb):
            ta, tb = d.time[0] + b * FRICTION_BLOCK_S, d.time[0] + (b + 1) * FRICTION_BLOCK_S
            xa, xb = np.interp([ta, tb], d.time, s_t)      # x is measured from axle 1 at the first sample
            sel = (rep.x >= xa) & (rep.x < xb) & rep.covered
            if sel.sum() < 64:
                continue
            warned = f"{ta:.0f}-{tb:.0f} s" in warn
            lr = []
            for s, est in (("L", rep.z_left), ("R", rep.z_right)):
                f, pe = welch(est[sel] - est[sel].mean(), fs=1 / dx, nperseg=min(256, int(sel.sum())))
                _, pt = welch(truth[s][sel] - truth[s][sel].mean(), fs=1 / dx, nperseg=min(256, int(sel.sum())))
                m = (f >= 0.5) & (f <= 2.0)
                lr.append(float(np.log(pe[m].mean() / pt[m].mean())))
            rows.append((seed, b, warned, float(np.mean(lr))))
        print(f"seed {seed}: {sum(r[2] for r in rows if r[0] == seed)} of "
              f"{sum(1 for r in rows if r[0] == seed)} blocks warned", flush=True)
    w = [r[3] for r in rows if r[2]]
    u = [r[3] for r in rows if not r[2]]
    lines = [f"FRICTION_BLOCK_RATIO {FRICTION_BLOCK_RATIO}, blocks of {FRICTION_BLOCK_S} s; random seeds {' '.join(seeds)}",
             f"warned blocks: {len(w)}; ln PSD ratio 0.5-2 m (mean of both sides) median "
             f"{np.median(w) if w else float('nan'):+.2f}, range {min(w) if w else float('nan'):+.2f}..{max(w) if w else float('nan'):+.2f}",
             f"unwarned blocks: {len(u)}; median {np.median(u):+.2f}, 10-90 % {np.percentile(u, 10):+.2f}..{np.percentile(u, 90):+.2f}",
             "per block (seed, block, warned, ln ratio): " + "; ".join(f"{r[0]}/{r[1]}{'W' if r[2] else ''} {r[3]:+.2f}" for r in rows)]
    Path(out).write_text("\n".join(lines) + "\n")
    print("\n".join(lines[:3]))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
