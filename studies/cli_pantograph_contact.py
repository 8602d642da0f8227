"""Command ``eroad pantograph-contact``: the e-tractor's pantograph under a contact line.

``eroad pantograph-contact --road FILE --out DIR [--speed-kmh 80] [--duration 30]``
drives the tractor over the road, feeds the DCDC-top motion into the pantograph in
contact with the line and writes ``DIR/pantograph_contact/<run-id>/`` with the contact
force statistics (also with the base at rest), the lateral offset against the head
width, ``data/contact.npz``, ``figures/contact.png`` and ``summary.json``
(:func:`studies.pantograph_contact.run_pantograph_contact`).  ``--railway-reference``
adds (or, without ``--road``, runs only) the railway reference case at 250 and 300 km/h.

``eroad pantograph-contact --road FILE --out DIR --chassis-grid [--frames LIST]
[--mounts LIST] [--workers N] [--run-dir DIR]`` runs the chassis-stiffness study in
contact-force terms instead: one drive per frame x DCDC-mount stiffness configuration
and one with the base still, in worker processes, into
``DIR/pantograph_chassis/<run-id>/`` (or the named ``--run-dir``) with ``data/table.csv``,
``data/table.md`` and ``figures/contact_vs_stiffness.png``; ``--seeds N`` drives the grid
on N statistically equivalent road realisations too (``figures/realisations.png``)
(:func:`studies.pantograph_chassis.run_pantograph_chassis`).
See ``docs/pantograph_contact.md``.
"""
from __future__ import annotations

import argparse
import json

from eroad.argtypes import nonnegative_float, nonnegative_int, positive_float

__all__ = ["register"]


_positive = positive_float
_nonnegative_int = nonnegative_int


def _factor_list(text: str, allow_rigid: bool) -> tuple:
    out = []
    for part in text.split(","):
        part = part.strip()
        if allow_rigid and part.lower() == "rigid":
            out.append("rigid")
            continue
        out.append(_positive(part))
    if not out:
        raise argparse.ArgumentTypeError("give at least one factor")
    return tuple(out)


def _frames(text: str) -> tuple:
    return _factor_list(text, True)


def _mounts(text: str) -> tuple:
    return _factor_list(text, False)


