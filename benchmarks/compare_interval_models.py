"""Which per-segment interval model holds its 90 % on blind drives it was not calibrated on?

Reads the records of ``benchmarks/bench_inverse.py`` (or ``bench_inverse_linear.py``) of
several sets (``NAME=ROOT``), calibrates each candidate model's one scale factor per
quantity on ONE set (``--calibrate NAME``: the factor at which 90 % of that set's segments
>= 3 s are covered, as ``calibrate_uncertainty.py`` does for KAPPA) and prints the coverage
on every set with that factor, i.e. out of sample on all but the calibration set.  Models:

* ``misfit``: inverse.uncertainty's formula (Laplace sd with Birge's factor plus the
  model-form term BETA * max(0, r / R_REF - 1), BETA as shipped);
* ``laplace``: the Laplace sd alone, scaled;
* ``robust``: the sandwich sd of ``inverse.sensitivity.robust_sd`` (``sd_robust`` in the
  records), scaled;
* ``robust+beta``: sqrt((k sd_robust)^2 + BETA max(0, r / R_REF - 1));
* ``misfit+consistency``: the misfit model's variance plus the channel-kind spread beyond
  noise (``consistency.excess`` of ``inverse.sensitivity.channel_consistency``; 0 where absent).

Run:  python benchmarks/compare_interval_models.py null=R1 random=R2 second=R3 --calibrate null
Nothing is written; the printout is what a results README quotes.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from calibrate_uncertainty import load, misfit  # noqa: E402
from inverse import uncertainty as U  # noqa: E402

ERR = {"ln_Gq_n0": "lnGq_err", "w": "w_err", "ln_G_n_best": "lnG_n_best_err"}


def _lap(r, q):
    return r["sd_ln_G_n_best_laplace"] if q == "ln_G_n_best" else r["sd_laplace"][q]


def _excess(r):
    return max(0.0, misfit(r) / U.R_REF - 1.0)


#: model name -> (unscaled sd of quantity q in record r, with a scale k)
MODELS = {
    "misfit": lambda r, q, k: U.reported_sd(_lap(r, q), misfit(r), q, kappa={**U.KAPPA, q: k}),
    "laplace": lambda r, q, k: k * _lap(r, q),
    "robust": lambda r, q, k: k * r["sd_robust"][q],
    "robust+beta": lambda r, q, k: float(np.sqrt((k * r["sd_robust"][q]) ** 2 + U.BETA[q] * _excess(r))),
    "misfit+consistency": lambda r, q, k: float(np.sqrt(
        U.reported_sd(_lap(r, q), misfit(r), q, kappa={**U.KAPPA, q: k}) ** 2
        + r.get("consistency", {}).get("excess", {}).get(q, 0.0))),
}


def usable(rows, q):
    return [r for r in rows if r.get(ERR[q]) is not None and "sd_robust" in r and q in r["sd_robust"]]


def calibrate(rows, model, q) -> float:
    """The smallest scale (bisection in 0.05-50) at which 90 % of ``rows`` are covered."""
    rows = usable(rows, q)
    lo, hi = 0.05, 50.0
    for _ in range(60):
        mid = np.sqrt(lo * hi)
        if coverage(rows, model, q, mid) >= 0.9:
            hi = mid
        else:
            lo = mid
    return hi


def coverage(rows, model, q, k) -> float:
    rows = usable(rows, q)
    if not rows:
        return float("nan")
    return float(np.mean([abs(r[ERR[q]]) <= U.Z90 * MODELS[model](r, q, k) for r in rows]))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sets", nargs="+", metavar="NAME=ROOT")
    ap.add_argument("--calibrate", required=True, metavar="NAME")
    ap.add_argument("--min-s", type=float, default=3.0)
    a = ap.parse_args(argv)
    sets = {}
    for item in a.sets:
        name, _, root = item.partition("=")
        sets[name] = load(Path(root), a.min_s)
    cal = sets[a.calibrate]
    print(f"scale factors calibrated on '{a.calibrate}' (90 % of its segments >= {a.min_s:g} s covered); "
          f"coverage elsewhere is out of sample")
    print("| model | quantity | scale | " + " | ".join(f"{n} ({len(usable(rows, 'w'))})" for n, rows in sets.items())
          + " |")
    print("|---|---|---|" + "---|" * len(sets))
    for model in MODELS:
        for q in ERR:
            k = calibrate(cal, model, q)
            print(f"| {model} | {q} | {k:.2f} | "
                  + " | ".join(f"{100 * coverage(rows, model, q, k):.0f} %" for rows in sets.values()) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
