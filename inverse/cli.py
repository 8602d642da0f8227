"""``eroad invert DATASET --out RUN``: the command line of the inverse road modelling.

This module only parses the options and prints; the run itself is
:func:`inverse.run.run_inversion` (the run folder it writes is described there).
Several datasets (``eroad invert DIR1 DIR2 ... --out ROOT``), or one with
``--scheduler ADDRESS``, run on Dask, one run folder each under ROOT
(:func:`inverse.batch.invert_many`), one line printed per drive.
A progress bar goes to stderr when stderr is a terminal (not with ``--json`` or
``--quiet``).
"""
from __future__ import annotations

import json
import math
import sys

from eroad.errors import EroadInputError
# the run's functions, kept importable from here for older callers
from inverse.run import (AXLE3_CHANNELS, RUN_FORMAT, check_out, fit_channels,  # noqa: F401
                         headline, noise_psd_from_sd, run_inversion)

_check_out = check_out      # older name
_headline = headline        # older name


def register(subparsers) -> None:
    """Add ``eroad invert``."""
    p = subparsers.add_parser(
        "invert", help="identify the road spectrum of each segment of a drive",
        description="Segment a measured drive, fit the ISO 8608 parameters of each segment with the "
                    "nominal Exudyn truck (sampled sensitivities, common random numbers), select the "
                    "road realisation, and write Tables 1-2, Figures 6/8/9 and the global road.")
    p.add_argument("dataset", nargs="+",
                   help="dataset folder (drives format); several: each inverted into OUT/<folder name> on Dask")
    p.add_argument("--out", required=True,
                   help="run folder to create (several datasets or --scheduler: the folder of the run folders)")
    p.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="run the drives on an existing Dask scheduler (tcp://host:8786); default with several "
                        "datasets: a local cluster of --workers processes, each drive serial in one")
    p.add_argument("--segments", type=int, default=None, help="number of segments K (default: BIC criterion)")
    p.add_argument("--workers", type=int, default=2,
                   help="processes for the simulations (default 2); several datasets: local Dask workers "
                        "(0 or 1: one drive after the other, no Dask)")
    p.add_argument("--seed", type=int, default=0, help="root seed of the fit and candidate phases")
    p.add_argument("--candidates", type=int, default=None,
                   help="phase realisations tried in the selection (default 16, 6 with --quick; 0: keep the fit's)")
    p.add_argument("--max-iter", type=int, default=None, help="most fit iterations (default 12, 3 with --quick)")
    p.add_argument("--channels", default=None,
                   help="fitted channels: default susp_disp and axle_acc of both sides of axle 3 (of the "
                        "lowest-numbered axle logged on both sides where axle 3 is not), 'axle<N>' (those of "
                        "axle N, e.g. axle3), 'axles' (axle_acc of every axle + that axle's susp_disp; the "
                        "default of --effects auto where the diagnosis finds no gap), 'all' (every response "
                        "channel), 'axle<N>_acc' / 'axles_acc' (the axle accelerations of those sets alone; "
                        "the displacements only segment the drive), or a comma list (fitted as listed; a "
                        "displacement pair is added for the segmentation, not fitted)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME[.PARAM]=VALUE",
                   help="effect added to the nominal model (repeatable), e.g. leaf_friction")
    p.add_argument("--effects", choices=("auto",), default=None,
                   help="auto: run the gap diagnosis first (RUN/diagnose) and, if it names an effect "
                        "(any confidence, its value inside the search range), invert with it at its "
                        "calibrated value; the nominal inversion goes to RUN/nominal and Table 1 side by "
                        "side to RUN/tables/table1_nominal_vs_corrected.md. Where it finds no gap, the "
                        "accelerations of every axle are fitted (--channels axles); where the gap is "
                        "unexplained, axle 3's accelerations alone (--channels axle3_acc), corrected with "
                        "the closest effect if it acts on the vehicle and explains >= 60 %% of the gap; a "
                        "--channels given is kept (about 3-4x the time)")
    p.add_argument("--noise", action="append", default=[], metavar="NAME=SD",
                   help="known white sensor noise, standard deviation in the channel's SI unit, for a "
                        "channel (susp_disp_3L=1e-4) or a quantity (axle_acc=0.03); repeatable; channels "
                        "not given are estimated from the top of their spectrum")
    p.add_argument("--fit", choices=("linear", "simulation"), default="linear",
                   help="fit model: 'linear' (linear-model features corrected by a few time simulations; "
                        "default) or 'simulation' (every evaluation a time simulation, about 3x slower); "
                        "docs/inverse.md section 12")
    p.add_argument("--selection", choices=("linear", "simulation"), default="linear",
                   help="how the candidate road realisations are scored: 'linear' (the linear truck's time "
                        "response corrected by the simulated ones; the fit's and the best candidates "
                        "simulated; default) or 'simulation' (every candidate simulated), docs/inverse.md section 12")
    p.add_argument("--road-model", choices=("auto", "one"), default="auto",
                   help="road spectrum per segment: 'auto' (one ISO slope or two, with a break frequency, "
                        "chosen by BIC; default) or 'one' (one slope everywhere); docs/road_model.md")
    p.add_argument("--segment-on", choices=("displacement", "axle_acc"), default=None,
                   help="what locates the segment boundaries: 'displacement' (the reference axle's "
                        "suspension displacements in 3-20 Hz; the default) or 'axle_acc' (octave bands of "
                        "its axle accelerations: more boundaries on our own truck's drives, not on the "
                        "independently written one, so not the default); docs/inverse.md section 1")
    p.add_argument("--solver", choices=("linear", "exudyn"), default=None,
                   help="integrator of the time simulations: 'linear' (Exudyn's linearisation, the nonlinear "
                        "suspension forces solved per step; the default) or 'exudyn' (every run in Exudyn); "
                        "docs/inverse.md section 12")
    p.add_argument("--quick", action="store_true", help="few iterations and candidates (smoke runs)")
    p.add_argument("--json", action="store_true", help="print summary.json to stdout")
    p.add_argument("--quiet", action="store_true", help="no progress bar or progress lines")
    p.add_argument("--force", action="store_true", help="replace an existing RUN")
    p.set_defaults(func=_cmd_invert)


