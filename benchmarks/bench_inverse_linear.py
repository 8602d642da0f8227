"""``benchmarks/bench_inverse.py`` with the linear-model fit (``eroad invert --fit linear``).

bench_inverse.py inverts every blind drive with ``inverse.cli.run_inversion`` at its
defaults (``--fit simulation``) and has no option for the fit model; this wrapper runs
its ``main`` unchanged with that function's ``fit_model`` set to "linear" (each record's
``fit_model`` field, read from the run's summary.json, says which fit ran), so the
blind set and ``benchmarks/calibrate_uncertainty.py`` can score the linear fit's
accuracy and interval coverage on the same drives (``--data-root``).

Run:  nice python benchmarks/bench_inverse_linear.py --scenario null --cases 10 --root R1 --data-root D
      (every option is bench_inverse.py's)
"""
from __future__ import annotations

import functools
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv=None) -> int:
    import bench_inverse
    import inverse.cli

    inverse.cli.run_inversion = functools.partial(inverse.cli.run_inversion, fit_model="linear")
    return bench_inverse.main(argv)


if __name__ == "__main__":
    sys.exit(main())
