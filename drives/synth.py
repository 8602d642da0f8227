"""The virtual test drive: a "measured" dataset made from a known truth.

What it is for: field data of the paper are not public, so ``eroad synth`` makes
datasets in the measurement format (``drives.format``) whose truth is known --
road segments with their spectral parameters, a speed profile, a truth vehicle
richer than the nominal model, sensor noise -- and keeps that truth in
``DIR/truth/`` for tests and benchmarks to score against.  What it is not: a
reader for estimation code (nothing that estimates may read ``truth/``; use
:func:`read_truth` only to score).

A scenario is a TOML file (``drives/scenarios/<name>.toml`` for the built-ins
``luliang``, ``random``, ``null``, ``second``, or any file with ``--config``).  It may leave
things to the seed (``[speed] kind = "smooth_random"``, ``[road.random]``);
:func:`resolve_scenario` draws them and returns the *explicit* scenario, which
is written to ``truth/scenario.toml`` and regenerates the same bytes with
``eroad synth --config truth/scenario.toml``.

Seeds (one root seed S; same seed, same bytes)::

    SeedSequence(S, spawn_key=(0,))            scenario draws (segments, classes, w)
    SeedSequence(S, spawn_key=(1,))            speed-profile knots
    SeedSequence(S, spawn_key=(2,)) -> int R   road: segmented_surface(seed=R), whose
                                               segment s uses SeedSequence(R, spawn_key=(s,))
    SeedSequence(S, spawn_key=(3, crc32(c)))   sensor noise of channel c
    SeedSequence(S, spawn_key=(4,)) -> int     simulate(seed=...) (random effects)
    SeedSequence(S, spawn_key=(5,))            [truth.independent] options given as ranges

Two truth families: ``[truth] model = "exudyn"`` (default; ``vehicles.simulate``) or
``"independent"`` (``drives.independent_truck``, a separately written lumped model with
structural differences the Exudyn model lacks; options in ``[truth.independent]``, a
two-number list ``[lo, hi]`` is drawn uniformly per seed).  ``[road] profile =
"profile_1"`` drives on a measured longitudinal profile instead of a synthetic road
(:func:`build_profile_road`).

Segment proportions are TIME proportions: the share of the record during which
the reference axle (axle 3) runs on the segment.  They become road lengths
through the speed profile: segment k ends where axle 3 is at record time
``T * (p_1 + ... + p_k)``.
"""
from __future__ import annotations

import copy
import json
import math
import os
import re
import shutil
import time
import tomllib
import zlib
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.interpolate import PchipInterpolator

from drives.format import TRUTH_DIR, ZERO_NOMINAL_STATIC, _umask, read_drive, write_drive
from eroad.errors import EroadInputError
from roadlib.profiles import bandlimited_profile, detrend_profile

#: folder of the built-in scenario files
SCENARIO_DIR = Path(__file__).with_name("scenarios")
#: built-in scenario names
SCENARIOS = ("luliang", "random", "null", "null_measured", "second", "second_measured")
#: spawn keys of the random streams (see module docstring)
STREAM_DRAWS, STREAM_SPEED, STREAM_ROAD, STREAM_NOISE, STREAM_VEHICLE = 0, 1, 2, 3, 4
STREAM_TRUTH_OPTIONS = 5
#: truth vehicle models ([truth] model)
TRUTH_MODELS = ("exudyn", "independent")
#: measured road profiles shipped as package data (drives/data/<name>.txt)
PROFILE_DIR = Path(__file__).with_name("data")
#: lateral shift [m] between the two ends of the measured-profile road (build_profile_road)
PROFILE_SHIFT_M = 40.0
#: sub-folder of a windowed scenario's dataset holding the whole record (a dataset itself)
RECORD_DIR = "record"
#: road beyond the vehicle at both ends of the simulated run [m]
ROAD_MARGIN_M = 10.0
#: where ``default_dataset`` caches the embedded dataset (env EROAD_CACHE overrides)
DEFAULT_CACHE = Path.home() / ".cache" / "eroad"
#: the embedded default: ``eroad synth --scenario luliang --seed 0``
DEFAULT_SCENARIO, DEFAULT_SEED = "luliang", 0

#: allowed keys per table of a scenario file
_KEYS = {
    "scenario": {"name", "dataset_name", "description", "vehicle", "duration_s",
                 "sample_rate_hz", "start_time_s", "runin_s", "reference_axle", "seed",
                 "window_s"},
    "speed": {"kind", "min_mps", "max_mps", "knot_spacing_s", "exact_range", "t_s", "v_mps"},
    "road": {"dx_m", "dy_m", "width_m", "lam", "segments", "random", "profile"},
    "road.random": {"n_segments", "classes", "w", "nmin", "nmax", "min_segment_s"},
    "road.segments": {"proportion", "Gq_n0", "w", "nmin", "nmax", "lam", "label"},
    "truth": {"chassis", "frame_segments", "dt_s", "effects", "model", "independent"},
    "noise": {"susp_disp_m", "axle_acc_mps2", "body_acc_mps2", "dcdc_m", "speed_mps"},
}
#: noise key per channel quantity
_NOISE_KEY = {"susp_disp": "susp_disp_m", "axle_acc": "axle_acc_mps2",
              "body_acc": "body_acc_mps2", "dcdc_y": "dcdc_m", "dcdc_z": "dcdc_m"}


# --------------------------------------------------------------------------- scenarios

def _rng(seed: int, *key: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=tuple(key)))


def _int_seed(seed: int, key: int) -> int:
    ss = np.random.SeedSequence(int(seed), spawn_key=(key,))
    return int(ss.generate_state(1, dtype=np.uint32)[0])


