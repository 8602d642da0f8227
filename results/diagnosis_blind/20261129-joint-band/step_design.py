"""The step statistic of diagnosis.band_edge on the design drives (measurement only, no simulation).

Usage: python step_design.py WORK SEED:SCENARIO:EFFECT[:PARAM=VALUE] ...
Each drive is made with drives.synth.synth_command into WORK/<seed> where it is not there already;
prints one line per drive: truth, the statistic at each trial cut, the trial cut (or -).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))


def main(argv):
    from diagnosis.band_edge import trial_cut
    from diagnosis.pipeline import NMAX_GRID, ROAD_NMAX, load_measured
    from drives.synth import synth_command

    work = Path(argv[0])
    for spec in argv[1:]:
        parts = spec.split(":")
        seed, scen, eff = int(parts[0]), parts[1], parts[2]
        ds = work / str(seed)
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=scen, seed=seed, effects=[f"{eff}.{parts[3]}"] if len(parts) > 3 else [],
                          out=ds, force=True, duration=None)
        _, sig = load_measured(ds)
        tc = trial_cut(sig, NMAX_GRID, ROAD_NMAX)
        val = parts[3] if len(parts) > 3 else ""
        print(f"{seed:>7d} {scen:15s} {eff:15s} {val[:18]:18s} "
              + " ".join(f"{g:g}:{'  -  ' if v is None else format(v, '5.2f')}" for g, v in tc["step"].items())
              + f"  -> trial cut {'-' if tc['cut'] is None else format(tc['cut'], 'g')}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
