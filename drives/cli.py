"""Commands of the drives package: ``eroad data check``, ``eroad data figures``,
``eroad synth``.

Heavy imports (Exudyn, matplotlib) happen inside the command functions so that
``eroad --help`` and ``eroad data check`` stay fast.
"""
from __future__ import annotations

import argparse
import json
import sys


def register(subparsers) -> None:
    """Add ``data`` and ``synth`` to the ``eroad`` command line.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The top-level subparsers of ``eroad``.
    """
    data = subparsers.add_parser(
        "data", help="measured datasets: import a logger file, check one, plot Figures 4-5",
        description="Work with measurement datasets (channels.csv + meta.toml; see "
        "docs/measurement.md).")
    dsub = data.add_subparsers(dest="data_command", metavar="ACTION")
    data.set_defaults(func=lambda a: _help(data))

    chk = dsub.add_parser(
        "check", help="validate a dataset and print a summary",
        description="Validate DATASET against the measurement-format contract. Prints a "
        "summary (duration, rate, channels, speed range), or one line per problem naming "
        "file, column and row with exit code 2. Reads nothing in truth/ and writes nothing.")
    chk.add_argument("dataset", metavar="DATASET", help="dataset folder")
    chk.add_argument("--json", action="store_true", help="print the summary (or problems) as JSON")
    chk.set_defaults(func=cmd_check)

    from drives.cli_import import register_import  # eroad data import (logger CSV + map)

    register_import(dsub)

    cut = dsub.add_parser(
        "cut", help="a dataset cut to a time window, or to the stretches where the vehicle moves",
        description="Write part of DATASET as new datasets: --window T0 T1 keeps that time span "
        "(record time, as in the time column) in OUT; --moving writes each stretch with speed > "
        "--min-speed of at least --min-duration as OUT/part01, OUT/part02, ... (what eroad invert "
        "and eroad replica need from a drive with stops). The source is only read; nothing is "
        "written unless every piece is valid.",
        epilog="Example: eroad data cut my-drive --moving --out my-drive-moving")
    cut.add_argument("dataset", metavar="DATASET", help="dataset folder")
    cut.add_argument("--out", required=True, metavar="DIR", help="output folder (new or empty)")
    cut.add_argument("--window", nargs=2, type=float, metavar=("T0", "T1"), default=None,
                     help="keep T0 <= time <= T1 [s]")
    cut.add_argument("--moving", action="store_true",
                     help="one dataset per moving stretch (OUT/part01, ...)")
    cut.add_argument("--min-speed", type=float, default=0.5, metavar="M_S",
                     help="speed above which the vehicle is moving [m/s] (default 0.5, as eroad invert)")
    cut.add_argument("--min-duration", type=float, default=3.0, metavar="S",
                     help="shortest moving stretch kept [s] (default 3)")
    cut.add_argument("--force", action="store_true", help="replace a non-empty --out")
    cut.add_argument("--json", action="store_true", help="print the summary as JSON")
    cut.set_defaults(func=cmd_cut)

    fig = dsub.add_parser(
        "figures", help="Figures 4 and 5: axle-3-left suspension displacement and spectra",
        description="Figure 4: third-axle left suspension displacement over the whole record "
        "with the selected window marked, and the window alone. Figure 5: its spectrum "
        "(Welch PSD) before and after slicing. Writes PNG and PDF, and summary.json.")
    fig.add_argument("dataset", metavar="DATASET", help="dataset folder")
    fig.add_argument("--out", required=True, metavar="DIR", help="output folder (new or empty)")
    fig.add_argument("--window", nargs=2, type=float, metavar=("T0", "T1"), default=None,
                     help="window [s] in the time column (default: the whole record)")
    fig.add_argument("--channel", default="susp_disp_3L",
                     help="channel to plot (default: susp_disp_3L)")
    fig.add_argument("--force", action="store_true", help="replace a non-empty --out")
    fig.add_argument("--json", action="store_true", help="print summary.json")
    fig.set_defaults(func=cmd_figures)

    syn = subparsers.add_parser(
        "synth", help="virtual test drive: a 'measured' dataset from a known truth",
        description="Make a measurement dataset from a known truth (road segments, speed "
        "profile, truth vehicle with effects, sensor noise); everything used goes to "
        "OUT/truth/. Scenarios: luliang (the paper's 460-490 s window, the embedded "
        "default; its whole 400-580 s record goes to OUT/record/), random (seed draws the road and speed), null (truth vehicle = nominal "
        "model), or a TOML file with --config. Same seed, same bytes.",
        epilog="Example: eroad synth --scenario luliang --seed 0 --out luliang-0")
    syn.add_argument("--scenario", default=None,
                     help="luliang | random | null (default luliang, or from --config)")
    syn.add_argument("--seed", type=int, default=None, help="root seed (default 0)")
    syn.add_argument("--effect", action="append", default=[], metavar="NAME=VALUE",
                     help="add an effect to the truth vehicle, e.g. leaf_friction=3000 or "
                     "payload.mass=2000 or bump_stop.gap=0.02 (repeatable; 'eroad effects' "
                     "lists them)")
    syn.add_argument("--no-default-effects", action="store_true",
                     help="drop the scenario's own effects (keep only --effect ones)")
    syn.add_argument("--vehicle", default=None,
                     help="built-in vehicle id or vehicle TOML file (default per scenario)")
    syn.add_argument("--duration", type=float, default=None,
                     help="record length [s]; for a scenario with a window (luliang) the "
                     "window's length, cut from the same record")
    syn.add_argument("--config", default=None, metavar="TOML",
                     help="scenario TOML setting everything explicitly (see "
                     "drives/scenarios/luliang.toml)")
    syn.add_argument("--out", required=True, metavar="DIR", help="dataset folder to create")
    syn.add_argument("--force", action="store_true", help="replace a non-empty --out")
    syn.add_argument("--json", action="store_true", help="print summary.json")
    syn.set_defaults(func=cmd_synth)


