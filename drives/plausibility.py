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

#: band of the two-input fit of the body acceleration [Hz]: it must hold the body's bounce
#: (1-3 Hz for trucks), where a_body is a fair share of s'' -- above 4 Hz the body term is a
#: few per cent of the axle's, and a body channel in g hides in the ratio's tolerance
FIT_BAND_HZ = (1.0, 15.0)
#: share of the band-passed s'' the two-input fit must explain before its body factor is
#: trusted [-]. Measured 0.93-0.998 per side-averaged axle on drives of the independently
#: written truck (drives/independent_truck.py); a mislabelled channel falls far below
MIN_FIT_R2 = 0.5
#: body factors accepted as SI for an axle with both sides [-]: 0.2-1.5 (below 0.2 only a
#: named unit is reported, see _body_finding). Measured per
#: side-averaged axle on 20 s drives: 0.97-1.05 on the independently written truck (with and
#: without leaf friction), 0.96-1.01 on our null truck, 0.75-1.07 on our truck with a
#: flexible frame (`random`; the frame bends between the spring seat and the body
#: accelerometer), and 0.50-0.56 above axle 2 on drives where the body barely moves there:
#: the body sensor's noise biases a least-squares factor low (errors in variables: beta times
#: var(signal) / (var(signal) + var(noise))), so below 1 the bound is loose; g is 9.81, mm/s^2
#: 0.001, both far outside (benchmarks/bench_units.py, results/units_blind/)
BODY_RANGE_PAIR = (0.2, 1.5)
#: the same for a single side [-]: the body above one axle end rolls and twists with the
#: frame, measured 0.49-1.63 on the same drives
BODY_RANGE = (0.2, 2.5)
#: standard errors by which beta must leave the SI range before it is reported [-]
BETA_SIGMAS = 3.0
#: records shorter than this get no body fit [s]: four periods of the band's lower edge
MIN_FIT_DURATION_S = 4.0 / FIT_BAND_HZ[0]
#: the body-acceleration unit errors the two-input fit identifies: log10 factor -> meaning
BODY_UNIT_ERRORS = {
    math.log10(G): "body accelerations in g (expected m/s^2: multiply by 9.80665)",
    math.log10(1.0 / 1000.0): "body accelerations in mm/s^2 (expected m/s^2: divide by 1000)",
}


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


def _band(x: np.ndarray, fs: float, band: tuple = BAND_HZ) -> np.ndarray:
    """``x`` less its mean, zero-phase band-passed (4th-order Butterworth) to ``band`` [Hz],
    the top held below 0.4 fs."""
    x = np.asarray(x, float)
    sos = butter(4, [band[0], min(band[1], 0.4 * fs)], btype="band", fs=fs, output="sos")
    return sosfiltfilt(sos, x - np.mean(x))


def _second_difference(x: np.ndarray, fs: float) -> np.ndarray:
    """Compact second difference of ``x`` [unit/s^2] (0.984 of s'' at 15 Hz with 200 Hz
    sampling), the end samples repeated."""
    x = np.asarray(x, float)
    s2 = np.empty_like(x)
    s2[1:-1] = (x[2:] - 2.0 * x[1:-1] + x[:-2]) * fs * fs
    s2[0], s2[-1] = s2[1], s2[-2]
    return s2


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
    s2 = _second_difference(susp, fs)
    a = np.asarray(axle_acc, float) - (0.0 if body_acc is None else np.asarray(body_acc, float))
    a_b, s_b = _band(a, fs), _band(s2, fs)
    ra, rs = float(np.std(a_b)), float(np.std(s_b))
    if rs == 0.0 or ra == 0.0:
        return float("nan"), 0.0
    corr = float(np.mean(a_b * s_b) / (ra * rs))
    return ra / rs, corr


