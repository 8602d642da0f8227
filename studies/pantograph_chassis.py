"""Chassis-stiffness study in contact-force terms: frame and DCDC-mount stiffness of the
e-tractor against the contact-force quality of its pantograph under the contact line.

What it is for (issue 18, item 5): the chassis-stiffness study
(:mod:`studies.chassis_study`) reports how the frame and DCDC-mount stiffness move the
band energies of the pantograph-base motion; an electrified-road engineer decides on the
contact force instead.  For every frame x mount configuration this module runs one drive
of :func:`studies.pantograph_contact.contact_drive` (tractor drive, DCDC-top motion by
the paper's kinematics, its vertical part ``Tz`` fed into the lumped pantograph in
penalty contact with the FE contact line, the lateral part through the head's lateral
DOF) and reports the EN 50367-style statistics (mean, sd, Fm +/- 3 sd, actual min and
max, contact loss) and the lateral offset against the head's half-width.  One extra run
holds the base still on the same line, speed, travel and time grid; the difference
``dF = F(drive) - F(base still)`` is the part of the contact force the base excitation
causes, split into frequency bands (periodogram, Parseval-exact) together with the base
velocity in the same bands.

* :func:`study_cases` -- the case list (one per configuration plus the still base);
* :func:`contact_case` -- the case function (module level, runs in a Dask worker
  process; Exudyn holds the GIL, so parallel work needs processes);
* :func:`band_rms` -- RMS of a signal per frequency band (periodogram);
* :func:`collect` -- the table (one row per configuration and one for the still base);
* :func:`plot_pantograph_chassis` -- the figure, from the saved table only;
* :func:`run_pantograph_chassis` -- all of it, archived.

Decisions: the road is one road file (default in the CLI: the identified road of the
committed reference run); the drive is as long as the road allows at the speed (whole
seconds, see :func:`studies.pantograph_contact.contact_drive`); statistics over the
contact run after its first second, 20 Hz low-pass (EN 50318); contact loss from the
unfiltered force.  The frame factors and mount factors default to the chassis study's.

Road realisations (``seeds``, since 2026-11-25): the grid can also be driven over
statistically equivalent roads (:func:`studies.chassis_study.road_specs`: the road file's
own generator segments, or an ISO 8608 fit of a measured or identified road, new phases).
One road is one draw: a chassis difference smaller than the spread of one configuration
over equivalent roads is not a property of the chassis. The figure, ``table.md``'s first
table and the summary's top-level numbers stay the road file's; :func:`realisation_summary`
and ``figures/realisations.png`` put every road side by side, with each configuration's sd
paired against the nominal configuration on the same road (the road's part cancels).

What it is not: a new tractor, pantograph or line model; one speed per run.
"""
from __future__ import annotations

import math
import os
import shutil
import time as _time
from pathlib import Path
from typing import Any

import numpy as np

from eroad.errors import EroadInputError

__all__ = ["STUDY", "FRAME_FACTORS", "MOUNT_FACTORS", "FORCE_BANDS", "TABLE_COLUMNS",
           "code_version", "study_cases", "contact_case", "band_rms", "collect",
           "table_markdown", "plot_pantograph_chassis", "run_pantograph_chassis",
           "realisation_summary", "plot_realisations", "FILE_ROAD"]

#: study name (folder under the results root)
STUDY = "pantograph_chassis"
#: frame stiffness factors (as the chassis-stiffness study; "rigid": one rigid body)
FRAME_FACTORS: tuple = (0.25, 0.5, 1.0, 2.0, 4.0, 16.0, "rigid")
#: DCDC mount stiffness factors (as the chassis-stiffness study)
MOUNT_FACTORS: tuple = (0.5, 1.0, 2.0)
#: bands of the base-induced force [Hz]: the chassis study's bands below 15 Hz, then
#: 15-20 Hz (inside the EN 50318 20 Hz statistics window) and everything above 20 Hz
#: (removed from the statistics by the low-pass, but present in the unfiltered force
#: that decides contact loss); the upper edge None means the Nyquist frequency
FORCE_BANDS: tuple = ((0.0, 0.5), (0.5, 5.0), (5.0, 15.0), (15.0, 20.0), (20.0, None))
#: statistics start this long after the start of the contact run [s]
T_START = 1.0
#: ``road`` of the road file's rows (equivalent realisations: ``realisation 1``, ...)
FILE_ROAD = "road file"
#: sources whose content is part of the cache's code version
_CODE_FILES = ("studies/pantograph_chassis.py", "studies/pantograph_contact.py",
               "studies/figure11.py", "studies/pantograph.py", "studies/chassis_study.py",
               "catenary/*.py", "catenary/data/*.toml", "vehicles/*.py",
               "vehicles/effects/*.py", "vehicles/params/*.toml", "vehicles/data/*.toml",
               "roadlib/*.py")


def _band_label(band) -> str:
    lo, hi = band
    if hi is None:
        return f">{lo:g}"
    if lo == 0:
        return f"<{hi:g}"
    return f"{lo:g}-{hi:g}"


#: the table's columns, in order (units in the names; ``frame`` "-" on the still row)
TABLE_COLUMNS: tuple = (
    "base", "road", "frame", "mount", "frame_torsion_hz", "frame_bending_hz", "dcdc_bounce_hz",
    "base_z_rms_mm", "base_vz_rms_mm_s",
    "mean_N", "sd_N", "fm_minus_3sd_N", "fm_plus_3sd_N", "min_N", "max_N",
    "unfiltered_min_N", "loss_percent",
    "base_induced_sd_N", "base_az_rms_0_20Hz_m_s2", "inertia_scale_N",
    *(f"dF_rms_{_band_label(b)}Hz_N" for b in FORCE_BANDS),
    *(f"vz_rms_{_band_label(b)}Hz_mm_s" for b in FORCE_BANDS),
    "lateral_max_mm", "lateral_rms_mm", "head_half_width_mm", "lateral_margin_mm",
    "lateral_beyond_percent", "duration_s", "contact_wall_s", "tyre_lift_off_percent", "tyres")


def code_version() -> str:
    """Cache code-version token: ``eroad-<version>+<sha256 of the sources, 12 hex>`` over
    this module, the contact study, the kinematics, the catenary and pantograph models
    and their data, the vehicle models and roadlib (a change of any of them invalidates
    the cached cases)."""
    from studies.sweep import code_version_of_files

    return code_version_of_files(_CODE_FILES, Path(__file__).resolve().parents[1])