def load_scenario(name_or_path) -> tuple[dict, Path]:
    """Read a scenario TOML file and check its keys.

    Parameters
    ----------
    name_or_path : str or Path
        A built-in name (``luliang``, ``random``, ``null``) or a TOML file.

    Returns
    -------
    cfg : dict
        The parsed file.
    path : Path
        The file read.

    Raises
    ------
    EroadInputError
        Unknown scenario, unreadable file, unknown table or key (naming key and file).
    """
    s = str(name_or_path)
    path = SCENARIO_DIR / f"{s}.toml" if s in SCENARIOS else Path(s)
    if not path.is_file():
        raise EroadInputError(f"unknown scenario {s!r}: not a built-in ({', '.join(SCENARIOS)}) "
                              "and not a TOML file")
    try:
        cfg = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise EroadInputError(f"{path}: not valid TOML: {exc}") from None
    for table, val in cfg.items():
        if table not in _KEYS:
            raise EroadInputError(f"{path}: unknown table [{table}] (known: "
                                  f"{', '.join(k for k in _KEYS if '.' not in k)})")
        if not isinstance(val, dict):
            raise EroadInputError(f"{path}: [{table}] must be a table")
        for key in val:
            if key not in _KEYS[table]:
                raise EroadInputError(f"{path}: unknown key {key!r} in [{table}] (known: "
                                      f"{', '.join(sorted(_KEYS[table]))})")
    road = cfg.get("road", {})
    for key in road.get("random", {}):
        if key not in _KEYS["road.random"]:
            raise EroadInputError(f"{path}: unknown key {key!r} in [road.random]")
    for i, seg in enumerate(road.get("segments", [])):
        for key in seg:
            if key not in _KEYS["road.segments"]:
                raise EroadInputError(f"{path}: unknown key {key!r} in road.segments[{i}] (known: "
                                      f"{', '.join(sorted(_KEYS['road.segments']))})")
    for table in ("scenario", "speed", "road", "truth", "noise"):
        if table not in cfg:
            raise EroadInputError(f"{path}: missing table [{table}]")
    return cfg, path


def _need(cfg: dict, table: str, key: str, src):
    try:
        return cfg[table][key]
    except KeyError:
        raise EroadInputError(f"{src}: [{table}] {key} is missing") from None


def smooth_speed(seed: int, t_from: float, t_to: float, *, lo: float, hi: float,
                 spacing: float, exact_range: bool, record: tuple[float, float]):
    """Knots of a smooth random speed profile (PCHIP through the knots).

    Parameters
    ----------
    seed : int
        Root seed (stream ``(1,)``).
    t_from, t_to : float
        Time span to cover [s] (record time; negative in the run-in).
    lo, hi : float
        Speed bounds [m/s].
    spacing : float
        Knot spacing [s] (about; the knots are uniform over the span).
    exact_range : bool
        Rescale so that the profile's minimum and maximum over ``record`` are
        exactly ``lo`` and ``hi`` (PCHIP commutes with an affine map of the
        values); else the knots are uniform in [lo, hi] and PCHIP, which does
        not overshoot, stays inside.
    record : (float, float)
        Record time span [s].

    Returns
    -------
    t_knots, v_knots : list of float
    """
    n = max(3, int(math.ceil((t_to - t_from) / spacing)) + 1)
    tk = np.linspace(t_from, t_to, n)
    vk = _rng(seed, STREAM_SPEED).uniform(lo, hi, n)
    if exact_range:
        tt = np.linspace(record[0], record[1], 20001)
        vv = PchipInterpolator(tk, vk)(tt)
        a = (hi - lo) / (vv.max() - vv.min())
        vk = lo + a * (vk - vv.min())
    return [float(v) for v in tk], [float(v) for v in vk]


def _random_segments(rnd: dict, seed: int, duration: float, src) -> list[dict]:
    from roadlib.psd import ISO_CLASSES

    rng = _rng(seed, STREAM_DRAWS)
    kmin, kmax = (int(v) for v in rnd.get("n_segments", [2, 6]))
    classes = list(rnd.get("classes", ["A", "B", "C", "D", "E"]))
    wlo, whi = (float(v) for v in rnd.get("w", [1.5, 2.5]))
    min_s = float(rnd.get("min_segment_s", 2.0))
    # a short record holds fewer segments: at most duration / min_segment_s of them
    kmax = min(kmax, int(math.floor(duration / min_s + 1e-9)))
    kmin = min(kmin, kmax)
    if kmax < 1:
        raise EroadInputError(f"{src}: [road.random] min_segment_s = {min_s} s is longer than the "
                              f"record ({duration} s)")
    k = int(rng.integers(kmin, kmax + 1))
    shares = rng.dirichlet(np.ones(k))
    props = min_s / duration + (1.0 - k * min_s / duration) * shares
    segs = []
    for i in range(k):
        c = ISO_CLASSES[classes[int(rng.integers(len(classes)))].upper()]
        lo, hi = c.nominal_bounds
        gq = float(math.exp(rng.uniform(math.log(lo), math.log(hi))))
        segs.append({"proportion": float(props[i]), "Gq_n0": gq, "w": float(rng.uniform(wlo, whi)),
                     "nmin": float(rnd.get("nmin", 0.1)), "nmax": float(rnd.get("nmax", 5.0)),
                     "label": c.name})
    return segs