def kinematic_fit(susp: np.ndarray, axle_acc: np.ndarray, body_acc: np.ndarray,
                  fs: float) -> tuple[float, float, float, float]:
    """Least-squares factors of ``s'' = alpha a_axle - beta a_body`` in ``FIT_BAND_HZ``.

    The ratio of :func:`kinematic_ratio` sees the two accelerations only as their
    difference, which above the body's bounce is almost all axle: a body channel in g
    moves it by a few per cent. Fitting the two factors apart, over a band that holds the
    body's bounce, weighs each channel on its own: ``alpha = beta = 1`` in SI units
    whatever the vehicle, road or model (the identity is kinematic), ``beta = 9.81`` for a
    body channel in g, ``beta = -1`` for one mounted upside down.

    Returns
    -------
    alpha, beta : float
        The factors [-] (NaN when a band-passed input is zero).
    r2 : float
        Share of the band-passed s'' variance the fit explains [-].
    se_beta : float
        Standard error of beta [-], from the residual over 2 x bandwidth x duration
        independent samples (a body that barely moves above this axle gives a large one).
    """
    n = len(susp)
    hi = min(FIT_BAND_HZ[1], 0.4 * fs)
    y = _band(_second_difference(susp, fs), fs, FIT_BAND_HZ)
    a, b = _band(axle_acc, fs, FIT_BAND_HZ), _band(body_acc, fs, FIT_BAND_HZ)
    if not (np.std(a) > 0 and np.std(b) > 0 and np.std(y) > 0):
        return float("nan"), float("nan"), 0.0, float("inf")
    design = np.c_[a, -b]
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    r = y - design @ coef
    # standard error of beta: band-passed samples are correlated, so the residual variance
    # counts n_eff = 2 x bandwidth x duration independent samples, not every sample
    n_eff = max(2.0 * (hi - FIT_BAND_HZ[0]) * n / fs, 3.0)
    cov = np.var(r) * np.linalg.inv(design.T @ design) * (n / n_eff)
    return (float(coef[0]), float(coef[1]), float(1.0 - np.var(r) / np.var(y)),
            float(np.sqrt(max(cov[1, 1], 0.0))))


def _body_finding(st: str, susp, axle, body, fs: float) -> Finding | None:
    """The body channel's own unit check at station ``st`` (None: it passes, or the fit
    cannot tell)."""
    if len(susp) / fs < MIN_FIT_DURATION_S:
        return None
    _, beta, r2, se = kinematic_fit(susp, axle, body, fs)
    if not np.isfinite(beta) or r2 < MIN_FIT_R2:
        return None
    # Reported only what the data tell apart from SI: beta must leave the SI range by more
    # than BETA_SIGMAS standard errors (a short record, a body at rest above the axle). Below
    # the range only a named unit is reported: noise in the body channel biases a
    # least-squares factor towards 0 (errors in variables), so a small beta cannot be told
    # from a quiet body; above it nothing but the channel's scale lifts beta.
    lo, hi = BODY_RANGE if st[-1] in "LR" else BODY_RANGE_PAIR
    margin = BETA_SIGMAS * se
    col = f"body_acc_{st}" if st[-1] in "LR" else f"body_acc_{st}L/R"
    text = (f"fit of s'' = alpha a_axle - beta a_body at station {st} in {FIT_BAND_HZ[0]:g}-"
            f"{FIT_BAND_HZ[1]:g} Hz (R^2 {r2:.2f}): beta = {beta:.3g} +- {se:.2g} (1 in SI units)")
    if beta >= 0.0:
        if beta <= hi + margin and (beta >= lo - margin or beta > 10 ** (-3 + UNIT_LOG10_TOL)):
            return None
        lb = math.log10(max(beta, 1e-12))
        best = min(BODY_UNIT_ERRORS, key=lambda v: abs(v - lb))
        if abs(best - lb) <= UNIT_LOG10_TOL:
            return Finding(col, f"{text}: {BODY_UNIT_ERRORS[best]}", True)
        return Finding(col, f"{text}: a scale error in the body accelerometer?", False)
    if -beta <= margin:
        return None                                   # not even the sign is determined
    if lo - margin <= -beta <= hi + margin:
        return Finding(col, f"{text}: the body acceleration's sign is flipped (positive up "
                       f"expected; a sensor mounted upside down?)", False)
    return Finding(col, f"{text}: does the body channel belong to this station?", False)