def _frame_value(frame):
    if isinstance(frame, str) and frame.strip().lower() == "rigid":
        return "rigid"
    f = float(frame)
    if not (math.isfinite(f) and f > 0):
        raise EroadInputError(f"frame stiffness factor must be positive or 'rigid', got {frame!r}")
    return f


def study_cases(road_spec: dict, *, frames=FRAME_FACTORS, mounts=MOUNT_FACTORS,
                speed_kmh: float = 80.0, duration: float = 30.0, t_skip: float = 1.0,
                line: str = "truck_ohl", pantograph: str = "truck", dt: float = 1e-3,
                vehicle: str = "e_tractor", frame_friction: float | None = None) -> list[dict]:
    """Case list: every frame x mount configuration, then one case with the base still.

    Parameters
    ----------
    road_spec : dict
        A road spec of :func:`studies.chassis_study.road_specs` (``kind`` ``"file"``).
    frames : sequence
        Frame stiffness factors [-] and/or ``"rigid"``.
    mounts : sequence of float
        DCDC mount stiffness factors [-].
    speed_kmh, duration, t_skip, line, pantograph, dt, vehicle, frame_friction
        As :func:`studies.pantograph_contact.contact_drive`.

    Returns
    -------
    list of dict
        JSON-able cases for :func:`contact_case`; the still-base case is the last one
        (frame 1, mount 1: its drive only sets the travel, its base motion is scaled by 0).
        A line or pantograph given as a file carries the file's sha256, so a cached case
        is not reused after the file was edited (the built-in files are part of the
        cache's code version).
    """
    frames = [_frame_value(f) for f in frames]
    mounts = [float(m) for m in mounts]
    if not frames or not mounts:
        raise EroadInputError("give at least one frame factor and one mount factor")
    for m in mounts:
        if not (math.isfinite(m) and m > 0):
            raise EroadInputError(f"DCDC mount stiffness factor must be positive, got {m}")
    if not (math.isfinite(speed_kmh) and 0 < speed_kmh <= 200):
        raise EroadInputError(f"speed must be in (0, 200] km/h, got {speed_kmh}")
    base = {"vehicle": str(vehicle), "road": road_spec, "speed_kmh": float(speed_kmh),
            "duration": float(duration), "t_skip": float(t_skip), "line": str(line),
            "pantograph": str(pantograph), "dt": float(dt)}
    for key, value in (("line", line), ("pantograph", pantograph)):
        if Path(value).suffix.lower() == ".toml" and Path(value).is_file():
            from eroad.archive import file_sha256

            base[f"{key}_sha256"] = file_sha256(value)
    if frame_friction is not None:  # absent otherwise: cases cached before it stay valid
        from vehicles.pantograph_model import load_pantograph, with_frame_friction

        base["frame_friction"] = with_frame_friction(load_pantograph(pantograph),
                                                     frame_friction).frame_friction
    cases = [{**base, "frame": f, "mount": m, "base_scale": 1.0}
             for m in mounts for f in frames]
    cases.append({**base, "frame": 1.0, "mount": 1.0, "base_scale": 0.0})
    return cases