def resolve_scenario(cfg: dict, seed: int | None = None, *, effects=(), vehicle=None,
                     duration=None, default_effects: bool = True, src="scenario") -> dict:
    """The explicit scenario: every random draw made, every option set.

    Parameters
    ----------
    cfg : dict
        Parsed scenario (:func:`load_scenario`).
    seed : int, optional
        Root seed; default the file's ``[scenario] seed``, else 0.
    effects : sequence of str
        ``NAME=VALUE`` / ``NAME.PARAM=VALUE`` items added to the truth vehicle
        (parsed by :func:`vehicles.effects.parse_effects`).
    vehicle : str, optional
        Built-in id or vehicle TOML file (nominal and truth base vehicle).
    duration : float, optional
        Record length [s].
    default_effects : bool
        Keep the scenario's own effects (False keeps only ``effects``).
    src : str or Path
        Where ``cfg`` came from, for messages.

    Returns
    -------
    dict
        Scenario with ``[speed] t_s, v_mps`` knots and explicit ``[road] segments``;
        TOML-serialisable.
    """
    cfg = copy.deepcopy(cfg)
    sc = cfg["scenario"]
    if seed is None:
        seed = int(sc.get("seed", 0))
    if not (isinstance(seed, int) and seed >= 0):
        raise EroadInputError(f"--seed must be a non-negative integer, got {seed!r}")
    sc["seed"] = int(seed)
    if vehicle is not None:
        sc["vehicle"] = str(vehicle)
    if "vehicle" in sc and str(sc["vehicle"]).endswith(".toml"):
        sc["vehicle"] = str(Path(sc["vehicle"]).resolve())  # the explicit scenario works anywhere
    if duration is not None:
        if "window_s" in sc:   # a windowed scenario: --duration is the window's (the dataset's)
            sc["window_s"] = [float(sc["window_s"][0]), float(sc["window_s"][0]) + float(duration)]
        else:
            sc["duration_s"] = float(duration)
    for key, default in (("duration_s", None), ("sample_rate_hz", 200.0), ("start_time_s", 0.0),
                         ("runin_s", 2.0), ("reference_axle", 3), ("vehicle", "dump_truck_8x4"),
                         ("name", "custom"), ("dataset_name", "synth-{seed}"), ("description", "")):
        if key not in sc:
            if default is None:
                raise EroadInputError(f"{src}: [scenario] {key} is missing")
            sc[key] = default
    T = float(sc["duration_s"])
    fs = float(sc["sample_rate_hz"])
    if not (T > 0 and fs > 0 and float(sc["runin_s"]) >= 0):
        raise EroadInputError(f"{src}: [scenario] duration_s and sample_rate_hz must be > 0, "
                              "runin_s >= 0")
    if abs(T * fs - round(T * fs)) > 1e-9 * T * fs:
        raise EroadInputError(f"{src}: duration_s * sample_rate_hz = {T * fs:g} must be a whole "
                              "number of samples")
    sc["dataset_name"] = str(sc["dataset_name"]).replace("{seed}", str(seed))
    runin = float(sc["runin_s"])
    if "window_s" in sc:
        _check_window(sc, src)

    sp = cfg["speed"]
    if "t_s" not in sp:
        if sp.get("kind", "smooth_random") != "smooth_random":
            raise EroadInputError(f"{src}: [speed] kind must be 'smooth_random' or give t_s, v_mps")
        tk, vk = smooth_speed(seed, -runin, T, lo=float(_need(cfg, "speed", "min_mps", src)),
                              hi=float(_need(cfg, "speed", "max_mps", src)),
                              spacing=float(sp.get("knot_spacing_s", 5.0)),
                              exact_range=bool(sp.get("exact_range", False)), record=(0.0, T))
        cfg["speed"] = {"kind": "pchip_knots", "t_s": tk, "v_mps": vk,
                        **{k: sp[k] for k in ("min_mps", "max_mps", "knot_spacing_s",
                                              "exact_range") if k in sp}}
    else:
        cfg["speed"]["kind"] = "pchip_knots"
    tk = np.asarray(cfg["speed"]["t_s"], float)
    vk = np.asarray(cfg["speed"]["v_mps"], float)
    if (tk.size < 2 or tk.size != vk.size or np.any(np.diff(tk) <= 0) or tk[0] > -runin + 1e-9
            or tk[-1] < T - 1e-9 or np.any(vk <= 0)):
        raise EroadInputError(f"{src}: [speed] t_s must increase and span {-runin:g} .. {T:g} s, "
                              "v_mps be > 0 and of the same length")

    road = cfg["road"]
    if "profile" in road and "segments" not in road:
        road["segments"] = [_profile_segment(str(road["profile"]), src)]
    if "segments" not in road:
        if "random" not in road:
            raise EroadInputError(f"{src}: [road] needs segments or a [road.random] table")
        road["segments"] = _random_segments(road["random"], seed, T, src)
    segs = road["segments"]
    if not segs:
        raise EroadInputError(f"{src}: [road] segments is empty")
    props = np.array([float(s.get("proportion", 0)) for s in segs])
    if np.any(props <= 0):
        raise EroadInputError(f"{src}: every road segment needs a proportion > 0")
    for s in segs:
        s["proportion"] = float(s["proportion"] / props.sum())
        for key, default in (("w", 2.0), ("nmin", 0.1), ("nmax", 5.0)):
            s.setdefault(key, default)
        if "Gq_n0" not in s:
            raise EroadInputError(f"{src}: a road segment lacks Gq_n0 [m^3]")
        if "label" not in s:
            from roadlib.psd import class_of

            s["label"] = class_of(s["Gq_n0"])
    for key, default in (("dx_m", 0.025), ("dy_m", 0.1), ("width_m", 3.0), ("lam", 1.0)):
        road.setdefault(key, default)

    tr = cfg["truth"]
    tr.setdefault("chassis", "nominal")
    tr.setdefault("frame_segments", 0)
    tr.setdefault("dt_s", 0.0)
    eff = dict(tr.get("effects", {})) if default_effects else {}
    if tr.get("model", "exudyn") != "exudyn":
        _resolve_independent(cfg, eff, effects, seed, src)
    elif "independent" in tr:
        raise EroadInputError(f"{src}: [truth.independent] needs [truth] model = \"independent\"")
    elif effects:
        from vehicles.effects import parse_effects

        for name, params in parse_effects(list(effects)).items():
            merged = dict(eff.get(name, {}))
            merged.update(params or {})
            eff[name] = merged
    if tr.get("model", "exudyn") == "exudyn":
        if eff:
            from vehicles.effects import resolve_effects

            eff = {name: dict(params) for name, params in resolve_effects(eff).items()}
        tr["effects"] = eff
    noise = cfg["noise"]
    for key in _KEYS["noise"]:
        noise.setdefault(key, 0.0)
        if not (isinstance(noise[key], (int, float)) and noise[key] >= 0):
            raise EroadInputError(f"{src}: [noise] {key} must be a number >= 0")
    return cfg