def _which_in_g(err: float, susp, axle, body, fs: float) -> str:
    """The unit error ``UNIT_ERRORS[err]``, narrowed to the axle or the body channel when the
    ratio says g and the two-input fit (:func:`kinematic_fit`) finds only one of them in g."""
    text = UNIT_ERRORS[err]
    if body is None or err != math.log10(1.0 / G):
        return text
    alpha, beta, r2, _ = kinematic_fit(susp, axle, body, fs)
    if r2 < MIN_FIT_R2 or not (alpha > 0 and beta > 0):
        return text
    in_g = [abs(math.log10(f) - math.log10(G)) <= UNIT_LOG10_TOL for f in (alpha, beta)]
    if in_g == [True, False]:
        return (f"axle accelerations in g, body accelerations in m/s^2 (fit factors {alpha:.3g} "
                f"and {beta:.3g}; multiply the axle channels by 9.80665)")
    return text


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
    swaps = swapped_columns(channels, fs)
    out += swaps
    swapped_axles = {str(parse_channel(f.column)[1]) for f in swaps}
    for st, (susp, axle, body) in _stations(channels).items():
        if st.rstrip("LR") in swapped_axles:
            continue   # said once, as the swap
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
            if body is not None:   # the ratio passes: the body channel on its own
                found = _body_finding(st, susp, axle, body, fs)
                if found is not None:
                    out.append(found)
            continue
        best = min(UNIT_ERRORS, key=lambda v: abs(v - lr))
        text = f"rms({pair}) / rms(d^2/dt^2 suspension displacement) = {ratio:.3g} {where} (1 in SI units)"
        if abs(best - lr) <= UNIT_LOG10_TOL:
            out.append(Finding(sname, f"{text}: {_which_in_g(best, susp, axle, body, fs)}", True))
        else:
            out.append(Finding(sname, f"{text}: a unit or scale error in one of them?", False))
    return out


def swapped_columns(channels: dict, fs: float) -> list[Finding]:
    """Wheel stations whose suspension displacement and axle (or body) acceleration columns
    are exchanged: the kinematic identity s'' = a_axle - a_body fails in SI units as labelled
    and holds with the two columns exchanged (single-side tolerance).  A displacement in an
    acceleration column stays inside every range check (centimetres read as m/s^2), so only
    this tells.  One fatal finding per swapped pair, on the displacement column."""
    out = []
    for name in channels:
        p = parse_channel(name)
        if not p or p[0] != "susp_disp":
            continue
        st = f"{p[1]}{p[2]}"
        axle, body = channels.get(f"axle_acc_{st}"), channels.get(f"body_acc_{st}")
        if axle is None:
            continue
        x = np.asarray(channels[name], float)
        axle = np.asarray(axle, float)
        body = None if body is None else np.asarray(body, float)
        if _kinematic_si(x, axle, body, fs, True)[0]:
            continue
        swap = _swap_partner(x, st, axle, body, fs)
        if swap is not None:
            other, ratio, corr = swap
            out.append(Finding(name, f"columns '{name}' and '{other}' look swapped: the "
                               f"kinematic relation s'' = a_axle - a_body fails as labelled and "
                               f"holds with the two exchanged (ratio {ratio:.3g}, correlation "
                               f"{corr:.2f} in {BAND_HZ[0]:g}-{BAND_HZ[1]:g} Hz)", True))
    return out


def _swap_partner(x, st: str, axle, body, fs: float) -> tuple[str, float, float] | None:
    """The acceleration column of station ``st`` that the displacement column ``x`` was
    swapped with -- the identity s'' = a_axle - a_body holds in SI units (single-side
    tolerance) with the two exchanged, the axle's tried first -- as ``(column, ratio,
    correlation)``; None where neither exchange makes it hold."""
    for other, args in ((f"axle_acc_{st}", (axle, x, body)),
                        (f"body_acc_{st}", None if body is None else (body, axle, x))):
        if args is not None:
            ok, ratio, corr = _kinematic_si(*args, fs, True)
            if ok:
                return other, ratio, corr
    return None


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


