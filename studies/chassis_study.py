"""Chassis-stiffness study: pantograph-base band energies against frame and mount stiffness.

What it is for (issue 6, item 3): sweeping the frame stiffness factor (0.25 ... 4 and
a rigid frame) and the DCDC mount stiffness factor over road realisations, on Dask
(:func:`studies.sweep.run_cases`, one case = one drive built from its parameters inside
the worker), archived with :class:`studies.runs.RunArchive` under
``<root>/chassis_stiffness/<run-id>/``, and showing how the band energies (< 0.5,
0.5-5, 5-15, 15-40 Hz) of the base motion (Ty, Tz, Rx, Ry: displacement/angle and
acceleration) move with stiffness.

* :func:`chassis_case` -- the case function (module level, importable by the workers);
* :func:`road_specs` -- the road realisations: the given road file plus ``n_seeds``
  statistically equivalent roads (same segments and spectra, new phases);
* :func:`study_cases` -- the case list of a configuration;
* :func:`collect` -- band energies, modes and findings of all cases as tables;
* :func:`plot_chassis_study` -- figures from the saved tables only;
* :func:`run_chassis_study` -- all of it, archived.

What it is not: the kinematics (:mod:`studies.pantograph`), one drive and the Figure-11
findings (:mod:`studies.figure11`), the sweep machinery (:mod:`studies.sweep`).

Seeds: road realisation ``i`` (1-based) uses the phases of
``SeedSequence(seed, spawn_key=(SEED_KEY, i))`` (its first 32-bit state word as the root
seed of ``roadlib.segments.segmented_surface``); realisation 0 is the road file itself.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from eroad.archive import file_sha256
from eroad.errors import EroadInputError
from studies.figure11 import (DEFAULT_VEHICLE, drive_base_motion, evaluate_findings, max_duration,
                              mode_table, tractor_variant)
from studies.pantograph import BANDS, QUANTITIES, amplitude_spectrum, band_label, motion_band_table

__all__ = [
    "STUDY",
    "SEED_KEY",
    "FRAME_FACTORS",
    "MOUNT_FACTORS",
    "PLOT_QUANTITIES",
    "StudyConfig",
    "quick_config",
    "full_config",
    "code_version",
    "road_specs",
    "build_road",
    "study_cases",
    "chassis_case",
    "collect",
    "save_tables",
    "trend_summary",
    "plot_chassis_study",
    "run_chassis_study",
]

#: study name (folder under the results root)
STUDY = "chassis_stiffness"
#: spawn key of the road realisations (see the module docstring)
SEED_KEY = 611
#: frame stiffness factors of the full study ("rigid": one rigid body); 16 shows how far
#: from the rigid limit a 4x stiffer frame still is (frame modes above 30 Hz)
FRAME_FACTORS: tuple = (0.25, 0.5, 1.0, 2.0, 4.0, 16.0, "rigid")
#: DCDC mount stiffness factors of the full study
MOUNT_FACTORS: tuple = (0.5, 1.0, 2.0)
#: quantities of the band-energy plots (displacement/angle and acceleration)
PLOT_QUANTITIES = ("Ty", "Tz", "Rx", "Ry", "Ty_acc", "Tz_acc", "Rx_acc", "Ry_acc")
#: bin width of the coarse spectra kept per case [Hz]
SPECTRUM_BIN_HZ = 0.25
#: highest frequency of the coarse spectra [Hz]
SPECTRUM_F_MAX = 50.0
#: source files whose content is part of the cache's code version
_CODE_FILES = ("studies/chassis_study.py", "studies/figure11.py", "studies/pantograph.py",
               "vehicles/*.py", "vehicles/effects/*.py", "vehicles/params/*.toml",
               "roadlib/*.py")


@dataclass(frozen=True)
class StudyConfig:
    """Configuration of one chassis-stiffness run.

    Attributes
    ----------
    frames : tuple
        Frame stiffness factors [-] and/or ``"rigid"``.
    mounts : tuple of float
        DCDC mount stiffness factors [-].
    n_seeds : int
        Statistically equivalent road realisations besides the road file.
    seed : int
        Root seed of the realisations.
    speed : float
        [m/s]
    duration : float or None
        Simulated time per case [s] (None: as long as the road allows).
    t_skip : float
        Leading time left out of the analysis [s].
    vehicle : str
        Vehicle id or TOML file.
    quick : bool
        The CI smoke configuration.
    solver : {"linear", "exudyn"}
        Integrator of each drive (``studies.figure11.simulate_tractor``): the linear model
        stepped with Exudyn's scheme (default; the study's vehicle is linear but for tyre
        lift-off, which it corrects as Exudyn does) or Exudyn itself.
    """

    frames: tuple = FRAME_FACTORS
    mounts: tuple = MOUNT_FACTORS
    n_seeds: int = 2
    seed: int = 2026
    speed: float = 10.0
    duration: float | None = 30.0
    t_skip: float = 1.0
    vehicle: str = DEFAULT_VEHICLE
    quick: bool = False
    solver: str = "linear"

    def to_dict(self) -> dict:
        """Plain dict (config.toml; ``duration`` omitted when None)."""
        return {"frames": [f if f == "rigid" else float(f) for f in self.frames],
                "mounts": [float(m) for m in self.mounts], "n_seeds": int(self.n_seeds),
                "seed": int(self.seed), "speed_mps": float(self.speed),
                "duration_s": None if self.duration is None else float(self.duration),
                "t_skip_s": float(self.t_skip), "vehicle": str(self.vehicle),
                "quick": bool(self.quick), "solver": str(self.solver),
                "bands_hz": [list(b) for b in BANDS]}


def full_config(**kw) -> StudyConfig:
    """The full study: 7 frame x 3 mount factors x (road + 2 realisations), 30 s drives.

    Parameters
    ----------
    **kw
        Overrides of :class:`StudyConfig` fields.

    Returns
    -------
    StudyConfig
    """
    return StudyConfig(**kw)


def quick_config(**kw) -> StudyConfig:
    """The CI smoke study: frames 0.25, 1, 4, rigid, nominal mounts, the road file and one
    realisation, 8 s drives (8 cases, ~10 s serial).

    Parameters
    ----------
    **kw
        Overrides of :class:`StudyConfig` fields.

    Returns
    -------
    StudyConfig
    """
    base = dict(frames=(0.25, 1.0, 4.0, "rigid"), mounts=(1.0,), n_seeds=1, duration=8.0,
                t_skip=1.0, quick=True)
    base.update(kw)
    return StudyConfig(**base)


def code_version() -> str:
    """Cache code-version token covering the code a case runs.

    Returns
    -------
    str
        ``"eroad-<version>+<sha256 of the sources, 12 hex>"`` over the studies, vehicles
        (models, effects, parameter files) and roadlib sources, so that a change of the
        vehicle model invalidates the cached cases (``studies.sweep``'s default covers
        only this module).
    """
    from studies.sweep import code_version_of_files

    return code_version_of_files(_CODE_FILES, Path(__file__).resolve().parents[1])


# ---------------------------------------------------------------------------
# roads
# ---------------------------------------------------------------------------
def _equivalent_segments(road) -> tuple[list[dict], str]:
    """Segments (RoadSegment fields) statistically equivalent to a road.

    A road made by ``roadlib`` keeps its generator parameters in ``meta``: the
    segments of ``segmented_surface`` (lengths as shares) or the spectrum of
    ``synth_surface``.  Any other road (measured, identified) gets one segment with
    Gd(n0) and w fitted to the Welch PSD of all its tracks (``roadlib.metrics``).
    """
    from roadlib.metrics import fit_iso_psd, profile_psd
    from roadlib.segments import RoadSegment

    meta = road.meta or {}
    gen = meta.get("generator", "")
    nyq = 0.5 / road.dx
    keys = ("Gq_n0", "w", "nmin", "nmax", "lam", "label", "w2", "n_break")
    if gen == "roadlib.segments.segmented_surface" and meta.get("segments"):
        segs = []
        for s in meta["segments"]:
            d = {k: s[k] for k in keys if k in s}
            d["share"] = float(s["end"]) - float(s["start"])
            d["nmax"] = min(float(d.get("nmax", nyq)), nyq)
            segs.append(RoadSegment(**d).to_dict())
        return segs, "segments of the road file's meta (roadlib.segments)"
    if gen == "roadlib.synthesis.synth_surface" and isinstance(meta.get("params"), dict):
        p = meta["params"]
        seg = RoadSegment(Gq_n0=float(p["Gq_n0"]), w=float(p["w"]), nmin=float(p["nmin"]),
                          nmax=min(float(p["nmax"]), nyq), lam=float(p.get("lam", 1.0)))
        return [seg.to_dict()], "spectrum of the road file's meta (roadlib.synthesis)"
    fit = fit_iso_psd(profile_psd(road.z, road.dx))
    seg = RoadSegment(Gq_n0=float(fit.Gd_n0), w=float(fit.w), nmin=0.011,
                      nmax=min(float(fit.band[1]), nyq), label=fit.iso_class)
    return [seg.to_dict()], (f"ISO 8608 fit of the road file's tracks: Gd(n0) = "
                             f"{fit.Gd_n0:.3g} m^3, w = {fit.w:.2f}, class {fit.iso_class}")


def road_specs(road_path: str | Path, n_seeds: int = 2,
               seed: int = 2026) -> tuple[list[dict], str]:
    """Road realisations of the study: the road file and equivalent synthetic roads.

    Parameters
    ----------
    road_path : str or Path
        Road file (``.npz`` or ``.crg``, :meth:`roadlib.surface.RoadSurface.load`).
    n_seeds : int, optional
        Number of statistically equivalent realisations besides the file (default 2).
    seed : int, optional
        Root seed of the realisations (see the module docstring).

    Returns
    -------
    (list of dict, str)
        JSON-able road specs (``kind`` ``"file"``: absolute path and SHA-256; ``kind``
        ``"segments"``: segments, grid, seed) and how the equivalent roads were
        derived.

    Raises
    ------
    eroad.errors.EroadInputError
        Unreadable road file, negative ``n_seeds``.
    """
    from roadlib.surface import RoadSurface

    if int(n_seeds) < 0:
        raise EroadInputError(f"--seeds {n_seeds}: must be >= 0")
    path = Path(road_path).resolve()
    road = RoadSurface.load(path)
    specs = [{"kind": "file", "path": str(path), "sha256": file_sha256(path), "label": "road file"}]
    how = "no synthetic realisations"
    if n_seeds:
        segs, how = _equivalent_segments(road)
        for i in range(1, int(n_seeds) + 1):
            state = np.random.SeedSequence(int(seed), spawn_key=(SEED_KEY, i)).generate_state(1)
            specs.append({"kind": "segments", "segments": segs, "length": float(road.length),
                          "width": float(road.width), "dx": float(road.dx),
                          "dy": float(road.dy) if road.y.size > 1 else 0.1,
                          "x0": float(road.x_min), "seed": int(state[0]),
                          "label": f"realisation {i}"})
    return specs, how


def build_road(spec: dict):
    """Build the road of a spec from :func:`road_specs` (inside the worker).

    Parameters
    ----------
    spec : dict

    Returns
    -------
    roadlib.surface.RoadSurface

    Raises
    ------
    eroad.errors.EroadInputError
        Unknown kind, or a road file whose content changed since the spec was made.
    """
    from roadlib.segments import RoadSegment, segmented_surface
    from roadlib.surface import RoadSurface

    kind = spec.get("kind")
    if kind == "file":
        path = Path(spec["path"])
        road = RoadSurface.load(path)
        if spec.get("sha256") and file_sha256(path) != spec["sha256"]:
            raise EroadInputError(f"{path}: road file changed since the study started")
        return road
    if kind == "segments":
        segs = [RoadSegment(**s) for s in spec["segments"]]
        return segmented_surface(segs, length=spec["length"], width=spec["width"],
                                 dx=spec["dx"], dy=spec["dy"], seed=int(spec["seed"]),
                                 x0=spec.get("x0", 0.0))
    raise EroadInputError(f"unknown road spec kind {kind!r}")


def study_cases(config: StudyConfig, roads: list[dict]) -> list[dict]:
    """Case list: every frame x mount factor x road realisation.

    Parameters
    ----------
    config : StudyConfig
    roads : list of dict
        From :func:`road_specs`.

    Returns
    -------
    list of dict
        JSON-able cases for :func:`chassis_case`.
    """
    cases = []
    for r_i, road in enumerate(roads):
        for mount in config.mounts:
            for frame in config.frames:
                cases.append({"vehicle": str(config.vehicle),
                              "frame": "rigid" if frame == "rigid" else float(frame),
                              "mount": float(mount), "road": road, "road_index": r_i,
                              "speed": float(config.speed),
                              "duration": None if config.duration is None
                              else float(config.duration),
                              "t_skip": float(config.t_skip), "solver": str(config.solver)})
    return cases


# ---------------------------------------------------------------------------
# the case function (runs in the worker)
# ---------------------------------------------------------------------------
def _first(modes: list[dict], prefix: str) -> float:
    for m in modes:
        if m["label"] == prefix or m["label"].startswith(prefix + " "):
            return float(m["freq_hz"])
    return float("nan")


def chassis_case(case: dict) -> dict:
    """One drive of the chassis-stiffness study (built from ``case`` in the worker).

    Parameters
    ----------
    case : dict
        ``vehicle`` (id or TOML file), ``frame`` (stiffness factor [-] or
        ``"rigid"``), ``mount`` (DCDC mount stiffness factor [-]), ``road`` (a spec of
        :func:`road_specs`), ``road_index``, ``speed`` [m/s], ``duration`` [s] or None
        (as long as the road allows), ``t_skip`` [s], ``solver`` ("linear" or "exudyn";
        absent: "exudyn", as cases made before it).

    Returns
    -------
    dict
        ``bands`` (12, 4) band mean squares of :data:`studies.pantograph.QUANTITIES`
        (rows in that order) in :data:`studies.pantograph.BANDS` [unit^2];
        ``f_spec`` (nb,) [Hz] and ``spectra`` (12, nb) amplitude spectra RMS-averaged
        over :data:`SPECTRUM_BIN_HZ` bins [unit]; ``rms`` (4,) of Ty, Tz, Rx, Ry
        [m, m, rad, rad]; ``modes`` (label, freq_hz, damping up to 60 Hz);
        ``frame_torsion_hz``, ``frame_bending_hz`` (first frame modes, NaN for a rigid
        frame), ``dcdc_modes_hz`` {label: freq}; ``findings`` {a..e: bool} and
        ``finding_values`` (Figure-11 criteria on this drive); ``duration_s`` [s],
        ``sim_wall_s`` [s].
    """
    road = build_road(case["road"])
    vp = tractor_variant(case.get("vehicle", DEFAULT_VEHICLE), case["mount"])
    rigid = case["frame"] == "rigid"
    chassis = "rigid" if rigid else "flexible"
    ff = 1.0 if rigid else float(case["frame"])
    speed = float(case["speed"])
    t_max = max_duration(road, vp, speed)
    dur = t_max if case.get("duration") is None else min(float(case["duration"]), t_max)
    if dur - float(case["t_skip"]) < 2.0:
        raise EroadInputError(f"road too short for the study: {road.length:.1f} m allow "
                              f"{t_max:.1f} s at {speed:g} m/s")
    d = drive_base_motion(vp, road, speed=speed, duration=dur, chassis=chassis,
                          frame_factor=ff, t_skip=float(case["t_skip"]),
                          solver=case.get("solver", "exudyn"))
    m, fs = d["motion"], d["fs"]
    table = motion_band_table(m, fs)
    bands = table[[band_label(b) for b in BANDS]].to_numpy(float)
    edges = np.arange(0.0, SPECTRUM_F_MAX + 1e-9, SPECTRUM_BIN_HZ)
    spectra = np.zeros((len(QUANTITIES), edges.size - 1))
    for q, (name, (comp, order, _, _)) in enumerate(QUANTITIES.items()):
        f, a = amplitude_spectrum(getattr(m, comp), fs, order=order)
        idx = np.digitize(f, edges) - 1
        ok = (idx >= 0) & (idx < edges.size - 1)
        s2 = np.bincount(idx[ok], weights=a[ok] ** 2, minlength=edges.size - 1)
        cnt = np.bincount(idx[ok], minlength=edges.size - 1)
        spectra[q] = np.sqrt(s2 / np.maximum(cnt, 1))
    modes, _ = mode_table(vp, chassis, ff, f_max=60.0)
    findings = evaluate_findings({c: getattr(m, c) for c in ("Ty", "Tz", "Rx", "Ry")}, fs, modes)
    keep = ("ratio", "f_peak_Ry_vel_hz", "f_peak_Ry_acc_hz", "n_peaks", "f_peak_Tz_vel_hz",
            "f_peak_Tz_acc_hz", "Ty_acc_share_20Hz_to_fmax")
    values = {f"{fd.id}.{k}": v for fd in findings for k, v in fd.values.items() if k in keep}
    return {
        "bands": bands,
        "f_spec": 0.5 * (edges[1:] + edges[:-1]),
        "spectra": spectra,
        "rms": np.array([float(np.sqrt(np.mean(getattr(m, c) ** 2)))
                         for c in ("Ty", "Tz", "Rx", "Ry")]),
        "modes": [{"label": x["label"], "freq_hz": x["freq_hz"], "damping": x["damping"]}
                  for x in modes],
        "frame_torsion_hz": _first(modes, "frame torsion"),
        "frame_bending_hz": _first(modes, "frame bending"),
        "dcdc_modes_hz": {x["label"]: x["freq_hz"] for x in modes
                          if x["label"].startswith("DCDC")},
        "findings": {fd.id: bool(fd.holds) for fd in findings},
        "finding_values": values,
        "duration_s": float(dur),
        "sim_wall_s": float(d["meta"].get("wall_s", float("nan"))),
    }


# ---------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------
def _frame_key(frame) -> float:
    """Sort/plot key of a frame factor: rigid = inf."""
    return math.inf if frame == "rigid" else float(frame)


def collect(sweep) -> dict:
    """Tables of a finished sweep.

    Parameters
    ----------
    sweep : studies.sweep.SweepResult
        Result of :func:`studies.sweep.run_cases` on :func:`study_cases`.

    Returns
    -------
    dict of pandas.DataFrame
        ``energies`` (long: frame, mount, road_index, quantity, unit, band, energy),
        ``modes`` (frame, mount, road_index, label, freq_hz, damping; road 0 only),
        ``cases`` (one row per case: factors, frame and DCDC mode frequencies, RMS,
        findings), ``spectra`` is returned as arrays: ``spectra_f`` (nb,),
        ``spectra`` (n_cases, 12, nb).
    """
    import pandas as pd

    rows, mrows, crows = [], [], []
    labels = [band_label(b) for b in BANDS]
    for case, res in zip(sweep.cases, sweep.results):
        key = {"frame": str(case["frame"]), "mount": case["mount"],
               "road_index": case["road_index"]}
        e = np.asarray(res["bands"])
        for q, (name, (_, _, unit, _)) in enumerate(QUANTITIES.items()):
            for b, lab in enumerate(labels):
                rows.append({**key, "quantity": name, "unit": f"({unit})^2", "band": lab,
                             "energy": float(e[q, b])})
        if case["road_index"] == 0:
            for m in res["modes"]:
                mrows.append({**key, **m})
        crow = {**key, "frame_torsion_hz": res["frame_torsion_hz"],
                "frame_bending_hz": res["frame_bending_hz"], "duration_s": res["duration_s"],
                "sim_wall_s": res["sim_wall_s"]}
        for c, v in zip(("Ty", "Tz", "Rx", "Ry"), np.asarray(res["rms"])):
            crow[f"rms_{c}"] = float(v)
        for lab, fz in res["dcdc_modes_hz"].items():
            crow[f"{lab} [Hz]"] = fz
        for k, v in res["findings"].items():
            crow[f"finding_{k}"] = bool(v)
        for k, v in res["finding_values"].items():
            crow[k] = v if not isinstance(v, list) else str(v)
        crows.append(crow)
    return {"energies": pd.DataFrame(rows), "modes": pd.DataFrame(mrows),
            "cases": pd.DataFrame(crows),
            "spectra_f": np.asarray(sweep.results[0]["f_spec"]),
            "spectra": np.stack([np.asarray(r["spectra"]) for r in sweep.results])}


def save_tables(tables: dict, folder: str | Path, cases: list[dict]) -> list[Path]:
    """Write the tables of :func:`collect` into ``folder`` (CSV + NPZ).

    Files: ``band_energies.csv``, ``modes.csv``, ``cases.csv``, ``spectra.npz`` (f,
    spectra, and per case frame / mount / road_index), ``trends.json``
    (:func:`trend_summary`).

    Parameters
    ----------
    tables : dict
    folder : str or Path
    cases : list of dict
        The sweep's cases (for the spectra index).

    Returns
    -------
    list of Path
    """
    from studies.runs import write_json_atomic

    folder = Path(folder)
    out = []
    for name, fn in (("energies", "band_energies.csv"), ("modes", "modes.csv"),
                     ("cases", "cases.csv")):
        p = folder / fn
        tables[name].to_csv(p, index=False, float_format="%.6e")
        out.append(p)
    p = folder / "spectra.npz"
    np.savez(p, f=tables["spectra_f"], spectra=tables["spectra"],
             frame=np.array([str(c["frame"]) for c in cases]),
             mount=np.array([c["mount"] for c in cases]),
             road_index=np.array([c["road_index"] for c in cases]),
             quantities=np.array(list(QUANTITIES)))
    out.append(p)
    out.append(write_json_atomic(folder / "trends.json", trend_summary(tables["energies"])))
    return out


def trend_summary(energies, threshold: float = 1.25) -> dict:
    """How each band energy depends on frame and mount stiffness (paired by road).

    For every quantity and band: the ratio of the band energy with each frame factor to
    the one with the rigid frame on the same road (nominal mounts), its mean and range
    over the roads, and the ratio between the softest and the stiffest mounts at frame
    factor 1 (or the nearest available).  A band *depends* on the frame stiffness when
    the softest frame's ratio to rigid lies outside [1/threshold, threshold] on every
    road.

    Parameters
    ----------
    energies : pandas.DataFrame
        ``energies`` table of :func:`collect` (or read from ``band_energies.csv``).
    threshold : float, optional
        Ratio counted as a change (default 1.25).

    Returns
    -------
    dict
        ``{quantity: {band: {"frame_ratio_to_rigid": {factor: [mean, min, max]},
        "mount_ratio": [mean, min, max] or None, "depends_on_frame": bool,
        "depends_on_mount": bool}}}`` plus ``"threshold"``.
    """
    df = energies.copy()
    df["frame"] = df["frame"].astype(str)
    mounts = sorted(df["mount"].unique())
    m_nom = min(mounts, key=lambda m: abs(m - 1.0))
    out: dict[str, Any] = {"threshold": threshold}
    frames = sorted({f for f in df["frame"] if f != "rigid"}, key=float)
    f_nom = min(frames, key=lambda f: abs(float(f) - 1.0)) if frames else "rigid"
    for (q, b), g in df.groupby(["quantity", "band"], sort=False):
        entry: dict[str, Any] = {}
        gm = g[g["mount"] == m_nom].pivot_table(index="road_index", columns="frame",
                                                 values="energy")
        ratios = {}
        if "rigid" in gm.columns:
            for f in frames:
                if f in gm.columns:
                    r = (gm[f] / gm["rigid"]).to_numpy(float)
                    ratios[f] = [float(np.mean(r)), float(np.min(r)), float(np.max(r))]
        entry["frame_ratio_to_rigid"] = ratios
        soft = ratios.get(frames[0]) if frames else None
        entry["depends_on_frame"] = bool(soft is not None and (soft[1] > threshold
                                                               or soft[2] < 1 / threshold))
        if len(mounts) > 1:
            gf = g[g["frame"] == f_nom].pivot_table(index="road_index", columns="mount",
                                                     values="energy")
            r = (gf[mounts[0]] / gf[mounts[-1]]).to_numpy(float)
            entry["mount_ratio"] = [float(np.mean(r)), float(np.min(r)), float(np.max(r))]
            entry["mount_ratio_def"] = (f"E(mount x{mounts[0]:g}) / E(mount x{mounts[-1]:g}) "
                                        f"at frame x{f_nom}")
            entry["depends_on_mount"] = bool(r.min() > threshold or r.max() < 1 / threshold)
        else:
            entry["mount_ratio"] = None
            entry["depends_on_mount"] = False
        out.setdefault(q, {})[b] = entry
    return out


# ---------------------------------------------------------------------------
# plots (from the saved tables only)
# ---------------------------------------------------------------------------
_BAND_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


def square_unit(unit: str) -> str:
    """A squared unit for a label: ``(m)^2`` -> ``m²``, ``(m/s^2)^2`` -> ``(m/s²)²``."""
    u = str(unit)
    if u.startswith("(") and u.endswith(")^2"):
        inner = u[1:-3]
        u = f"{inner}^2" if all(c.isalnum() for c in inner) else f"({inner})^2"
    return u.replace("^2", "\u00b2")


def readable_log_axis(ax) -> None:
    """A log y axis holding fewer than two powers of ten gets ticks at 1, 2, 5 x 10^k with
    plain labels (matplotlib's default leaves one labelled tick, or none, on such a range)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    lo, hi = ax.get_ylim()
    if lo <= 0:
        return
    decades = np.arange(np.ceil(np.log10(lo) - 1e-9), np.floor(np.log10(hi) + 1e-9) + 1)
    if decades.size < 2:
        ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())


