"""The per-block friction model's cost against one damper, on the same drive (stop 72).

    python speed.py CACHE SEED DURATION_S

A `random` drive of DURATION_S (our truck, leaf friction 2000 N + flexible frame), replicated with the
truth's effects twice in this process: one damper (per_block=False) and per block; prints wall times, CG
iterations and their ratio (the same machine, the same run)."""
import sys
import time
from pathlib import Path

from drives.format import read_drive
from drives.synth import synth_command
from inverse.replica import reconstruct, replica_linear_model, response_channels
from vehicles.effects import parse_effects


def main(cache, seed, duration):
    ds = Path(cache) / f"random-{seed}-{duration:.0f}s"
    if not (ds / "truth" / "summary.json").is_file():
        synth_command(scenario="random", seed=seed, duration=duration, out=ds, force=True)
    d = read_drive(ds)
    names = response_channels(d.channel_names)
    ch = {c: d.channels[c].to_numpy(float) for c in names}
    out = {}
    for key, pb in (("one damper", False), ("per block", True)):
        t0 = time.perf_counter()
        lm, _, notes = replica_linear_model(d.vehicle, parse_effects(["leaf_friction=2000", "frame_flex=1"]), ch,
                                            d.sample_rate_hz, per_block=pb)
        t1 = time.perf_counter()
        rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
        t2 = time.perf_counter()
        out[key] = (t1 - t0, t2 - t1, rep.info["cg_iterations"], len(getattr(lm, "pieces", [0])))
        print(f"{key}: model {t1 - t0:.1f} s, reconstruct {t2 - t1:.1f} s, CG {rep.info['cg_iterations']} it, "
              f"{out[key][3]} piece(s); {notes[-1][:90]}", flush=True)
    a, b = out["one damper"], out["per block"]
    print(f"{d.duration_s:.0f} s drive, {len(names)} channels: per block / one damper = "
          f"{(b[0] + b[1]) / (a[0] + a[1]):.2f} in wall time, {b[1] / b[2] / (a[1] / a[2]):.2f} per CG iteration")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), float(sys.argv[3]))