def _check_window(sc: dict, src) -> None:
    """``[scenario] window_s = [T0, T1]``: inside the record, whole samples from its start."""
    w = sc["window_s"]
    if not (isinstance(w, (list, tuple)) and len(w) == 2
            and all(isinstance(v, (int, float)) for v in w)):
        raise EroadInputError(f"{src}: [scenario] window_s must be two numbers [T0, T1] in s")
    t0, t1 = float(w[0]), float(w[1])
    start, T, fs = float(sc["start_time_s"]), float(sc["duration_s"]), float(sc["sample_rate_hz"])
    if not (start - 1e-9 <= t0 < t1 <= start + T + 1e-9):
        raise EroadInputError(f"{src}: window {t0:g}-{t1:g} s must lie inside the record "
                              f"{start:g}-{start + T:g} s (with --duration: the window's length)")
    for v in ((t0 - start) * fs, (t1 - t0) * fs):
        if abs(v - round(v)) > 1e-6:
            raise EroadInputError(f"{src}: window {t0:g}-{t1:g} s must start and end on the "
                                  f"record's {fs:g} Hz sample grid")
    sc["window_s"] = [t0, t1]


def window_segments(segments: list, window, x_of_t) -> list:
    """The segments of a record clipped to a window (what the window's truth lists).

    Parameters
    ----------
    segments : list of dict
        Record segments with ``t_start, t_end`` [s] (record time axis) and ``x_start, x_end``.
    window : (float, float)
        [s] on the same axis.
    x_of_t : callable
        Road x [m] of the reference axle at a time on that axis.

    Returns
    -------
    list of dict
        Segments overlapping the window, times and positions clipped to it,
        ``proportion`` and ``duration_s`` of the window, ``record_segment`` (1-based).
    """
    t0, t1 = float(window[0]), float(window[1])
    out = []
    for i, s in enumerate(segments):
        if s["t_end"] <= t0 or s["t_start"] >= t1:
            continue
        d = dict(s, record_segment=i + 1)
        if s["t_start"] < t0:
            d["t_start"], d["x_start"] = t0, float(x_of_t(t0))
        if s["t_end"] > t1:
            d["t_end"], d["x_end"] = t1, float(x_of_t(t1))
        d["duration_s"] = d["t_end"] - d["t_start"]
        d["proportion"] = d["duration_s"] / (t1 - t0)
        out.append(d)
    return out


def _parse_effect_items(items) -> dict:
    """``NAME``, ``NAME=VALUE`` (primary parameter), ``NAME.PARAM=VALUE`` -> {name: {param: value}}
    for the independent model's own effects (``drives.independent_truck.EFFECTS``)."""
    from drives.independent_truck import EFFECTS

    out: dict = {}
    for item in items:
        key, eq, val = str(item).partition("=")
        name, dot, param = key.strip().partition(".")
        if name not in EFFECTS:
            raise EroadInputError(f"effect {name!r} is not available with [truth] model = "
                                  f"\"independent\" (supported: {', '.join(EFFECTS)})")
        params = out.setdefault(name, {})
        if eq:
            try:
                value = float(val)
            except ValueError:
                raise EroadInputError(f"--effect {item}: {val!r} is not a number") from None
            params[param if dot else next(iter(EFFECTS[name]))] = value
    return out


def _resolve_independent(cfg: dict, eff: dict, effects, seed: int, src) -> None:
    """Fill ``[truth]`` of an independent-model scenario: options drawn and checked, effects."""
    from drives.independent_truck import resolve_effects, resolve_options

    tr = cfg["truth"]
    if tr["model"] not in TRUTH_MODELS:
        raise EroadInputError(f"{src}: [truth] model = {tr['model']!r}: use one of "
                              f"{', '.join(TRUTH_MODELS)}")
    if tr["chassis"] != "nominal" or int(tr["frame_segments"]) != 0 or float(tr["dt_s"]) != 0:
        raise EroadInputError(f"{src}: [truth] chassis, frame_segments and dt_s are Exudyn options; "
                              "the independent model takes its step from [truth.independent] dt_s")
    opts = dict(tr.get("independent", {}))
    rng = _rng(seed, STREAM_TRUTH_OPTIONS)
    for key in sorted(opts):            # a [lo, hi] range is drawn per seed (sorted: stable order)
        v = opts[key]
        if isinstance(v, list):
            if len(v) != 2 or not all(isinstance(x, (int, float)) for x in v) or v[0] > v[1]:
                raise EroadInputError(f"{src}: [truth.independent] {key} must be a number or [lo, hi]")
            opts[key] = float(rng.uniform(float(v[0]), float(v[1])))
    tr["independent"] = resolve_options(opts, src=f"{src}: [truth.independent]")
    for name, params in _parse_effect_items(effects).items():
        merged = dict(eff.get(name, {}))
        merged.update(params)
        eff[name] = merged
    tr["effects"] = resolve_effects(eff)


def _profile_file(name: str, src) -> Path:
    p = PROFILE_DIR / f"{name}.txt"
    if not (re.fullmatch(r"[A-Za-z0-9_]+", name) and p.is_file()):
        known = sorted(f.stem for f in PROFILE_DIR.glob("*.txt"))
        raise EroadInputError(f"{src}: [road] profile = {name!r}: unknown (known: {', '.join(known)})")
    return p


def read_profile(name: str, src="profile") -> tuple[np.ndarray, np.ndarray]:
    """A measured longitudinal profile: chainage from 0 [m] and detrended height [m].

    The straight line fitted by least squares (grade and level) is removed.
    """
    data = np.loadtxt(_profile_file(name, src))
    x, z, _ = detrend_profile(data[:, 0], data[:, 1])
    return x, z


def _profile_segment(name: str, src) -> dict:
    """One road segment describing a measured profile: an ISO 8608 fit of its PSD.

    Gq(n0) and w from a least-squares line through log Welch PSD (0.05-2 cycles/m,
    one-sided, displacement PSD in m^3) -- descriptive truth for scoring only.
    """
    from scipy.signal import welch

    from roadlib.psd import class_of

    x, z = read_profile(name, src)
    dx = float(np.mean(np.diff(x)))
    n, g = welch(z, fs=1.0 / dx, nperseg=512, detrend="linear")
    sel = (n >= 0.05) & (n <= 2.0)
    slope, icpt = np.polyfit(np.log10(n[sel] / 0.1), np.log10(g[sel]), 1)
    gq = float(10 ** icpt)
    return {"proportion": 1.0, "Gq_n0": gq, "w": float(-slope), "nmin": 0.05, "nmax": 2.0,
            "label": class_of(gq)}


