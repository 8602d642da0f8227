"""The lateral road structure the inversion assumes, and how much the fitted level hangs on it.

What it is for: the inverse fit turns response levels into a road spectrum through an
assumed lateral structure -- an isotropic surface (anisotropy ``lam = 1``, eq (5) of the
paper) whose coherence between two tyre tracks falls with their distance and the
spatial frequency.  Nothing in one drive's responses pins that structure down well: a
truck whose dual tyres run in one rut, or a road whose left and right tracks are more
(or less) alike than the isotropic model says, responds with other levels to the same
longitudinal spectrum.  This module states the assumption and answers, per segment,
"had the road's lateral structure been X, the fitted level Gd(n0) would be a factor F
away" -- the sensitivity line of Table 1's notes and ``summary.json``.

Method: the linear vehicle (:mod:`vehicles.linear`) gives each fitted channel's RMS in
the fit's frequency band for the fitted segment spectrum under the assumed coherence
and under each alternative.  Response power is proportional to Gd(n0), so the level the
fit would have returned under an alternative is the assumed one divided by the power
ratio; the ratios of the fitted channels are combined geometrically (the fit matches
log band levels).  Linear first order: the waviness is held, nonlinear effects are
absent -- a sensitivity, not a refit.

What it is not: a model of real lateral road structure (``roadlib.psd`` has the
isotropic one) or a fit of ``lam`` (one drive does not resolve it).
"""
from __future__ import annotations

import math

import numpy as np

from eroad.errors import EroadInputError

#: what the inversion assumes (roadlib's surface synthesis, eq (5), lam = 1)
ASSUMED = "isotropic surface (lam = 1), coherence between tracks from eq (5)"

#: dual tyres of one wheel station are closer than this [m] (twin tyres 0.3-0.4 m apart;
#: a wheel station's two tracks are 1.8-2.1 m apart)
DUAL_DY_MAX = 0.5


def _surface(lam: float, w: float):
    from vehicles.linear import surface_coherence

    return lambda n, dy: surface_coherence(n, dy, w, lam)


def _duals_one_track(w: float):
    """Dual tyres of a wheel station on one profile (coherence 1 between them), the
    rest of the surface as assumed."""
    from vehicles.linear import surface_coherence

    def gam(n, dy):
        g = surface_coherence(n, dy, w, 1.0)
        return np.where(np.asarray(dy) < DUAL_DY_MAX, 1.0, g)
    return gam


def alternatives(w: float) -> dict:
    """Named alternative lateral structures: ``{name: coherence for vehicles.linear}``.

    * ``lam=0.5`` / ``lam=2``: an anisotropic surface (lateral correlation length half /
      twice the longitudinal; the paper's eq (5) with lam != 1);
    * ``duals in one rut``: the twin tyres of a wheel station see one profile;
    * ``tracks identical``: left and right tracks the same profile (bounce and pitch
      only; the upper limit of coherence);
    * ``tracks independent``: left and right tracks unrelated (the lower limit).
    """
    return {"lam=0.5": _surface(0.5, w), "lam=2": _surface(2.0, w),
            "duals in one rut": _duals_one_track(w),
            "tracks identical": "correlated", "tracks independent": "independent"}


def level_sensitivity(lm, segment: dict, speed: float, channels, band=None,
                      n_freq: int = 600) -> dict:
    """How far the fitted level of one segment moves under other lateral structures.

    Parameters
    ----------
    lm : vehicles.linear.LinearModel
        The vehicle the inversion used (same effects).
    segment : dict
        Fitted spectrum: ``Gq_n0`` [m^3], ``w``, ``nmin``, ``nmax`` [cycles/m].
    speed : float
        Mean speed over the segment [m/s].
    channels : sequence of str
        Channels the fit used (names of ``lm``'s outputs).
    band : (float, float), optional
        Frequency band of the fit's features [Hz]; default the road band at this speed,
        capped at 0.5-40 Hz.
    n_freq : int
        Points of the logarithmic frequency grid of the RMS integrals (600 keep the
        factors within 0.1 % of a 3000-point grid).

    Returns
    -------
    dict
        ``{name: {"factor": F, "dln_Gq_n0": ln F}}``: the level the fit would have
        returned under that structure is ``F`` times the reported one.
    """
    chans = [c for c in channels if c in lm.channel_names]
    if not chans:
        raise EroadInputError("level_sensitivity: none of the fitted channels is an output of the "
                              f"linear model ({', '.join(channels)})")
    if not (speed > 0 and math.isfinite(speed)):
        raise EroadInputError(f"level_sensitivity: speed must be positive, got {speed!r}")
    road = {k: float(segment[k]) for k in ("Gq_n0", "w", "nmin", "nmax")}
    if band is None:
        band = (max(0.5, road["nmin"] * speed), min(40.0, road["nmax"] * speed))
    if not band[0] < band[1]:
        raise EroadInputError(f"level_sensitivity: empty band {band}")
    base = lm.response_rms(road, speed, "surface", chans, band, n_freq=n_freq)
    out = {}
    for name, coh in alternatives(road["w"]).items():
        alt = lm.response_rms(road, speed, coh, chans, band, n_freq=n_freq)
        lr = [2.0 * math.log(alt[c] / base[c]) for c in chans if base[c] > 0 and alt[c] > 0]
        d = -float(np.mean(lr)) if lr else float("nan")
        out[name] = {"factor": math.exp(d), "dln_Gq_n0": d}
    return out