# --------------------------------------------------------------------------- speed
# The speed channel sets the distance scale of everything that follows (a spatial frequency
# is a temporal one divided by the speed): a speed in km/h labelled m/s moves every road
# spectrum by a factor 3.6 in wavenumber and the road class by several classes, while every
# value stays inside a range check. Physics again tells: the axles of one side run over the
# same track one behind the other, so their signals are copies of each other shifted by the
# axle spacing in DISTANCE travelled, whatever the speed profile, vehicle model or road. The
# distance comes from integrating the speed channel; a speed off by a factor k moves the
# correlation peak to k times the spacing the vehicle file gives.

#: band of the axle signals correlated [Hz]: the road's input through the tyres (the wheel
#: hop at 8-15 Hz included), above the body's bounce that couples the axles at zero lag
DELAY_BAND_HZ = (1.0, 20.0)
#: grid of the distance-domain resampling [m]
DELAY_GRID_M = 0.05
#: lags searched, as multiples of the axle spacing [-]: 0.2-5 holds km/h (3.6), mph (2.24)
#: and their inverses, and leaves out the zero-lag coupling through the frame
DELAY_SCALE_RANGE = (0.2, 5.0)
#: peak correlation below which an axle pair is not used [-]. Measured 0.6-0.99 on 20 s
#: drives of the independently written truck (pairs across the tandem lower: its bogie
#: and frame move the axles apart between the stations)
MIN_DELAY_CORRELATION = 0.3
#: pairs shorter than this are not used [m]: the peak must be resolved on the grid
MIN_PAIR_SPACING_M = 1.0
#: distance a record must cover, in axle spacings [-]
MIN_SPACINGS_COVERED = 20.0
#: |log10 k| accepted as a correct speed [-]: factor 1.1 (measured 0.99-1.00 on the
#: independent truck's drives; the grid step is 1-4 % of a spacing)
SPEED_LOG10_TOL = math.log10(1.1)
#: a consistent k beyond this factor is refused even when no unit explains it [-]: the
#: distance scale, and with it every wavelength and the road class, would be wrong by more
#: than a factor 2 (a constant meta speed_mps for a drive whose speed varied, a wrong vehicle)
SPEED_FATAL_FACTOR = 2.0
#: the speed unit errors the delay identifies: k -> meaning
SPEED_UNIT_ERRORS = {
    3.6: "speed in km/h (expected m/s: divide by 3.6)",
    1.0 / 3.6: "speed 3.6x too small (converted from km/h twice, or m/s read as km/h?)",
    2.2369362921: "speed in mph (expected m/s: multiply by 0.44704)",
    1.0 / 2.2369362921: "speed 2.24x too small (converted from mph twice?)",
}
#: relative distance to a named speed error within which it is named [-]
SPEED_UNIT_TOL = 0.1
#: a speed above this is not a heavy vehicle's [m/s]: 120 km/h, above the 90 km/h limiter of
#: EU heavy goods vehicles (Directive 92/6/EEC as amended by 2002/85/EC) and the 65-80 mph
#: of US truck speed limits, with margin
HEAVY_VEHICLE_MAX_SPEED = 120.0 / 3.6