#: the options that shape a drive (``--road``) and their defaults: given without a road (the
#: railway reference alone) they would be ignored, so they are refused there
DRIVE_ONLY = {"speed_kmh": 80.0, "duration": 30.0, "line": "truck_ohl", "pantograph": "truck",
              "chassis": "flexible", "frame_factor": 1.0, "mount_factor": 1.0, "dt": 1e-3,
              "frame_friction": None}


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``eroad pantograph-contact`` to the top-level subparsers."""
    from studies.sweep import add_sweep_arguments
    p = subparsers.add_parser(
        "pantograph-contact", help="pantograph on the e-tractor under a contact line: "
        "contact force statistics",
        description="Drive the e-tractor over a road, feed the pantograph-base motion into "
        "a lumped (two- or three-mass) pantograph in penalty contact with a finite-element "
        "contact line, "
        "and report EN 50367-style contact force statistics (mean, sd, Fm +/- 3 sd, "
        "min, max, contact loss) and the lateral offset against the head width.")
    p.add_argument("--road", metavar="FILE", help="road file (.npz or .crg)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="results root; the run goes to DIR/pantograph_contact/<run-id>/")
    p.add_argument("--speed-kmh", type=_positive, default=DRIVE_ONLY["speed_kmh"],
                   help="speed [km/h] (default 80)")
    p.add_argument("--duration", type=_positive, default=DRIVE_ONLY["duration"],
                   help="drive [s] (default 30; shortened to what the road covers)")
    p.add_argument("--line", default=DRIVE_ONLY["line"],
                   help="contact line id or TOML file (default truck_ohl)")
    p.add_argument("--pantograph", default=DRIVE_ONLY["pantograph"],
                   help="pantograph id or TOML file (default truck)")
    p.add_argument("--chassis", choices=("flexible", "rigid"), default=DRIVE_ONLY["chassis"])
    p.add_argument("--frame-factor", type=_positive, default=DRIVE_ONLY["frame_factor"],
                   help="frame stiffness factor [-] (default 1)")
    p.add_argument("--mount-factor", type=_positive, default=DRIVE_ONLY["mount_factor"],
                   help="DCDC mount stiffness factor [-] (default 1)")
    p.add_argument("--frame-friction", type=nonnegative_float, default=None, metavar="N",
                   help="Coulomb friction of the pantograph's frame joints [N] (default: the "
                   "pantograph file's, 0 in the built-in files)")
    p.add_argument("--dt", type=_positive, default=DRIVE_ONLY["dt"], help="contact time step [s] (default 1e-3)")
    p.add_argument("--no-compare", action="store_true",
                   help="skip the run with the pantograph base at rest")
    p.add_argument("--railway-reference", action="store_true",
                   help="also run the railway reference case (250 and 300 km/h, about 1 min)")
    p.add_argument("--json", action="store_true", help="print summary.json")
    g = p.add_argument_group(
        "chassis-stiffness grid (--chassis-grid)",
        "contact-force quality against frame and DCDC-mount stiffness: one drive per "
        "configuration plus one with the base still; --frame-factor, --mount-factor, "
        "--chassis, --no-compare and --railway-reference do not apply")
    g.add_argument("--chassis-grid", action="store_true",
                   help="run the frame x mount grid into DIR/pantograph_chassis/<run-id>/")
    g.add_argument("--frames", type=_frames, default=None, metavar="LIST",
                   help="frame stiffness factors, comma-separated, 'rigid' allowed "
                   "(default 0.25,0.5,1,2,4,16,rigid)")
    g.add_argument("--mounts", type=_mounts, default=None, metavar="LIST",
                   help="DCDC mount stiffness factors, comma-separated (default 0.5,1,2)")
    g.add_argument("--seeds", type=_nonnegative_int, default=0, metavar="N",
                   help="also drive the grid on N statistically equivalent road realisations "
                   "(as the chassis study: the file's generator segments or its ISO 8608 "
                   "fit, new phases; default 0)")
    g.add_argument("--seed", type=int, default=2026,
                   help="root seed of the road realisations (default 2026)")
    g.add_argument("--run-dir", default=None, metavar="DIR",
                   help="write the grid run into this named folder (must not exist or be "
                   "empty) instead of DIR/pantograph_chassis/<run-id>/")
    add_sweep_arguments(p)
    p.set_defaults(func=_run)


def _fmt(st: dict) -> str:
    return (f"mean {st['mean']:.1f} N, sd {st['sd']:.1f} N, Fm-3sd {st['stat_min']:.1f} N, "
            f"Fm+3sd {st['stat_max']:.1f} N, min {st['actual_min']:.1f} N, "
            f"max {st['actual_max']:.1f} N, loss {st['loss_percent']:.2f} %")


#: how each reference statistic is named and scaled in the printout (uplift in mm)
_REF_NAMES = {"mean": ("mean", 1.0, "N"), "sd": ("sd", 1.0, "N"), "stat_max": ("Fm+3sd", 1.0, "N"),
              "stat_min": ("Fm-3sd", 1.0, "N"), "actual_max": ("max", 1.0, "N"),
              "actual_min": ("min", 1.0, "N"), "max_support_uplift": ("support uplift", 1e3, "mm"),
              "loss_percent": ("loss", 1.0, "%")}


def _ref_lines(kmh: str, case: dict) -> list:
    """The reference case at one speed: its statistics, then what lies inside and outside the
    published ranges (each outside value with its range)."""
    st, rg, inside = case["stats"], case["ranges"], case["inside"]
    ok = [_REF_NAMES.get(k, (k, 1.0, ""))[0] for k in rg if inside.get(k)]
    out = []
    for k in rg:
        if not inside.get(k):
            name, f, unit = _REF_NAMES.get(k, (k, 1.0, ""))
            out.append(f"{name} {f * st[k]:.1f} {unit} (range {f * rg[k][0]:g} to {f * rg[k][1]:g})")
    line2 = f"  inside the EN 50318:2002 ranges: {len(ok)} of {len(rg)} ({', '.join(ok) or 'none'})"
    if out:
        line2 += "; outside: " + ", ".join(out)
    return [f"reference {kmh} km/h: {_fmt(st)}", line2]


def _run(args: argparse.Namespace) -> int:
    import sys

    from studies.pantograph_contact import run_pantograph_contact

    if args.chassis_grid:
        return _run_grid(args)
    if args.road is None:
        given = [k for k, v in DRIVE_ONLY.items() if getattr(args, k) != v]
        if given:
            from eroad.errors import EroadInputError

            raise EroadInputError(
                f"{', '.join('--' + k.replace('_', '-') for k in given)}: options of a drive "
                f"(--road FILE); the railway reference runs its own line and pantograph at 250 "
                f"and 300 km/h")
    kw = {}
    if args.road is not None:
        kw = dict(speed_kmh=args.speed_kmh, duration=args.duration, line=args.line,
                  pantograph=args.pantograph, chassis=args.chassis,
                  frame_factor=args.frame_factor, mount_factor=args.mount_factor,
                  dt=args.dt, compare_static=not args.no_compare,
                  frame_friction=args.frame_friction)
    s = run_pantograph_contact(args.road, args.out, reference=args.railway_reference,
                               command=sys.argv, **kw)
    if args.json:
        print(json.dumps(s, indent=2, default=str))
        return 0
    if "contact" in s:
        cfg = s["config"]
        print(f"pantograph: {cfg['pantograph']}, frame friction {cfg['frame_friction_N']:g} N")
        win = cfg.get("statistics_window_s")
        if win:
            asked = cfg.get("duration_requested_s")
            short = (f" (asked {asked:g} s: the road is shorter)"
                     if asked is not None and asked > cfg["duration_s"] else "")
            print(f"drive {cfg['duration_s']:g} s{short}; statistics over t = {win[0]:g}-{win[1]:g} s "
                  f"({win[1] - win[0]:g} s: the vehicle's run-in and the contact's settling left out)")
        print(f"contact force (drive):      {_fmt(s['contact'])}")
        if s.get("contact_base_at_rest"):
            print(f"contact force (base still): {_fmt(s['contact_base_at_rest'])}")
        lat = s["lateral"]
        print(f"lateral offset: max {1e3 * lat['max_abs_offset']:.1f} mm of half-width "
              f"{1e3 * lat['half_width']:.0f} mm (margin {1e3 * lat['margin']:.1f} mm)")
        note = (s.get("tractor") or {}).get("note")
        if note:
            print(f"tractor: {note}")
        w = s["wall"]
        print(f"wall: vehicle {w['vehicle_s']:.1f} s, contact {w['contact_s']:.1f} s")
    ref = (s.get("reference") or {}).get("cases", {})
    for kmh, c in ref.items():
        print("\n".join(_ref_lines(kmh, c)))
    if ref and not all(all(c["inside"].values()) for c in ref.values()):
        print("  the line's parameters are secondary-source values; its pre-sag moves the sd and the "
              "support uplift most (benchmarks/catenary_presag_scan.py, docs/pantograph_contact.md)")
    print(s["path"])
    return 0


def _run_grid(args: argparse.Namespace) -> int:
    import sys

    from eroad.errors import EroadInputError
    from studies.pantograph_chassis import (FRAME_FACTORS, MOUNT_FACTORS,
                                            run_pantograph_chassis)
    from studies.sweep import sweep_kwargs

    if args.road is None:
        raise EroadInputError("--chassis-grid needs a road file (--road)")
    if args.railway_reference:
        raise EroadInputError("--chassis-grid and --railway-reference are separate runs")
    s = run_pantograph_chassis(
        args.road, args.out, run_dir=args.run_dir,
        frames=args.frames or FRAME_FACTORS, mounts=args.mounts or MOUNT_FACTORS,
        speed_kmh=args.speed_kmh, duration=args.duration, line=args.line,
        pantograph=args.pantograph, dt=args.dt, seeds=args.seeds, seed=args.seed,
        frame_friction=args.frame_friction, command=sys.argv, **sweep_kwargs(args))
    if args.json:
        print(json.dumps(s, indent=2, default=str))
        return 0
    b = s["base_still"]
    print(f"{s['n_configurations']} configurations at {s['speed_kmh']:g} km/h, "
          f"{s['duration_s']:g} s drive")
    print(f"contact force sd: {s['sd_N_range'][0]:.2f}-{s['sd_N_range'][1]:.2f} N "
          f"(base still {b['sd_N']:.2f} N); base-induced sd "
          f"{s['base_induced_sd_N_range'][0]:.2f}-{s['base_induced_sd_N_range'][1]:.2f} N")
    print(f"contact loss: at most {s['max_loss_percent']:.2f} %; lowest unfiltered force "
          f"{s['lowest_unfiltered_force_N']:.1f} N")
    print(f"lateral offset: at most {s['max_lateral_offset_mm']:.1f} mm of half-width "
          f"{s['head_half_width_mm']:.0f} mm")
    if s.get("tractor_note"):
        print(f"tractor (worst configuration): {s['tractor_note']}")
    R = s.get("realisations")
    if R:
        print(f"over {R['n_roads']} equivalent roads: the chassis grid spans "
              f"{R['chassis_span_N'][0]:.2f}-{R['chassis_span_N'][1]:.2f} N of sd per road, one "
              f"configuration spans {R['road_span_N'][0]:.2f}-{R['road_span_N'][1]:.2f} N over "
              f"the roads; contact loss at most {R['max_loss_percent_any_road']:.2f} %")
    print(s["path"])
    return 0
