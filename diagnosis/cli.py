"""``eroad diagnose``: where the nominal model misses a measured drive, which effect closes it.

The work is in :mod:`diagnosis.pipeline`; this module only parses the command line.
"""
from __future__ import annotations

import json
import sys


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "diagnose", help="sim-to-real gap diagnosis of a measured dataset",
        description="Diagnose the gap between a measured dataset and the nominal truck model: "
        "where (channel x third-octave band x road segment), which effect of the library "
        "closes it (calibrated on alternate time windows, scored on the others) and how far. "
        "The verdict: 'none' (no gap beyond noise), an effect (it explains a share of the gap "
        "and its axle-to-body transmissibility agrees), or 'unexplained' (a gap no library "
        "effect explains: what is left is reported). Writes report.md, figures/ and "
        "summary.json into RUN. The dataset's truth/ folder is never read.")
    p.add_argument("dataset", metavar="DATASET", help="dataset folder (measurement format)")
    p.add_argument("--vehicle", metavar="FILE", default=None,
                   help="nominal vehicle (built-in id or TOML file; default: the dataset's)")
    p.add_argument("--out", metavar="RUN", required=True, help="run folder to write")
    p.add_argument("--effects", metavar="a,b,...", default=None,
                   help="candidate effects (default: the whole library)")
    p.add_argument("--workers", type=int, default=2, metavar="N",
                   help="processes for the candidate calibrations (default 2)")
    p.add_argument("--seed", type=int, default=0, help="root seed of the road phases (default 0)")
    p.add_argument("--road-fit", choices=("levels", "inverse"), default="levels",
                   help="road identification: 'levels' (default: segment level and waviness "
                   "from the nominal model on the calibration windows, seconds) or 'inverse' "
                   "(the full inverse fit of the whole record, Gq, w, nmin, nmax; about a minute)")
    p.add_argument("--folds", type=int, choices=(1, 2), default=None,
                   help="2 (default; 1 with --quick): rank a second time with calibration and "
                   "held-out windows swapped and combine (twice the held-out evidence, twice the "
                   "time, no pairs); 1: one ranking, plus pairs of the two best effects")
    p.add_argument("--quick", action="store_true",
                   help="smoke-test settings: 4 candidates, fewer seeds, shorter search, no pairs")
    p.add_argument("--json", action="store_true", help="print summary.json's verdict part as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar or progress lines")
    p.add_argument("--force", action="store_true", help="replace an existing RUN folder")
    p.set_defaults(func=run)


def _silent(message: str) -> None:
    pass


def _to_stderr(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def run(args) -> int:
    from diagnosis.pipeline import diagnose
    from eroad.errors import EroadInputError
    from eroad.progress import MessageCounter, progress_bar, wants_progress

    effects = None
    if args.effects:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
    if args.workers < 1:
        raise EroadInputError(f"--workers must be >= 1, got {args.workers}")
    show = wants_progress(args)
    with progress_bar(show, desc="diagnose") as bar:
        if show:     # the bar counts candidate calibrations; the stage lines print above it
            say = MessageCounter(bar, total_pattern=r"calibrating (\d+) candidates",
                                 step_pattern=r"^\s+\S+: held-out gap", echo=True)
        elif args.quiet or args.json:
            say = _silent
        else:
            say = _to_stderr
        summary = diagnose(args.dataset, args.out, vehicle=args.vehicle, effects=effects,
                           workers=args.workers, quick=args.quick, force=args.force, seed=args.seed,
                           road_fit=args.road_fit,
                           settings=None if args.folds is None else {"folds": args.folds}, progress=say)
    if args.json:
        best = summary["ranking"][0] if summary.get("ranking") else None
        print(json.dumps({"verdict": summary["verdict"],
                          "verdict_confidence": summary.get("verdict_confidence"),
                          "verdict_reason": summary.get("verdict_reason"),
                          "best": best and {k: best.get(k) for k in (
                              "effect", "parameters", "heldout_gap_before", "heldout_gap_after",
                              "shrink_fraction", "accepted")},
                          "out": str(args.out)}, indent=1))
    else:
        print(f"wrote {args.out}: verdict {summary['verdict']} ({summary.get('verdict_confidence')}); "
              f"{summary.get('verdict_reason')}")
    return 0
