"""One diagnosis of seed 151102 (our truck, leaf friction 3921 N) under cProfile; argument: workers."""
import cProfile, pstats, sys, time
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from drives.synth import copy_without_truth, synth_command
from diagnosis.blind import BLIND_SETTINGS
from diagnosis.pipeline import diagnose
W = Path("/tmp/prof")
W.mkdir(parents=True, exist_ok=True)
ds = W / "151102"
if not (ds / "truth" / "summary.json").is_file():
    synth_command(scenario="null", seed=151102, effects=["leaf_friction.force=3920.558258924793"], out=ds, force=True, duration=None)
    copy_without_truth(ds, W / "151102-blind")
workers = int(sys.argv[1])
t = time.perf_counter()
pr = cProfile.Profile()
pr.enable()
s = diagnose(W / "151102-blind", W / f"run{workers}", workers=workers, force=True, settings=dict(BLIND_SETTINGS), progress=lambda m: print(f"{time.perf_counter()-t:7.1f} {m}", flush=True))
pr.disable()
print("wall", time.perf_counter() - t, s["verdict"], s["verdict_confidence"])
pr.dump_stats(W / f"prof{workers}.out")
pstats.Stats(pr).sort_stats("cumulative").print_stats(45)
