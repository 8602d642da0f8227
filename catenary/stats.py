"""Contact-force quality statistics (EN 50367 / EN 50318 style) and lateral margin.

What it is for: reducing a contact force time history to the numbers a current
collection assessment quotes: mean ``Fm``, standard deviation ``sd``, ``Fm +/- 3 sd``
(statistical max/min), actual min and max, the percentage of contact loss, and the
lateral offset of the contact point against the collector head's half-width.

Conventions (decisions where the standards leave room or where we cannot quote them):

* Mean, sd, ``Fm +/- 3 sd``, min and max are taken of the (optionally low-pass
  filtered) force; EN 50318 uses a 20 Hz cut-off.  The filter here is a zero-phase
  4th-order Butterworth (``scipy.signal.sosfiltfilt``); ``lowpass_hz=None`` skips it.
* sd is the population standard deviation (``ddof = 0``), so a sine of amplitude A
  gives exactly ``A / sqrt(2)`` over whole periods.
* Contact loss is the fraction of samples (= of time, uniformly sampled) in which the
  **unfiltered** force is at or below ``loss_threshold`` (default 0 N: the penalty
  contact is open), in percent.
* A window in position (``x_range``) or time (``t_range``) selects the analysed section
  (e.g. the two middle spans) after filtering, so filter edge effects stay outside.

What it is not: the arcing measurements of EN 50317 or the percentage of arcing; nor
the simulation producing the force.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from scipy import signal

from eroad.errors import EroadInputError

__all__ = ["ContactStats", "LateralStats", "contact_statistics", "lateral_statistics",
           "lowpass"]


@dataclass(frozen=True)
class ContactStats:
    """Statistics of a contact force [N] (``loss_percent`` in %)."""

    mean: float
    sd: float
    stat_max: float
    stat_min: float
    actual_max: float
    actual_min: float
    loss_percent: float
    n_samples: int
    lowpass_hz: float | None

    units = {"mean": "N", "sd": "N", "stat_max": "N", "stat_min": "N", "actual_max": "N",
             "actual_min": "N", "loss_percent": "%", "n_samples": "-", "lowpass_hz": "Hz"}

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class LateralStats:
    """Lateral offset of the contact point on the head [m] against the half-width."""

    max_abs_offset: float
    rms_offset: float
    half_width: float
    margin: float
    beyond_percent: float

    units = {"max_abs_offset": "m", "rms_offset": "m", "half_width": "m", "margin": "m",
             "beyond_percent": "%"}

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def _as_1d(name: str, v) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise EroadInputError(f"{name}: expected a 1-D series with at least 2 samples, "
                              f"got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise EroadInputError(f"{name}: sample {int(np.argmax(~np.isfinite(a)))} is not finite")
    return a


def lowpass(x, fs: float, cutoff_hz: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass of ``x`` sampled at ``fs`` [Hz], cut-off [Hz]."""
    x = _as_1d("signal", x)
    if not (0 < cutoff_hz < 0.5 * fs):
        raise EroadInputError(f"low-pass cut-off {cutoff_hz} Hz must be in (0, fs/2 = "
                              f"{0.5 * fs} Hz)")
    sos = signal.butter(order, cutoff_hz, fs=fs, output="sos")
    return signal.sosfiltfilt(sos, x)


def contact_statistics(force, *, fs: float | None = None, lowpass_hz: float | None = 20.0,
                       x=None, x_range: tuple[float, float] | None = None, time=None,
                       t_range: tuple[float, float] | None = None,
                       loss_threshold: float = 0.0) -> ContactStats:
    """EN 50367-style statistics of a contact force.

    Parameters
    ----------
    force : array_like, shape (N,)
        Contact force [N], uniformly sampled.
    fs : float, optional
        Sample rate [Hz]; needed when ``lowpass_hz`` is set (or taken from ``time``).
    lowpass_hz : float or None, optional
        Low-pass cut-off [Hz] (default 20, EN 50318); None for none.
    x, x_range : array_like, (float, float), optional
        Contact point position [m] per sample and the analysed section [m].
    time, t_range : array_like, (float, float), optional
        Time [s] per sample and the analysed interval [s].
    loss_threshold : float, optional
        A sample is a contact loss when the unfiltered force is <= this [N] (default 0).

    Returns
    -------
    ContactStats
    """
    f = _as_1d("force", force)
    if time is not None:
        time = _as_1d("time", time)
        if time.size != f.size:
            raise EroadInputError("time and force differ in length")
        if fs is None:
            fs = 1.0 / float(np.median(np.diff(time)))
    keep = np.ones(f.size, dtype=bool)
    if x_range is not None:
        if x is None:
            raise EroadInputError("x_range needs the positions x")
        x = _as_1d("x", x)
        if x.size != f.size:
            raise EroadInputError("x and force differ in length")
        keep &= (x >= x_range[0]) & (x <= x_range[1])
    if t_range is not None:
        if time is None:
            raise EroadInputError("t_range needs the times")
        keep &= (time >= t_range[0]) & (time <= t_range[1])
    if keep.sum() < 2:
        raise EroadInputError("the analysed section holds fewer than 2 samples")
    ff = f
    if lowpass_hz is not None:
        if fs is None:
            raise EroadInputError("lowpass_hz needs the sample rate fs (or time)")
        ff = lowpass(f, fs, lowpass_hz)
    sel = ff[keep]
    mean = float(np.mean(sel))
    sd = float(np.std(sel))
    loss = float(np.mean(f[keep] <= loss_threshold)) * 100.0
    return ContactStats(mean=mean, sd=sd, stat_max=mean + 3 * sd, stat_min=mean - 3 * sd,
                        actual_max=float(np.max(sel)), actual_min=float(np.min(sel)),
                        loss_percent=loss, n_samples=int(keep.sum()),
                        lowpass_hz=None if lowpass_hz is None else float(lowpass_hz))


def lateral_statistics(offset, half_width: float) -> LateralStats:
    """Lateral offset of the contact point from the head centre [m] against the usable
    half-width of the head [m]: largest and RMS offset, the margin ``half_width -
    max|offset|`` (negative: the wire leaves the head) and the share of samples beyond
    the half-width [%]."""
    o = _as_1d("lateral offset", offset)
    if not (half_width > 0 and math.isfinite(half_width)):
        raise EroadInputError(f"head half-width must be positive, got {half_width}")
    mx = float(np.max(np.abs(o)))
    return LateralStats(max_abs_offset=mx, rms_offset=float(np.sqrt(np.mean(o * o))),
                        half_width=float(half_width), margin=float(half_width - mx),
                        beyond_percent=float(np.mean(np.abs(o) > half_width)) * 100.0)
