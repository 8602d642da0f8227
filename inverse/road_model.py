"""One slope or two: the road's spectral form per segment, chosen by an information criterion.

What this module is for: after the inverse fit (either fit model), deciding for each
segment whether the one-slope ISO 8608 spectrum Gd(n) = Gd(n0) (n/n0)^-w explains the
response features, or whether the two-slope spectrum of ``roadlib.psd.two_slope_psd``
(waviness ``w_low`` below a break frequency ``n_break``, ``w_high`` above, continuous)
explains them enough better to pay for its two extra parameters.  Real road profiles
often bend (Andren 2006, Int. J. Vehicle Design 40; Kropac and Mucka 2004, Int. J.
Vehicle Design 36); a one-slope fit to a bent spectrum puts w on a bound and the level
where the line happens to cross n0.  What it is not: a new fit of the band or of the
realisation.  A segment reported two-slope hands its two slopes on (:func:`road_params`:
road.npz, the realisation selection, Table 2, Figure 11, the chassis study); see
docs/road_model.md.

Method (docs/road_model.md has the derivation and the measured rates)
------------------------------------------------------------------------
For segment k, on the linear model's expected features
(:class:`inverse.linear_features.LinearFeatures`) WITH the offsets c the hybrid fit
used (``--fit linear``; a simulation fit has none and the linear model is used as is):

1. one slope: minimise the fit's weighted residual
   ``chi2 = sum_j weight_j (y_j - F_j)^2`` (``FeatureSet.objective``) over (ln Gq_n0, w)
   from the fit's values, the band [nmin, nmax] held at the fit's;
2. two slopes: minimise the same chi2 over (ln Gq_n0, w_low, w_high, ln n_break) from
   w_low = w_high = w of step 1, from ``N_BREAK_STARTS`` break frequencies spread
   log-evenly inside the band (the break enters non-linearly and the objective can have
   a minimum per side of a resonance), keeping the best.  Both waviness exponents keep
   the fit's bounds (``ParamBounds.w``, sourced there); the break stays a factor
   ``BREAK_MARGIN`` inside the band, so each slope is seen over some of it.
   The one-slope model is the two-slope one with w_high = w_low: the models are
   nested, and the same objective, data and band are used for both.
3. BIC on that residual: the features are logs of chi-square estimates with weights
   1 / variance, so chi2 is -2 ln L up to a constant and
   ``BIC = chi2 / c + p ln(n_eff)``.  ``n_eff`` is the number of independent features,
   each feature counted 1 / (channels at its wheel station) (the station weighting of
   ``FeatureSpec``: the displacement and the acceleration of one wheel carry the same
   road information, so the objective already counts them once together).  ``c`` is
   the quasi-likelihood dispersion (as in QAIC/QBIC, Burnham and Anderson 2002, 6.2)
   from the larger model: ``max(1, chi2_two / (n_eff - 4))``, its residual per degree
   of freedom (4 refitted parameters: ln Gq_n0, w_low, w_high, ln n_break).  A residual
   beyond noise -- a vehicle the model lacks, or the 20-30 % excess scatter correctly
   modelled drives show (``inverse.uncertainty.R_REF`` = 0.56 per feature against 0.5
   expected) -- would otherwise turn any flexibility into "evidence"; dividing the gain
   by c puts it back on the chi-square scale.  The two-slope model has p = 2 more
   parameters (w_high, n_break), so

       ic_delta = (chi2_one - chi2_two) / c - 2 ln(n_eff)

   and the segment is reported ``two_slope`` when ic_delta > 0 (the two-slope BIC is
   lower) and neither slope sits on a bound of w (``ParamBounds.w``, the published
   range of real roads): a pinned slope is the bound's, not the road's, so the two
   slopes then describe a misfit (a vehicle gap, a band edge) rather than the road, and
   the segment keeps one slope with ``road_model_note`` saying so (the refit is kept in
   ``road_model_fit``, with ``rejected_at_bound``).  Penalty: 2 ln(n_eff) = 6.8 at n_eff = 30 (a 15 s segment with four axle-3
   channels), 4.2 at n_eff = 8.

   Why BIC and not AIC: the choice is between a simple model that is usually right
   (the synthetic roads of ``null`` and ``random`` are one-slope by construction, and
   ISO 8608's classes assume one) and a richer one; AIC's penalty 2 per parameter
   (4 here) would accept a chi2 gain that chi-square(2) noise exceeds 14 % of the time,
   before the search over the break (which makes the gain's null distribution heavier
   than chi-square(2): n_break has no meaning when the slopes are equal) -- too many
   false two-slope reports.  BIC's ln(n_eff) per parameter is consistent (picks the
   true model as the data grow) and at n_eff 8-60 makes the false rate under
   chi-square(2) 1.5-0.03 % before the break search; the measured false rate on
   ``null`` drives is in docs/road_model.md.

Reported per segment (new summary.json fields; the old ones keep their meaning, the
one-slope fit): ``road_model`` ('one_slope' / 'two_slope'), ``w_low``, ``w_high`` (both
the fit's w for one slope), ``n_break`` [cycles/m] (None for one slope), ``ic_delta``
(None when not evaluated), and ``road_model_fit`` with both refits (objectives,
parameters, c, n_eff, penalty; ``Gd_n0`` of the two-slope refit is its PSD at n0).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares

from eroad.errors import EroadInputError
from inverse.pipeline import w_bound_side
from inverse.spectral import N0, ParamBounds

#: starting break frequencies per segment, log-even inside the band (3: on 40 one-slope and 10
#: two-slope toy draws (tests/test_road_model.py) every selection and BIC gain equal to 5
#: starts', at 60 % of their evaluations)
N_BREAK_STARTS = 3
#: the break stays this factor inside [nmin, nmax]
BREAK_MARGIN = 1.25
#: parameters the two-slope model adds (w_high, n_break)
EXTRA_PARAMS = 2
#: road models of ``eroad invert --road-model``
ROAD_MODEL_MODES = ("auto", "one")


def effective_features(features, k: int) -> float:
    """Independent features of window ``k``: each counted 1 / (used channels at its
    wheel station) when the FeatureSpec weights stations, else 1 [-]."""
    spec = features.spec
    wf = features.windows[k]
    if not spec.station_weighting:
        return float(wf.y.size)
    station = {c: c.rsplit("_", 1)[-1] for c in spec.channels}
    share = {c: sum(1 for d in spec.channels if station[d] == station[c]) for c in spec.channels}
    return float(sum(1.0 / share[lab.split("@")[0].split(":")[0]] for lab in wf.labels))


def _chi2(r: np.ndarray) -> float:
    return float(np.dot(r, r))


def _fit_one(linear, k, wf, Gq, w, nmin, nmax, bounds):
    sw = np.sqrt(wf.weight)

    def resid(x):
        return sw * (wf.y - linear.window_features(k, (math.exp(x[0]), x[1], nmin, nmax)))

    lo = [math.log(bounds.Gq_n0[0]), bounds.w[0]]
    hi = [math.log(bounds.Gq_n0[1]), bounds.w[1]]
    x0 = np.clip([math.log(Gq), w], lo, hi)
    r = least_squares(resid, x0, bounds=(lo, hi), x_scale=[1.0, 0.25], diff_step=1e-4, xtol=1e-6,
                      ftol=1e-6, max_nfev=200)
    return r.x, _chi2(r.fun)


def _fit_two(linear, k, wf, Gq, w, nmin, nmax, bounds, n_starts=None):
    n_starts = N_BREAK_STARTS if n_starts is None else int(n_starts)
    sw = np.sqrt(wf.weight)
    b_lo, b_hi = nmin * BREAK_MARGIN, nmax / BREAK_MARGIN
    if not b_lo < b_hi:
        return None, math.inf

    def resid(x):
        return sw * (wf.y - linear.window_features(k, (math.exp(x[0]), x[1], nmin, nmax, x[2], math.exp(x[3]))))

    lo = [math.log(bounds.Gq_n0[0]), bounds.w[0], bounds.w[0], math.log(b_lo)]
    hi = [math.log(bounds.Gq_n0[1]), bounds.w[1], bounds.w[1], math.log(b_hi)]
    best = (None, math.inf)
    for lb in np.linspace(math.log(b_lo), math.log(b_hi), n_starts + 2)[1:-1]:
        # the one-slope line, with its level at n0 kept whatever side of n0 the break is
        x0 = np.clip([math.log(Gq), w, w, lb], lo, hi)
        # ftol 1e-6 of chi2 (20-100 here): far below the BIC penalty 4-8 it is compared with
        r = least_squares(resid, x0, bounds=(lo, hi), x_scale=[1.0, 0.25, 0.25, 0.5], diff_step=1e-4,
                          xtol=1e-6, ftol=1e-6, max_nfev=300)
        c = _chi2(r.fun)
        if c < best[1]:
            best = (r.x, c)
    return best


def select_segment(linear, features, k: int, row, bounds: ParamBounds | None = None) -> dict:
    """One slope or two for segment ``k`` (module docstring).

    Parameters
    ----------
    linear : inverse.linear_features.LinearFeatures
        Built on ``features``, with the offsets the fit used (if any).
    features : inverse.features.FeatureSet
    k : int
        Segment index.
    row : sequence
        The fit's (Gq_n0 [m^3], w [-], nmin, nmax [cycles/m]) of segment k.
    bounds : ParamBounds, optional
        The fit's bounds (default ``ParamBounds()``).

    Returns
    -------
    dict
        ``road_model``, ``w_low``, ``w_high``, ``n_break``, ``ic_delta`` and
        ``road_model_fit`` (module docstring, "Reported").
    """
    from roadlib.psd import two_slope_psd

    bounds = bounds or ParamBounds()
    wf = features.windows[k]
    Gq, w, nmin, nmax = (float(v) for v in row[:4])
    if wf.y.size == 0:
        raise EroadInputError(f"road model: segment {k + 1} has no features")
    x1, chi1 = _fit_one(linear, k, wf, Gq, w, nmin, nmax, bounds)
    x2, chi2 = _fit_two(linear, k, wf, math.exp(x1[0]), x1[1], nmin, nmax, bounds)
    n_feat = int(wf.y.size)
    n_eff = effective_features(features, k)
    if x2 is None:     # a band too narrow for a break: one slope by construction
        return one_slope_fields(w, note="band too narrow for a break") | {
            "road_model_fit": {"objective_one": chi1, "n_features": n_feat, "n_eff": n_eff}}
    chi2 = min(chi2, chi1)      # nested: the two-slope optimum is never worse than one slope
    disp = max(1.0, chi2 / max(n_eff - 4.0, 1.0))
    penalty = EXTRA_PARAMS * math.log(max(n_eff, 1.0))
    delta = (chi1 - chi2) / disp - penalty
    gq2, wl, wh, nb = math.exp(x2[0]), float(x2[1]), float(x2[2]), math.exp(x2[3])
    fit = {"objective_one": chi1, "objective_two": chi2, "dispersion": disp, "n_features": n_feat,
           "n_eff": n_eff, "penalty": penalty, "criterion": "BIC",
           "one_slope": {"Gq_n0": math.exp(x1[0]), "w": float(x1[1])},
           "two_slope": {"Gq_n0_low_line": gq2, "Gd_n0": float(two_slope_psd([N0], gq2, wl, wh, nb)[0]),
                         "w_low": wl, "w_high": wh, "n_break": nb}}
    pinned = [f"{name} = {v:.3g}" for name, v in (("w_low", wl), ("w_high", wh)) if w_bound_side(v, bounds)]
    if delta > 0 and not pinned:
        return {"road_model": "two_slope", "w_low": wl, "w_high": wh, "n_break": nb, "ic_delta": delta,
                "road_model_fit": fit}
    note = None
    if delta > 0:
        # a slope on the waviness bound is the bound's, not the road's: the two slopes then
        # describe a misfit the published range of real roads does not hold (a vehicle gap,
        # a band edge), and the road handed on keeps the one-slope fit
        note = (f"two slopes rejected although BIC prefers them: {', '.join(pinned)} on a bound of "
                f"w ({bounds.w[0]:g}-{bounds.w[1]:g})")
        fit["rejected_at_bound"] = pinned
    out = one_slope_fields(w, note=note)
    out.update(ic_delta=delta, road_model_fit=fit)
    return out


def one_slope_fields(w: float, note: str | None = None) -> dict:
    """The new fields of a segment reported with one slope (w_low = w_high = the fit's w)."""
    out = {"road_model": "one_slope", "w_low": float(w), "w_high": float(w), "n_break": None, "ic_delta": None}
    if note:
        out["road_model_note"] = note
    return out


def linear_features_for(inv, simulate, speed):
    """The LinearFeatures the road-model selection works on: the hybrid fit's own (with
    its offsets) when the fit was ``linear``, else one built as ``inverse.pipeline.invert``
    builds it for a linear fit (the simulator's vehicle, chassis, linear effects, road
    grid and lam; no offsets)."""
    lin = getattr(inv.fit, "linear_features", None)
    if lin is not None:
        return lin
    from inverse.linear_features import features_for_simulator

    return features_for_simulator(inv.features, speed, simulate, None,
                                  "road model: the simulator has no vehicle to build the linear model from")[0]


def _select_task(args) -> dict:
    return select_segment(*args)


def select_road_models(inv, simulate, speed, mode: str = "auto", bounds: ParamBounds | None = None,
                       map_fn=map) -> list:
    """Per segment of an :class:`inverse.pipeline.Inversion`, the road-model fields
    (:func:`select_segment`); ``mode`` 'one' reports one slope everywhere without
    fitting a second.  ``map_fn`` (e.g. a process pool's ``map``) runs the segments in
    parallel, the longest window first; the fields are the same either way."""
    if mode not in ROAD_MODEL_MODES:
        raise EroadInputError(f"--road-model must be one of {', '.join(ROAD_MODEL_MODES)}, got {mode!r}")
    P = np.asarray(inv.fit.params, dtype=float)
    if mode == "one":
        return [one_slope_fields(P[k, 1], note="--road-model one") for k in range(P.shape[0])]
    lin = linear_features_for(inv, simulate, speed)
    bounds = bounds or inv.config.bounds
    order = sorted(range(P.shape[0]), key=lambda k: -inv.features.windows[k].y.size)
    fields = list(map_fn(_select_task, [(lin, inv.features, k, P[k], bounds) for k in order]))
    out = [None] * P.shape[0]
    for k, f in zip(order, fields):
        out[k] = f
    return out


def add_road_models(segments: list, fields: list) -> list:
    """``segments`` (summary.json rows) with the road-model fields added beside the old
    ones (no old field is changed)."""
    if len(segments) != len(fields):
        raise EroadInputError("road model: one entry per segment expected")
    for s, f in zip(segments, fields):
        for key, v in f.items():
            if key in s and key not in ("road_model", "w_low", "w_high", "n_break", "ic_delta",
                                        "road_model_fit", "road_model_note"):
                raise RuntimeError(f"road model would overwrite segment field {key!r}")
            s[key] = v
    return segments


def segment_spectrum(seg: dict) -> tuple:
    """The road spectrum a summary.json segment reports: ``(Gq_n0, w, w2, n_break)``, the
    two-slope refit (Gq_n0 of its low-frequency line, w_low, w_high, n_break) where the road
    model chose two slopes, else the one-slope fit with ``w2 = n_break = None``
    (``roadlib.psd.road_psd`` takes the four)."""
    if seg.get("road_model") == "two_slope":
        two = (seg.get("road_model_fit") or {}).get("two_slope", {})
        return two["Gq_n0_low_line"], seg["w_low"], seg["w_high"], seg["n_break"]
    return seg["Gq_n0"], seg["w"], None, None


def road_params(params, segments: list) -> np.ndarray:
    """The fit's (K, 4) ``params`` with the road model of each segment: (K, 6), columns
    (Gq_n0, w, nmin, nmax, w2, n_break) for :func:`inverse.truck.road_from_params`.

    A segment reported ``two_slope`` gets its two-slope refit (Gq_n0 of the low-frequency
    line, w_low, nmin, nmax, w_high, n_break), so the road handed on (road.npz, the
    realisation selection, Table 2, Figure 11, the chassis study) is the road the report
    describes; a one-slope segment keeps the fit's row with NaN in the last two columns.
    Without any two-slope segment the (K, 4) ``params`` are returned unchanged.
    """
    P = np.atleast_2d(np.asarray(params, dtype=float))
    if len(segments) != P.shape[0]:
        raise EroadInputError("road model: one entry per segment expected")
    if not any(s.get("road_model") == "two_slope" for s in segments):
        return P[:, :4].copy()
    out = np.full((P.shape[0], 6), np.nan)
    out[:, :4] = P[:, :4]
    for k, s in enumerate(segments):
        if s.get("road_model") == "two_slope":
            out[k, 0], out[k, 1], out[k, 4], out[k, 5] = segment_spectrum(s)
    return out


def note_line(segments: list) -> str:
    """The line under Table 1 on the road model of each segment."""
    parts = []
    for i, s in enumerate(segments):
        if "road_model" not in s:
            continue
        if s["road_model"] == "two_slope":
            parts.append(f"segment {i + 1}: two slopes, w {s['w_low']:.2f} below / {s['w_high']:.2f} above "
                         f"{s['n_break']:.3g} cycles/m (BIC gain {s['ic_delta']:.1f})")
        else:
            d = s.get("ic_delta")
            parts.append(f"segment {i + 1}: one slope" + (f" (BIC gain of two {d:+.1f})" if d is not None else ""))
    if not parts:
        return ""
    return ("Road model (one ISO slope or two, chosen per segment by BIC on the fit's weighted residual, "
            "docs/road_model.md; Gq_n0 and w above are the one-slope fit): " + "; ".join(parts) + ".")


def fit_two_slope_psd(n, G, band, n_starts: int = 12) -> dict:
    """Whittle fit of the two-slope PSD to a PSD estimate (n [cycles/m], G [m^3]) in
    ``band``: for each break on a log grid inside the band (factor ``BREAK_MARGIN``),
    the level profiled out and (w_low, w_high) minimised; then the break refined.
    The check of docs/road_model.md fits a measured profile's own spectrum with it.

    Returns
    -------
    dict
        Gd_n0 [m^3] (the PSD at n0), Gq_n0_low_line [m^3], w_low, w_high [-],
        n_break [cycles/m], and the one-slope Whittle fit (Gq_n0, w) of the same bins.
    """
    from scipy.optimize import minimize

    from roadlib.psd import two_slope_psd

    n = np.asarray(n, float)
    G = np.asarray(G, float)
    sel = (n >= band[0]) & (n <= band[1]) & np.isfinite(G) & (G > 0)
    n, G = n[sel], G[sel]
    if n.size < 8:
        raise EroadInputError(f"fit_two_slope_psd: only {n.size} bins in {band}")

    def shape(x):
        return two_slope_psd(n, 1.0, x[0], x[1], math.exp(x[2]))

    def whittle(x):
        s = shape(x)
        c = float(np.mean(G / s))
        return n.size * math.log(c) + float(np.sum(np.log(s)))

    lo, hi = math.log(band[0] * BREAK_MARGIN), math.log(band[1] / BREAK_MARGIN)
    best = None
    for lb in np.linspace(lo, hi, n_starts):
        r = minimize(lambda x: whittle((x[0], x[1], lb)), [2.0, 2.0], method="L-BFGS-B",
                     bounds=[(0.2, 5.8), (0.2, 5.8)])
        if best is None or r.fun < best[1]:
            best = ((r.x[0], r.x[1], lb), r.fun)
    r = minimize(whittle, best[0], method="L-BFGS-B", bounds=[(0.2, 5.8), (0.2, 5.8), (lo, hi)])
    x = r.x if r.fun <= best[1] else np.asarray(best[0])
    c = float(np.mean(G / shape(x)))
    gq_low = c   # shape() is 1 at n0 on the low line
    nb = math.exp(x[2])

    def whittle1(wv):
        s = (n / N0) ** (-wv)
        return n.size * math.log(float(np.mean(G / s))) + float(np.sum(np.log(s)))

    from scipy.optimize import minimize_scalar
    w1 = float(minimize_scalar(whittle1, bounds=(0.2, 5.8), method="bounded").x)
    return {"Gd_n0": float(two_slope_psd([N0], gq_low, x[0], x[1], nb)[0]), "Gq_n0_low_line": gq_low,
            "w_low": float(x[0]), "w_high": float(x[1]), "n_break": nb,
            "one_slope": {"Gq_n0": float(np.mean(G / (n / N0) ** (-w1))), "w": w1},
            "whittle_two": float(r.fun), "whittle_one": float(whittle1(w1))}
