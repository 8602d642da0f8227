"""Pantograph-contact study: the e-tractor's DCDC-top motion driven into a pantograph
running under a contact line, and the contact-force quality it causes.

What it is for (issue 18): one drive of the e-tractor over a road at 60-90 km/h; the
pantograph-base motion from the paper's kinematics (eq. 9-11,
:func:`studies.figure11.drive_base_motion`); the base's vertical motion ``Tz`` fed into
the lumped pantograph (:mod:`vehicles.pantograph_model`) in penalty contact with the
contact line FE model (:mod:`catenary`); the same run with the base at rest for
comparison; EN 50367-style statistics (:mod:`catenary.stats`); and the lateral offset
of the contact point on the head (base lateral motion at head height ``Ty - Rx h``
through the head's lateral DOF, against the wire's lateral position).

Also the railway reference case (:func:`railway_reference`): an EN 50318-type 60 m
reference catenary with slack droppers and the two-mass reference pantograph at 250 and
300 km/h, compared with the EN 50318:2002 reference ranges (:data:`REFERENCE_RANGES`).

Decisions (the issue is silent): the vehicle drives centred under the wire (no lane
wander); the pantograph base moves vertically with ``Tz`` only (pitch ``Ry`` and roll
``Rx`` change the head height only to second order and are left out vertically); one
pole of the two-pole line is modelled; statistics over the drive after the first
second, 20 Hz low-pass (EN 50318).

What it is not: a plot of a figure from data it does not save (plots read the saved
``contact.npz``), or a model of the line or the pantograph.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from catenary.contact import ContactResult, simulate_contact
from catenary.line import ContactLine, LineParams, load_line
from catenary.stats import contact_statistics, lateral_statistics
from eroad.errors import EroadInputError

__all__ = ["STUDY", "REFERENCE_RANGES", "LIFT_OFF_LIMIT_PERCENT", "tractor_range",
           "tractor_range_note",
           "contact_drive", "railway_reference",
           "run_pantograph_contact", "plot_contact"]

STUDY = "pantograph_contact"

#: share of the tractor drive's output samples in which some tyre would lift off [%] above
#: which a drive with *bilateral* tyres (``vehicles.simulate(..., tyres="bilateral")``, the
#: model before lift-off was modelled) is outside the tractor model's range: such tyres also
#: pull, so while a tyre should fly the model holds it on the road.  The contact drives use
#: unilateral tyres (the default since 2026-11-25: a tyre off the road carries nothing,
#: vehicles/tyre_contact.py), for which lift-off is part of the model and no limit applies;
#: the share is still reported.  Measured with unilateral tyres: ISO class D at 80 km/h,
#: 20 % of the samples, and the DCDC-top motion differs from the bilateral model's by 0.1 %
#: in rms (docs/pantograph_contact.md).
LIFT_OFF_LIMIT_PERCENT = 1.0


def tractor_range(lift_off_percent: float, tyres: str = "unilateral") -> dict:
    """The tractor drive's validity from its tyre lift-off share [%] and its tyre model: the
    share, the limit (bilateral tyres only), whether the drive is within the model's range
    (None when the share is unknown), and :func:`tractor_range_note`'s sentence.  The one
    place that judges it (the single drive, the grid summary, its figure)."""
    p = float(lift_off_percent)
    within = None if not math.isfinite(p) else (
        True if tyres == "unilateral" else bool(p < LIFT_OFF_LIMIT_PERCENT))
    return {"tyre_lift_off_percent": p, "tyres": tyres,
            "lift_off_limit_percent": None if tyres == "unilateral" else LIFT_OFF_LIMIT_PERCENT,
            "within_model_range": within, "note": tractor_range_note(p, tyres)}


def tractor_range_note(lift_off_percent: float, tyres: str = "unilateral") -> str | None:
    """One sentence on the tractor drive's validity from its tyre lift-off share [%] and its
    tyre model (None when no tyre lifts off)."""
    p = float(lift_off_percent)
    if not math.isfinite(p):
        return "tyre lift-off share unknown (the drive did not report it)"
    if p <= 0.0:
        return None
    if tyres == "unilateral":
        return (f"a tyre was off the road in {p:.1f} % of the tractor drive's samples "
                "(modelled: the tyres carry no force off the road)")
    if p < LIFT_OFF_LIMIT_PERCENT:
        return (f"tyre lift-off in {p:.2f} % of the tractor drive's samples (isolated peaks; "
                f"the model's tyres do not lift off, below the {LIFT_OFF_LIMIT_PERCENT:g} % limit)")
    return (f"OUTSIDE THE TRACTOR MODEL'S RANGE: a tyre would lift off in {p:.1f} % of the "
            f"drive's samples (limit {LIFT_OFF_LIMIT_PERCENT:g} %); the model's linear tyres stay "
            "on the road, so the base motion, and the contact statistics driven by it, are not "
            "the truck's on this road at this speed: use a smoother road or a lower speed")


#: EN 50318:2002 reference-model results (the ranges issue 18 quotes; they are the
#: standard's, not the 2015 benchmark's): speed [km/h] -> {quantity: (lo, hi)}, forces
#: [N], uplift at the support [m], loss [%].  Source: Wang, Liu, Mu, Huang, Wang, Gao, "An
#: Extended Habedank's Equation-Based EMTP Model of Pantograph Arcing Considering
#: Pantograph-Catenary Interactions and Train Speeds" (IEEE), Table III "Ranges of EN
#: 50318" (paper text in the public GitHub search index, id 56138154433); the same
#: 250/300 km/h mean, sd, statistical max/min, uplift and loss ranges are in
#: github.com/ChandraguptSharma07/faraway backend/sim/validate.py.
REFERENCE_RANGES: dict[float, dict[str, tuple[float, float]]] = {
    250.0: {"mean": (110.0, 120.0), "sd": (26.0, 31.0), "stat_max": (190.0, 210.0),
            "stat_min": (20.0, 40.0), "actual_max": (175.0, 210.0), "actual_min": (50.0, 75.0),
            "max_support_uplift": (0.048, 0.055), "loss_percent": (0.0, 0.0)},
    300.0: {"mean": (110.0, 120.0), "sd": (32.0, 40.0), "stat_max": (210.0, 230.0),
            "stat_min": (-5.0, 20.0), "actual_max": (190.0, 225.0), "actual_min": (30.0, 55.0),
            "max_support_uplift": (0.055, 0.065), "loss_percent": (0.0, 0.0)},
}


def _line_for_travel(line: str | Path, travel: float) -> tuple[ContactLine, float, float]:
    """Contact line long enough for ``travel`` [m] plus one span before and after."""
    lp = load_line(line)
    n = int(math.ceil(travel / lp.span - 1e-9)) + 2
    cl = ContactLine(replace(lp, n_spans=max(n, lp.n_spans)))
    x0 = lp.span
    return cl, x0, x0 + travel


def contact_drive(road, *, speed_kmh: float = 80.0, duration: float = 30.0,
                  line: str | Path = "truck_ohl", pantograph: str | Path = "truck",
                  chassis: str = "flexible", frame_factor: float = 1.0,
                  mount_factor: float = 1.0, dt: float = 1e-3, t_skip: float = 1.0,
                  compare_static: bool = True, lowpass_hz: float = 20.0,
                  base_scale: float = 1.0,
                  frame_friction: float | None = None) -> dict[str, Any]:
    """Drive, base motion, pantograph-contact simulation and statistics.

    Parameters
    ----------
    road : roadlib.surface.RoadSurface
    speed_kmh : float
        Vehicle speed [km/h] (60-90 for the electrified road).
    duration : float
        Drive [s]; shortened to what the road covers.
    line, pantograph : str or Path
        Built-in ids or TOML files (``catenary/data/line_*.toml``,
        ``vehicles/data/pantograph_*.toml``).
    chassis, frame_factor, mount_factor
        Tractor configuration (as :func:`studies.figure11.drive_base_motion`).
    dt : float
        Contact simulation step [s].
    t_skip : float
        Start-up time left out of the vehicle drive [s].
    compare_static : bool
        Also run the pantograph with its base at rest (same line, speed).
    lowpass_hz : float
        Statistics low-pass cut-off [Hz].
    base_scale : float
        Factor on the base motion fed to the pantograph (vertical and lateral; default
        1).  0 holds the base still on the same line, speed, travel and time grid as the
        drive (the reference of :mod:`studies.pantograph_chassis`).
    frame_friction : float, optional
        Coulomb friction of the pantograph's frame joints [N], replacing the file's
        ``frame_friction`` (default: the file's, 0 in the built-in files).

    Returns
    -------
    dict
        ``result`` (:class:`ContactResult`), ``static`` (or None), ``stats`` and
        ``stats_static`` (dicts), ``lateral`` (dict), ``lateral_series`` (time, offset),
        ``wall`` timings [s], ``config``, ``tractor`` (:func:`tractor_range` of the drive:
        its tyre lift-off share [%], its tyre model, whether it is within the model's range,
        a sentence).
    """
    from studies.figure11 import (DEFAULT_VEHICLE, drive_base_motion, max_duration,
                                  tractor_variant)
    from vehicles.pantograph_model import (collector, lateral_response, load_pantograph,
                                           with_frame_friction)

    if not (math.isfinite(speed_kmh) and 0 < speed_kmh <= 200):
        raise EroadInputError(f"speed must be in (0, 200] km/h, got {speed_kmh}")
    if not (math.isfinite(duration) and duration > t_skip):
        raise EroadInputError(f"duration must exceed t_skip = {t_skip} s, got {duration}")
    if not (math.isfinite(base_scale) and base_scale >= 0):
        raise EroadInputError(f"base_scale must be a finite number >= 0, got {base_scale}")
    pp = load_pantograph(pantograph)
    pp = with_frame_friction(pp, frame_friction)
    v = speed_kmh / 3.6
    vp = tractor_variant(DEFAULT_VEHICLE, mount_factor)
    # whole seconds, at least half a second short of the road's end: with t_max - 0.5
    # (14.52 s at 80 km/h on the identified Luliang road) vehicles.simulate stopped one
    # output sample short of the end ('no output stored'); 10 s ran.  Not investigated
    # further (vehicles/ is not this study's module).
    dur = float(math.floor(min(float(duration), max_duration(road, vp, v) - 0.5)))
    if dur <= t_skip + 1.0:
        raise EroadInputError(f"the road ({road.length:.1f} m) is too short for a drive at "
                              f"{speed_kmh} km/h")
    w0 = _time.perf_counter()
    drive = drive_base_motion(vp, road, speed=v, duration=dur, chassis=chassis,
                              frame_factor=frame_factor, t_skip=t_skip)
    wall_vehicle = _time.perf_counter() - w0
    lift_pct = 100.0 * float(drive["meta"].get("tyre_lift_off_fraction", float("nan")))
    tyres = str(drive["meta"].get("tyres", "bilateral"))
    m = drive["motion"]
    tm = np.asarray(m.time)
    T = float(tm[-1])
    cl, xs, xe = _line_for_travel(line, v * T)
    n_steps = int(math.floor((xe - xs) / v / dt + 1e-9))
    tc = dt * np.arange(n_steps + 1)
    zb = base_scale * np.interp(tc, tm, m.Tz)
    zbd = base_scale * np.interp(tc, tm, np.gradient(m.Tz, tm))
    col = collector(pp)
    w0 = _time.perf_counter()
    res = simulate_contact(cl, col, speed=v, x_start=xs, x_end=xe, dt=dt,
                           base_z=zb, base_zdot=zbd)
    wall_contact = _time.perf_counter() - w0
    t_range = (1.0, float(res.time[-1]))
    st = contact_statistics(res["force"], time=res.time, t_range=t_range, lowpass_hz=lowpass_hz)
    static = None
    st0 = None
    if compare_static:
        static = simulate_contact(cl, col, speed=v, x_start=xs, x_end=xe, dt=dt)
        st0 = contact_statistics(static["force"], time=static.time, t_range=t_range,
                                 lowpass_hz=lowpass_hz)
    yb = base_scale * (np.asarray(m.Ty) - np.asarray(m.Rx) * pp.head_height)
    yh = lateral_response(pp, tm, yb)
    offset = cl.lateral(xs + v * tm) - yh
    lat = lateral_statistics(offset, pp.head_half_width)
    return {"result": res, "static": static, "stats": st.as_dict(),
            "stats_static": None if st0 is None else st0.as_dict(),
            "lateral": lat.as_dict(), "lateral_series": (tm, offset, yb),
            "wall": {"vehicle_s": wall_vehicle, "contact_s": wall_contact},
            "tractor": tractor_range(lift_pct, tyres),
            "config": {"speed_kmh": float(speed_kmh), "duration_s": dur,
                       "duration_requested_s": float(duration),
                       # the statistics' interval in the drive's time: the vehicle's run-in
                       # (t_skip) and the contact's own settling (t_range[0]) left out
                       "statistics_window_s": [t_skip + t_range[0], t_skip + t_range[1]],
                       "dt_s": dt,
                       "line": str(line), "pantograph": str(pp.name),
                       "frame_friction_N": pp.frame_friction,
                       "n_spans": cl.params.n_spans, "n_dof": int(res.meta["n_dof"]),
                       "base_z_rms_m": float(base_scale * np.std(m.Tz)),
                       "base_scale": float(base_scale),
                       "chassis": chassis, "frame_factor": frame_factor,
                       "mount_factor": mount_factor}}


def railway_reference(speeds_kmh=(250.0, 300.0), *, dt: float = 5e-4,
                      line: str | Path | LineParams = "en50318",
                      pantograph: str | Path = "en50318",
                      analysis_spans: tuple[int, int] = (4, 6)) -> dict[str, Any]:
    """The railway reference case at the given speeds against :data:`REFERENCE_RANGES`.

    Runs the pantograph from 5 m to 5 m before the end of the line, statistics over the
    spans ``analysis_spans`` (0-based, end exclusive: (4, 6) = the 5th and 6th of 10, as
    the benchmark's two central spans), 20 Hz low-pass.  ``line`` is a built-in id, a TOML
    file or :class:`catenary.line.LineParams` (a sensitivity study varies one field with
    :func:`dataclasses.replace`, ``benchmarks/catenary_presag_scan.py``).

    Returns
    -------
    dict
        Per speed: ``stats``, ``ranges``, ``inside`` (per quantity), ``wall_s``.
    """
    from vehicles.pantograph_model import collector, load_pantograph

    cl = ContactLine(line if isinstance(line, LineParams) else load_line(line))
    col = collector(load_pantograph(pantograph))
    span = cl.params.span
    out: dict[str, Any] = {"line": cl.params.name, "source": cl.params.source, "cases": {}}
    for kmh in speeds_kmh:
        w0 = _time.perf_counter()
        r = simulate_contact(cl, col, speed=kmh / 3.6, x_start=5.0, x_end=cl.x[-1] - 5.0, dt=dt)
        xr = (analysis_spans[0] * span, analysis_spans[1] * span)
        st = contact_statistics(r["force"], time=r.time, x=r["x"], x_range=xr)
        ranges = REFERENCE_RANGES.get(float(kmh), {})
        sd = st.as_dict()
        # uplift at the supports of the analysed spans while the pantograph is in them
        sel = (r["x"] >= xr[0]) & (r["x"] <= xr[1])
        pole_x = cl.x[cl.pole_nodes]
        cols = (pole_x >= xr[0] - 1e-9) & (pole_x <= xr[1] + 1e-9)
        sd["max_support_uplift"] = float(np.max(r["pole_uplift"][sel][:, cols]))
        inside = {k: bool(lo - 1e-9 <= sd[k] <= hi + 1e-9) for k, (lo, hi) in ranges.items()}
        out["cases"][f"{kmh:g}"] = {"stats": sd, "ranges": {k: list(v) for k, v in ranges.items()},
                                    "inside": inside, "wall_s": _time.perf_counter() - w0,
                                    "max_slack_droppers": int(np.max(r["n_slack"])),
                                    "max_pole_uplift_m": float(np.max(r["pole_uplift"]))}
    return out


def _save(run, out: dict) -> None:
    res: ContactResult = out["result"]
    extra = {}
    if out["static"] is not None:
        extra = {"static_force": out["static"]["force"]}
    tm, offset, yb = out["lateral_series"]
    np.savez_compressed(run.data_dir / "contact.npz", time=res.time, x=res["x"],
                        force=res["force"], head_z=res["head_z"], uplift=res["uplift"],
                        base_z=res["base_z"], friction=res["friction"], lateral_time=tm,
                        lateral_offset=offset, base_y_head=yb, **extra)


def plot_contact(folder: str | Path, path: str | Path) -> list[Path]:
    """Contact force (with and without base motion), base motion and lateral offset from
    a saved ``contact.npz`` (``folder`` is the run's ``data/``), and the frame friction
    force when the pantograph has friction; writes PNG and PDF."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = np.load(Path(folder) / "contact.npz")
    fric = "friction" in d and bool(np.any(d["friction"] != 0.0))
    fig, ax = plt.subplots(4 if fric else 3, 1, figsize=(9, 10.5 if fric else 8), sharex=False)
    ax[0].plot(d["time"], d["force"], lw=0.6, label="base motion from the drive")
    if "static_force" in d:
        ax[0].plot(d["time"], d["static_force"], lw=0.6, alpha=0.8, label="base at rest")
    ax[0].axhline(0.0, color="k", lw=0.5)
    ax[0].set_ylabel("contact force [N]")
    ax[0].set_xlabel("time [s]")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[1].plot(d["time"], 1e3 * d["base_z"], lw=0.6, label="pantograph base Tz")
    ax[1].plot(d["time"], 1e3 * (d["head_z"] - d["head_z"][0]), lw=0.6, label="head (from start)")
    ax[1].set_ylabel("vertical [mm]")
    ax[1].set_xlabel("time [s]")
    ax[1].legend(loc="upper right", fontsize=8)
    ax[2].plot(d["lateral_time"], 1e3 * d["lateral_offset"], lw=0.6,
               label="contact point offset on the head")
    ax[2].plot(d["lateral_time"], 1e3 * d["base_y_head"], lw=0.6, alpha=0.7,
               label="base lateral at head height (Ty - Rx h)")
    ax[2].set_ylabel("lateral [mm]")
    ax[2].set_xlabel("time [s]")
    ax[2].legend(loc="upper right", fontsize=8)
    if fric:
        ax[3].plot(d["time"], d["friction"], lw=0.6, color="tab:red",
                   label="frame friction on the lower frame (drive)")
        fmax = float(np.max(np.abs(d["friction"])))
        ax[3].set_ylim(-1.2 * fmax, 1.6 * fmax)  # room for the legend above the slip level
        ax[3].set_ylabel("friction force [N]")
        ax[3].set_xlabel("time [s]")
        ax[3].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return save_png_pdf(fig, path, dpi=120)


def save_png_pdf(fig, path, dpi: int = 120) -> list:
    """Write ``fig`` as PNG at ``path`` and as PDF beside it, close it; the two paths."""
    from eroad.figures import save_figure

    p = Path(path)
    return save_figure(fig, [p, p.with_suffix(".pdf")], dpi=dpi)


def run_pantograph_contact(road_path: str | Path | None, out_root: str | Path = "results", *,
                           reference: bool = False, command: list[str] | None = None,
                           **kw) -> dict[str, Any]:
    """Archived run: ``<out_root>/pantograph_contact/<run-id>/`` with ``data/contact.npz``,
    ``figures/contact.png|pdf``, ``summary.json`` (and ``reference`` in it when asked).

    Parameters
    ----------
    road_path : str or Path or None
        Road file for the drive; None with ``reference=True`` runs only the reference.
    out_root : str or Path
        Results root.
    reference : bool
        Also run :func:`railway_reference`.
    **kw
        Passed to :func:`contact_drive`.
    """
    from eroad.archive import RunArchive

    if road_path is None and not reference:
        raise EroadInputError("give a road file (--road) or ask for the railway reference")
    if road_path is not None:  # refuse bad line / pantograph ids before reading anything
        from vehicles.pantograph_model import load_pantograph

        load_line(kw.get("line", "truck_ohl"))
        load_pantograph(kw.get("pantograph", "truck"))
    road = None
    config: dict[str, Any] = {"reference": bool(reference), **{k: v for k, v in kw.items()}}
    if road_path is not None:
        from roadlib.surface import RoadSurface

        road_path = Path(road_path).resolve()
        if not road_path.is_file():
            raise EroadInputError(f"road file not found: {road_path}")
        road = RoadSurface.load(road_path)
        config["road_file"] = str(road_path)
    with RunArchive(STUDY, config, root=out_root, command=command) as run:
        summary: dict[str, Any] = {"study": STUDY}
        if road is not None:
            out = contact_drive(road, **kw)
            _save(run, out)
            figs = plot_contact(run.data_dir, run.figures_dir / "contact.png")
            summary.update({"config": out["config"], "contact": out["stats"],
                            "contact_base_at_rest": out["stats_static"],
                            "lateral": out["lateral"], "wall": out["wall"],
                            "tractor": out["tractor"],
                            "figures": [str(p.relative_to(run.path)) for p in figs]})
        if reference:
            summary["reference"] = railway_reference()
        run.write_summary(summary)
    summary["path"] = str(run.path)
    return summary