def plot_chassis_study(data_dir: str | Path, figures_dir: str | Path, pdf: bool = True
                       ) -> list[Path]:
    """Figures of a chassis-stiffness run, drawn from its ``data/`` files.

    * ``band_energy_vs_frame.png``: one panel per quantity of :data:`PLOT_QUANTITIES`,
      band energy against the frame stiffness factor (log-log, nominal mounts), mean
      over the roads with the range shaded; the rigid frame as a star at the right
      and a dotted line across (its asymptote);
    * ``band_ratio_vs_frame.png``: the same as ratios to the rigid frame (paired by road);
    * ``band_energy_vs_mount.png``: band energy against the mount factor, nominal
      frame (solid) and rigid frame (dashed) (only with more than one mount factor);
    * ``spectra_vs_frame.png``: acceleration amplitude spectra (0.25 Hz bins) of the
      first road for every frame factor (nominal mounts).

    Parameters
    ----------
    data_dir : str or Path
        The run's ``data/`` folder (``band_energies.csv``, ``spectra.npz``).
    figures_dir : str or Path
        Where to write.
    pdf : bool, optional
        Also write PDFs.

    Returns
    -------
    list of Path
        Files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    data_dir, figures_dir = Path(data_dir), Path(figures_dir)
    df = pd.read_csv(data_dir / "band_energies.csv", dtype={"frame": str})
    mounts = sorted(df["mount"].unique())
    m_nom = min(mounts, key=lambda m: abs(m - 1.0))
    frames = sorted({f for f in df["frame"] if f != "rigid"}, key=float)
    fx = np.array([float(f) for f in frames])
    has_rigid = "rigid" in set(df["frame"])
    x_rigid = (fx.max() if fx.size else 1.0) * 4.0
    labels = [band_label(b) for b in BANDS]
    written = []

    def save(fig, name):
        p = figures_dir / name
        fig.savefig(p, dpi=110)
        written.append(p)
        if pdf:
            fig.savefig(p.with_suffix(".pdf"))
            written.append(p.with_suffix(".pdf"))
        plt.close(fig)

    def frame_axis(ax):
        ax.set_xscale("log")
        ticks = list(fx) + ([x_rigid] if has_rigid else [])
        ax.set_xticks(ticks)
        ax.set_xticklabels([f"{t:g}" for t in fx] + (["rigid"] if has_rigid else []))
        ax.minorticks_off()
        ax.set_xlabel("frame stiffness factor [-]")

    for kind in ("energy", "ratio"):
        fig, axes = plt.subplots(2, 4, figsize=(15, 7.5))
        for ax, q in zip(axes.ravel(), PLOT_QUANTITIES):
            g = df[(df["quantity"] == q) & (df["mount"] == m_nom)]
            unit = g["unit"].iloc[0]
            piv = g.pivot_table(index=["road_index", "band"], columns="frame", values="energy")
            for b, lab in enumerate(labels):
                sub = piv.xs(lab, level="band")
                if kind == "ratio":
                    if "rigid" not in sub.columns:
                        continue
                    sub = sub.div(sub["rigid"], axis=0)
                ys = sub[frames].to_numpy(float) if frames else np.empty((len(sub), 0))
                mean, lo, hi = ys.mean(axis=0), ys.min(axis=0), ys.max(axis=0)
                col = _BAND_COLORS[b % len(_BAND_COLORS)]
                ax.plot(fx, mean, "o-", color=col, ms=4, label=f"{lab} Hz")
                if ys.shape[0] > 1:
                    ax.fill_between(fx, lo, hi, color=col, alpha=0.15, lw=0)
                if has_rigid and kind == "energy":
                    r = sub["rigid"].to_numpy(float)
                    # the bands' stars side by side (on top of each other they hid one another)
                    xr = x_rigid * 1.15 ** (b - (len(labels) - 1) / 2)
                    ax.plot([xr], [r.mean()], "*", color=col, ms=10, mec="k", mew=0.5, zorder=3)
                    ax.axhline(r.mean(), color=col, ls=":", lw=0.9)
                    if r.size > 1:
                        ax.errorbar([xr], [r.mean()], yerr=[[r.mean() - r.min()],
                                                            [r.max() - r.mean()]],
                                    color=col, lw=0.8, capsize=2)
            if has_rigid and kind == "ratio":   # 1 for every band by definition: one star
                ax.plot([x_rigid], [1.0], "*", color="k", ms=11, zorder=3)
                ax.axhline(1.0, color="k", ls=":", lw=0.9)
            ax.set_yscale("log")
            readable_log_axis(ax)
            frame_axis(ax)
            _, _, u, lab_q = QUANTITIES[q]
            ax.set_title(f"{q}: {lab_q}", fontsize=9)
            ax.set_ylabel(f"band mean square [{square_unit(unit)}]" if kind == "energy"
                          else "E / E(rigid frame) [-]", fontsize=8)
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(labelsize=8)
        handles, labs = axes[0, 0].get_legend_handles_labels()
        fig.legend(handles, labs, loc="lower center", ncol=len(labs), fontsize=9,
                   title="frequency band", title_fontsize=9, frameon=False)
        n_roads = df["road_index"].nunique()
        what = "band energy" if kind == "energy" else "band energy relative to the rigid frame"
        rig = ("stars + dotted lines: rigid frame" if kind == "energy" else
               "star + dotted line: rigid frame = 1 for every band")
        fig.suptitle(f"Chassis-stiffness study: pantograph-base {what} vs frame stiffness "
                     f"(DCDC mounts x{m_nom:g}; mean over {n_roads} road(s), range shaded; "
                     f"{rig})", fontsize=10)
        fig.tight_layout(rect=(0, 0.07, 1, 0.96))
        save(fig, f"band_{kind}_vs_frame.png")

    if len(mounts) > 1:
        f_nom = min(frames, key=lambda f: abs(float(f) - 1.0)) if frames else None
        fig, axes = plt.subplots(2, 4, figsize=(15, 7.5))
        for ax, q in zip(axes.ravel(), PLOT_QUANTITIES):
            g = df[df["quantity"] == q]
            unit = g["unit"].iloc[0]
            for b, lab in enumerate(labels):
                col = _BAND_COLORS[b % len(_BAND_COLORS)]
                for frame, ls in ((f_nom, "-"), ("rigid" if has_rigid else None, "--")):
                    if frame is None:
                        continue
                    s = g[(g["band"] == lab) & (g["frame"] == frame)].groupby("mount")["energy"]
                    ax.plot(s.mean().index, s.mean().to_numpy(), "o" + ls, color=col, ms=4,
                            label=f"{lab} Hz" if ls == "-" else None)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xticks(mounts)
            ax.set_xticklabels([f"{m:g}" for m in mounts])
            ax.minorticks_off()
            ax.set_xlabel("DCDC mount stiffness factor [-]")
            _, _, u, lab_q = QUANTITIES[q]
            ax.set_title(f"{q}: {lab_q}", fontsize=9)
            ax.set_ylabel(f"band mean square [{square_unit(unit)}]", fontsize=8)
            readable_log_axis(ax)
            ax.grid(True, which="major", alpha=0.3)
            ax.tick_params(labelsize=8)
        handles, labs = axes[0, 0].get_legend_handles_labels()
        fig.legend(handles, labs, loc="lower center", ncol=len(labs), fontsize=9,
                   title="frequency band", title_fontsize=9, frameon=False)
        fig.suptitle(f"Chassis-stiffness study: band energy vs DCDC mount stiffness "
                     f"(solid: frame x{f_nom}, dashed: rigid frame; mean over roads)",
                     fontsize=10)
        fig.tight_layout(rect=(0, 0.07, 1, 0.96))
        save(fig, "band_energy_vs_mount.png")

    with np.load(data_dir / "spectra.npz", allow_pickle=False) as z:
        f, spec = z["f"], z["spectra"]
        fr, mo, ri = z["frame"], z["mount"], z["road_index"]
        qn = [str(x) for x in z["quantities"]]
    fig, axes = plt.subplots(2, 2, figsize=(12, 7.5), sharex=True)
    order = sorted(set(str(x) for x in fr), key=_frame_key)
    cmap = plt.get_cmap("viridis")
    for ax, q in zip(axes.ravel(), ("Rx_acc", "Ry_acc", "Ty_acc", "Tz_acc")):
        qi = qn.index(q)
        for k, frame in enumerate(order):
            sel = np.flatnonzero((fr == frame) & (mo == m_nom) & (ri == 0))
            if not sel.size:
                continue
            col = "k" if frame == "rigid" else cmap(k / max(1, len(order) - 1))
            ax.semilogy(f, spec[sel[0], qi], color=col, lw=1.4 if frame == "rigid" else 1.0,
                        ls="--" if frame == "rigid" else "-",
                        label="rigid" if frame == "rigid" else f"frame x{float(frame):g}")
        for lo, hi in BANDS[1:]:
            ax.axvline(lo, color="0.6", lw=0.6, ls=":")
        ax.axvline(BANDS[-1][1], color="0.6", lw=0.6, ls=":")
        _, _, u, lab_q = QUANTITIES[q]
        ax.set_title(f"{q}: {lab_q}", fontsize=9)
        ax.set_ylabel(f"amplitude [{u}]", fontsize=8)
        ax.grid(True, which="major", alpha=0.3)
        ax.set_xlim(0, BANDS[-1][1] + 5)
    for ax in axes[1]:
        ax.set_xlabel("frequency [Hz]")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"Acceleration spectra of the pantograph base vs frame stiffness (first road, "
                 f"DCDC mounts x{m_nom:g}; {SPECTRUM_BIN_HZ:g} Hz bins, RMS of the amplitude "
                 "spectrum; dotted: band edges)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save(fig, "spectra_vs_frame.png")
    return written


# ---------------------------------------------------------------------------
# the whole study
# ---------------------------------------------------------------------------
def run_chassis_study(road_path: str | Path, out_root: str | Path = "results",
                      config: StudyConfig | None = None, *, scheduler: Any = None,
                      n_workers: int = 2, cache_dir: str | Path = ".eroad-cache",
                      progress: bool = True, command: list[str] | None = None) -> dict:
    """Run the chassis-stiffness study on a road and archive it.

    Parameters
    ----------
    road_path : str or Path
        Road file (``.npz`` / ``.crg``).
    out_root : str or Path, optional
        Results root; the run goes to ``<out_root>/chassis_stiffness/<run-id>/``.
    config : StudyConfig, optional
        Default :func:`full_config`.
    scheduler, n_workers, cache_dir, progress
        Passed to :func:`studies.sweep.run_cases` (``n_workers`` 0/1: serial).
    command : list of str, optional
        Command line recorded in ``run.json`` (default ``sys.argv``).

    Returns
    -------
    dict
        The summary (also ``summary.json``) with ``path`` (the run folder).
    """
    from studies.runs import RunArchive
    from studies.sweep import run_cases

    config = config or full_config()
    roads, how = road_specs(road_path, config.n_seeds, config.seed)
    cases = study_cases(config, roads)
    cfg = {**config.to_dict(), "road_file": str(Path(road_path).resolve()),
           "road_sha256": roads[0]["sha256"], "equivalent_roads": how,
           "n_cases": len(cases), "case_function": "studies.chassis_study:chassis_case"}
    version = code_version()
    with RunArchive(STUDY, cfg, root=out_root, seed=config.seed, command=command) as run:
        sweep = run_cases(chassis_case, cases, cache_dir=cache_dir, scheduler=scheduler,
                          n_workers=n_workers, progress=progress, code_version=version,
                          desc="chassis study")
        tables = collect(sweep)
        save_tables(tables, run.data_dir, cases)
        run.write_json("roads.json", roads)
        figs = plot_chassis_study(run.data_dir, run.figures_dir)
        summary = _summary(tables, sweep, config, how)
        summary.update(_road_input(road_path, config.speed))
        summary["figures"] = [str(p.relative_to(run.path)) for p in figs]
        run.write_summary(summary)
    summary["path"] = str(run.path)
    return summary


def _road_input(road_path, speed: float) -> dict:
    """Where the road file's input ends (:func:`roadlib.metrics.road_input_band`) and the
    study bands (:data:`studies.pantograph.BANDS`) reaching above it: there an energy's
    dependence on the frame is the vehicle ringing, not its response to short road waves.
    The equivalent realisations share the file's segments and spectra, so its band too."""
    from roadlib.metrics import road_input_band
    from roadlib.surface import RoadSurface

    band = road_input_band(RoadSurface.load(road_path), speed)
    beyond = [band_label(b) for b in BANDS if b[1] > band["road_input_top_hz"]]
    return {**band, "bands_beyond_road_input": beyond}