def profile_mix_weight(y, width: float):
    """Weight a(y) of the profile p(x) in the measured-profile road at lateral position ``y`` [m]
    (:func:`build_profile_road`: z = a p(x) + (1 - a) p(x + PROFILE_SHIFT_M)), 1 at the left edge,
    0 at the right one of a road ``width`` [m] wide."""
    return 0.5 + np.asarray(y, dtype=float) / float(width)


def build_profile_road(cfg: dict, plan: dict):
    """The road of a measured profile (``[road] profile``).

    Both wheel tracks come from the one detrended profile p(x): z(x, y) =
    a(y) p(x) + (1 - a(y)) p(x + PROFILE_SHIFT_M), a(y) running linearly from 1 at
    the left road edge to 0 at the right one, so the two tracks are different
    mixes of the same measured profile (partly coherent, as real left/right tracks;
    left track at y = +0.93 m is 0.81 p(x) + 0.19 p(x + 40 m) on a 3 m road). p(x) between
    the profile's samples is band-limited (:func:`bandlimited_profile`): the road keeps the
    profile's spectrum up to its Nyquist wavenumber and has nothing above it.

    Raises
    ------
    EroadInputError
        The drive needs more road than the profile has.
    """
    from roadlib.surface import RoadSurface

    road = cfg["road"]
    name = str(road["profile"])
    xp, zp = read_profile(name, "[road] profile")
    dx, dy, width = float(road["dx_m"]), float(road["dy_m"]), float(road["width_m"])
    length = float(plan["road_length"])
    if length + PROFILE_SHIFT_M > xp[-1]:
        raise EroadInputError(f"[road] profile = {name!r}: the drive needs {length:.0f} m of road "
                              f"(+{PROFILE_SHIFT_M:g} m lateral-mix shift) but the profile has "
                              f"{xp[-1]:.0f} m; shorten duration_s or lower the speed")
    x = np.arange(int(round(length / dx)) + 1) * dx
    ny = int(round(width / dy)) + 1 if width > 0 else 1
    y = (np.arange(ny) - (ny - 1) / 2) * dy
    a = profile_mix_weight(y, width) if width > 0 else np.ones(1)
    xf, zf = bandlimited_profile(xp, zp, dx)
    p0 = np.interp(x, xf, zf)
    p1 = np.interp(x + PROFILE_SHIFT_M, xf, zf)
    z = a[None, :] * p0[:, None] + (1 - a[None, :]) * p1[:, None]
    meta = {"generator": "drives.synth.build_profile_road", "profile": name,
            "shift_m": PROFILE_SHIFT_M, "segments": [{"start": 0.0, "end": float(x[-1])}],
            "junctions": []}
    return RoadSurface(x, y, z, meta)


# --------------------------------------------------------------------------- the drive

def _speed_samples(cfg: dict, t: np.ndarray) -> np.ndarray:
    sp = cfg["speed"]
    return PchipInterpolator(np.asarray(sp["t_s"], float), np.asarray(sp["v_mps"], float))(t)


def _positions(t: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Distance travelled [m] at samples t of a piecewise-linear speed (trapezoid, exact)."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])


def plan_drive(cfg: dict, axle_x: list[float]) -> dict:
    """Speed samples, road layout and segment boundaries of an explicit scenario.

    Parameters
    ----------
    cfg : dict
        Explicit scenario (:func:`resolve_scenario`).
    axle_x : list of float
        Axle positions [m] in the vehicle frame (0 first axle, negative behind).

    Returns
    -------
    dict
        ``t_sim`` (simulation time from 0, at the output rate), ``v_sim``,
        ``x_front0`` (road x of axle 1 at t_sim = 0), ``road_length``,
        ``seg_lengths`` (road lengths [m] in order), ``segments`` (dicts with
        ``x_start, x_end`` [m] and ``t_start, t_end`` [s] record time, for the
        reference axle).
    """
    sc = cfg["scenario"]
    T, fs, runin = float(sc["duration_s"]), float(sc["sample_rate_hz"]), float(sc["runin_s"])
    ref = int(sc["reference_axle"])
    if not 1 <= ref <= len(axle_x):
        raise EroadInputError(f"[scenario] reference_axle = {ref}: the vehicle has "
                              f"{len(axle_x)} axles")
    n_run = int(round(runin * fs))
    n_rec = int(round(T * fs))
    k = np.arange(-n_run, n_rec + 1)
    t_rec = k / fs                       # record time of each simulation sample
    v = _speed_samples(cfg, t_rec)
    s = _positions(t_rec, v)             # distance since the simulation start
    rear = min(axle_x)
    x_front0 = ROAD_MARGIN_M - rear      # the rearmost axle starts ROAD_MARGIN_M into the road
    x_ref = x_front0 + axle_x[ref - 1] + s
    props = np.array([float(seg["proportion"]) for seg in cfg["road"]["segments"]])
    t_bounds = T * np.concatenate([[0.0], np.cumsum(props)])
    t_bounds[-1] = T
    x_bounds = np.interp(t_bounds, t_rec, x_ref)
    dx = float(cfg["road"]["dx_m"])
    road_length = float(math.ceil((x_front0 + s[-1] + ROAD_MARGIN_M) / dx) * dx)
    edges = np.concatenate([[0.0], x_bounds[1:-1], [road_length]])
    seg_out = []
    for i, seg in enumerate(cfg["road"]["segments"]):
        seg_out.append(dict(seg, t_start=float(t_bounds[i]), t_end=float(t_bounds[i + 1]),
                            x_start=float(edges[i]), x_end=float(edges[i + 1])))
    return {"t_sim": t_rec + runin, "t_rec": t_rec, "v_sim": v, "x_ref": x_ref, "n_runin": n_run,
            "n_record": n_rec, "x_front0": float(x_front0), "road_length": road_length,
            "seg_lengths": list(np.diff(edges)), "segments": seg_out}


def build_road(cfg: dict, plan: dict):
    """The truth road surface (roadlib.segments, junctions patched).

    Returns
    -------
    roadlib.surface.RoadSurface
    """
    from roadlib.segments import RoadSegment, segmented_surface

    road = cfg["road"]
    if "profile" in road:
        return build_profile_road(cfg, plan)
    segs = [RoadSegment(Gq_n0=float(s["Gq_n0"]), share=float(length), w=float(s["w"]),
                        nmin=float(s["nmin"]), nmax=float(s["nmax"]),
                        lam=float(s.get("lam", road["lam"])), label=str(s.get("label", "")))
            for s, length in zip(road["segments"], plan["seg_lengths"])]
    seed = _int_seed(cfg["scenario"]["seed"], STREAM_ROAD)
    return segmented_surface(segs, plan["road_length"], float(road["width_m"]),
                             float(road["dx_m"]), float(road["dy_m"]), seed=seed)


def add_noise(frame: pd.DataFrame, noise: dict, seed: int) -> pd.DataFrame:
    """Add white Gaussian sensor noise per channel (stream ``(3, crc32(name))``).

    Parameters
    ----------
    frame : DataFrame
        ``time``, channels, ``speed``.
    noise : dict
        Standard deviations per quantity ([noise] table).
    seed : int
        Root seed.

    Returns
    -------
    DataFrame
        A noisy copy (speed clipped at 0).
    """
    from drives.format import parse_channel

    out = frame.copy()
    for c in frame.columns:
        if c == "time":
            continue
        q = parse_channel(c)[0]
        sd = float(noise["speed_mps"] if q == "speed" else noise[_NOISE_KEY[q]])
        if sd > 0:
            rng = _rng(seed, STREAM_NOISE, zlib.crc32(c.encode()))
            out[c] = frame[c].to_numpy() + sd * rng.standard_normal(len(frame))
    if "speed" in out:
        out["speed"] = np.maximum(out["speed"].to_numpy(), 0.0)
    return out


def _sim_kwargs(cfg: dict) -> dict:
    tr = cfg["truth"]
    if tr.get("model", "exudyn") == "independent":
        return {"model": "independent", "options": dict(tr["independent"]),
                "effects": {k: dict(v) for k, v in tr["effects"].items()}}
    kw = {"effects": {k: dict(v) for k, v in tr["effects"].items()}}
    if tr["chassis"] != "nominal":
        kw["chassis"] = tr["chassis"]
    if int(tr["frame_segments"]) > 0:
        kw["frame_segments"] = int(tr["frame_segments"])
    if float(tr["dt_s"]) > 0:
        kw["dt"] = float(tr["dt_s"])
    return kw


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, (str, int, float, bool)) or obj is None:
        return obj
    return repr(obj)


