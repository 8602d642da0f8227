"""``eroad replica DATASET --out RUN``: the road replica of a drive (issue 17).

Parse and print only; the method and the run folder are :mod:`inverse.replica`
(:func:`inverse.replica.run_replica`).  Reads the dataset's channels, speed and meta
only -- never ``truth/``.
"""
from __future__ import annotations

import json
import sys

from eroad.errors import EroadInputError


def register(subparsers) -> None:
    """Add ``eroad replica``."""
    p = subparsers.add_parser(
        "replica", help="reconstruct the left and right wheel-track profiles a drive went over",
        description="Reconstruct the two wheel-track profiles z_L(x), z_R(x) on a 0.1 m grid from every "
                    "response channel and the speed (input estimation on the linearised vehicle, every "
                    "axle on the same track with its wheelbase delay; docs/replica.md), with the identified "
                    "wavelength band, IRI per 20 m and 100 m, PSDs, a time-domain comparison with channels "
                    "held out, and the road as .npz / .crg.")
    p.add_argument("dataset", help="dataset folder (drives format)")
    p.add_argument("--out", required=True, help="run folder to create")
    p.add_argument("--effects", nargs="*", action="extend", default=[], metavar="NAME=VALUE|auto",
                   help="effects of the vehicle model (several after one flag, or the flag repeated): linear "
                        "ones enter the linear model; leaf_friction and bump_stop by statistical linearisation "
                        "per 5 s block (equivalent damping from the measured suspension velocity, equivalent "
                        "stiffness from the measured displacement); damper_asymmetry is left out (its "
                        "linearisation is the nominal damper) and listed; 'auto': run the diagnosis first and use "
                        "the effect it names (any confidence, its value inside the search range), or, on an "
                        "unexplained gap, its closest effect where that acts on the vehicle and explains >= 60 %% "
                        "of the gap (RUN/diagnose/)")
    p.add_argument("--noise", action="append", default=[], metavar="NAME=SD",
                   help="known white sensor noise (sd, SI unit) per channel or quantity, e.g. axle_acc=0.03; "
                        "repeatable; the rest is estimated from the top of each spectrum")
    p.add_argument("--holdout", default="auto", metavar="AXLE|none",
                   help="axle whose channels are left out of a second reconstruction and predicted from it "
                        "(validation, shown in red in figures/replica_time.png; default: axle 2 where logged "
                        "besides another axle; 'none' skips it; a drive logged on one axle has none)")
    p.add_argument("--diagnosis", default=None, metavar="RUN",
                   help="with --effects auto: an existing 'eroad diagnose' run folder of this dataset "
                        "(otherwise the diagnosis runs first, about 2 minutes)")
    p.add_argument("--inversion", default=None, metavar="RUN",
                   help="an 'eroad invert' run folder of this dataset: compare each segment's fitted PSD with "
                        "the replica's (figures/replica_vs_inversion.png, psd_segments.csv)")
    p.add_argument("--lines", choices=("tyre", "track"), default="tyre",
                   help="unknowns per side: a profile per lateral tyre position, coupled by the road's lateral "
                        "structure (default), or one track for all tyres of a side")
    p.add_argument("--json", action="store_true", help="print summary.json to stdout")
    p.add_argument("--force", action="store_true", help="replace an existing RUN")
    p.set_defaults(func=_cmd_replica)


def _holdout(value: str):
    if value.strip().lower() == "none":
        return None
    if value.strip().lower() == "auto":
        return "auto"
    try:
        a = int(value)
    except ValueError:
        a = 0
    if a < 1:
        raise EroadInputError(f"--holdout {value!r}: expected an axle number (1, 2, ...) or 'none'")
    return a


def _cmd_replica(args) -> int:
    from inverse.cli import _noise
    from inverse.replica import run_replica

    effects = None
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    common = dict(noise_sd=_noise(args.noise), lines=args.lines, inversion=args.inversion, holdout=_holdout(args.holdout), force=args.force,
                  argv=sys.argv, progress=say)
    if "auto" in args.effects:
        if args.effects != ["auto"]:
            raise EroadInputError("--effects auto and NAME=VALUE effects cannot be combined")
        from diagnosis.closed_loop import replica_closed_loop   # the closed loop sits above inverse
        summary = replica_closed_loop(args.dataset, args.out, diagnosis=args.diagnosis, **common)
    else:
        if args.diagnosis:
            raise EroadInputError("--diagnosis is used with --effects auto only")
        if args.effects:
            from vehicles.effects import parse_effects
            effects = parse_effects(args.effects)
        summary = run_replica(args.dataset, args.out, effects=effects, **common)
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0
    band = summary["identified_band_m"]
    iri = summary["iri_m_per_km"]
    ho = summary["holdout"]
    line = (f"wrote {args.out}: tracks over {summary['grid']['covered_m'][1] - summary['grid']['covered_m'][0]:.0f} m, "
            f"identified {band['median_lambda_min']:.2g}-{band['median_lambda_max']:.3g} m (median over the drive); "
            + (f"IRI per 100 m left {', '.join(f'{v:.2f}' for v in iri['left_100m'])}, "
               f"right {', '.join(f'{v:.2f}' for v in iri['right_100m'])} m/km" if iri["left_100m"]
               else "no IRI per 100 m (under 100 m covered)"))
    if ho["channels"]:
        worst = max(ho["nrmse"].values())
        line += f"; axle {ho['axle']} held out: nRMSE <= {worst:.2f}"
    elif ho.get("note"):
        line += f"; {ho['note']}"
    print(line + f" ({summary['timing']['total_s']:.0f} s wall)")
    if "closed_loop" in summary:
        print(f"closed loop: {summary['closed_loop']['reason']}")
    from inverse.replica import note_warnings

    for n in summary["linear_model"]["notes"]:
        if "statistically linearised" in n:
            print(f"note: {n}")
    for w in note_warnings(summary["linear_model"]["notes"]):
        print(f"warning: {w}")
    left = summary["linear_model"]["effects_left_out"]
    if left:
        print(f"note: nonlinear effect(s) {', '.join(left)} left out of the linear model")
    return 0
