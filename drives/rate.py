"""A measured drive brought to the rate the road methods simulate at.

The road methods (``eroad invert``, ``eroad diagnose``, ``eroad replica``) compare the
record with simulations that output at the record's own rate; the truck's solver step
(``[solver] dt``, 2.5 ms for the built-in trucks) cannot be coarser than the output
period, so a record above 1 / dt (400 Hz) stopped them with "dt exceeds the output
period". Data loggers on vehicles often run at 500 Hz-2 kHz. Nothing these methods use
lies above 60 Hz (third-octave bands up to 56 Hz, the fit's features below), so such a
record is resampled to ``TARGET_HZ`` = 200 Hz, the rate of the paper's data and of every
calibration in this project, before they see it:

* channels: polyphase resampling (``scipy.signal.resample_poly``, its Kaiser-window
  anti-aliasing FIR at the new Nyquist frequency); the record's mean is removed before
  and added after, so the filter's edge transient is that of the fluctuation only;
* speed: linear interpolation on the new time grid (a speed signal is smooth; a FIR would
  ring at its ends);
* time: ``t_0 + k / TARGET_HZ`` within the record (record time kept).

Records at or below 1 / the vehicle's solver step are used as they are (they simulate
directly). What was done is returned as a note for the run's summary.
"""
from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pandas as pd

#: the rate a fast record is brought to [Hz]
TARGET_HZ = 200.0
#: records up to this rate are used as they are where the vehicle file cannot be read [Hz]:
#: 1 / the 8x4 truck's 2.5 ms step
MAX_DIRECT_HZ = 400.0


def max_direct_hz(vehicle) -> float:
    """The highest record rate the vehicle simulates at directly: 1 / its solver step
    (``[solver] dt``; 400 Hz for the 8x4 truck, 800 Hz for the tractor), at least
    ``TARGET_HZ``; ``MAX_DIRECT_HZ`` when the vehicle file cannot be read here (its own
    loader reports that where the vehicle is used)."""
    try:
        from vehicles.params import load_vehicle
        return max(TARGET_HZ, 1.0 / float(load_vehicle(vehicle).solver.dt))
    except Exception:  # noqa: BLE001 - any unreadable vehicle: the default, the loader says why later
        return MAX_DIRECT_HZ


def for_road_methods(drive):
    """``drive`` unchanged when its rate is at most :func:`max_direct_hz` of its vehicle, else
    resampled to ``TARGET_HZ``.

    Returns
    -------
    drive : drives.format.Drive
    note : dict or None
        ``{"from_hz", "to_hz", "method"}`` when resampled.
    """
    from scipy.signal import resample_poly

    fs = float(drive.sample_rate_hz)
    if fs <= max_direct_hz(drive.vehicle) * (1 + 1e-9):
        return drive, None
    ratio = Fraction(TARGET_HZ / fs).limit_denominator(1000)
    up, down = ratio.numerator, ratio.denominator
    t = np.asarray(drive.time, float)
    n_new = int(np.floor((t[-1] - t[0]) * TARGET_HZ + 1e-9)) + 1
    t_new = t[0] + np.arange(n_new) / TARGET_HZ
    cols = {}
    for c in drive.channel_names:
        x = drive.channels[c].to_numpy(float)
        m = float(np.mean(x))
        y = resample_poly(x - m, up, down) + m
        cols[c] = y[:n_new] if y.size >= n_new else np.pad(y, (0, n_new - y.size), mode="edge")
    speed = np.interp(t_new, t, np.asarray(drive.speed, float))
    meta = dict(drive.meta)
    meta["sample_rate_hz"] = TARGET_HZ
    new = dataclasses.replace(drive, time=t_new, speed=speed, meta=meta,
                              channels=pd.DataFrame(cols, columns=drive.channel_names))
    note = {"from_hz": fs, "to_hz": TARGET_HZ,
            "method": f"scipy.signal.resample_poly up {up} down {down} (Kaiser-window FIR); "
                      f"speed linearly interpolated"}
    return new, note
