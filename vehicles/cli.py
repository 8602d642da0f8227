"""Command line of the vehicles package: ``eroad simulate``, ``eroad effects`` and
``eroad vehicle new|check``.

What it is for: running one simulation from files (vehicle, road, speed) into a
dataset folder in the measurement format plus ``summary.json``, and listing the
effect library.  What it is not: the simulator (:mod:`vehicles.simulate`) or the
modal analysis command (``eroad modes``, :mod:`vehicles.cli_modes`).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from eroad.errors import EroadInputError


def register(subparsers) -> None:
    """Add ``simulate``, ``effects`` and ``vehicle`` to the CLI."""
    p = subparsers.add_parser(
        "simulate", help="drive a vehicle model over a road file and write a dataset",
        description="Simulate a vehicle (rigid or flexible chassis, optional effects) over a "
        "road surface (.npz or .crg) at a constant speed or a speed profile; write the "
        "measurement dataset (channels.csv, meta.toml) and summary.json to --out.")
    p.add_argument("--vehicle", required=True, help="built-in id (dump_truck_8x4, e_tractor) or a vehicle .toml file")
    p.add_argument("--road", required=True, help="road surface file (.npz or .crg)")
    sp = p.add_mutually_exclusive_group(required=True)
    sp.add_argument("--speed", type=float, help="constant speed [m/s]")
    sp.add_argument("--speed-profile", help="CSV with columns time [s], speed [m/s]")
    p.add_argument("--duration", type=float, required=True, help="simulated time [s]")
    p.add_argument("--chassis", choices=("rigid", "flexible"), default="rigid")
    p.add_argument("--frame-segments", type=int, default=None,
                   help="segments of the flexible frame (default: the vehicle's)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME[=VALUE]|NAME.PARAM=VALUE",
                   help="switch an effect on (repeatable); see 'eroad effects'")
    p.add_argument("--dt", type=float, default=None, help="time step [s] (default: the vehicle's)")
    p.add_argument("--fs", type=float, default=200.0, help="output sample rate [Hz] (default 200)")
    p.add_argument("--x-start", type=float, default=None,
                   help="road x of the first axle at t = 0 [m] (default: last axle at the road start)")
    p.add_argument("--y-offset", type=float, default=0.0, help="road y of the vehicle centre line [m]")
    p.add_argument("--seed", type=int, default=0, help="root seed of random effects (sensor noise)")
    p.add_argument("--name", default=None, help="dataset name (default: the folder name)")
    p.add_argument("--out", required=True, help="output dataset folder (must not exist or be empty)")
    p.add_argument("--force", action="store_true", help="replace an existing non-empty --out")
    p.add_argument("--json", action="store_true", help="print summary.json to stdout")
    p.set_defaults(func=cmd_simulate)

    e = subparsers.add_parser("effects", help="list the effect library",
                              description="List the effect switches: name, parameters with unit, "
                              "default and sensible range, and what each does physically.")
    e.add_argument("--json", action="store_true", help="machine-readable list")
    e.set_defaults(func=cmd_effects)

    v = subparsers.add_parser(
        "vehicle", help="your own vehicle: copy a built-in one, check a vehicle file",
        description="Make your own vehicle file from a built-in one (every field commented "
        "with unit and meaning) and check a vehicle file against heavy-truck ranges.")
    vsub = v.add_subparsers(dest="vehicle_command", metavar="ACTION")
    v.set_defaults(func=lambda a: (v.print_help(), 2)[1])
    vn = vsub.add_parser(
        "new", help="write a commented copy of a built-in vehicle to edit",
        description="Write a commented copy of a vehicle (built-in id or file) to OUT; the "
        "copy's id is OUT's name. Refuses to overwrite an existing file.",
        epilog="Example: eroad vehicle new --from dump_truck_8x4 --out my_truck.toml")
    vn.add_argument("--from", dest="source", required=True, metavar="VEHICLE",
                    help="built-in id (dump_truck_8x4, e_tractor) or a vehicle .toml file")
    vn.add_argument("--out", required=True, metavar="FILE.toml", help="new file to write")
    vn.set_defaults(func=cmd_vehicle_new)
    vc = vsub.add_parser(
        "check", help="static deflections, natural frequencies, damping vs heavy-truck ranges",
        description="Load a vehicle (the loader refuses missing or non-positive fields), then "
        "compute per axle the static loads and spring and tyre deflections, the quarter-car "
        "body bounce and axle hop frequencies and the damping ratios, and compare them with "
        "heavy-truck ranges (body bounce 1-3 Hz, axle hop 8-15 Hz, suspension damping ratio "
        "0.1-0.5 (leaf springs 0.05-0.5), spring deflection 20-250 mm, tyre deflection "
        "10-60 mm). Warnings name the numbers; the exit code is 0 with warnings, 2 if the "
        "file does not load.")
    vc.add_argument("vehicle", metavar="VEHICLE", help="vehicle .toml file or built-in id")
    vc.add_argument("--json", action="store_true", help="print the full report as JSON")
    vc.set_defaults(func=cmd_vehicle_check)



def load_road(path):
    """Read a road file with ``RoadSurface.load`` (.npz or .crg).

    Raises
    ------
    EroadInputError
        Missing or unreadable file.
    """
    from roadlib.surface import RoadSurface

    p = Path(path)
    if not p.is_file():
        raise EroadInputError(f"{p}: no such road file")
    return RoadSurface.load(p)


def _check_out(out: Path, force: bool) -> None:
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; use --force to replace it")


def cmd_simulate(args) -> int:
    """Run ``eroad simulate``; returns the exit code."""
    from vehicles.params import builtin_ids, load_vehicle, vehicle_path
    from vehicles.simulate import SpeedProfile, simulate

    out = Path(args.out)
    _check_out(out, args.force)
    vpath = vehicle_path(args.vehicle)           # refuses a missing vehicle file
    vp = load_vehicle(vpath)
    road = load_road(args.road)
    if args.speed_profile:
        speed = SpeedProfile.from_csv(args.speed_profile)
    else:
        if not args.speed > 0:
            raise EroadInputError(f"--speed must be > 0 m/s, got {args.speed:g}")
        speed = args.speed
    if not args.duration > 0:
        raise EroadInputError(f"--duration must be > 0 s, got {args.duration:g}")
    res = simulate(vp, road, speed, args.duration, chassis=args.chassis, effects=list(args.effect),
                   dt=args.dt, fs_out=args.fs, x_start=args.x_start, y_offset=args.y_offset,
                   seed=args.seed, frame_segments=args.frame_segments)
    summary = res.summary()
    summary.update({"command": "simulate", "argv": sys.argv[1:], "vehicle_file": str(vpath),
                    "road_file": str(args.road), "out": str(out)})
    # where the road's input ends: above it at the drive's top speed the channels hold no road input
    from roadlib.metrics import road_input_band

    v_max = (max(float(v) for v in res.channels["speed"]) if "speed" in res.channels
             else float(summary.get("speed_mean", float("nan"))))
    band = road_input_band(road, v_max)
    n_top = band["road_content_top_cpm"]
    summary["road_content_top_cpm"] = n_top
    summary["road_input_top_hz_at_max_speed"] = band["road_input_top_hz"]

    def add(folder: Path) -> None:
        with open(folder / "summary.json", "w") as fh:
            json.dump(summary, fh, indent=2, default=float)

    vehicle = args.vehicle if args.vehicle in builtin_ids() else str(vpath)
    res.save_dataset(out, name=args.name, vehicle=vehicle, add_files=add, overwrite=args.force)
    if args.json:
        print(json.dumps(summary, indent=2, default=float))
    else:
        m = res.meta
        print(f"wrote {out}: {m['duration']:g} s of {m['vehicle']} ({m['chassis']}), "
              f"{sum(c != 'speed' for c in res.channels)} channels"
              f"{' + speed' if 'speed' in res.channels else ''} at {m['fs_out']:g} Hz; {m['steps']} steps in "
              f"{m['wall_s']:.2f} s wall ({m['realtime_factor']:.0f}x real time)")
        print(f"road input: the road carries wavelengths down to {1.0 / n_top:.2f} m ({n_top:.2f} "
              f"cycles/m), so above {band['road_input_top_hz']:.1f} Hz (at {v_max:.3g} m/s) the channels hold no "
              "road input")
    return 0


def cmd_effects(args) -> int:
    """Run ``eroad effects``; returns the exit code."""
    from vehicles.effects import EFFECTS

    lib = [e.to_dict() for e in EFFECTS.values()]
    if args.json:
        print(json.dumps({"effects": lib}, indent=2))
        return 0
    for e in lib:
        print(f"{e['name']}  (NAME=VALUE sets {e['primary']})")
        print(f"    {e['description']}")
        for p in e["parameters"]:
            lo, hi = p["range"]
            print(f"    - {p['name']} [{p['unit']}] default {p['default']:g}, range {lo:g}..{hi:g}: {p['doc']}")
    return 0


def cmd_vehicle_new(args) -> int:
    """Run ``eroad vehicle new``; returns the exit code."""
    from vehicles.check import new_vehicle_file

    out = new_vehicle_file(args.source, args.out)
    print(f"wrote {out}: a commented copy of {args.source}; edit it, then run "
          f"'eroad vehicle check {out}'")
    return 0


def cmd_vehicle_check(args) -> int:
    """Run ``eroad vehicle check``; returns the exit code (0 also with warnings)."""
    from vehicles.check import check_vehicle, format_check
    from vehicles.params import load_vehicle

    rep = check_vehicle(load_vehicle(args.vehicle))
    if args.json:
        print(json.dumps(rep, indent=2, default=float))
    else:
        print(format_check(rep))
    return 0
