"""The friction family with the shipped closed loop and today's constants, all five sets of 20 drives
(python results/inverse_blind/20261128-effect-profile/friction_sets.py, from the repository root).

Truth: our own Exudyn truck with leaf friction 2000 N and a flexible frame (a gap our code made).
Seeds 1-40 composed from saved loops as ../20261128-closest-vehicle-effect/score.py does; 41-60, 61-80
and 81-100 are fresh closed-loop roots (81-100 made at stop 51, the shipped loop's records of the
profile's third set). Segments >= 3 s; intervals with each drive's channel set's constants."""
import sys
from contextlib import redirect_stdout
from io import StringIO
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-closest-vehicle-effect'))
from score import fresh, line, saved  # noqa: E402

ROOTS = {'seeds 41-60': HERE.parent / '20261128-closest-vehicle-effect' / 'fresh-friction-41-60',
         'seeds 61-80': HERE.parent / '20261128-beta-diagnosed-pooled' / 'fresh-friction-61-80',
         'seeds 81-100': HERE / 'fresh-friction-81-100'}


def main():
    sets = {}
    with redirect_stdout(StringIO()):
        sets['seeds 1-20'], sets['seeds 21-40'] = saved()
        for name, root in ROOTS.items():
            sets[name] = fresh(root)
    for name, d in sets.items():
        line(f"{name:13s}", d)
    keys = sorted({k for d in sets.values() for k in d})
    line(f"pooled ({len(sets)} sets)", {k: sum((d.get(k, []) for d in sets.values()), []) for k in keys})
    fresh3 = [sets[n] for n in ROOTS]
    line("fresh 41-100 ", {k: sum((d.get(k, []) for d in fresh3), []) for k in keys})


if __name__ == '__main__':
    main()
