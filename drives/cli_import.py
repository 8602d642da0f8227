"""``eroad data import``: a logger CSV and a column map into a measurement dataset.

Only argument parsing and printing; the work is :func:`drives.importer.import_logger`.
Registered by :func:`drives.cli.register` inside the ``data`` group.
"""
from __future__ import annotations

import argparse
import json
import sys

from eroad.argtypes import finite_float
from eroad.errors import EroadInputError


def register_import(dsub) -> None:
    """Add ``import`` to the ``data`` subcommands.

    Parameters
    ----------
    dsub : argparse._SubParsersAction
        The subparsers of ``eroad data``.
    """
    p = dsub.add_parser(
        "import", help="a logger CSV + column map (TOML) -> a dataset",
        description="Convert a logger CSV (any delimiter, own column names, units g, mm, "
        "ms, km/h, non-uniform time, gravity in the accelerations) into a measurement "
        "dataset, using a column map. Time is resampled onto a uniform grid by a cubic "
        "spline; a time step above 1.5 median steps (the map's max_step_factor) is a gap, "
        "refused unless the map says on_gap = \"split\" or --split-gaps is given (then "
        "one dataset per continuous piece: OUT/part01, ...). Every conversion is recorded "
        "in OUT/meta.toml [import]. Nothing is written on any error. Rules: docs/import.md.",
        epilog="Start with: eroad data import --template > map.toml   (then edit it)\n"
        "Example:    eroad data import logger.csv --map map.toml --out my-drive\n"
        "            eroad data check my-drive",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("raw", metavar="RAW", nargs="?", help="the logger CSV file")
    p.add_argument("--map", metavar="MAP.toml", help="column map (see --template)")
    p.add_argument("--out", metavar="DATASET", help="dataset folder to create (new or empty)")
    p.add_argument("--template", action="store_true",
                   help="print a commented template map and exit")
    p.add_argument("--window", nargs=2, type=finite_float, metavar=("T0", "T1"), default=None,
                   help="keep T0 <= t <= T1 [s, the logger's time] (overrides the map)")
    p.add_argument("--vehicle", default=None,
                   help="built-in vehicle id or vehicle .toml (overrides the map)")
    p.add_argument("--speed", type=finite_float, default=None, metavar="MPS",
                   help="constant speed [m/s] when the map has no speed column")
    p.add_argument("--rate", type=finite_float, default=None, metavar="HZ",
                   help="output sample rate [Hz] (default: the map's, else the logger's)")
    p.add_argument("--split-gaps", action="store_true",
                   help="split at gaps into OUT/part01, part02, ... instead of refusing")
    p.add_argument("--name", default=None, help="dataset name (overrides the map)")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=cmd_import)


def cmd_import(args) -> int:
    """Run ``eroad data import``; return the exit code."""
    from drives.importer import import_logger, template_text

    if args.template:
        sys.stdout.write(template_text())
        return 0
    missing = [n for n, v in (("RAW", args.raw), ("--map", args.map), ("--out", args.out))
               if v is None]
    if missing:
        raise EroadInputError(f"data import needs {', '.join(missing)} (or --template to print "
                              "a map to start from); see 'eroad data import --help'")
    s = import_logger(args.raw, args.map, args.out, window=args.window, vehicle=args.vehicle,
                      speed_mps=args.speed, rate_hz=args.rate, split_gaps=args.split_gaps,
                      name=args.name)
    if args.json:
        print(json.dumps(s, indent=2))
        return 0
    print(f"read {s['source']}: {s['rows_read']} rows, delimiter {s['delimiter']!r}; "
          f"resampled ({s['method']}) to {s['rate_hz']:g} Hz")
    for g in s["gaps"]:
        print(f"gap       row {g['row']}: t = {g['from_s']:.6g} .. {g['to_s']:.6g} s (split there)")
    for p in s["skipped_pieces"]:
        print(f"left out  rows {p['rows'][0]}-{p['rows'][1]} (t = {p['t_s'][0]:.6g} .. "
              f"{p['t_s'][1]:.6g} s): shorter than the shortest piece kept")
    for d in s["datasets"]:
        print(f"wrote     {d['path']}: {d['samples']} samples, t = {d['t_start_s']:.6g} .. "
              f"{d['t_end_s']:.6g} s")
        for c, conv in d["conversions"].items():
            print(f"          {c:14s} {conv}")
    print(f"next      eroad data check {s['datasets'][0]['path']}")
    return 0
