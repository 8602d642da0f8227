"""The pool tasks of one diagnosis, timed (run profile_run.py first: it makes the drive)."""
import sys, time, os, json
from pathlib import Path
sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
import diagnosis.which as wh
_orig = wh._score_task
def timed(args):
    t = time.time()
    r = _orig(args)
    with open("/tmp/prof/tasks.jsonl", "a") as f:
        f.write(json.dumps({"cands": [c.name for c in args[1]], "t0": t, "t1": time.time(), "pid": os.getpid()}) + "\n")
    return r
wh._score_task = timed
_orig_s = wh._sims_task
def timed_s(args):
    t = time.time()
    r = _orig_s(args)
    with open("/tmp/prof/tasks.jsonl", "a") as f:
        f.write(json.dumps({"cands": ["nominal-sims"], "t0": t, "t1": time.time(), "pid": os.getpid()}) + "\n")
    return r
wh._sims_task = timed_s
from diagnosis.blind import BLIND_SETTINGS
from diagnosis.pipeline import diagnose
t = time.time()
print("start", t)
s = diagnose(Path("/tmp/prof/151102-blind"), Path("/tmp/prof/runT"), workers=2, force=True, settings=dict(BLIND_SETTINGS), progress=lambda m: print(f"{time.time()-t:7.1f} {m}", flush=True))
print("wall", time.time() - t, s["verdict"])
