"""``eroad modes``: the labelled mode table of a vehicle.

What it is for: the command-line face of :mod:`vehicles.modal` (argument parsing,
printing, the summary file).  The computing is in :func:`vehicles.modal.modal_analysis`.

Output: a text table, or with ``--json`` a JSON list of ``{label, freq_hz, damping,
freq_damped_hz, freq_undamped_hz}`` (``freq_hz`` is the natural frequency
``|lambda| / 2 pi`` of the damped mode [Hz], ``damping`` the damping ratio [-]).
``--out FILE`` also writes the full summary (vehicle, chassis, stiffness factor, count
of the stiff modes above ``--f-max``, energy shares of every mode) as JSON, atomically.
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

from eroad.argtypes import positive_float
from eroad.errors import EroadInputError




def _write_json_atomic(path: Path, doc, force: bool) -> None:
    if path.exists() and not force:
        raise EroadInputError(f"{path} exists; refusing to overwrite it (use --force)")
    if not path.parent.is_dir():
        raise EroadInputError(f"{path.parent}: no such directory for --out")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            json.dump(doc, fh, indent=2)
            fh.write("\n")
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def cmd_modes(args) -> int:
    """Run ``eroad modes``; return the exit code."""
    from vehicles.modal import format_table, modal_analysis
    from vehicles.params import load_vehicle

    vp = load_vehicle(args.vehicle)
    chassis = args.chassis
    if args.frame_stiffness is not None and chassis == "rigid":
        raise EroadInputError("--frame-stiffness needs --chassis flexible")
    if args.frame_segments is not None and args.frame_segments < 2:
        raise EroadInputError(f"--frame-segments must be >= 2, got {args.frame_segments}")
    res = modal_analysis(vp, chassis=chassis, frame_segments=args.frame_segments,
                         stiffness_factor=args.frame_stiffness or 1.0, effects=args.effect or None,
                         f_max=args.f_max)
    if args.out:
        summary = res.summary()
        summary["modes"] = [m.to_dict(energies=True) for m in res.modes]
        _write_json_atomic(Path(args.out), summary, args.force)
    if args.json:
        print(json.dumps(res.table(), indent=2))
    else:
        m = res.meta
        head = f"{vp.name} ({vp.id}), {m['chassis']} chassis"
        if m["chassis"] == "flexible":
            head += f", {m['frame_segments']} segments, frame stiffness x{m['stiffness_factor']:g}"
        if m.get("effects"):
            head += f", effects {', '.join(m['effects'])}"
        print(head)
        print(format_table(res))
        for note in m.get("notes", []):
            print(f"note: {note}")
    return 0


def register(subparsers) -> None:
    """Add ``eroad modes`` to the top-level subparsers."""
    p = subparsers.add_parser(
        "modes", help="eigenfrequencies, damping ratios and labels of a vehicle's modes",
        description="Linearise the vehicle at static equilibrium (Exudyn), solve the damped "
        "eigenproblem and label each mode (body bounce/pitch/roll, axle hop/tramp, frame "
        "torsion/bending, DCDC modes) by its energy distribution.  freq_hz is the natural "
        "frequency |lambda|/(2 pi) of the damped mode.")
    p.add_argument("--vehicle", required=True, metavar="ID|FILE",
                   help="built-in vehicle id (dump_truck_8x4, e_tractor) or a vehicle .toml file")
    p.add_argument("--chassis", choices=("rigid", "flexible"), default="rigid",
                   help="rigid chassis or flexible frame (default rigid)")
    p.add_argument("--frame-stiffness", type=positive_float, default=None, metavar="F",
                   help="scale of the frame's torsion and bending stiffness [-] (flexible; default 1)")
    p.add_argument("--frame-segments", type=int, default=None, metavar="N",
                   help="rigid segments of the flexible frame (default: the vehicle's)")
    p.add_argument("--effect", action="append", metavar="NAME=VALUE",
                   help="switch on an effect (configuration effects change the modes; repeatable)")
    p.add_argument("--f-max", type=positive_float, default=100.0, metavar="HZ",
                   help="list modes up to this frequency [Hz]; stiffer ones are only counted (100)")
    p.add_argument("--json", action="store_true",
                   help="print a JSON list of {label, freq_hz, damping, freq_damped_hz, freq_undamped_hz}")
    p.add_argument("--out", metavar="FILE", default=None,
                   help="also write the full summary (energy shares, stiff-mode count) as JSON")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out file")
    p.set_defaults(func=cmd_modes)
