"""Blind datasets of a scenario, as benchmarks/bench_inverse.py makes them (stop 52):
PYTHONPATH=. python results/inverse_blind/20261129-calibration-seeds/make_drives.py ROOT SCENARIO SEEDS

ROOT/SCENARIO-SEED (with truth) and ROOT/blind-SCENARIO-SEED (without) per comma-separated seed, made with the
bench's own calls (drives.synth.synth_command with the scenario's default effects, copy_without_truth)."""
import sys, time
from pathlib import Path
from drives.synth import copy_without_truth, synth_command
root = Path(sys.argv[1]); scen = sys.argv[2]
for s in [int(x) for x in sys.argv[3].split(',')]:
    t = time.perf_counter()
    ds = root / f"{scen}-{s}"
    if not (ds / "truth" / "summary.json").is_file():
        synth_command(scenario=scen, seed=s, out=ds, force=True, default_effects=True)
    b = root / f"blind-{scen}-{s}"
    if not b.exists():
        copy_without_truth(ds, b)
    print(s, round(time.perf_counter() - t, 1), flush=True)
