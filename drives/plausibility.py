"""Physical plausibility of a measured drive's units: the checks a value range cannot make.

A record in g instead of m/s^2, with gravity left in, or with displacements in
millimetres stays inside every per-sample range the reader checks when the road is
smooth, and then goes through to a wrong road class. Physics tells them apart:

* **Gravity left in**: a vertical acceleration measured over a drive on a level road
  averages to zero once gravity is removed (the vehicle does not keep accelerating up
  or down); its mean is then far below g. A mean of magnitude above ``GRAVITY_MEAN_LIMIT``
  (half of g) is gravity, with either sign (a sensor mounted upside down).
* **The kinematic relation at a wheel station**: the suspension displacement s is the
  axle's height relative to the body above it (positive in compression), so
  d^2 s / dt^2 = a_axle - a_body exactly, whatever the vehicle, road or model. Band-passed
  to ``BAND_HZ`` (where the displacement stands well above sensor noise after two
  differentiations), the ratio of the RMS of (a_axle - a_body) to the RMS of s'' is 1 in SI
  units, 1/9.81 when the accelerations are in g, 1/1000 when the displacement is in mm.
  The two sides of an axle are averaged first (see :func:`_stations`: the axle's roll
  cancels). Where the station has no body acceleration, a_axle alone is used: above the
  body's bounce (2-4 Hz for trucks) the body moves far less than the axle; measured
  0.97-1.10 on the synthetic drives, far from the factors 10 and 1000 to separate.

A ratio is trusted only when the two signals agree in shape (correlation at least
``MIN_CORRELATION`` in the band): a poor correlation means the channels do not belong
to one station, which is itself reported.

The module knows nothing of vehicles or models; it reads arrays.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import butter, sosfiltfilt

from drives.format import parse_channel

#: standard gravity [m/s^2]
G = 9.80665
#: |mean| of a vertical acceleration above which gravity is taken to be in it [m/s^2]
GRAVITY_MEAN_LIMIT = 0.5 * G
#: band of the kinematic check [Hz]: above the body bounce, below where s'' is noise
BAND_HZ = (4.0, 15.0)
#: correlation in the band below which the ratio is not trusted [-]
MIN_CORRELATION = 0.6
#: |log10 ratio| accepted as SI for an axle with both sides [-]: factor 1.5. Measured on
#: synthetic drives (luliang, random, null, sensor low-pass at 5 Hz): 1.01-1.06, the excess from
#: sensor noise and the finite-difference second derivative
SI_LOG10_TOL_PAIR = math.log10(1.5)
#: the same for a single side [-]: factor 3, since the axle end (accelerometer) and the spring
#: seat (displacement) move differently in the axle's roll; measured 1.25-1.95 on those drives
SI_LOG10_TOL = math.log10(3.0)
#: the unit errors the kinematic ratio identifies: log10 of the ratio -> what it means
UNIT_ERRORS = {
    math.log10(1.0 / G): "accelerations in g (expected m/s^2: multiply by 9.80665)",
    math.log10(1.0 / 1000.0): "suspension displacement in mm (expected m: divide by 1000)",
    math.log10(1.0 / (G * 1000.0)): "accelerations in g and suspension displacement in mm",
    math.log10(1000.0): "accelerations in mm/s^2 (expected m/s^2: divide by 1000)",
}
#: |log10| distance to an identified unit error within which it is named [-]
UNIT_LOG10_TOL = 0.3

@dataclass(frozen=True)
class Finding:
    """One plausibility finding.

    Attributes
    ----------
    column : str
        The channel concerned.
    message : str
        One line: what was measured and what it means.
    fatal : bool
        True when the data are in the wrong units for certain (refused); False for
        an inconsistency worth a warning.
    """

    column: str
    message: str
    fatal: bool


def _band(x: np.ndarray, fs: float) -> np.ndarray:
    hi = min(BAND_HZ[1], 0.4 * fs)
    sos = butter(4, [BAND_HZ[0], hi], btype="band", fs=fs, output="sos")
    return sosfiltfilt(sos, x - np.mean(x))


def kinematic_ratio(susp: np.ndarray, axle_acc: np.ndarray, body_acc: np.ndarray | None,
                    fs: float) -> tuple[float, float]:
    """RMS ratio and correlation of (a_axle - a_body) against d^2 s/dt^2 in ``BAND_HZ``.

    Parameters
    ----------
    susp : (N,) array
        Suspension displacement of one wheel station (its unit as recorded).
    axle_acc, body_acc : (N,) arrays
        Accelerations of the same station (``body_acc`` may be None).
    fs : float
        Sample rate [Hz].

    Returns
    -------
    ratio : float
        rms(a_axle - a_body) / rms(s'') in the band: 1 in SI units.
    corr : float
        Correlation of the two band-passed signals [-].
    """
    x = np.asarray(susp, float)
    s2 = np.empty_like(x)   # compact second difference: 0.984 of s'' at 15 Hz, 200 Hz sampling
    s2[1:-1] = (x[2:] - 2.0 * x[1:-1] + x[:-2]) * fs * fs
    s2[0], s2[-1] = s2[1], s2[-2]
    a = np.asarray(axle_acc, float) - (0.0 if body_acc is None else np.asarray(body_acc, float))
    a_b, s_b = _band(a, fs), _band(s2, fs)
    ra, rs = float(np.std(a_b)), float(np.std(s_b))
    if rs == 0.0 or ra == 0.0:
        return float("nan"), 0.0
    corr = float(np.mean(a_b * s_b) / (ra * rs))
    return ra / rs, corr


def check_units(channels: dict, fs: float) -> list[Finding]:
    """Every plausibility finding of a drive's channels.

    Parameters
    ----------
    channels : dict
        Channel name -> (N,) array, contract names (``susp_disp_3L``, ``axle_acc_3L``...).
    fs : float
        Sample rate [Hz].

    Returns
    -------
    list of Finding
        Empty for a plausible record.
    """
    out: list[Finding] = []
    for name, x in channels.items():
        if name.startswith(("axle_acc_", "body_acc_")):
            m = float(np.mean(x))
            if abs(m) > GRAVITY_MEAN_LIMIT:
                out.append(Finding(name, f"mean {m:+.3g} m/s^2 over the record: gravity left in "
                                   f"(a vertical acceleration with gravity removed averages near 0; "
                                   f"remove the constant {np.sign(m) * G:+.5g} m/s^2)", True))
    duration = len(next(iter(channels.values()), ())) / fs if channels else 0.0
    if duration < 4.0 / BAND_HZ[0] or fs < 2.5 * BAND_HZ[0]:
        return out   # too short or too slowly sampled for the band check
    for st, (susp, axle, body) in _stations(channels).items():
        ratio, corr = kinematic_ratio(susp, axle, body, fs)
        if not np.isfinite(ratio):
            continue
        tol = SI_LOG10_TOL_PAIR if st[-1] not in "LR" else SI_LOG10_TOL
        sname = f"susp_disp_{st}" if st[-1] in "LR" else f"susp_disp_{st}L/R"
        pair = f"axle_acc{'' if body is None else ' - body_acc'} at station {st}"
        where = f"in {BAND_HZ[0]:g}-{BAND_HZ[1]:g} Hz"
        if corr < MIN_CORRELATION:
            out.append(Finding(sname, f"d^2/dt^2 of the suspension displacement and {pair} do not agree "
                               f"in shape {where} (correlation {corr:.2f}; the displacement is the axle "
                               f"relative to the body, so they must): displacement noise far above "
                               f"0.1 mm, channels mislabelled or a sign flipped?", False))
            continue
        lr = math.log10(ratio)
        if abs(lr) <= tol:
            continue
        best = min(UNIT_ERRORS, key=lambda v: abs(v - lr))
        text = f"rms({pair}) / rms(d^2/dt^2 suspension displacement) = {ratio:.3g} {where} (1 in SI units)"
        if abs(best - lr) <= UNIT_LOG10_TOL:
            out.append(Finding(sname, f"{text}: {UNIT_ERRORS[best]}", True))
        else:
            out.append(Finding(sname, f"{text}: a unit or scale error in one of them?", False))
    return out


def _stations(channels: dict) -> dict:
    """Wheel stations that have a suspension displacement and an axle acceleration.

    Where both sides of an axle have them the key is the axle ('3') and the signals are
    the averages of the two sides: for a rigid axle and body the average of the two ends
    is the motion of the centre line, so the roll of the axle (its tramp mode), which moves
    the axle ends (where the accelerometers sit) more than the spring seats (where the
    displacement is taken), cancels and the relation holds exactly. Otherwise the key is
    the station ('3L') and the relation holds only up to that geometry.

    Returns
    -------
    dict
        key -> (susp, axle_acc, body_acc or None).
    """
    have: dict[str, list[str]] = {}
    for name in channels:
        p = parse_channel(name)
        if p and p[0] == "susp_disp" and f"axle_acc_{p[1]}{p[2]}" in channels:
            have.setdefault(str(p[1]), []).append(p[2])
    out = {}
    for a, sides in sorted(have.items()):
        if len(sides) == 2:
            bodies = [channels.get(f"body_acc_{a}{s}") for s in "LR"]
            body = None if any(b is None for b in bodies) else 0.5 * (np.asarray(bodies[0]) + bodies[1])
            out[a] = tuple(0.5 * (np.asarray(channels[f"{q}_{a}L"], float) + channels[f"{q}_{a}R"])
                           for q in ("susp_disp", "axle_acc")) + (body,)
        else:
            s = sides[0]
            out[f"{a}{s}"] = (channels[f"susp_disp_{a}{s}"], channels[f"axle_acc_{a}{s}"],
                              channels.get(f"body_acc_{a}{s}"))
    return out