def _cmd_invert(args) -> int:
    from eroad.progress import progress_bar, wants_progress

    common = dict(segments=args.segments, workers=args.workers, seed=args.seed, quick=args.quick,
                  force=args.force, candidates=args.candidates, max_iter=args.max_iter,
                  channels=args.channels, noise_sd=_noise(args.noise), argv=sys.argv, fit_model=args.fit,
                  selection=args.selection, road_model=args.road_model, solver=args.solver,
                  **({} if args.segment_on is None else {"segment_on": args.segment_on}))
    if len(args.dataset) > 1 or args.scheduler is not None:
        return _cmd_invert_many(args, common)
    args.dataset = args.dataset[0]
    show = wants_progress(args)
    with progress_bar(show, desc="invert") as bar:
        if args.effects == "auto":
            if args.effect:
                raise EroadInputError("--effects auto and --effect NAME=VALUE cannot be combined")
            # the one place the inverse CLI reaches the diagnosis layer: the closed loop sits above both
            from diagnosis.closed_loop import invert_closed_loop
            say = bar.write if show else (lambda m: None) if args.quiet else \
                (lambda m: print(m, file=sys.stderr, flush=True))
            summary = invert_closed_loop(args.dataset, args.out, progress=say, bar=bar, **common)
        else:
            summary = run_inversion(args.dataset, args.out, effects=_effects(args.effect), bar=bar, **common)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        e = summary["errors"]
        segs = summary["segments"]

        def err(c):
            if "rms_err_p16" in e[c]:
                return (f"{c} RMS err {100 * e[c]['rms_err']:+.1f}% "
                        f"[{100 * e[c]['rms_err_p16']:+.1f}, {100 * e[c]['rms_err_p84']:+.1f}]")
            return f"{c} RMS err {100 * e[c]['rms_err']:+.1f}%"
        ref = summary.get("fit", {}).get("reference_axle", 3)
        errs = ", ".join(err(c) for c in (f"axle_acc_{ref}L", f"axle_acc_{ref}R") if c in e)
        from inverse.report import class_label

        print(f"wrote {args.out}: K = {len(segs)} segments, classes {' '.join(class_label(s) for s in segs)}"
              + (f"; {errs} (median [16-84 %] over road realisations)" if errs else
                 f"; no Table 2 headline (axle {ref}'s accelerations were not fitted)")
              + f" ({summary['timing']['total_s']:.1f} s wall)")
        for w in summary["dataset"].get("warnings", []):
            print(f"warning: {args.dataset}/{w}")
        fq = summary.get("fit_quality", {})
        if fq.get("status") == "poor":
            print(f"POOR FIT: {fq['message']}")
        for i, sg in enumerate(segs):
            if sg.get("at_bound"):
                print(f"ON A BOUND: segment {i + 1}: {', '.join(sg['at_bound'])} (the road lies outside the "
                      f"road model's range; docs/road_model.md)")
        if "closed_loop" in summary:
            print(f"closed loop: {summary['closed_loop']['reason']}")
    return 0