def delay_scale(a: np.ndarray, b: np.ndarray, spacing: float, s: np.ndarray,
                fs: float) -> tuple[float, float]:
    """Distance scale of the speed from one axle pair of one side.

    Parameters
    ----------
    a, b : (N,) arrays
        The front and the rear axle's signal (acceleration or suspension displacement).
    spacing : float
        Their spacing from the vehicle file [m].
    s : (N,) array
        Distance travelled, the integral of the speed channel [m], non-decreasing.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    k : float
        Lag of the correlation peak over ``spacing`` [-]: 1 for a right speed, 3.6 for km/h
        labelled m/s (NaN when the record is too short).
    corr : float
        The peak's correlation coefficient [-].
    """
    if s[-1] - s[0] < MIN_SPACINGS_COVERED * spacing:
        return float("nan"), 0.0
    a, b = _band(a, fs, DELAY_BAND_HZ), _band(b, fs, DELAY_BAND_HZ)   # in time, on the uniform grid
    keep = np.concatenate([[True], np.diff(s) > 0])   # standstill: one sample per position
    s, a, b = s[keep], a[keep], b[keep]
    grid = np.arange(s[0], s[-1], min(DELAY_GRID_M, spacing / 40.0))
    fa, fb = np.interp(grid, s, a), np.interp(grid, s, b)
    step = grid[1] - grid[0]
    lags = np.arange(int(DELAY_SCALE_RANGE[0] * spacing / step),
                     min(int(DELAY_SCALE_RANGE[1] * spacing / step), grid.size // 2) + 1)
    if lags.size < 3:
        return float("nan"), 0.0
    n = grid.size
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    xc = np.fft.irfft(np.conj(np.fft.rfft(fa, nfft)) * np.fft.rfft(fb, nfft), nfft)[lags]
    # the rear axle sees at s + L what the front saw at s: correlate a(s) with b(s + L)
    ca = np.cumsum(fa ** 2)
    cb = np.cumsum(fb[::-1] ** 2)[::-1]
    norm = np.sqrt(ca[n - 1 - lags] * cb[lags])
    c = xc / np.where(norm > 0, norm, np.inf)
    i = int(np.argmax(c))
    return float(lags[i] * step / spacing), float(c[i])


def speed_delay_scale(channels: dict, speed: np.ndarray, fs: float,
                      axle_x: dict | None) -> dict | None:
    """The speed's distance scale measured by the axle-to-axle delay (:func:`delay_scale` on
    every pair of axles of a side with a spacing of ``MIN_PAIR_SPACING_M`` or more).

    Returns
    -------
    dict or None
        ``scale`` (median over the pairs: 1 for a right speed) [-], ``pairs`` (used),
        ``agree`` (pairs within ``SPEED_UNIT_TOL`` of the median), ``signal`` (the channel
        quantity used); None when fewer than two pairs could be used (no two axles of a
        side recorded, the vehicle file unknown, too short a record, no clear peak).
    """
    speed = np.asarray(speed, float)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1])) / fs])
    ks, used = [], None
    for side in "LR":
        for q in ("axle_acc", "susp_disp"):
            have = sorted(a for a in (axle_x or {}) if f"{q}_{a}{side}" in channels)
            if len(have) >= 2:
                break
        for i, a in enumerate(have):
            for b in have[i + 1:]:
                spacing = abs(axle_x[a] - axle_x[b])
                if spacing < MIN_PAIR_SPACING_M:
                    continue
                k, c = delay_scale(channels[f"{q}_{a}{side}"], channels[f"{q}_{b}{side}"],
                                   spacing, s, fs)
                if np.isfinite(k) and c >= MIN_DELAY_CORRELATION:
                    ks.append(k)
                    used = q
    if len(ks) < 2:
        return None
    ks = np.array(ks)
    k = float(np.median(ks))
    agree = int(np.sum(np.abs(np.log(ks / k)) <= math.log(1.0 + SPEED_UNIT_TOL)))
    return {"scale": k, "pairs": int(ks.size), "agree": agree, "signal": used}


