"""Score the closed loop's channel choice (``diagnosis.closed_loop.loop_channels``) on saved
blind sets, without inverting again.

The closed loop fits axle 3 unless the diagnosis answers ``none``; then it fits the
``axles`` set (axle accelerations of every axle + suspension of axle 3). Given, for the
same drives,

* ``CL_ROOT``: a closed-loop set fitted on axle 3 (``bench_inverse.py --effects-auto
  --channels axle3``; its records carry the verdicts), and
* ``AXLES_ROOT``: the same drives inverted with the nominal model on the ``axles`` set
  (``bench_inverse.py --channels axles``, or the committed every-axle sets),

this composes the set the closed loop makes today: a drive whose verdict is ``none`` takes
its ``axles`` rows, every other drive its closed-loop rows. Each row's 90 % interval is
recomputed with the constants the code would use (``inverse.uncertainty.calibration_key``
of its channel set; model form by ``diagnosis.closed_loop.model_form``), so the scores are
those of the code as it is, on fits made earlier. ``--verdicts NAME=DIAG_ROOT`` re-decides
the verdicts from saved diagnoses as ``calibrate_uncertainty.py`` does.

Usage::

    python benchmarks/score_channels_by_verdict.py NAME=CL_ROOT,AXLES_ROOT [...] [--verdicts NAME=DIAG]
    python benchmarks/score_channels_by_verdict.py NAME=ROOT      # a set run with the choice itself (its fits,
                                                                  # today's constants)

Prints, per set, segments >= 3 s: the 90 % coverage of ln Gq(n0), w, ln G(n_best), G(1
cycle/m) within 20 % and class right, for axle 3 throughout and for the choice by verdict.
Nothing is written.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from calibrate_uncertainty import QUANTITIES, accuracy, load, misfit, redecided_loops  # noqa: E402

from inverse import uncertainty as U  # noqa: E402


def interval_holds(r: dict, key: str) -> dict:
    """Per quantity, whether the row's 90 % interval (constants ``key``, its model form) holds."""
    c = U.calibration(key)
    out = {}
    for q, (err, sd) in QUANTITIES.items():
        if r.get(err) is None or not sd(r):
            continue
        out[q] = abs(r[err]) <= U.Z90 * U.state_sd(sd(r), misfit(r), q, c, r["model_form"])
    return out


def score(rows: list) -> str:
    cov = {q: [h[q] for _, h in rows if q in h] for q in QUANTITIES}
    acc = accuracy([r for r, _ in rows])
    return (" | ".join(f"{100 * np.mean(v):.0f} %" for v in cov.values())
            + f" | {100 * acc['g1'][0]:.0f} % | {100 * acc['class'][0]:.0f} %")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sets", nargs="+", metavar="NAME=CL_ROOT,AXLES_ROOT")
    ap.add_argument("--verdicts", action="append", default=[], metavar="NAME=DIAG_ROOT")
    ap.add_argument("--min-s", type=float, default=3.0)
    ap.add_argument("--beta-diagnosed-from", default=None, metavar="CL_AXLES_ROOT",
                    help="also choose the axles set's BETA_DIAGNOSED by calibrate_uncertainty's rule on the "
                         "diagnosed rows of this closed-loop set fitted on 'axles' pooled with the 'none' "
                         "drives' rows of the sets above (and on each alone)")
    a = ap.parse_args(argv)
    pool = {}
    verdicts = {n: redecided_loops(Path(d)) for n, _, d in (v.partition("=") for v in a.verdicts)}
    print("| set | drives 'none' | segments | rule | 90 % cover ln Gq(n0) | w | ln G(n_best) "
          "| G(1 cycle/m) within 20 % | class right |")
    print("|---|---|---|---|---|---|---|---|---|")
    for item in a.sets:
        name, _, roots = item.partition("=")
        if "," not in roots:          # a closed-loop set run with the choice by verdict itself
            rows = load(Path(roots), a.min_s)
            rec = {json.loads(li)["seed"]: (json.loads(li).get("closed_loop") or {}).get("verdict")
                   for li in (Path(roots) / "results.jsonl").read_text().splitlines() if li.strip()}
            none = {s for s, v in rec.items() if v == "none"}
            got = [(r, interval_holds(r, "linear/axles" if r["seed"] in none else "linear")) for r in rows]
            print(f"| {name} | {len(none)}/{len(rec)} | {len(got)} | by verdict (fits as run) | {score(got)} |")
            sub = [(r, h) for r, h in got if r["seed"] in none]
            if sub:
                print(f"| {name}, the 'none' drives | {len(none)} | {len(sub)} | axles (fits as run) | {score(sub)} |")
            continue
        cl_root, ax_root = (Path(p) for p in roots.split(","))
        loops = verdicts.get(name)
        cl = load(cl_root, a.min_s, loops=loops)
        ax = load(ax_root, a.min_s)
        # the verdict per seed: re-decided, or as the closed-loop records hold it
        recorded = {json.loads(li)["seed"]: (json.loads(li).get("closed_loop") or {}).get("verdict")
                    for li in (cl_root / "results.jsonl").read_text().splitlines() if li.strip()}
        verdict = {s: (loops[s][0] if loops and s in loops else v) for s, v in recorded.items()}
        none = {s for s, v in verdict.items() if v == "none"}
        base = [(r, interval_holds(r, "linear")) for r in cl]
        mixed = [(r, interval_holds(r, "linear")) for r in cl if r["seed"] not in none]
        for r in ax:
            if r["seed"] in none:
                r["model_form"] = "diagnosed"
                mixed.append((r, interval_holds(r, "linear/axles")))
                pool.setdefault(name, []).append(r)
        n_none = len(none)
        print(f"| {name} | {n_none}/{len(verdict)} | {len(base)} | axle 3 | {score(base)} |")
        print(f"| {name} | {n_none}/{len(verdict)} | {len(mixed)} | by verdict | {score(mixed)} |")
        sub = [(r, h) for r, h in mixed if r["seed"] in none]
        if sub:
            sub0 = [(r, h) for r, h in base if r["seed"] in none]
            print(f"| {name}, the 'none' drives | {n_none} | {len(sub)} | axle 3 | {score(sub0)} |")
            print(f"| {name}, the 'none' drives | {n_none} | {len(sub)} | axles | {score(sub)} |")
    if a.beta_diagnosed_from:
        from calibrate_uncertainty import choose_beta_diagnosed

        const = {k: (dict(v) if isinstance(v, dict) else v) for k, v in U.calibration("linear/axles").items()}
        fams = {"closed loop on axles": [r for r in load(Path(a.beta_diagnosed_from), a.min_s)
                                         if r["model_form"] == "diagnosed"], **pool}
        print()
        for label, rows in [("pooled", [r for v in fams.values() for r in v]), *fams.items()]:
            print(f"BETA_DIAGNOSED (axles) chosen on {label} ({len(rows)} segments): {choose_beta_diagnosed(rows, const)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
