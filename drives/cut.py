"""``eroad data cut``: a dataset cut to a time window, or to the stretches where it moves.

A real drive starts from rest, stops at junctions and crawls through yards; the road
methods (``eroad invert``, ``eroad replica``) turn time into distance with the speed and
need the vehicle moving (speed above ``MIN_SPEED``, 0.5 m/s) throughout. Cutting a
measured drive by hand is where records get damaged, so this module does it the one
way the contract allows: every piece is a dataset of its own (channels.csv and meta.toml
of the source, rows of the piece only, the vehicle file copied along), validated and
renamed into place atomically; the source is only read.

Decisions:

* **Moving stretches**: maximal runs of samples with speed > ``min_speed``; runs shorter
  than ``min_duration`` (3 s: the shortest segment the inversion's accuracy is stated for,
  docs/inverse.md) are dropped and reported. No padding into the slow parts and no
  joining of pieces: the response of a truck pulling away is not a stationary road
  response, and two pieces joined in distance would put a step into every channel.
* **Times stay record times**: the time column is copied as it is; ``start_time_s`` is the
  piece's first time, and ``cut_from`` / ``cut_window_s`` in ``[dataset]`` record where it
  came from (optional fields the contract allows).
* **Output**: ``--window`` alone writes OUT as one dataset; ``--moving`` writes one per
  stretch, OUT/part01, OUT/part02, ... (as ``eroad data import --split-gaps``), all in one
  atomic step.
"""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from eroad.archive import file_sha256
from drives.format import (CHANNELS_FILE, VEHICLE_FILE, read_drive, swap_into_place,
                           temp_folder_beside, write_drive)
from eroad.errors import EroadInputError

#: speed [m/s] above which the road methods take the vehicle as moving
MIN_SPEED = 0.5
#: shortest moving stretch kept [s]
MIN_DURATION = 3.0


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``[i0, i1)`` of the maximal runs of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.r_[0, np.asarray(mask, bool).astype(int), 0]))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def runs_above(speed: np.ndarray, min_speed: float = MIN_SPEED) -> list[tuple[int, int]]:
    """Index ranges ``[i0, i1)`` of the maximal runs with ``speed > min_speed``."""
    return _runs(np.asarray(speed, float) > min_speed)


def slow_stretches(time: np.ndarray, speed: np.ndarray, min_speed: float = MIN_SPEED,
                   most: int = 3) -> str:
    """The stretches at or below ``min_speed``, as text for an error line
    (``"460.00-461.99 s, 470.50-472.00 s"``, at most ``most`` of them and a count)."""
    t = np.asarray(time, float)
    slow = _runs(np.asarray(speed, float) <= min_speed)
    text = ", ".join(f"{t[a]:.2f}-{t[b - 1]:.2f} s" for a, b in slow[:most])
    return text + (f" and {len(slow) - most} more" if len(slow) > most else "")


def require_moving(drive, command: str) -> None:
    """Refuse, with one line, a drive whose speed is at or below ``MIN_SPEED`` anywhere: the
    road methods (``command``: "eroad invert", "eroad diagnose", "eroad replica") turn time
    into distance with it. The line names the slow stretches and the cut that helps."""
    if np.all(np.asarray(drive.speed, float) > MIN_SPEED):
        return
    raise EroadInputError(
        f"{drive.path}: {command} needs a moving vehicle (speed > {MIN_SPEED:g} m/s throughout); "
        f"the speed is at or below that in {slow_stretches(drive.time, drive.speed)}: "
        f"`eroad data cut {drive.path} --moving --out DIR` writes each moving stretch as a dataset "
        f"of its own")


def require_road_record(drive, command: str) -> None:
    """Refuse, with one line, a drive the road methods (``command``: "eroad invert", "eroad
    diagnose", "eroad replica") cannot use: not moving throughout (:func:`require_moving`) or
    shorter than ``MIN_DURATION`` seconds, the shortest stretch ``eroad data cut`` keeps (a
    0.25 s record reached the segmentation and stopped there with a traceback; 3 s records
    invert and diagnose, measured 2026-11-27)."""
    require_moving(drive, command)
    t = np.asarray(drive.time, float)
    dur = float(t[-1] - t[0]) if t.size > 1 else 0.0
    if dur < MIN_DURATION:
        raise EroadInputError(
            f"{drive.path}: {command} needs at least {MIN_DURATION:g} s of record; this one holds "
            f"{dur:.3g} s ({t.size} samples)")


