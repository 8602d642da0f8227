"""Commands of the pantograph studies: ``eroad study pantograph`` and ``eroad study chassis``.

``eroad study pantograph --road FILE --out DIR`` drives the e-tractor over the road,
computes Figure 11 (pantograph-base spectra), judges the paper's findings and checks the
kinematics against Exudyn's rigid-body motion of the DCDC block
(:func:`studies.figure11.run_figure11`).

``eroad study chassis --road FILE --out DIR [--quick] [--scheduler ADDRESS] [--workers N]``
sweeps the frame and DCDC mount stiffness over road realisations on Dask
(:func:`studies.chassis_study.run_chassis_study`).

``--out DIR`` is the results root: each run is a new folder ``DIR/<study>/<run-id>/``
(``figure11`` or ``chassis_stiffness``), written atomically; nothing that exists is
touched.  ``--json`` prints the run's ``summary.json``.  See ``docs/pantograph.md``.
"""
from __future__ import annotations

import argparse
import json
import sys

from eroad.errors import EroadInputError
from roadlib.metrics import SHORT_WAVE_ROAD_HINT

from eroad.argtypes import positive_float

__all__ = ["register"]


_positive = positive_float


def _frame_factor(text: str):
    if text.strip().lower() == "rigid":
        return "rigid"
    return _positive(text)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``eroad study`` with the actions ``pantograph`` and ``chassis``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The top-level ``eroad`` subparsers.
    """
    from studies.chassis_study import FRAME_FACTORS, MOUNT_FACTORS
    from studies.sweep import add_sweep_arguments

    study = subparsers.add_parser(
        "study", help="pantograph-base studies (Figure 11, chassis stiffness)",
        description="Pantograph-base studies of the e-tractor, archived under "
        "<out>/<study>/<run-id>/.")
    study.set_defaults(func=lambda args: _usage(study))
    actions = study.add_subparsers(dest="study_action", metavar="STUDY")

    p = actions.add_parser(
        "pantograph", help="Figure 11, the paper's findings and the kinematics check",
        description="Drive the e-tractor over a road, compute the pantograph-base spectra "
        "of Figure 11 (Rx, Ry, Ty, Tz and their derivatives), judge the paper's five "
        "findings by explicit criteria, explain the peaks by modes, and check the "
        "four-point kinematics against Exudyn's rigid-body motion of the DCDC block.")
    p.add_argument("--road", required=True, metavar="FILE", help="road file (.npz or .crg)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="results root; the run goes to DIR/figure11/<run-id>/")
    p.add_argument("--speed", type=_positive, default=10.0, help="speed [m/s] (default 10)")
    p.add_argument("--duration", type=_positive, default=30.0,
                   help="simulated time [s] (default 30; shortened to what the road covers)")
    p.add_argument("--chassis", choices=("flexible", "rigid"), default="flexible",
                   help="frame model (default flexible)")
    p.add_argument("--frame-factor", type=_positive, default=1.0,
                   help="frame stiffness factor [-] (default 1)")
    p.add_argument("--mount-factor", type=_positive, default=1.0,
                   help="DCDC mount stiffness factor [-] (default 1)")
    p.add_argument("--json", action="store_true", help="print summary.json")
    p.set_defaults(func=_cmd_pantograph)

    c = actions.add_parser(
        "chassis", help="chassis-stiffness study (frame and DCDC mounts) on Dask",
        description="Sweep the frame stiffness factor and the DCDC mount stiffness factor "
        "over the road file and statistically equivalent road realisations; band energies "
        "(<0.5, 0.5-5, 5-15, 15-40 Hz) of the pantograph-base motion against stiffness.")
    c.add_argument("--road", required=True, metavar="FILE", help="road file (.npz or .crg)")
    c.add_argument("--out", required=True, metavar="DIR",
                   help="results root; the run goes to DIR/chassis_stiffness/<run-id>/")
    c.add_argument("--quick", action="store_true",
                   help="CI smoke test: frames 0.25, 1, 4, rigid; nominal mounts; the road "
                   "and 1 realisation; 8 s drives")
    c.add_argument("--frames", nargs="+", type=_frame_factor, default=None, metavar="F",
                   help="frame stiffness factors and/or 'rigid' (default "
                   f"{' '.join(str(f) for f in FRAME_FACTORS)})")
    c.add_argument("--mounts", nargs="+", type=_positive, default=None, metavar="M",
                   help="DCDC mount stiffness factors (default "
                   f"{' '.join(str(m) for m in MOUNT_FACTORS)})")
    c.add_argument("--seeds", type=int, default=None, metavar="N",
                   help="statistically equivalent road realisations besides the file "
                   "(default 2, quick 1)")
    c.add_argument("--seed", type=int, default=2026, help="root seed of the realisations")
    c.add_argument("--speed", type=_positive, default=10.0, help="speed [m/s] (default 10)")
    c.add_argument("--duration", type=_positive, default=None,
                   help="simulated time per case [s] (default 30, quick 8)")
    c.add_argument("--solver", choices=("linear", "exudyn"), default="linear",
                   help="integrator of each drive: the linear model stepped with Exudyn's scheme "
                   "(default; tyre lift-off corrected as Exudyn does; the study's findings the same "
                   "as Exudyn's, band energies within 5 %%, about 2.5x faster) or Exudyn")
    c.add_argument("--json", action="store_true", help="print summary.json")
    add_sweep_arguments(c)
    c.set_defaults(func=_cmd_chassis)


def _usage(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


def _cmd_pantograph(args: argparse.Namespace) -> int:
    from studies.figure11 import run_figure11

    summary = run_figure11(args.road, args.out, speed=args.speed, duration=args.duration,
                           chassis=args.chassis, frame_factor=args.frame_factor,
                           mount_factor=args.mount_factor, command=["eroad"] + sys.argv[1:])
    if args.json:
        return _print_summary(summary)
    print(f"run: {summary['path']}")
    chk = summary["kinematics_check"]
    print(f"kinematics: cond(A) = {chk['cond']:.3g}; exact method vs Exudyn: max relative "
          f"error {chk['exact_max_rel_error']:.2g}; paper's linear method: "
          + ", ".join(f"{k} {v:.2g}" for k, v in chk["linear_max_rel_error"].items()))
    print("paper's findings for our model:")
    beyond = set(summary.get("findings_beyond_road_input") or [])
    for k, holds in summary["findings"].items():
        print(f"  ({k}) {'TRUE ' if holds else 'false'}  {summary['findings_claims'][k]}"
              + ("  [band beyond the road's input]" if k in beyond else ""))
    if summary.get("road_input_note"):
        print(f"road input: {summary['road_input_note']}")
    print(f"details: {summary['path']}/data/findings.md; figure: "
          f"{summary['path']}/{summary['figures'][0]}")
    return 0


def _cmd_chassis(args: argparse.Namespace) -> int:
    from studies.chassis_study import full_config, quick_config, run_chassis_study
    from studies.sweep import sweep_kwargs

    kw = {"seed": args.seed, "speed": args.speed, "solver": args.solver}
    if args.frames is not None:
        kw["frames"] = tuple(args.frames)
    if args.mounts is not None:
        kw["mounts"] = tuple(args.mounts)
    if args.seeds is not None:
        if args.seeds < 0:
            raise EroadInputError(f"--seeds {args.seeds}: must be >= 0")
        kw["n_seeds"] = args.seeds
    if args.duration is not None:
        kw["duration"] = args.duration
    config = quick_config(**kw) if args.quick else full_config(**kw)
    sk = sweep_kwargs(args)
    summary = run_chassis_study(args.road, args.out, config, scheduler=sk["scheduler"],
                                n_workers=sk["n_workers"], cache_dir=sk["cache_dir"],
                                progress=sk["progress"], command=["eroad"] + sys.argv[1:])
    if args.json:
        return _print_summary(summary)
    print(f"run: {summary['path']}")
    print(f"{summary['n_cases']} cases ({summary['n_computed']} computed, "
          f"{summary['n_cached']} from the cache) in {summary['sweep_wall_s']:.1f} s")
    print("frame modes [Hz] (torsion, bending) by frame factor: "
          + "; ".join(f"{k}: {v['torsion_hz']:.2f}, {v['bending_hz']:.2f}"
                      for k, v in summary["frame_modes_hz"].items() if k != "rigid"))
    if summary.get("bands_beyond_road_input"):
        print(f"road input: the road's content ends at {summary['road_content_top_cpm']:.2f} "
              f"cycles/m, {summary['road_input_top_hz']:.1f} Hz at this speed; band(s) "
              f"{', '.join(b + ' Hz' for b in summary['bands_beyond_road_input'])} reach beyond it (no road input "
              f"there: use a road with shorter waves, e.g. `{SHORT_WAVE_ROAD_HINT}`)")
    print("bands whose energy changes with the frame stiffness (softest vs rigid, every "
          f"road, factor > {summary['trend_threshold']:g}):")
    for q, bands in summary["bands_depending_on_frame"].items():
        if q in ("Ty", "Tz", "Rx", "Ry", "Ty_acc", "Tz_acc", "Rx_acc", "Ry_acc"):
            print(f"  {q:7s} {', '.join(bands) if bands else '-'}")
    print(f"figures: {summary['path']}/figures/")
    return 0


def _print_summary(summary: dict) -> int:
    """Print the run's summary.json (standard JSON: NaN written as null) with its path."""
    from pathlib import Path

    doc = json.loads((Path(summary["path"]) / "summary.json").read_text())
    doc["path"] = summary["path"]
    print(json.dumps(doc, indent=2))
    return 0
