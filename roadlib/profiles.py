"""Measured longitudinal profiles as road surfaces.

A profilometer (or a rod-and-level survey, a laser profiler, an inertial profiler) records
the height of one or two wheel tracks along the road: chainage x [m] and height z [m] at a
uniform step.  To drive a vehicle model over it, the profile becomes a
:class:`roadlib.surface.RoadSurface`:

* **Detrended**: the straight line fitted by least squares (grade and level) is removed --
  a 2 % grade is 20 m over a kilometre, which a vehicle model on a flat reference would
  take as road height; the grade is recorded in the surface's metadata.
* **Band-limited onto the road grid** (:func:`bandlimited_profile`): a profile measured every
  ``dxp`` holds the road up to its Nyquist wavenumber 1 / (2 dxp) and nothing above; it is
  upsampled by zero-padding its spectrum (of the even extension, so that the periodic wrap
  adds no step), which keeps the band's power -- linear interpolation would low-pass it
  (power factor sinc^4(n dxp): 0.66 at 1 cycle/m for 0.25 m) and add images above it.
* **Across the road** (:func:`surface_from_profiles`): two profiles are the left and right
  wheel tracks at y = +-track/2 (y positive to the left); between them the height is linear
  in y, beyond them it is held (the conditional mean of a random-walk-like lateral field
  given two lines, the choice of the road replica, docs/replica.md).  One profile gives both
  tracks the same heights: the vehicle then gets no roll input from the road -- said in the
  metadata and by the command line, because a real road's tracks differ.

``eroad road from-profile`` is the command (docs/roadlib.md, "Measured profiles").
"""
from __future__ import annotations

import math

import numpy as np

from eroad.errors import EroadInputError

__all__ = ["bandlimited_profile", "detrend_profile", "surface_from_profiles",
           "DEFAULT_TRACK_WIDTH_M", "DEFAULT_WIDTH_M"]

#: lateral distance between the two wheel-track profiles [m] when the user does not give it:
#: heavy trucks' track widths are 1.8-2.1 m (the built-in dump truck's front axle: 2 x 0.76 m
#: between tyre centres is narrower, its rear twin tyres 2.0-2.2 m) and profilometers measure
#: the wheel paths about 1.7-1.8 m apart
DEFAULT_TRACK_WIDTH_M = 1.8
#: width of the surface [m] (centred on y = 0): covers every tyre line of the built-in
#: vehicles (outer twin tyres at +-1.1 m) with margin
DEFAULT_WIDTH_M = 3.0


def detrend_profile(x, z) -> tuple[np.ndarray, np.ndarray, float]:
    """Chainage from 0 [m], the height with its least-squares line removed [m], and the
    removed grade [-] (rise per metre)."""
    x = np.asarray(x, float)
    z = np.asarray(z, float)
    x0 = x - x[0]
    slope, icpt = np.polyfit(x0, z, 1)
    return x0, z - (icpt + slope * x0), float(slope)


def _uniform_step(x, what: str) -> float:
    steps = np.diff(np.asarray(x, float))
    if steps.size == 0 or not np.all(steps > 0):
        k = int(np.argmax(~(steps > 0))) if steps.size else 0
        raise EroadInputError(f"{what}: the chainage must increase; it does not after row {k + 1}")
    dxp = float(np.mean(steps))
    if np.ptp(steps) > 1e-6 * dxp + 1e-9:
        k = int(np.argmax(np.abs(steps - np.median(steps))))
        raise EroadInputError(f"{what}: chainage step varies ({steps.min():g}-{steps.max():g} m; "
                              f"row {k + 2}): a uniform step is needed (resample the profile first)")
    return dxp


def bandlimited_profile(xp, zp, dx: float, what: str = "measured profile") -> tuple[np.ndarray, np.ndarray]:
    """A uniformly sampled profile on a grid at least as fine as ``dx``, band-limited.

    The profile is upsampled by an integer factor m with ``dxp / m <= dx / 4`` by
    zero-padding its spectrum (the even extension of the profile first, so the periodic wrap
    adds no step): the band up to 1 / (2 dxp) keeps its power, nothing is added above it.  A
    linear read-out of the fine grid then loses at most sinc^4(1 / 8) = 0.90 of the power at
    the profile's Nyquist wavenumber and under 1 % below half of it.

    Parameters
    ----------
    xp, zp : ndarray
        Chainage [m] (uniform step) and height [m].
    dx : float
        Road grid step [m].
    what : str
        How an error names the profile.

    Returns
    -------
    xf, zf : ndarray
        Fine chainage [m] (same start and end as ``xp``) and height [m].
    """
    from scipy.signal import resample

    xp, zp = np.asarray(xp, float), np.asarray(zp, float)
    dxp = _uniform_step(xp, what)
    m = max(1, int(math.ceil(4.0 * dxp / dx - 1e-9)))
    ext = np.concatenate([zp, zp[-2:0:-1]])          # even extension: period 2 (N - 1) samples
    fine = resample(ext, m * ext.size)
    n = (zp.size - 1) * m + 1
    return xp[0] + np.arange(n) * (dxp / m), fine[:n]