def _summary(tables: dict, sweep, config: StudyConfig, how: str) -> dict:
    """Key numbers of a run (summary.json)."""
    cases = tables["cases"]
    m_nom = min(config.mounts, key=lambda m: abs(m - 1.0))
    flex = [f for f in config.frames if f != "rigid"]
    f_nom = str(float(min(flex, key=lambda f: abs(float(f) - 1.0)))) if flex else "rigid"
    road0 = cases[(cases["road_index"] == 0) & (cases["mount"] == m_nom)]
    frame_modes = {r["frame"]: {"torsion_hz": r["frame_torsion_hz"],
                                "bending_hz": r["frame_bending_hz"]}
                   for _, r in road0.iterrows()}
    dcdc_cols = [c for c in cases.columns if c.startswith("DCDC")]
    mounts = {}
    for m, g in cases[(cases["road_index"] == 0) & (cases["frame"] == f_nom)].groupby("mount"):
        mounts[f"{m:g}"] = {c: float(g[c].iloc[0]) for c in dcdc_cols if g[c].notna().any()}
    findings = {}
    for k in "abcde":
        col = f"finding_{k}"
        if col in cases:
            findings[k] = {"true_in_cases": int(cases[col].sum()), "n_cases": int(len(cases))}
    trends = trend_summary(tables["energies"])
    on_frame = {q: [b for b, v in bands.items() if v["depends_on_frame"]]
                for q, bands in trends.items() if q != "threshold"}
    on_mount = {q: [b for b, v in bands.items() if v["depends_on_mount"]]
                for q, bands in trends.items() if q != "threshold"}
    ratio_soft = {q: {b: round(v["frame_ratio_to_rigid"][min(v["frame_ratio_to_rigid"],
                                                              key=float)][0], 4)
                      for b, v in bands.items() if v["frame_ratio_to_rigid"]}
                  for q, bands in trends.items() if q != "threshold"}
    return {"study": STUDY, "quick": config.quick, "n_cases": len(sweep.cases),
            "n_computed": sweep.n_computed, "n_cached": sweep.n_cached,
            "sweep_wall_s": round(sweep.wall_s, 2),
            "case_wall_s_sum": round(float(sum(w for w in sweep.case_wall_s if w)), 2),
            "n_roads": int(cases["road_index"].nunique()), "equivalent_roads": how,
            "frame_modes_hz": frame_modes, "dcdc_modes_hz_by_mount": mounts,
            "findings": findings, "trend_threshold": trends["threshold"],
            "bands_depending_on_frame": on_frame, "bands_depending_on_mount": on_mount,
            "softest_frame_energy_over_rigid": ratio_soft}