def sensitivity_line(sens: dict) -> str:
    """One line for a report: ``lam=0.5 x0.93, lam=2 x1.05, ...``."""
    return ", ".join(f"{k} x{v['factor']:.2f}" for k, v in sens.items())


def twin_tyre_axles(lm) -> list:
    """Axles of the linear model with two or more tyres on a side (twin tyres), ascending."""
    per = {}
    for c in lm.contacts:
        per.setdefault((c["axle"], c["side"]), []).append(c["y"])
    return sorted({a for (a, _), ys in per.items() if len(ys) > 1})


def fitted_axles(channels) -> list:
    """Axle numbers of the wheel channels among ``channels`` (``drives.format.parse_channel``), ascending."""
    from drives.format import parse_channel

    parsed = (parse_channel(str(c)) for c in channels)
    return sorted({p[1] for p in parsed if p is not None and p[2] is not None})


#: what the twin-tyre note quotes: the independent 8x4 truck's five measured-profile drives (seeds 1-5),
#: whose twin tyres run on one profile; G(1 cycle/m) fitted / the profile under each segment, median
#: (results/roads/20261129-measured-lateral/: axle 3 alone, axle 3 told that structure, every axle)
TWIN_EVIDENCE = ("1.34x with axle 3 alone, 0.92x once told that structure, 1.02x with every axle "
                 "(8x4 dump truck, a measured profile)")


def run_summary(vehicle, segments, time, speed, channels, *, effects=None, chassis="rigid") -> dict:
    """The lateral-structure entry of an inversion's ``summary.json``.

    Parameters
    ----------
    vehicle : str or Path
        The vehicle the inversion used.
    segments : list of dict
        Fitted segments (``t_start``, ``t_end`` [s], ``Gq_n0``, ``w``, ``nmin``, ``nmax``).
    time, speed : ndarray
        Record time [s] and speed [m/s].
    channels : sequence of str
        Fitted channels.
    effects, chassis
        As the inversion's model.

    Returns
    -------
    dict
        ``assumed`` (the structure), ``segments`` (per segment: mean speed and
        :func:`level_sensitivity`'s factors), ``factor_range`` (per alternative, the
        smallest and largest factor over the segments), or ``error`` where the linear
        model could not be built for this vehicle.
    """
    from vehicles.linear import linear_model

    try:
        lm = linear_model(vehicle, chassis, effects=effects or None)
    except EroadInputError as exc:
        return {"assumed": ASSUMED, "error": f"sensitivity not computed: {exc}"}
    time = np.asarray(time, float)
    speed = np.asarray(speed, float)
    twins = twin_tyre_axles(lm)
    singles = sorted({c["axle"] for c in lm.contacts} - set(twins))
    fitted = fitted_axles(channels)
    twin_only = bool(fitted) and set(fitted) <= set(twins)
    rows, rng = [], {}
    for i, s in enumerate(segments):
        m = (time >= s["t_start"]) & (time <= s["t_end"])
        v = float(np.mean(speed[m])) if m.any() else float(np.mean(speed))
        try:
            sens = level_sensitivity(lm, s, v, channels)
        except EroadInputError as exc:
            return {"assumed": ASSUMED, "error": f"sensitivity not computed: {exc}"}
        rows.append({"segment": i + 1, "speed_mps": v,
                     "factor": {k: d["factor"] for k, d in sens.items()}})
        for k, d in sens.items():
            lo, hi = rng.get(k, (math.inf, -math.inf))
            rng[k] = (min(lo, d["factor"]), max(hi, d["factor"]))
    return {"assumed": ASSUMED, "segments": rows,
            "factor_range": {k: [float(a), float(b)] for k, (a, b) in rng.items()},
            "fitted_axles": fitted, "twin_tyre_axles": twins, "single_tyre_axles": singles,
            "twin_tyres_only": twin_only,
            "meaning": "the level Gd(n0) the fit would have returned under that lateral structure "
                       "is 'factor' times the reported one (linear truck, waviness held)"}


def note_line(entry: dict) -> str:
    """The sentence under Table 1."""
    if "error" in entry:
        return f"Lateral road structure assumed: {entry['assumed']} ({entry['error']})."
    parts = []
    for k, (a, b) in entry["factor_range"].items():
        parts.append(f"{k} x{a:.2f}" if abs(b - a) < 0.005 else f"{k} x{a:.2f}-{b:.2f}")
    line = (f"Lateral road structure assumed: {entry['assumed']}; not identified by the data. "
            "Had it been otherwise, the fitted Gd(n0) would be (over the segments): "
            + ", ".join(parts) + " (docs/inverse.md, section 13).")
    if entry.get("twin_tyres_only"):
        singles = entry.get("single_tyre_axles") or []
        line += (" Every fitted axle runs on twin tyres, whose level hangs most on how alike the twins' "
                 "tracks are ('duals in one rut'): on drives whose twin tyres ran on one profile G(1 cycle/m) "
                 f"came out {TWIN_EVIDENCE}" + (f"; fit axle {' or '.join(map(str, singles))} too "
                                                "(--channels axles) where the drive logs it" if singles else "")
                 + ".")
    return line