def surface_from_profiles(left, right=None, *, track_width: float = DEFAULT_TRACK_WIDTH_M,
                          width: float = DEFAULT_WIDTH_M, dx: float = 0.05, dy: float = 0.05,
                          names=("left profile", "right profile")):
    """A road surface from one or two measured wheel-track profiles.

    Parameters
    ----------
    left : (x, z) arrays
        Chainage [m] (uniform step) and height [m] of the left wheel track (or of the one
        profile).
    right : (x, z) arrays, optional
        The right wheel track, on the same chainage (the overlap of the two is kept; their
        steps may differ).  None: the left profile on both tracks (no roll input).
    track_width : float
        Lateral distance between the two profiles [m]; they lie at y = +-track_width / 2.
    width : float
        Surface width [m], centred on y = 0 (heights held beyond the profiles).
    dx, dy : float
        Grid steps along and across [m].
    names : (str, str)
        How errors name the two profiles (file names).

    Returns
    -------
    roadlib.surface.RoadSurface
        x from 0 at the start of the (common) chainage; ``meta`` records the source
        chainage start, the removed grades, the profiles' steps and Nyquist wavenumbers,
        and the lateral layout.
    """
    from roadlib.surface import RoadSurface

    for v, what in ((track_width, "track width"), (width, "width"), (dx, "dx"), (dy, "dy")):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise EroadInputError(f"{what} must be a positive number of metres, got {v!r}")
    if width < track_width:
        raise EroadInputError(f"width {width:g} m is narrower than the track width {track_width:g} m "
                              "between the profiles")
    profs = [left] if right is None else [left, right]
    starts, ends, steps = [], [], []
    for (x, z), name in zip(profs, names):
        x, z = np.asarray(x, float), np.asarray(z, float)
        if x.size < 8:
            raise EroadInputError(f"{name}: {x.size} rows; a profile needs at least 8")
        steps.append(_uniform_step(x, name))
        starts.append(float(x[0]))
        ends.append(float(x[-1]))
    x0, x1 = max(starts), min(ends)
    if x1 - x0 < 10 * dx:
        raise EroadInputError(f"{names[0]} ({starts[0]:g}-{ends[0]:g} m) and {names[1]} "
                              f"({starts[1]:g}-{ends[1]:g} m) share no stretch of chainage")
    xg = np.arange(int(math.floor((x1 - x0) / dx + 1e-9)) + 1) * dx
    tracks, grades = [], []
    for (x, z), name in zip(profs, names):
        x, z = np.asarray(x, float), np.asarray(z, float)
        keep = (x >= x0 - 1e-9) & (x <= x1 + 1e-9)
        xr, zr, grade = detrend_profile(x[keep], z[keep])
        xf, zf = bandlimited_profile(xr + (x[keep][0] - x0), zr, dx, name)
        tracks.append(np.interp(xg, xf, zf))
        grades.append(grade)
    ny = int(round(width / dy)) + 1
    y = (np.arange(ny) - (ny - 1) / 2) * dy
    if right is None:
        z = np.repeat(tracks[0][:, None], ny, axis=1)
        lateral = "one profile on both wheel tracks: no roll input from the road"
    else:
        a = np.clip(0.5 + y / track_width, 0.0, 1.0)       # 1 on the left profile and beyond
        z = a[None, :] * tracks[0][:, None] + (1 - a[None, :]) * tracks[1][:, None]
        lateral = (f"left profile at y = +{track_width / 2:g} m, right at -{track_width / 2:g} m, "
                   "linear between, held beyond")
    meta = {"generator": "roadlib.profiles.surface_from_profiles", "source_x_start_m": x0,
            "grades": grades, "profile_steps_m": steps,
            "profile_nyquist_cpm": [0.5 / s for s in steps], "lateral": lateral,
            "track_width_m": float(track_width) if right is not None else None,
            "segments": [{"start": 0.0, "end": float(xg[-1])}], "junctions": []}
    return RoadSurface(xg, y, z, meta)
