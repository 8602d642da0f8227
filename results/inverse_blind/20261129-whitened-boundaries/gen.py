import sys
from pathlib import Path
from drives.synth import synth_command
from eroad.errors import EroadInputError
a, b, root = int(sys.argv[1]), int(sys.argv[2]), Path(sys.argv[3])
for s in range(a, b):
    ds = root / f"null-{s}"
    if (ds / "truth" / "truth.json").is_file(): continue
    try:
        synth_command(scenario="null", seed=s, out=ds, force=True)
    except EroadInputError as e:
        print(s, "skipped", e)