def cut_dataset(src, out, *, window: tuple[float, float] | None = None, moving: bool = False,
                min_speed: float = MIN_SPEED, min_duration: float = MIN_DURATION,
                force: bool = False) -> dict:
    """Cut dataset ``src`` to ``window`` and/or its moving stretches; write them under ``out``.

    Parameters
    ----------
    src : str or Path
        Source dataset folder (read only; validated first).
    out : str or Path
        New (or empty, or with ``force``) folder: the dataset itself (``window`` alone) or
        the folder of ``part01``, ``part02``, ... (``moving``).
    window : (float, float), optional
        Keep ``t0 <= time <= t1`` [s, the time column's record time].
    moving : bool
        Split into the stretches with speed > ``min_speed`` of at least ``min_duration``.
    min_speed : float
        [m/s], > 0.
    min_duration : float
        [s], > 0.
    force : bool
        Replace a non-empty ``out``.

    Returns
    -------
    dict
        ``out``, ``pieces`` (each ``folder``, ``t_start_s``, ``t_end_s``, ``duration_s``,
        ``speed_min_mps``), ``dropped`` (moving stretches shorter than ``min_duration``:
        ``t_start_s``, ``t_end_s``), ``slow_s`` (time at or below ``min_speed``).

    Raises
    ------
    EroadInputError
        One line: an invalid source, a bad window or threshold, an existing non-empty
        ``out``, no piece left.
    """
    src, out = Path(src), Path(out)
    if not (window is not None or moving):
        raise EroadInputError("eroad data cut: give --window T0 T1, --moving, or both")
    if not (np.isfinite(min_speed) and min_speed > 0 and np.isfinite(min_duration) and min_duration > 0):
        raise EroadInputError(f"eroad data cut: --min-speed and --min-duration must be > 0, got "
                              f"{min_speed:g} and {min_duration:g}")
    if out.resolve() == src.resolve() or src.resolve() in out.resolve().parents:
        raise EroadInputError(f"{out}: --out must lie outside the source dataset {src}")
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; choose another folder or use --force")
    drive = read_drive(src)
    t, v = np.asarray(drive.time, float), np.asarray(drive.speed, float)
    keep = np.ones(t.size, bool)
    if window is not None:
        t0, t1 = (float(x) for x in window)
        if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
            raise EroadInputError(f"eroad data cut: --window needs T0 < T1, got {t0:g} {t1:g}")
        keep = (t >= t0) & (t <= t1)
        if np.count_nonzero(keep) < 2:
            raise EroadInputError(f"{src / CHANNELS_FILE}: window {t0:g}-{t1:g} s holds fewer than 2 "
                                  f"samples (record spans {t[0]:g} to {t[-1]:g} s)")
    dt = float(np.median(np.diff(t)))
    pieces, dropped = [], []
    if moving:
        for a, b in runs_above(np.where(keep, v, -np.inf), min_speed):
            dur = (b - a) * dt
            (pieces if dur >= min_duration - 1e-9 else dropped).append((a, b))
        if not pieces:
            raise EroadInputError(
                f"{src}: no stretch of at least {min_duration:g} s with speed > {min_speed:g} m/s"
                + (f" in {window[0]:g}-{window[1]:g} s" if window is not None else "")
                + f" (speed {v[keep].min():.3g}-{v[keep].max():.3g} m/s)")
    else:
        idx = np.flatnonzero(keep)
        pieces = [(int(idx[0]), int(idx[-1]) + 1)]
    frame = drive.to_dataframe()
    base = {k: val for k, val in drive.meta.items() if k not in ("start_time_s", "cut_from", "cut_window_s")}
    vehicle_file = drive.vehicle if isinstance(drive.vehicle, Path) else None
    if vehicle_file is not None:
        base["vehicle"] = VEHICLE_FILE
    sha = file_sha256(src / CHANNELS_FILE)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_folder_beside(out) if moving else None
    written = []
    try:
        for k, (a, b) in enumerate(pieces, start=1):
            meta = dict(base)
            meta["name"] = f"{drive.name} {t[a]:.2f}-{t[b - 1]:.2f} s"
            meta["start_time_s"] = float(t[a])
            meta["cut_from"] = str(src.resolve())
            meta["cut_from_sha256"] = sha
            meta["cut_window_s"] = [float(t[a]), float(t[b - 1])]
            if drive.speed_source != "column":
                meta["speed_mps"] = float(v[0])
            target = (tmp / f"part{k:02d}") if moving else out
            write_drive(target, frame.iloc[a:b].reset_index(drop=True), meta,
                        vehicle_file=vehicle_file, units=dict(drive.units), overwrite=force)
            written.append({"folder": str(out / f"part{k:02d}") if moving else str(out),
                            "t_start_s": float(t[a]), "t_end_s": float(t[b - 1]),
                            "duration_s": float((b - a) * dt),
                            "speed_min_mps": float(v[a:b].min())})
        if moving:
            swap_into_place(tmp, out)
    finally:
        if tmp is not None and tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return {"out": str(out), "pieces": written,
            "dropped": [{"t_start_s": float(t[a]), "t_end_s": float(t[b - 1])} for a, b in dropped],
            "slow_s": float(np.count_nonzero(keep & (v <= min_speed)) * dt)}