def band_rms(x, fs: float, bands=FORCE_BANDS, order: int = 0) -> np.ndarray:
    """RMS of ``x`` (mean removed) in each frequency band, from the one-sided periodogram.

    The squares of the band values add up to the variance of ``x`` when the bands tile
    0 ... fs/2 (Parseval; bin ``k`` at ``k fs / n`` belongs to the band with
    ``lo <= f < hi``, the last band includes the Nyquist bin).  ``order`` 1 gives the RMS
    of the time derivative of ``x`` per band (each bin weighted by ``(2 pi f)^2``).

    Parameters
    ----------
    x : array_like, shape (n,)
    fs : float
        Sample rate [Hz].
    bands : sequence of (float, float or None)
        Band edges [Hz]; None as upper edge: fs/2.

    Returns
    -------
    numpy.ndarray, shape (len(bands),)
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    if n < 2:
        raise EroadInputError("band_rms: fewer than 2 samples")
    X = np.fft.rfft(x - x.mean())
    p = np.abs(X) ** 2 / n ** 2
    p[1:] *= 2.0
    if n % 2 == 0:
        p[-1] /= 2.0  # the Nyquist bin is not doubled
    f = np.fft.rfftfreq(n, 1.0 / fs)
    p = p * (2 * math.pi * f) ** (2 * int(order))
    out = np.zeros(len(bands))
    for i, (lo, hi) in enumerate(bands):
        top = np.inf if hi is None else hi
        out[i] = math.sqrt(float(np.sum(p[(f >= lo) & (f < top)])))
    return out


def contact_case(case: dict) -> dict:
    """One configuration: drive, base motion, pantograph-contact run and statistics.

    Parameters
    ----------
    case : dict
        From :func:`study_cases`.

    Returns
    -------
    dict
        Scalars: the contact statistics (``mean``, ``sd``, ``stat_min``, ``stat_max``,
        ``actual_min``, ``actual_max``, ``loss_percent``, ``n_samples`` [N, %]),
        ``unfiltered_min`` [N], the lateral statistics [m, %], ``base_z_rms`` [m],
        ``frame_torsion_hz``, ``frame_bending_hz``, ``dcdc_bounce_hz`` (NaN if absent),
        ``duration_s``, ``n_spans``, ``n_dof``, ``wall_vehicle_s``, ``wall_contact_s``;
        arrays ``time`` [s], ``force`` [N] (unfiltered, every contact step) and
        ``base_z`` [m] (on the same grid).
    """
    from studies.chassis_study import build_road
    from studies.figure11 import mode_table, tractor_variant
    from studies.pantograph_contact import contact_drive

    road = build_road(case["road"])
    rigid = case["frame"] == "rigid"
    chassis = "rigid" if rigid else "flexible"
    ff = 1.0 if rigid else float(case["frame"])
    out = contact_drive(road, speed_kmh=float(case["speed_kmh"]),
                        duration=float(case["duration"]), line=case["line"],
                        pantograph=case["pantograph"], chassis=chassis, frame_factor=ff,
                        mount_factor=float(case["mount"]), dt=float(case["dt"]),
                        t_skip=float(case["t_skip"]), compare_static=False,
                        base_scale=float(case["base_scale"]),
                        frame_friction=case.get("frame_friction"))
    res = out["result"]
    modes, _ = mode_table(tractor_variant(case["vehicle"], float(case["mount"])), chassis, ff,
                          f_max=80.0)

    def first(label):
        for m in modes:
            if m["label"] == label or m["label"].startswith(label + " "):
                return float(m["freq_hz"])
        return float("nan")

    sel = res.time >= T_START - 1e-12
    return {**{k: v for k, v in out["stats"].items() if k != "lowpass_hz"},
            "unfiltered_min": float(np.min(res["force"][sel])),
            **{f"lateral_{k}": v for k, v in out["lateral"].items()},
            "base_z_rms": float(out["config"]["base_z_rms_m"]),
            "frame_torsion_hz": first("frame torsion"),
            "frame_bending_hz": first("frame bending"),
            "dcdc_bounce_hz": first("DCDC bounce"),
            "duration_s": float(out["config"]["duration_s"]),
            "n_spans": int(out["config"]["n_spans"]), "n_dof": int(out["config"]["n_dof"]),
            "wall_vehicle_s": float(out["wall"]["vehicle_s"]),
            "wall_contact_s": float(out["wall"]["contact_s"]),
            "tyre_lift_off_percent": float(out["tractor"]["tyre_lift_off_percent"]),
            "tyres": str(out["tractor"].get("tyres", "bilateral")),
            "time": np.asarray(res.time, dtype=float),
            "force": np.asarray(res["force"], dtype=float),
            "base_z": np.asarray(res["base_z"], dtype=float)}


def collect(cases: list[dict], results: list[dict], lowpass_hz: float = 20.0):
    """The study table and the arrays behind it.

    The still-base case (``base_scale`` 0) gives ``F0``; each configuration's
    base-induced force is ``dF = F - F0`` on the common time grid, its sd after the same
    20 Hz low-pass as the statistics (``base_induced_sd_N``) and its unfiltered RMS per
    :data:`FORCE_BANDS` band; the base velocity ``d(base_z)/dt`` per band likewise.  All
    over ``t >= T_START``.

    ``inertia_scale_N`` bounds the inertial coupling of the base acceleration that the
    lumped chain leaves out (its masses feel the base through ``k3, c3`` only).  In an
    articulated frame on a moving base a part ``i`` moves with the share ``r_i`` in
    [0, 1] of the relative head-base motion (``z_i = z_b + r_i q``, ``q = z_head - z_b``);
    Lagrange's equation in ``q`` with the head held on the wire gives the contact force
    the extra term ``-sum m_i r_i (1 - r_i) a_b``, and ``r (1 - r) <= 1/4``.  The
    head (``r = 1``) adds nothing, so ``inertia_scale_N = (m2 + m3) / 4 x`` RMS base
    acceleration below 20 Hz is an upper bound of that term's RMS for frame parts of the
    lumped masses (not a result of the model).

    Returns
    -------
    (pandas.DataFrame, dict)
        The table (:data:`TABLE_COLUMNS`; configurations in case order, the still base
        last) and arrays ``time``, ``force`` (n_rows, n), ``base_z`` (n_rows, n).
    """
    import pandas as pd

    from catenary.stats import lowpass
    from vehicles.pantograph_model import load_pantograph

    still = [i for i, c in enumerate(cases) if float(c["base_scale"]) == 0.0]
    if len(still) != 1:
        raise EroadInputError("the study needs exactly one case with the base still")
    r0 = results[still[0]]
    t = np.asarray(r0["time"])
    fs = 1.0 / float(t[1] - t[0])
    sel = t >= T_START - 1e-12
    f0 = np.asarray(r0["force"])
    f0_lp = lowpass(f0, fs, lowpass_hz)
    rows, forces, bases = [], [], []
    order = [i for i in range(len(cases)) if i != still[0]] + still
    for i in order:
        c, r = cases[i], results[i]
        ti = np.asarray(r["time"])
        if ti.shape != t.shape or np.max(np.abs(ti - t)) > 1e-9:
            raise EroadInputError(f"case {i}: time grid differs from the still-base case")
        f = np.asarray(r["force"])
        zb = np.asarray(r["base_z"])
        is_still = i == still[0]
        dF = f - f0
        vz = np.gradient(zb, t)
        pp = load_pantograph(c["pantograph"])
        m_frame = pp.upper_mass + pp.lower_mass
        a_lo = float(band_rms(vz[sel], fs, ((0.0, 20.0),), order=1)[0])
        d_band = band_rms(dF[sel], fs)
        v_band = band_rms(vz[sel], fs)
        row = {"base": "still" if is_still else "drive",
               "road": str(c.get("road_label", FILE_ROAD)),
               "frame": "-" if is_still else str(c["frame"]),
               "mount": float("nan") if is_still else float(c["mount"]),
               "frame_torsion_hz": float("nan") if is_still else r["frame_torsion_hz"],
               "frame_bending_hz": float("nan") if is_still else r["frame_bending_hz"],
               "dcdc_bounce_hz": float("nan") if is_still else r["dcdc_bounce_hz"],
               "base_z_rms_mm": 1e3 * r["base_z_rms"],
               "base_vz_rms_mm_s": 1e3 * float(np.std(vz[sel])),
               "mean_N": r["mean"], "sd_N": r["sd"], "fm_minus_3sd_N": r["stat_min"],
               "fm_plus_3sd_N": r["stat_max"], "min_N": r["actual_min"],
               "max_N": r["actual_max"], "unfiltered_min_N": r["unfiltered_min"],
               "loss_percent": r["loss_percent"],
               "base_induced_sd_N": float(np.std((lowpass(f, fs, lowpass_hz) - f0_lp)[sel])),
               "base_az_rms_0_20Hz_m_s2": a_lo, "inertia_scale_N": 0.25 * m_frame * a_lo}
        for b, dv, vv in zip(FORCE_BANDS, d_band, v_band):
            row[f"dF_rms_{_band_label(b)}Hz_N"] = float(dv)
            row[f"vz_rms_{_band_label(b)}Hz_mm_s"] = 1e3 * float(vv)
        row.update({"lateral_max_mm": 1e3 * r["lateral_max_abs_offset"],
                    "lateral_rms_mm": 1e3 * r["lateral_rms_offset"],
                    "head_half_width_mm": 1e3 * r["lateral_half_width"],
                    "lateral_margin_mm": 1e3 * r["lateral_margin"],
                    "lateral_beyond_percent": r["lateral_beyond_percent"],
                    "duration_s": r["duration_s"], "contact_wall_s": r["wall_contact_s"],
                    "tyre_lift_off_percent": (float("nan") if is_still else
                                              float(r.get("tyre_lift_off_percent", float("nan")))),
                    "tyres": "" if is_still else str(r.get("tyres", "bilateral"))})
        rows.append(row)
        forces.append(f)
        bases.append(zb)
    table = pd.DataFrame(rows, columns=list(TABLE_COLUMNS))
    return table, {"time": t, "force": np.array(forces), "base_z": np.array(bases)}


def file_rows(table):
    """The road file's rows (every row of a table written before the ``road`` column)."""
    if "road" not in table:
        return table
    return table[table["road"].astype(str) == FILE_ROAD]