def _cmd_invert_many(args, common) -> int:
    """Several drives on Dask: one line per drive as it finishes, exit 1 if any failed."""
    from inverse.batch import invert_many, silent

    if args.json:
        raise EroadInputError("--json prints one run's summary; with several datasets read OUT/batch.json "
                              "and OUT/<name>/summary.json")
    kw = {k: v for k, v in common.items() if k not in ("workers", "argv")}
    if args.effects == "auto":
        if args.effect:
            raise EroadInputError("--effects auto and --effect NAME=VALUE cannot be combined")
        runner = "diagnosis.closed_loop:invert_closed_loop"   # the closed loop sits above inverse
        kw["progress"] = silent                               # its progress lines stay in the worker
    else:
        runner = "inverse.run:run_inversion"
        kw["effects"] = _effects(args.effect)

    def line(r):
        if r["status"] == "complete":
            e = r.get("rms_err", {})
            errs = ", ".join(f"{c} RMS err {100 * v:+.1f}%" for c, v in e.items() if v is not None)
            poor = "; POOR FIT" if r.get("fit_quality") == "poor" else ""
            print(f"{r['dataset']}: wrote {r['run']}: classes {' '.join(r['classes'])}"
                  + (f"; {errs}" if errs else "") + f"{poor} ({r['wall_s']:.1f} s)", flush=True)
        else:
            print(f"{r['dataset']}: FAILED: {r['error']}", flush=True)

    res = invert_many(args.dataset, args.out, scheduler=args.scheduler, n_workers=args.workers, runner=runner,
                      argv=sys.argv, report=line, **kw)
    n_bad = sum(r["status"] != "complete" for r in res)
    print(f"{len(res) - n_bad} of {len(res)} drives inverted into {args.out} ({args.out}/batch.json)"
          + (f"; {n_bad} failed" if n_bad else ""))
    return 1 if n_bad else 0


def _noise(items) -> dict | None:
    """``["axle_acc=0.03", ...]`` -> {"axle_acc": 0.03}; one clear line on a bad item."""
    out = {}
    for item in items:
        name, sep, val = item.partition("=")
        try:
            sd = float(val) if sep else float("nan")
        except ValueError:
            sd = float("nan")
        if not name.strip() or not (sd > 0 and math.isfinite(sd)):
            raise EroadInputError(f"--noise {item!r}: expected NAME=SD with SD a positive number in the "
                                  f"channel's SI unit, e.g. axle_acc=0.03")
        out[name.strip()] = sd
    return out or None


def _effects(items):
    if not items:
        return None
    from vehicles.effects import parse_effects
    return parse_effects(items)