#: SimResult.meta keys that vary from run to run (timings, host) stay out of truth/
_VOLATILE = re.compile(r"wall|cpu|realtime|solve_s|elapsed|host|start(ed)?_at|finished|date")


def synthesize(cfg: dict, out, *, force: bool = False, src: str = "") -> dict:
    """Run the virtual test drive of an explicit scenario and write the dataset.

    Parameters
    ----------
    cfg : dict
        Explicit scenario (:func:`resolve_scenario`).
    out : str or Path
        Dataset folder to create (new or empty unless ``force``).
    force : bool
        Replace a non-empty ``out``.
    src : str
        Command line or file that made ``cfg``, recorded in truth/.

    Returns
    -------
    dict
        Summary (also ``truth/summary.json`` without the wall time).
    """
    t_wall = time.perf_counter()
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; choose another --out or use --force")
    sc = cfg["scenario"]
    seed = int(sc["seed"])
    independent = cfg["truth"].get("model", "exudyn") == "independent"
    if independent:
        from drives.independent_truck import build_truck, read_vehicle_toml, simulate_independent

        axle_x = [float(a["x"]) for a in read_vehicle_toml(sc["vehicle"])["axle"]]
    else:
        from vehicles.params import load_vehicle
        from vehicles.simulate import SpeedProfile, simulate

        vp = load_vehicle(sc["vehicle"])
        axle_x = [float(a.x) for a in vp.axles]
    plan = plan_drive(cfg, axle_x)
    road = build_road(cfg, plan)
    fs = float(sc["sample_rate_hz"])
    n_rec, n_run = plan["n_record"], plan["n_runin"]
    duration_sim = (n_run + n_rec) / fs
    if independent:
        model = build_truck(sc["vehicle"], options=cfg["truth"]["independent"],
                            effects=cfg["truth"]["effects"])
        res = simulate_independent(model, road, t_speed=plan["t_sim"], v_speed=plan["v_sim"],
                                   duration=duration_sim, fs_out=fs, x_start=plan["x_front0"],
                                   y_offset=0.0)
    else:
        res = simulate(vp, road, speed=SpeedProfile(plan["t_sim"], plan["v_sim"]),
                       duration=duration_sim, fs_out=fs, x_start=plan["x_front0"], y_offset=0.0,
                       seed=_int_seed(seed, STREAM_VEHICLE), **_sim_kwargs(cfg))
    truth_tyres = ("unilateral" if model.tyres["liftoff"] else "bilateral") if independent \
        else str(res.meta.get("tyres", "unilateral"))
    tsim = np.asarray(res.time, float)
    idx = np.searchsorted(tsim, n_run / fs - 0.25 / fs)
    if tsim.size - idx < n_rec:
        from eroad.errors import SimulationError

        raise SimulationError(f"simulation returned {tsim.size - idx} record samples, expected {n_rec}")
    sel = slice(idx, idx + n_rec)
    start = float(sc["start_time_s"])
    clean = pd.DataFrame({"time": start + np.arange(n_rec) / fs})
    from drives.format import parse_channel

    names = [c for c in res.channels if parse_channel(c) is not None and c != "speed"]
    for c in names:
        clean[c] = np.asarray(res.channels[c], float)[sel]
    # the recorded speed: the simulator's channel (effects such as speed_scale act on it)
    if "speed" in res.channels:
        clean["speed"] = np.asarray(res.channels["speed"], float)[sel]
    else:
        clean["speed"] = plan["v_sim"][n_run:n_run + n_rec]
    noisy = add_noise(clean, cfg["noise"], seed)

    # the road puts each junction half-way between grid samples: the actual boundaries
    # (within dx/2 of the planned ones) and the reference axle's times at them
    actual = road.meta["segments"]
    segments = []
    for i, s in enumerate(plan["segments"]):
        d = dict(s)
        d["x_start"] = 0.0 if i == 0 else float(actual[i]["start"])
        d["x_end"] = float(road.x_max) if i == len(actual) - 1 else float(actual[i]["end"])
        d["t_start"] = start + (0.0 if i == 0 else float(np.interp(d["x_start"], plan["x_ref"],
                                                                     plan["t_rec"])))
        d["t_end"] = start + (n_rec / fs if i == len(actual) - 1 else
                              float(np.interp(d["x_end"], plan["x_ref"], plan["t_rec"])))
        d["duration_s"] = d["t_end"] - d["t_start"]
        d["dx_m"] = float(cfg["road"]["dx_m"])
        d["dy_m"] = float(cfg["road"]["dy_m"])
        segments.append(d)
    # a windowed scenario (luliang): the dataset is the window cut from the record (the same
    # samples and noise); the whole record goes to record/, a dataset of its own
    window = sc.get("window_s")
    record_noisy, record_segments, n_ds, ds_start = noisy, segments, n_rec, start
    if window is not None:
        i0 = int(round((float(window[0]) - start) * fs))
        n_ds = int(round((float(window[1]) - float(window[0])) * fs))
        ds_start = float(window[0])

        def cut(df):   # the window's rows; time written as the dataset's own grid
            w = df.iloc[i0:i0 + n_ds].reset_index(drop=True).copy()
            w["time"] = ds_start + np.arange(n_ds) / fs
            return w

        clean, noisy = cut(clean), cut(noisy)
        segments = window_segments(record_segments, window,
                                   lambda t: np.interp(t - start, plan["t_rec"], plan["x_ref"]))
    sim_meta = {k: v for k, v in dict(getattr(res, "meta", {}) or {}).items() if not _VOLATILE.search(k)}
    truth = {
        "generator": "eroad synth (drives.synth)",
        "scenario": sc["name"],
        "seed": seed,
        "streams": {"draws": [seed, STREAM_DRAWS], "speed": [seed, STREAM_SPEED],
                    "road_seed": _int_seed(seed, STREAM_ROAD),
                    "noise": [seed, STREAM_NOISE, "crc32(channel)"],
                    "vehicle_seed": _int_seed(seed, STREAM_VEHICLE)},
        "record": {"start_time_s": ds_start, "duration_s": n_ds / fs, "sample_rate_hz": fs,
                   "runin_s": n_run / fs, "reference_axle": int(sc["reference_axle"])},
        "segments": segments,
        "junctions": road.meta.get("junctions", []),
        "road": {"file": "road.npz", "length_m": plan["road_length"], "width_m": cfg["road"]["width_m"],
                 "dx_m": cfg["road"]["dx_m"], "dy_m": cfg["road"]["dy_m"],
                 "x_axle1_at_sim_start_m": plan["x_front0"]},
        "speed": {"interpolation": "pchip", "t_s": [start + t for t in cfg["speed"]["t_s"]],
                  "v_mps": cfg["speed"]["v_mps"], "min_mps": float(clean["speed"].min()),
                  "max_mps": float(clean["speed"].max())},
        "vehicle": {"nominal": sc["vehicle"], "axle_x_m": axle_x, "truth": cfg["truth"],
                    "simulate_kwargs": _sim_kwargs(cfg), "simulate_meta": sim_meta},
        "noise": cfg["noise"],
        "made_by": src,
    }
    if window is not None:
        truth["whole_record"] = {"folder": RECORD_DIR, "start_time_s": start,
                                 "duration_s": n_rec / fs, "window_s": list(window),
                                 "segments": record_segments}
    truth = _jsonable(truth)
    summary = {
        "scenario": sc["name"], "seed": seed, "dataset_name": sc["dataset_name"],
        "duration_s": n_ds / fs, "sample_rate_hz": fs, "channels": list(noisy.columns[1:]),
        "speed_range_mps": [truth["speed"]["min_mps"], truth["speed"]["max_mps"]],
        "segments": [{k: s[k] for k in ("t_start", "t_end", "proportion", "Gq_n0", "w", "nmin",
                                         "nmax", "label", "x_start", "x_end")} for s in segments],
        "effects": cfg["truth"]["effects"], "chassis": cfg["truth"]["chassis"],
        # what made the drive: the truth model, its tyres and how often a tyre left the road
        "truth_model": {"model": "independent" if independent else "exudyn",
                        "version": TRUTH_MODEL_VERSION,
                        "tyres": truth_tyres,
                        "tyre_lift_off_fraction": float(res.meta.get("tyre_lift_off_fraction",
                                                                     float("nan")))},
    }
    if window is not None:
        summary["record_s"] = [start, start + n_rec / fs]
        summary["window_s"] = list(window)

    def add_truth(tmp: Path):
        import tomli_w

        td = tmp / TRUTH_DIR
        td.mkdir()
        (td / "scenario.toml").write_text(tomli_w.dumps(_jsonable(cfg)), encoding="utf-8")
        (td / "truth.json").write_text(json.dumps(truth, indent=1, sort_keys=True) + "\n")
        (td / "summary.json").write_text(json.dumps(_jsonable(summary), indent=1) + "\n")
        clean.to_csv(td / "channels_clean.csv", index=False, lineterminator="\n")
        road.save(td / "road.npz")
        mode = 0o666 & ~_umask()
        for f in td.iterdir():
            os.chmod(f, mode)
        if window is not None:
            rmeta = dict(meta, name=f"{sc['name']}-record-{start:g}-{start + n_rec / fs:g}",
                         start_time_s=start,
                         description=(f"virtual test drive (eroad synth), the whole record; the "
                                      f"dataset one folder up is its {window[0]:g}-{window[1]:g} s "
                                      "window"))
            write_drive(tmp / RECORD_DIR, record_noisy, rmeta, vehicle_file=vfile)

    # both truth models zero their outputs at the nominal vehicle's static equilibrium
    # (a payload error sags the mean displacement): say so (drives.format.SUSP_DISP_ZERO)
    meta = {"name": sc["dataset_name"], "sample_rate_hz": fs, "start_time_s": ds_start,
            "susp_disp_zero": ZERO_NOMINAL_STATIC,
            "description": "virtual test drive (eroad synth); what made it is in truth/"}
    if window is not None:
        meta["description"] = (f"virtual test drive (eroad synth), the {window[0]:g}-{window[1]:g} s "
                               f"window of the record in {RECORD_DIR}/; what made it is in truth/")
    vfile = None
    vpath = Path(str(sc["vehicle"]))
    if vpath.suffix == ".toml" and vpath.is_file():
        vfile = vpath
    else:
        meta["vehicle"] = str(sc["vehicle"])
    write_drive(out, noisy, meta, vehicle_file=vfile, overwrite=force, add_files=add_truth)
    summary["out"] = str(out)
    summary["wall_s"] = time.perf_counter() - t_wall
    return _jsonable(summary)