def _f(v, fmt="{:.1f}") -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else fmt.format(v)


def table_markdown(table) -> str:
    """Two markdown tables of the road file's rows: the contact-force quality per
    configuration and the base-induced force per band with the base velocity per band;
    with equivalent road realisations a third: sd and loss per configuration and road."""
    full = table
    table = file_rows(table)
    bl = [_band_label(b) for b in FORCE_BANDS]
    lines = ["| frame | mount | Fm [N] | sd [N] | Fm-3sd [N] | min [N] | max [N] | "
             "loss [%] | base-induced sd [N] | lateral max / half-width [mm] | "
             "tyre lift-off [% of drive] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for _, r in table.iterrows():
        fr = "base still" if r["base"] == "still" else r["frame"]
        mo = "-" if r["base"] == "still" else f"{r['mount']:g}"
        lines.append(f"| {fr} | {mo} | {_f(r['mean_N'])} | {_f(r['sd_N'], '{:.2f}')} | "
                     f"{_f(r['fm_minus_3sd_N'])} | {_f(r['min_N'])} | {_f(r['max_N'])} | "
                     f"{_f(r['loss_percent'], '{:.2f}')} | "
                     f"{_f(r['base_induced_sd_N'], '{:.2f}')} | "
                     f"{_f(r['lateral_max_mm'])} / {_f(r['head_half_width_mm'], '{:.0f}')} | "
                     f"{_f(r.get('tyre_lift_off_percent', float('nan')), '{:.2f}')} |")
    lines += ["", "Base-induced contact force dF = F(drive) - F(base still), unfiltered RMS "
              "per band [N], and base vertical velocity RMS per band [mm/s]:", "",
              "| frame | mount | " + " | ".join(f"dF {b} Hz" for b in bl) + " | "
              + " | ".join(f"vz {b} Hz" for b in bl) + " |",
              "|---|---|" + "---|" * (2 * len(bl))]
    for _, r in table[table["base"] == "drive"].iterrows():
        lines.append(f"| {r['frame']} | {r['mount']:g} | "
                     + " | ".join(_f(r[f"dF_rms_{b}Hz_N"], "{:.2f}") for b in bl) + " | "
                     + " | ".join(_f(r[f"vz_rms_{b}Hz_mm_s"], "{:.1f}") for b in bl) + " |")
    roads = _roads(full)
    if len(roads) > 1:
        drive = full[full["base"] == "drive"]
        lines += ["", "Every road (the file and its statistically equivalent realisations): "
                  "contact-force sd [N] / contact loss [%] / tyre lift-off [% of samples]; "
                  "paired: sd minus the nominal configuration's (frame 1, mount 1) on the "
                  "same road [N]:", "",
                  "| frame | mount | " + " | ".join(roads) + " | paired, per road |",
                  "|---|---|" + "---|" * (len(roads) + 1)]
        paired = _paired_sd(drive, roads)
        for (fr, mo), g in drive.groupby(["frame", "mount"], sort=False):
            cells = []
            for rd in roads:
                r = g[g["road"] == rd]
                cells.append("-" if r.empty else
                             f"{_f(r['sd_N'].iloc[0], '{:.2f}')} / "
                             f"{_f(r['loss_percent'].iloc[0], '{:.2f}')} / "
                             f"{_f(r['tyre_lift_off_percent'].iloc[0], '{:.1f}')}")
            pd_ = paired.get((str(fr), float(mo)))
            lines.append(f"| {fr} | {mo:g} | " + " | ".join(cells) + " | "
                         + ("-" if pd_ is None else
                            ", ".join(_f(v, "{:+.2f}") for v in pd_)) + " |")
    return "\n".join(lines) + "\n"


def _roads(table) -> list[str]:
    """Road labels of a table, the file first."""
    if "road" not in table:
        return [FILE_ROAD]
    labs = list(dict.fromkeys(table["road"].astype(str)))
    return sorted(labs, key=lambda r: (r != FILE_ROAD, r))


def _nominal_key(drive):
    """(frame, mount) of the nominal configuration: frame 1 and mount 1 where in the grid,
    else the configuration closest to them."""
    keys = [(str(f), float(m)) for f, m in zip(drive["frame"], drive["mount"])]

    def dist(k):
        f = 1e3 if k[0] == "rigid" else float(k[0])
        return abs(math.log(f)) + abs(math.log(k[1]))
    return min(dict.fromkeys(keys), key=dist)


def _paired_sd(drive, roads) -> dict:
    """(frame, mount) -> per road, sd minus the nominal configuration's sd on that road [N]."""
    nom = _nominal_key(drive)
    ref = {}
    for rd in roads:
        r = drive[(drive["road"] == rd) & (drive["frame"].astype(str) == nom[0])
                  & (drive["mount"] == nom[1])]
        if not r.empty:
            ref[rd] = float(r["sd_N"].iloc[0])
    out = {}
    for (fr, mo), g in drive.groupby(["frame", "mount"], sort=False):
        vals = []
        for rd in roads:
            r = g[g["road"] == rd]
            if not r.empty and rd in ref:
                vals.append(float(r["sd_N"].iloc[0]) - ref[rd])
        out[(str(fr), float(mo))] = vals
    return out


def realisation_summary(table) -> dict | None:
    """How the contact statistics move over equivalent roads against over the chassis grid.

    Per road: the sd range over the configurations, the largest contact loss and tyre
    lift-off. Per configuration: the sd's median and range over the roads. Paired: each
    configuration's sd minus the nominal configuration's on the same road, its range over
    the roads, and on how many roads its sign is that of the road file's. The two
    spreads the engineer weighs: ``chassis_span_N`` (largest sd minus smallest over the
    configurations, per road) against ``road_span_N`` (largest minus smallest over the
    roads, per configuration). None with a single road.
    """
    roads = _roads(table)
    if len(roads) < 2:
        return None
    drive = table[table["base"] == "drive"]
    per_road = {}
    for rd in roads:
        g = drive[drive["road"] == rd]
        lift = g["tyre_lift_off_percent"].to_numpy(float)
        per_road[rd] = {"sd_N_range": [float(g["sd_N"].min()), float(g["sd_N"].max())],
                        "max_loss_percent": float(g["loss_percent"].max()),
                        "lowest_unfiltered_force_N": float(g["unfiltered_min_N"].min()),
                        "max_tyre_lift_off_percent": (float(np.nanmax(lift))
                                                      if np.isfinite(lift).any() else None)}
    paired = _paired_sd(drive, roads)
    per_config = []
    for (fr, mo), g in drive.groupby(["frame", "mount"], sort=False):
        sd = g["sd_N"].to_numpy(float)
        pv = np.asarray(paired[(str(fr), float(mo))], float)
        sign0 = np.sign(pv[0]) if pv.size else 0.0
        per_config.append({
            "frame": str(fr), "mount": float(mo), "sd_N_median": float(np.median(sd)),
            "sd_N_range": [float(sd.min()), float(sd.max())],
            "loss_percent_range": [float(g["loss_percent"].min()),
                                   float(g["loss_percent"].max())],
            "paired_sd_N": [float(v) for v in pv],
            "paired_sd_N_range": [float(pv.min()), float(pv.max())] if pv.size else None,
            "paired_same_sign_roads": (int(np.sum(np.sign(pv) == sign0)) if sign0 != 0
                                       else None)})
    chassis = [v["sd_N_range"][1] - v["sd_N_range"][0] for v in per_road.values()]
    road = [c["sd_N_range"][1] - c["sd_N_range"][0] for c in per_config]
    nom = _nominal_key(drive)
    return {"roads": roads, "n_roads": len(roads),
            "nominal_configuration": {"frame": nom[0], "mount": nom[1]},
            "per_road": per_road, "per_configuration": per_config,
            "chassis_span_N": [float(min(chassis)), float(max(chassis))],
            "road_span_N": [float(min(road)), float(max(road))],
            "max_loss_percent_any_road": float(drive["loss_percent"].max())}


def _frame_x(frames: list[str]) -> tuple[dict, list[float], list[str]]:
    """x positions of the frame factors on a log axis (rigid: one factor 4 beyond the
    stiffest flexible frame)."""
    flex = sorted({float(f) for f in frames if f != "rigid"})
    pos = {str(f): f for f in flex}
    for f in frames:
        if f != "rigid":
            pos[f] = float(f)
    if "rigid" in frames:
        pos["rigid"] = (flex[-1] if flex else 1.0) * 4.0
    ticks = flex + ([pos["rigid"]] if "rigid" in frames else [])
    labels = [f"{f:g}" for f in flex] + (["rigid"] if "rigid" in frames else [])
    return pos, ticks, labels


def _frame_axis(a, ticks, labels) -> None:
    """A log frame-factor x axis with the grid's factors as ticks (rigid last)."""
    a.set_xscale("log")
    a.set_xticks(ticks)
    a.set_xticklabels(labels)
    a.minorticks_off()
    a.set_xlabel("frame stiffness factor [-]")
    a.grid(True, alpha=0.3)


def plot_pantograph_chassis(table_csv: str | Path, path: str | Path, *, title: str = ""
                            ) -> list[Path]:
    """The study figure from the saved table (``table.csv``): contact-force sd, contact
    loss (with the lowest unfiltered force), base-induced sd and its bands, against the
    frame stiffness factor, one line per DCDC mount factor; writes PNG and PDF."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    df = file_rows(pd.read_csv(table_csv, dtype={"frame": str, "road": str}))
    drive = df[df["base"] == "drive"].copy()
    still = df[df["base"] == "still"]
    frames = list(dict.fromkeys(drive["frame"]))
    pos, ticks, tlabels = _frame_x(frames)
    drive["x"] = [pos[f] for f in drive["frame"]]
    mounts = sorted(drive["mount"].unique())
    cmap = plt.get_cmap("viridis")
    colors = {m: cmap(0.15 + 0.7 * k / max(1, len(mounts) - 1)) for k, m in enumerate(mounts)}

    fig, ax = plt.subplots(2, 2, figsize=(12, 8.5))

    def frame_axis(a):
        _frame_axis(a, ticks, tlabels)

    for m in mounts:
        g = drive[drive["mount"] == m].sort_values("x")
        flex = g[g["frame"] != "rigid"]
        rig = g[g["frame"] == "rigid"]
        kw = dict(color=colors[m], lw=1.3)
        for a, col in ((ax[0, 0], "sd_N"), (ax[0, 1], "loss_percent"),
                       (ax[1, 0], "base_induced_sd_N")):
            a.plot(flex["x"], flex[col], "o-", label=f"DCDC mounts x{m:g}", **kw)
            a.plot(rig["x"], rig[col], "*", ms=11, **kw)
    if len(still):
        s0 = float(still["sd_N"].iloc[0])
        ax[0, 0].axhline(s0, color="k", ls="--", lw=1.0, label=f"base still: {s0:.2f} N")
    ax[0, 0].set_ylabel("contact-force sd [N] (20 Hz low-pass)")
    span = float(drive["sd_N"].max() - drive["sd_N"].min())
    ax[0, 0].set_title(f"(a) contact-force sd (all configurations within {span:.2f} N = "
                       f"{100 * span / float(drive['sd_N'].mean()):.1f} %)", fontsize=10)
    ax[0, 0].legend(fontsize=8)
    ax[0, 1].set_ylabel("contact loss [% of time]")
    lo = float(np.nanmin(drive["unfiltered_min_N"]))
    mean = float(np.nanmean(drive["mean_N"]))
    ax[0, 1].set_title(f"(b) contact loss (lowest unfiltered force {lo:.1f} N, "
                       f"mean {mean:.1f} N)", fontsize=10)
    if float(np.nanmax(drive["loss_percent"])) == 0.0:
        ax[0, 1].set_ylim(-0.5, 5.0)
        ax[0, 1].text(0.5, 0.2, "no contact loss in any configuration", ha="center",
                      transform=ax[0, 1].transAxes, fontsize=10)
    tw = ax[0, 1].twinx()
    for m in mounts:
        g = drive[drive["mount"] == m].sort_values("x")
        tw.plot(g["x"], g["unfiltered_min_N"], "s--", color=colors[m], ms=4, lw=0.9)
    vals = list(drive["unfiltered_min_N"])
    if len(still):
        tw.axhline(float(still["unfiltered_min_N"].iloc[0]), color="k", ls=":", lw=1.0)
        vals.append(float(still["unfiltered_min_N"].iloc[0]))
    lo_v, hi_v = float(np.nanmin(vals)), float(np.nanmax(vals))
    rng = max(hi_v - lo_v, 0.5)
    tw.set_ylim(lo_v - 1.5 * rng, hi_v + 0.3 * rng)  # squares above the loss markers
    tw.set_ylabel("lowest unfiltered force [N] (squares; dotted: base still)", fontsize=8, color="0.3")
    tw.tick_params(axis="y", colors="0.3")
    from matplotlib.lines import Line2D
    ax[0, 1].legend(handles=[Line2D([], [], marker="o", color="0.4", ls="-", label="contact loss [%] (left axis)"),
                             Line2D([], [], marker="s", color="0.4", ls="--", ms=4,
                                    label="lowest unfiltered force [N] (right axis)")],
                    fontsize=7, loc="upper center", bbox_to_anchor=(0.5, 0.86), ncol=2)
    ax[1, 0].set_ylabel("sd of F(drive) - F(base still) [N] (20 Hz)")
    ax[1, 0].set_title("(c) part of the force the base excitation causes", fontsize=10)
    for a in (ax[0, 0], ax[0, 1], ax[1, 0]):
        frame_axis(a)

    # (d) base-induced force per band, nominal mounts, stacked as mean squares
    m_nom = min(mounts, key=lambda m: abs(m - 1.0))
    g = drive[drive["mount"] == m_nom].sort_values("x")
    bl = [_band_label(b) for b in FORCE_BANDS]
    xs = np.arange(len(g))
    bottom = np.zeros(len(g))
    bcols = plt.get_cmap("tab10")
    for k, b in enumerate(bl):
        v = g[f"dF_rms_{b}Hz_N"].to_numpy() ** 2
        ax[1, 1].bar(xs, v, bottom=bottom, color=bcols(k), label=f"{b} Hz")
        bottom += v
    ax[1, 1].set_xticks(xs)
    ax[1, 1].set_xticklabels([("rigid" if f == "rigid" else f"{float(f):g}") for f in g["frame"]])
    ax[1, 1].set_xlabel(f"frame stiffness factor [-] (DCDC mounts x{m_nom:g})")
    ax[1, 1].set_ylabel("mean square of F(drive) - F(base still) [N²], unfiltered")
    ax[1, 1].set_title("(d) base-induced force by frequency band", fontsize=10)
    ax[1, 1].set_ylim(0, 1.35 * float(bottom.max()) if bottom.max() > 0 else 1.0)
    ax[1, 1].legend(fontsize=8, title="band", title_fontsize=8, ncol=len(bl),
                    loc="upper center")
    ax[1, 1].grid(True, axis="y", alpha=0.3)
    fig.suptitle(title or "Contact-force quality against frame and DCDC-mount stiffness",
                 fontsize=11)
    from studies.pantograph_contact import LIFT_OFF_LIMIT_PERCENT, tractor_range
    lift = (drive["tyre_lift_off_percent"].to_numpy(float) if "tyre_lift_off_percent" in drive
            else np.full(len(drive), np.nan))
    top = 0.96
    if np.isfinite(lift).any() and \
            tractor_range(np.nanmax(lift), _grid_tyres(drive))["within_model_range"] is False:
        fig.text(0.5, 0.918, f"OUTSIDE THE TRACTOR MODEL'S RANGE: a tyre would lift off in up to "
                 f"{np.nanmax(lift):.1f} % of the drive (limit {LIFT_OFF_LIMIT_PERCENT:g} %).\nThe "
                 "model's tyres stay on the road, so these statistics are not the truck's.",
                 ha="center", va="bottom", color="C3", fontsize=9, fontweight="bold")
        top = 0.91
    elif np.isfinite(lift).any() and np.nanmax(lift) > 0:
        fig.text(0.5, 0.925, f"tractor: a tyre was off the road in up to {np.nanmax(lift):.1f} % of "
                 "the drive's samples (one-sided tyres: modelled)", ha="center", va="bottom",
                 color="0.35", fontsize=8.5)
        top = 0.925
    fig.tight_layout(rect=(0, 0, 1, top))
    from studies.pantograph_contact import save_png_pdf
    return save_png_pdf(fig, path, dpi=110)


def plot_realisations(table_csv: str | Path, path: str | Path, *, title: str = ""
                      ) -> list[Path]:
    """Every road side by side (from the saved table): (a) contact-force sd against the
    frame factor at the nominal mounts, one line per road; (b) the same paired against the
    nominal configuration on its own road; (c) contact loss. Writes PNG and PDF."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    df = pd.read_csv(table_csv, dtype={"frame": str, "road": str})
    drive = df[df["base"] == "drive"].copy()
    roads = _roads(drive)
    frames = list(dict.fromkeys(drive["frame"]))
    pos, ticks, tlabels = _frame_x(frames)
    drive["x"] = [pos[f] for f in drive["frame"]]
    nom = _nominal_key(drive)
    paired = _paired_sd(drive, roads)
    drive["paired"] = [paired[(str(f), float(m))][roads.index(r)]
                       if len(paired[(str(f), float(m))]) == len(roads) else np.nan
                       for f, m, r in zip(drive["frame"], drive["mount"], drive["road"])]
    g_nom = drive[drive["mount"] == nom[1]]
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.8))
    for k, rd in enumerate(roads):
        g = g_nom[g_nom["road"] == rd].sort_values("x")
        kw = dict(color="k" if rd == FILE_ROAD else plt.get_cmap("tab10")(k % 10),
                  lw=1.8 if rd == FILE_ROAD else 1.1, ms=5)
        for a, col in zip(ax, ("sd_N", "paired", "loss_percent")):
            a.plot(g["x"], g[col], "o-", label=rd, **kw)
    still = df[df["base"] == "still"]
    if len(still):
        ax[0].axhline(float(still["sd_N"].iloc[0]), color="0.5", ls="--", lw=1.0,
                      label=f"base still: {float(still['sd_N'].iloc[0]):.2f} N")
    chassis = max(float(g["sd_N"].max() - g["sd_N"].min()) for _, g in drive.groupby("road"))
    road = max(float(g["sd_N"].max() - g["sd_N"].min())
               for _, g in drive.groupby(["frame", "mount"]))
    ax[0].set_ylabel("contact-force sd [N] (20 Hz low-pass)")
    ax[0].set_title(f"(a) sd per road (DCDC mounts x{nom[1]:g}): chassis grid spans <= "
                    f"{chassis:.2f} N,\none configuration over the roads <= {road:.2f} N",
                    fontsize=9.5)
    ax[1].axhline(0.0, color="0.5", lw=0.8)
    ax[1].set_ylabel("sd minus the nominal configuration's [N]")
    ax[1].set_title(f"(b) paired on each road against frame {nom[0]}, mounts x{nom[1]:g}:\n"
                    "what the chassis changes", fontsize=9.5)
    ax[2].set_ylabel("contact loss [% of time]")
    lmax = float(drive["loss_percent"].max())
    ax[2].set_title(f"(c) contact loss (largest {lmax:.2f} %)", fontsize=9.5)
    if lmax == 0.0:
        ax[2].set_ylim(-0.5, 5.0)
        ax[2].text(0.5, 0.2, "no contact loss on any road", ha="center",
                   transform=ax[2].transAxes, fontsize=10)
    for a in ax:
        _frame_axis(a, ticks, tlabels)
    h, lab = ax[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="lower center", ncol=len(lab), fontsize=8, frameon=False)
    fig.suptitle(title or "Contact-force quality over statistically equivalent roads",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0.06, 1, 0.95))
    from studies.pantograph_contact import save_png_pdf
    return save_png_pdf(fig, path, dpi=110)