def check_speed(channels: dict, speed: np.ndarray, fs: float,
                axle_x: dict | None = None, estimate: dict | None = None) -> list[Finding]:
    """Speed plausibility: the axle-to-axle delay against the vehicle's axle spacing, and
    the speed's level against a heavy vehicle's.

    Parameters
    ----------
    channels : dict
        Channel name -> (N,) array, contract names.
    speed : (N,) array
        The drive's speed [m/s as recorded].
    fs : float
        Sample rate [Hz].
    axle_x : dict, optional
        Axle number (1 = front) -> its position along x [m] from the vehicle file; without
        it only the level is checked.
    estimate : dict, optional
        :func:`speed_delay_scale` of these arguments, when the caller has it already.

    Returns
    -------
    list of Finding
        On the column ``speed``. Fatal for a named unit error, or a factor beyond
        ``SPEED_FATAL_FACTOR``, found by at least two axle pairs (and half of them) that agree.
    """
    speed = np.asarray(speed, float)
    out: list[Finding] = []
    est = estimate if estimate is not None else speed_delay_scale(channels, speed, fs, axle_x)
    if est is not None:
        k, agree, n = est["scale"], est["agree"], est["pairs"]
        if abs(math.log10(k)) > SPEED_LOG10_TOL:
            text = (f"the axles' signals repeat {k:.3g}x farther apart than the vehicle file's "
                    f"axle spacing, in distance integrated from this speed ({agree} of "
                    f"{n} axle pairs agree)")
            best = min(SPEED_UNIT_ERRORS, key=lambda v: abs(math.log(k / v)))
            consistent = agree >= 2 and 2 * agree >= n
            if abs(math.log(k / best)) <= math.log(1.0 + SPEED_UNIT_TOL) and consistent:
                out.append(Finding("speed", f"{text}: {SPEED_UNIT_ERRORS[best]}", True))
            elif abs(math.log(k)) > math.log(SPEED_FATAL_FACTOR) and consistent:
                out.append(Finding("speed", f"{text}: the speed is off by that factor, or the "
                                   f"vehicle file's axle positions are not this vehicle's; either "
                                   f"way no road could be identified from it", True))
            else:
                out.append(Finding("speed", f"{text}: the speed is off by that factor, or the "
                                   f"vehicle file's axle positions are not this vehicle's", False))
        return out
    vmax = float(np.max(speed)) if speed.size else 0.0
    if vmax > HEAVY_VEHICLE_MAX_SPEED:
        out.append(Finding("speed", f"up to {vmax:.4g} m/s ({vmax * 3.6:.4g} km/h), above what a "
                           f"heavy vehicle drives ({HEAVY_VEHICLE_MAX_SPEED * 3.6:.0f} km/h): in "
                           f"km/h? ({vmax / 3.6:.3g} m/s if so; no two axles of one side to "
                           f"check it on)", False))
    return out


# --------------------------------------------------------------------------- dead and clipped
#: share of the samples at the record's extreme value (either end) from which a channel is
#: called clipped [-]; with at least CLIP_MIN_SAMPLES of them. A continuous signal with
#: noise takes its extreme value once
CLIP_SHARE = 0.002
CLIP_MIN_SAMPLES = 5


#: |correlation| above which a column is taken for a copy of another one [-]: the most alike
#: distinct channels of the synthetic drives are the body accelerations above the two rear
#: axles of the independent truck (0.988 on `second` seeds 3 and 4; our truck: the two axle
#: ends of axle 2, -0.77), ten times further from 1
COPY_CORRELATION = 0.999


def _kinematic_si(susp, axle, body, fs: float, single_side: bool) -> tuple[bool, float, float]:
    """Does the station obey s'' = a_axle - a_body in SI units (ratio within the check's
    tolerance, correlation at least ``MIN_CORRELATION``)?  Returns (ok, ratio, corr)."""
    ratio, corr = kinematic_ratio(susp, axle, body, fs)
    tol = SI_LOG10_TOL if single_side else SI_LOG10_TOL_PAIR
    ok = bool(np.isfinite(ratio) and ratio > 0 and corr >= MIN_CORRELATION
              and abs(math.log10(ratio)) <= tol)
    return ok, ratio, corr