def synth_command(*, scenario=None, seed=None, effects=(), vehicle=None, duration=None,
                  config=None, out, force=False, default_effects=True) -> dict:
    """``eroad synth``: load, resolve and run a scenario.

    Parameters
    ----------
    scenario : str, optional
        Built-in name; default ``luliang`` unless ``config`` is given.
    seed : int, optional
        Root seed (default: the config's, else 0).
    effects : sequence of str
        ``NAME=VALUE`` items.
    vehicle : str, optional
        Vehicle id or file.
    duration : float, optional
        Record length [s].
    config : str or Path, optional
        Scenario TOML file (explicit or generative).
    out : str or Path
        Dataset folder.
    force : bool
        Replace a non-empty ``out``.
    default_effects : bool
        Keep the scenario's own effects.

    Returns
    -------
    dict
        Summary (with ``wall_s``).
    """
    if scenario is not None and config is not None:
        raise EroadInputError("give --scenario or --config, not both")
    cfg, path = load_scenario(config if config is not None else (scenario or DEFAULT_SCENARIO))
    resolved = resolve_scenario(cfg, seed, effects=effects, vehicle=vehicle, duration=duration,
                                default_effects=default_effects, src=path)
    made_by = f"scenario {path.name}, seed {resolved['scenario']['seed']}"
    if effects:
        made_by += ", effects " + " ".join(effects)
    return synthesize(resolved, out, force=force, src=made_by)