def _grid_tyres(drive) -> str:
    """The tyre model of a grid's drives: ``"unilateral"`` only if every drive says so (grids
    made before the column existed were driven with bilateral tyres)."""
    if "tyres" not in drive:
        return "bilateral"
    return "unilateral" if (drive["tyres"].astype(str) == "unilateral").all() else "bilateral"


def _summary(table, cases, sweep, road_label: str) -> dict:
    full = table
    table = file_rows(table)
    drive = table[table["base"] == "drive"]
    still = table[table["base"] == "still"].iloc[0]
    c0 = cases[0]

    def pick(idx):
        r = table.loc[idx]
        return {"frame": r["frame"], "mount": float(r["mount"]), "sd_N": float(r["sd_N"]),
                "base_induced_sd_N": float(r["base_induced_sd_N"])}

    from studies.pantograph_contact import tractor_range

    lift_max = float(np.nanmax(drive["tyre_lift_off_percent"].to_numpy(float))) \
        if drive["tyre_lift_off_percent"].notna().any() else float("nan")
    tractor = tractor_range(lift_max, _grid_tyres(drive))
    bl = [_band_label(b) for b in FORCE_BANDS]
    band_ms = {b: float(np.mean(drive[f"dF_rms_{b}Hz_N"] ** 2)) for b in bl}
    tot = sum(band_ms.values())
    return {
        "study": STUDY, "road": road_label, "speed_kmh": float(c0["speed_kmh"]),
        "line": c0["line"], "pantograph": c0["pantograph"],
        "frame_friction_N": c0.get("frame_friction"), "dt_s": float(c0["dt"]),
        "n_configurations": int(len(drive)), "duration_s": float(still["duration_s"]),
        "base_still": {k: float(still[k]) for k in ("mean_N", "sd_N", "fm_minus_3sd_N",
                                                      "min_N", "max_N", "loss_percent")},
        "sd_N_range": [float(drive["sd_N"].min()), float(drive["sd_N"].max())],
        "base_induced_sd_N_range": [float(drive["base_induced_sd_N"].min()),
                                    float(drive["base_induced_sd_N"].max())],
        "lowest_sd": pick(drive["sd_N"].idxmin()), "highest_sd": pick(drive["sd_N"].idxmax()),
        "max_loss_percent": float(drive["loss_percent"].max()),
        "max_tyre_lift_off_percent": lift_max,
        "tractor_tyres": tractor["tyres"],
        "tractor_within_model_range": tractor["within_model_range"],
        "tractor_note": tractor["note"],
        "lowest_unfiltered_force_N": float(drive["unfiltered_min_N"].min()),
        "max_lateral_offset_mm": float(drive["lateral_max_mm"].max()),
        "head_half_width_mm": float(drive["head_half_width_mm"].iloc[0]),
        "base_induced_band_share": {b: (v / tot if tot > 0 else float("nan"))
                                    for b, v in band_ms.items()},
        # base-induced force per unit base velocity, per band [N s/m] (median over the
        # configurations): the damper c3 between base and lower frame if the chain is
        # driven through it alone
        "dF_over_vz_N_s_per_m": {b: float(np.median(drive[f"dF_rms_{b}Hz_N"]
                                                    / (1e-3 * drive[f"vz_rms_{b}Hz_mm_s"])))
                                 for b in bl},
        "inertia_scale_N_range": [float(drive["inertia_scale_N"].min()),
                                  float(drive["inertia_scale_N"].max())],
        "realisations": realisation_summary(full),
        "n_cases": len(sweep.cases), "n_computed": sweep.n_computed,
        "n_cached": sweep.n_cached, "sweep_wall_s": round(sweep.wall_s, 2),
        "case_wall_s_sum": round(float(sum(w for w in sweep.case_wall_s if w)), 2)}


