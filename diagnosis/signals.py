"""Named, uniformly sampled signals as the diagnosis sees them.

What it is for: one small typed container (:class:`Signals`) that every diagnosis
function takes, plus :func:`as_signals`, which adapts the objects the other
packages produce (``drives.format.Drive``, ``vehicles.result.SimResult``, plain
dicts) without importing those packages.  Time windows (road segments, calibration
and held-out windows) are :class:`Segment` objects in seconds from the start of a
record.

What it is not: a dataset reader or validator (``drives.format`` does that).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from eroad.errors import EroadInputError

__all__ = ["Signals", "Segment", "as_signals", "as_segments"]


@dataclass(frozen=True)
class Segment:
    """A time window of a record.

    Parameters
    ----------
    label : str
        Name shown in tables and figures (e.g. ``"S1"``).
    t_start, t_end : float
        Window in s, measured from the first sample of the record
        (``time - time[0]``), ``t_start < t_end``.
    """

    label: str
    t_start: float
    t_end: float

    def __post_init__(self):
        if not (np.isfinite(self.t_start) and np.isfinite(self.t_end)) or self.t_end <= self.t_start:
            raise EroadInputError(
                f"segment {self.label!r}: need t_start < t_end, got {self.t_start}..{self.t_end} s")


@dataclass(frozen=True)
class Signals:
    """Uniformly sampled named channels.

    Parameters
    ----------
    time : (N,) array, s
        Strictly increasing, uniform.
    channels : mapping name -> (N,) array
        SI units (m, m/s^2), names as in the measurement format
        (``susp_disp_3L``, ``axle_acc_1R``, ``body_acc_3L``, ...).
    units : mapping name -> str, optional
    speed : (N,) array, m/s, optional
        Vehicle speed; used by the front-to-rear delay comparison.
    meta : mapping, optional
        Free metadata (dataset name, vehicle, ...).
    """

    time: np.ndarray
    channels: Mapping[str, np.ndarray]
    units: Mapping[str, str] = field(default_factory=dict)
    speed: np.ndarray | None = None
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        t = np.asarray(self.time, dtype=float)
        if t.ndim != 1 or t.size < 2:
            raise EroadInputError("signals: time must be a 1-D array with at least 2 samples")
        dt = np.diff(t)
        if not np.all(np.isfinite(t)) or np.any(dt <= 0):
            raise EroadInputError("signals: time must be finite and strictly increasing")
        if np.max(np.abs(dt - dt.mean())) > 1e-6 * dt.mean():
            raise EroadInputError("signals: time is not uniformly sampled")
        object.__setattr__(self, "time", t)
        chans = {}
        for name, x in self.channels.items():
            a = np.asarray(x, dtype=float)
            if a.shape != t.shape:
                raise EroadInputError(
                    f"signals: channel {name!r} has {a.size} samples, time has {t.size}")
            if not np.all(np.isfinite(a)):
                raise EroadInputError(f"signals: channel {name!r} has NaN or infinite values")
            chans[str(name)] = a
        object.__setattr__(self, "channels", chans)
        if self.speed is not None:
            v = np.broadcast_to(np.asarray(self.speed, dtype=float), t.shape).copy()
            object.__setattr__(self, "speed", v)

    @property
    def fs(self) -> float:
        """Sample rate in Hz."""
        return float((self.time.size - 1) / (self.time[-1] - self.time[0]))

    @property
    def duration(self) -> float:
        """Record length in s (N / fs)."""
        return self.time.size / self.fs

    @property
    def names(self) -> list[str]:
        """Channel names in insertion order."""
        return list(self.channels)

    def window(self, t_start: float, t_end: float) -> "Signals":
        """Samples with ``t_start <= time - time[0] < t_end`` (s)."""
        rel = self.time - self.time[0]
        m = (rel >= t_start - 1e-9) & (rel < t_end - 1e-9)
        if m.sum() < 2:
            raise EroadInputError(f"signals: window {t_start}..{t_end} s holds fewer than 2 samples")
        return Signals(self.time[m], {k: v[m] for k, v in self.channels.items()}, dict(self.units),
                       None if self.speed is None else self.speed[m], dict(self.meta))

    def select(self, names: Iterable[str]) -> "Signals":
        """A copy restricted to ``names`` (missing names raise EroadInputError)."""
        names = list(names)
        missing = [n for n in names if n not in self.channels]
        if missing:
            raise EroadInputError(f"signals: missing channel(s) {', '.join(missing)}")
        return Signals(self.time, {n: self.channels[n] for n in names}, dict(self.units),
                       self.speed, dict(self.meta))


def as_signals(obj: Any) -> Signals:
    """Adapt a dataset-like object to :class:`Signals`.

    Accepts a :class:`Signals`; any object with ``time`` and ``channels``
    attributes (``drives.format.Drive`` with a DataFrame, ``vehicles.result.SimResult``
    with a dict), optionally ``speed``, ``units``, ``meta``; or a mapping with a
    ``"time"`` key and channel arrays.  A ``speed`` column among the channels is
    moved to ``speed``.  A constant ``meta["speed_mps"]`` is used when no speed
    signal exists.

    Parameters
    ----------
    obj : Signals, Drive-like, SimResult-like or mapping

    Returns
    -------
    Signals
    """
    if isinstance(obj, Signals):
        return obj
    if isinstance(obj, Mapping):
        if "time" not in obj:
            raise EroadInputError("signals: mapping has no 'time' entry")
        time = obj["time"]
        chans = {k: v for k, v in obj.items() if k != "time"}
        units, meta, speed = {}, {}, None
    elif hasattr(obj, "time") and hasattr(obj, "channels"):
        time = obj.time
        ch = obj.channels
        if hasattr(ch, "columns"):  # pandas DataFrame
            chans = {str(c): np.asarray(ch[c]) for c in ch.columns if str(c) != "time"}
        else:
            chans = dict(ch)
        units = dict(getattr(obj, "units", {}) or {})
        meta = dict(getattr(obj, "meta", {}) or {})
        speed = getattr(obj, "speed", None)
    else:
        raise EroadInputError(f"signals: cannot read {type(obj).__name__} (need time and channels)")
    if "speed" in chans:
        sp = chans.pop("speed")
        speed = sp if speed is None else speed
    if speed is None and "speed_mps" in meta:
        speed = float(meta["speed_mps"])
    return Signals(np.asarray(time, dtype=float), chans, units, speed, meta)


def as_segments(segments: Sequence[Segment | tuple] | None, duration: float) -> list[Segment]:
    """Normalise a segment list; ``None`` gives no segments.

    Parameters
    ----------
    segments : sequence of Segment or (label, t_start, t_end) or (t_start, t_end)
    duration : float, s
        Record length; windows are clipped to it.
    """
    out = []
    for i, s in enumerate(segments or ()):
        if isinstance(s, Segment):
            seg = s
        elif len(s) == 3:
            seg = Segment(str(s[0]), float(s[1]), float(s[2]))
        elif len(s) == 2:
            seg = Segment(f"S{i + 1}", float(s[0]), float(s[1]))
        else:
            raise EroadInputError(f"segment {i}: need (label, t_start, t_end), got {s!r}")
        out.append(Segment(seg.label, max(0.0, seg.t_start), min(duration, seg.t_end)))
    labels = [s.label for s in out]
    if len(set(labels)) != len(labels):
        raise EroadInputError("segments: labels must be unique")
    return out