def read_truth(dataset) -> dict:
    """The truth of a synthetic dataset, for scoring only (never for estimation).

    Parameters
    ----------
    dataset : str or Path
        Dataset folder made by ``eroad synth``.

    Returns
    -------
    dict
        ``truth/truth.json`` with ``road_file`` (Path of ``truth/road.npz``) added.

    Raises
    ------
    EroadInputError
        No ``truth/`` (real data, or a copy without it).
    """
    p = Path(dataset) / TRUTH_DIR / "truth.json"
    if not p.is_file():
        raise EroadInputError(f"{p}: missing; only synthetic datasets carry truth/")
    truth = json.loads(p.read_text())
    truth["road_file"] = p.parent / "road.npz"
    return truth


#: the truth model's version, part of the default dataset's cache key: change it whenever
#: the simulation of a scenario changes its output (a cached record made by an older model
#: must not be served as the embedded dataset).  2026-11-25: one-sided tyres.  2026-11-27:
#: meta.toml declares the displacement zero (``susp_disp_zero``), which the diagnosis reads.
TRUTH_MODEL_VERSION = ("2026-11-27 one-sided tyres; truth_model in the truth summary; "
                       "susp_disp_zero declared; 2026-12-01 tyres read the road's own lines")


def _scenario_key() -> str:
    """Ten hex digits of the default scenario as resolved and of :data:`TRUTH_MODEL_VERSION`:
    the cache folder's name carries it, so a changed scenario file or truth model is never
    served from a stale cache."""
    import hashlib

    import tomli_w

    cfg, path = load_scenario(DEFAULT_SCENARIO)
    text = tomli_w.dumps(_jsonable(resolve_scenario(cfg, DEFAULT_SEED, src=path)))
    return hashlib.sha256((TRUTH_MODEL_VERSION + "\n" + text).encode()).hexdigest()[:10]


def default_dataset(path=None) -> Path:
    """The embedded default dataset (``eroad synth --scenario luliang --seed 0``).

    Generated on first use into ``path`` (default ``$EROAD_CACHE/datasets/luliang-seed0-KEY``
    or ``~/.cache/eroad/datasets/luliang-seed0-KEY``, KEY a hash of the resolved scenario)
    and reused afterwards when it is a valid dataset.

    Parameters
    ----------
    path : str or Path, optional
        Where the dataset lives.

    Returns
    -------
    Path
        The dataset folder.
    """
    if path is None:
        root = Path(os.environ.get("EROAD_CACHE", DEFAULT_CACHE))
        path = root / "datasets" / f"{Path(DEFAULT_SCENARIO).stem}-seed{DEFAULT_SEED}-{_scenario_key()}"
    path = Path(path)
    if (path / TRUTH_DIR / "summary.json").is_file():
        read_drive(path)  # raises with one line if the cache was damaged
        return path
    if path.exists() and any(path.iterdir()):
        raise EroadInputError(f"{path}: exists but is not a complete luliang dataset; remove it")
    try:
        synth_command(scenario=DEFAULT_SCENARIO, seed=DEFAULT_SEED, out=path)
    except (OSError, EroadInputError):
        if not (path / TRUTH_DIR / "summary.json").is_file():  # not a concurrent writer
            raise
    return path


def copy_without_truth(dataset, dest) -> Path:
    """Copy a dataset without ``truth/`` (what a blind consumer sees).

    Returns
    -------
    Path
        ``dest``.
    """
    dest = Path(dest)
    shutil.copytree(dataset, dest, ignore=shutil.ignore_patterns(TRUTH_DIR))
    return dest