def _write_outputs(folder: Path, table, arrays, title: str) -> list[Path]:
    data = folder / "data"
    figs = folder / "figures"
    data.mkdir(parents=True, exist_ok=True)
    figs.mkdir(parents=True, exist_ok=True)
    table.to_csv(data / "table.csv", index=False, float_format="%.6g")
    (data / "table.md").write_text(table_markdown(table), encoding="utf-8")
    np.savez_compressed(data / "forces.npz", time=arrays["time"].astype(np.float32),
                        force=arrays["force"].astype(np.float32),
                        base_z=arrays["base_z"].astype(np.float32),
                        frame=np.array(table["frame"], dtype=str),
                        road=np.array(table["road"], dtype=str),
                        mount=table["mount"].to_numpy(float),
                        base=np.array(table["base"], dtype=str))
    out = plot_pantograph_chassis(data / "table.csv", figs / "contact_vs_stiffness.png",
                                  title=title)
    if len(_roads(table)) > 1:
        out += plot_realisations(data / "table.csv", figs / "realisations.png",
                                 title=title.replace("vs frame", "over equivalent roads vs frame"))
    return out


def run_pantograph_chassis(road_path: str | Path, out_root: str | Path = "results", *,
                           run_dir: str | Path | None = None, frames=FRAME_FACTORS,
                           mounts=MOUNT_FACTORS, speed_kmh: float = 80.0,
                           duration: float = 30.0, line: str = "truck_ohl",
                           pantograph: str = "truck", dt: float = 1e-3, seeds: int = 0,
                           seed: int = 2026, frame_friction: float | None = None,
                           scheduler: Any = None,
                           n_workers: int = 2, cache_dir: str | Path = ".eroad-cache",
                           progress: bool = True, command: list[str] | None = None) -> dict:
    """Run the study on a road and archive it.

    Parameters
    ----------
    road_path : str or Path
        Road file.
    out_root : str or Path
        Results root: the run goes to ``<out_root>/pantograph_chassis/<run-id>/``
        (:class:`eroad.archive.RunArchive`) unless ``run_dir`` is given.
    run_dir : str or Path, optional
        A named run folder instead (must not exist or be empty; written as a hidden
        temporary folder and renamed into place, ``run.json`` by
        :func:`eroad.archive.run_info`).
    frames, mounts, speed_kmh, duration, line, pantograph, dt, frame_friction
        See :func:`study_cases`.
    seeds, seed
        Statistically equivalent road realisations driven besides the file, and their
        root seed (:func:`studies.chassis_study.road_specs`, as the chassis study); every
        configuration is driven on every road, the still base once.
    scheduler, n_workers, cache_dir, progress
        Passed to :func:`studies.sweep.run_cases` (processes; ``n_workers`` 0/1: serial).
    command : list of str, optional
        Command line for ``run.json``.

    Returns
    -------
    dict
        The summary (also ``summary.json``) with ``path``.
    """
    from catenary.line import load_line
    from eroad.archive import (RunArchive, finish_run_info, run_info, write_json_atomic,
                               write_run_json)
    from studies.chassis_study import road_specs
    from studies.sweep import run_cases
    from vehicles.pantograph_model import load_pantograph

    load_line(line)  # refuse bad ids before anything runs
    load_pantograph(pantograph)
    p = Path(road_path)
    if not p.is_file():
        raise EroadInputError(f"road file not found: {road_path}")
    if int(seeds) < 0:
        raise EroadInputError(f"--seeds {seeds}: must be >= 0")
    specs, how = road_specs(p, n_seeds=int(seeds), seed=int(seed))
    cases = []
    for k, spec in enumerate(specs):
        cs = study_cases(spec, frames=frames, mounts=mounts, speed_kmh=speed_kmh,
                         duration=duration, line=line, pantograph=pantograph, dt=dt,
                         frame_friction=frame_friction)
        if k:
            cs = [{**c, "road_label": spec["label"]} for c in cs[:-1]]
        cases.append(cs)
    # the road file's configurations, then each realisation's, the still base last
    cases = cases[0][:-1] + [c for cs in cases[1:] for c in cs] + cases[0][-1:]
    config = {"road_file": str(p), "road_sha256": specs[0]["sha256"],
              "frames": [_frame_value(f) for f in frames],
              "mounts": [float(m) for m in mounts], "speed_kmh": float(speed_kmh),
              "duration_s": float(duration), "line": line, "pantograph": pantograph,
              "dt_s": float(dt), "t_start_s": T_START, "lowpass_hz": 20.0,
              "road_realisations": int(seeds), "realisation_seed": int(seed),
              "realisations_from": how,
              "force_bands_hz": [[lo, -1.0 if hi is None else hi] for lo, hi in FORCE_BANDS],
              "n_cases": len(cases), "case_function": "studies.pantograph_chassis:contact_case"}
    if frame_friction is not None:
        config["frame_friction_N"] = float(frame_friction)
    version = code_version()
    title = (f"Pantograph contact force vs frame and DCDC-mount stiffness: {p.name}, "
             f"{speed_kmh:g} km/h, line {line}, pantograph {pantograph}"
             + ("" if frame_friction is None else f" with {frame_friction:g} N frame friction"))

    def compute(folder: Path) -> dict:
        sweep = run_cases(contact_case, cases, cache_dir=cache_dir, scheduler=scheduler,
                          n_workers=n_workers, progress=progress, code_version=version,
                          desc="pantograph chassis")
        table, arrays = collect(sweep.cases, sweep.results)
        figs = _write_outputs(folder, table, arrays, title)
        summary = _summary(table, cases, sweep, str(p))
        summary["code_version"] = version
        summary["figures"] = [str(f.relative_to(folder)) for f in figs]
        summary["table"] = "data/table.csv"
        return summary

    if run_dir is None:
        with RunArchive(STUDY, config, root=out_root, command=command) as run:
            summary = compute(run.path)
            run.write_summary(summary)
        summary["path"] = str(run.path)
        return summary

    import tomli_w

    out = Path(run_dir)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise EroadInputError(f"{out}: exists and is not empty; choose another --run-dir")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    record = run_info(STUDY, run_id=out.name, command=command)
    t0 = _time.perf_counter()
    (tmp / "config.toml").write_text(tomli_w.dumps(config), encoding="utf-8")
    try:
        summary = compute(tmp)
        finish_run_info(record, "complete", wall_s=_time.perf_counter() - t0)
    except BaseException as exc:
        finish_run_info(record, "failed", wall_s=_time.perf_counter() - t0, error=exc)
        write_run_json(tmp, record)
        tmp.rename(out.with_name(f"{out.name}.failed-{os.getpid()}"))
        raise
    write_run_json(tmp, record)
    write_json_atomic(tmp / "summary.json", summary)
    if out.exists():
        out.rmdir()
    tmp.rename(out)
    summary["path"] = str(out)
    return summary