def _help(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


def format_summary(s: dict) -> str:
    """Human-readable lines for a :meth:`drives.format.Drive.summary` dict."""
    from drives.format import ZERO_NOMINAL_STATIC

    lines = [
        f"dataset   {s['name']}: valid",
        f"duration  {s['duration_s']:.3f} s ({s['n_samples']} samples, "
        f"t = {s['t_start_s']:g} .. {s['t_end_s']:g} s)",
        f"rate      {s['sample_rate_hz']:g} Hz",
        f"channels  {len(s['channels'])}: {', '.join(s['channels'])}",
        f"speed     {s['speed_min_mps']:.3f} .. {s['speed_max_mps']:.3f} m/s "
        f"({'speed column' if s['speed_source'] == 'column' else 'constant from meta.toml'})",
        f"vehicle   {s['vehicle']}{' (file in the dataset)' if s['vehicle_is_file'] else ''}",
    ]
    sc = s.get("speed_check")
    lines.append("speed chk " + (f"axle-to-axle delay in distance: x{sc['scale']:.3f} of the vehicle's axle "
                                 f"spacing ({sc['agree']} of {sc['pairs']} axle pairs agree; 1 for a right speed)"
                                 if sc else "not measured (needs two axles of one side and the vehicle's "
                                 "axle positions)"))
    if any(c.startswith("susp_disp_") for c in s["channels"]):
        lines.append("disp zero " + ("the nominal vehicle at rest (declared): the mean displacement "
                                     "is evidence of a static load (eroad diagnose uses it)"
                                     if s.get("susp_disp_zero") == ZERO_NOMINAL_STATIC else
                                     "unknown: the mean displacement is not used (declare "
                                     "susp_disp_zero = \"nominal_static\" in meta.toml if the "
                                     "sensors were zeroed on the nominal vehicle at rest)"))
    lines += [f"warning   {w}" for w in s.get("warnings", [])]
    return "\n".join(lines)


def cmd_check(args) -> int:
    """``eroad data check DATASET``: 0 if valid, 2 with one line per problem."""
    from drives.format import inspect_drive

    problems, drive = inspect_drive(args.dataset)
    if problems:
        if args.json:
            print(json.dumps({"valid": False, "problems": problems}, indent=2))
        else:
            for p in problems:
                print(f"eroad: error: {p}", file=sys.stderr)
            print(f"eroad: {len(problems)} problem(s); the dataset breaks the contract "
                  "(docs/measurement.md)", file=sys.stderr)
        return 2
    s = {"valid": True, **drive.summary()}
    print(json.dumps(s, indent=2) if args.json else format_summary(s))
    return 0


def cmd_cut(args) -> int:
    """``eroad data cut DATASET --out DIR [--window T0 T1] [--moving]``."""
    from drives.cut import cut_dataset

    s = cut_dataset(args.dataset, args.out, window=args.window, moving=args.moving,
                    min_speed=args.min_speed, min_duration=args.min_duration, force=args.force)
    if args.json:
        print(json.dumps(s, indent=2))
        return 0
    for p in s["pieces"]:
        print(f"wrote     {p['folder']}: t = {p['t_start_s']:.3f} .. {p['t_end_s']:.3f} s "
              f"({p['duration_s']:.2f} s, speed >= {p['speed_min_mps']:.2f} m/s)")
    for d in s["dropped"]:
        print(f"dropped   t = {d['t_start_s']:.3f} .. {d['t_end_s']:.3f} s: moving, but shorter than "
              f"{args.min_duration:g} s")
    if args.moving:
        print(f"left out  {s['slow_s']:.2f} s at or below {args.min_speed:g} m/s")
    return 0


def cmd_figures(args) -> int:
    """``eroad data figures DATASET --out DIR``."""
    from drives.figures import figures_command

    summary = figures_command(args.dataset, args.out, window=args.window,
                              channel=args.channel, force=args.force)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        for f in summary["files"]:
            print(f)
    return 0


def cmd_synth(args) -> int:
    """``eroad synth ...``."""
    from drives.synth import synth_command

    summary = synth_command(scenario=args.scenario, seed=args.seed, effects=args.effect,
                            vehicle=args.vehicle, duration=args.duration, config=args.config,
                            out=args.out, force=args.force,
                            default_effects=not args.no_default_effects)
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"wrote {summary['out']}: {summary['duration_s']:g} s at "
              f"{summary['sample_rate_hz']:g} Hz, {len(summary['channels']) - 1} channels + speed, "
              f"{len(summary['segments'])} road segment(s), seed {summary['seed']} "
              f"({summary['wall_s']:.1f} s wall)")
    return 0

