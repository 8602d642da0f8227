"""compare.py for any scenario (decision_independent.txt): SYNTH_SCENARIO, SYNTH_EFFECTS (space separated,
as eroad synth --effect) and REPLICA_EFFECTS (the replica's; default the random family's truth) from the
environment; otherwise compare.py itself.

    SYNTH_SCENARIO=second SYNTH_EFFECTS=leaf_friction=2500 REPLICA_EFFECTS=leaf_friction=2500 \\
        python compare_family.py CACHE OUT.txt SEED [SEED ...]

(The run of 301-310 was made by this file's first version, a copy of compare.py with these three settings
read from the environment; since then it sets them on compare.py, whose first output line now names the
scenario instead of always "random".)"""
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import compare  # noqa: E402

compare.EFFECTS = os.environ.get("REPLICA_EFFECTS", " ".join(compare.EFFECTS)).split()
compare.SCENARIO = os.environ.get("SYNTH_SCENARIO", compare.SCENARIO)
compare.SYNTH_EFFECTS = os.environ.get("SYNTH_EFFECTS", "").split()

if __name__ == "__main__":
    compare.main(sys.argv[1], sys.argv[2], [int(s) for s in sys.argv[3:]])