def large_displacement_cause(name: str, channels: dict, fs: float,
                             named_only: bool = False) -> str | None:
    """What a suspension-displacement column too large for metres holds, where physics says
    more than "millimetres" (None: millimetres fits, or nothing can tell).

    A column over its range is most often the right quantity in mm, and the range check says
    so.  Two mistakes of a column map give the same symptom and a misleading hint: an
    acceleration column mapped onto the displacement (or the two swapped), whose peaks of a
    few m/s^2 read as millimetres.  Told apart by the kinematic identity s'' = a_axle - a_body
    (:func:`kinematic_ratio`), which a displacement in mm obeys once divided by 1000 and an
    acceleration does not:

    * a copy of another column (|correlation| >= ``COPY_CORRELATION``);
    * swapped with the station's axle or body acceleration (the identity holds in SI units
      with the two columns exchanged);
    * divided by 1000 the identity fails in shape (correlation below ``MIN_CORRELATION``)
      or in scale: the millimetre hint stands, with that finding beside it (a station whose
      sensors do not obey the identity, e.g. one very noisy, is not proof of another quantity).

    Parameters
    ----------
    name : str
        The displacement column, e.g. ``"susp_disp_3L"``.
    channels : dict
        Column name -> (N,) array of every channel of the file (finite values).
    fs : float
        Sample rate [Hz].
    named_only : bool
        Report only a copy or a swap (for values too small for millimetres, whose own hint,
        a diverged simulation or a faulty sensor, stands otherwise).
    """
    p = parse_channel(name)
    if p is None or p[0] != "susp_disp":
        return None
    x = np.asarray(channels[name], float)
    if x.size < 3 or not np.all(np.isfinite(x)) or np.std(x) == 0.0:
        return None
    for other, y in channels.items():
        y = np.asarray(y, float)
        if other in (name, "time") or y.shape != x.shape or not np.all(np.isfinite(y)) \
                or np.std(y) == 0.0:
            continue
        r = float(np.corrcoef(x, y)[0, 1])
        if abs(r) >= COPY_CORRELATION:
            return (f"not millimetres: the column repeats column '{other}' (correlation {r:.4f}); "
                    f"a column mapped twice?")
    st = f"{p[1]}{p[2]}"
    axle, body = channels.get(f"axle_acc_{st}"), channels.get(f"body_acc_{st}")
    if axle is None or x.size / fs < 4.0 / BAND_HZ[0] or fs < 2.5 * BAND_HZ[0]:
        return None
    axle = np.asarray(axle, float)
    body = None if body is None else np.asarray(body, float)
    ok, ratio, corr = _kinematic_si(x / 1000.0, axle, body, fs, True)
    if ok:
        return None
    swap = _swap_partner(x, st, axle, body, fs)
    if swap is not None:
        return (f"not millimetres: columns '{name}' and '{swap[0]}' look swapped (the "
                f"kinematic relation s'' = a_axle - a_body holds with the two exchanged)")
    if named_only:
        return None
    pair = f"axle_acc_{st}" + ("" if body is None else f" - body_acc_{st}")
    return (f"looks like millimetres, but divided by 1000 its second derivative does not match "
            f"{pair} in {BAND_HZ[0]:g}-{BAND_HZ[1]:g} Hz (ratio {ratio:.3g}, correlation "
            f"{corr:.2f}; about 1 and 1 for a displacement): check the column map before "
            f"converting (an acceleration in this column?)")


def check_signals(channels: dict) -> list[Finding]:
    """Channels that hold no measurement: constant over the record (a dead sensor, an
    unconnected logger input), or clipped (many samples at exactly the extreme value: the
    sensor's or the logger's range). Warnings: the column may not be one a command uses."""
    out: list[Finding] = []
    for name, x in channels.items():
        x = np.asarray(x, float)
        if x.size < 2:
            continue
        lo, hi = float(np.min(x)), float(np.max(x))
        if hi == lo:
            out.append(Finding(name, f"constant {lo:g} over the whole record: a dead sensor or an "
                               f"empty logger channel; a command that uses it will see no motion", False))
            continue
        tol = 1e-9 * (hi - lo)
        n = x.size
        for v, end in ((hi, "maximum"), (lo, "minimum")):
            k = int(np.sum(np.abs(x - v) <= tol))
            if k >= max(CLIP_MIN_SAMPLES, CLIP_SHARE * n):
                out.append(Finding(name, f"{k} samples ({100.0 * k / n:.2g} %) sit at exactly the "
                                   f"{end} {v:g}: clipped at the sensor's or logger's range? The "
                                   f"spectrum above that level is lost", False))
    return out
