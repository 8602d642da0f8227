"""Expected response features of each segment window from the linear vehicle model,
and the hybrid fit that uses them (issue 14, item 6).

What it is for: replacing the time simulations in the inner loop of the inverse fit
(:func:`inverse.sensitivity.fit_segments`) by the linear model's expected features
(:class:`LinearFeatures`, a ``features_fn`` of the fit's contract), and correcting
what the linear model lacks with a few time simulations (:func:`fit_hybrid`).  What
it is not: a new feature definition -- the layout, bands, masks, noise and weights are
those of the measured :class:`inverse.features.FeatureSet` -- nor a simulator.

Expected features of one window
-------------------------------
For segment k with parameters (Gq_n0, w, nmin, nmax), channel o and speed v:

    S_o(f) = G(f) sum_g gamma(f / v, dy_g; w, lam) T_{o,g}(f; v)
    G(f) = Gq_n0 (f / (v n0))^-w / v   inside [nmin v, nmax v]  (edge cells fractional)
    T_{o,g}(f; v) = sum_{(c, d) with |y_c - y_d| = dy_g} Re(H_oc H_od^* e^{j 2 pi f (x_c - x_d) / v})

with H the linear model's FRFs from the road height under each tyre
(:meth:`vehicles.linear.LinearModel.frf`), gamma the lateral coherence of the
synthesised surface (:func:`vehicles.linear.surface_coherence`), the footprint filter
of ``tyre_enveloping`` and, optionally, the loss of a linearly interpolated road grid
(sinc(n dx)^4, ``grid_dx``).  This is :meth:`LinearModel.response_psd` regrouped so
that everything independent of the road (H, the wheelbase delays, the pairs of tyres)
is computed once per window and speed: an evaluation costs G, gamma for the few
distinct lateral distances and matrix products.

* The expected Welch estimate of the window is the kernel of
  :func:`vehicles.linear.welch_expectation` (Hann, the window's ``nperseg``) applied to
  S_o, with the rows of bins 0 and 1 recomputed for scipy's per-segment mean removal
  (``detrend="constant"``; it changes only those bins for a Hann window, and bin 1 is
  inside the 0.8 Hz band for windows shorter than 5.12 s).
* Band powers: Welch bins summed into the FeatureSet's third-octave bands exactly as
  :meth:`FeatureSet._band_powers` does (:func:`band_matrix`; test: identical on a
  random record), then only the window's used bands (``WindowFeatures.bands``) and
  the log RMS over the bands that hold a bin, with the measured noise power N_b added.
* **Speed**: the speed varies inside a window; a Welch estimate of a slowly varying
  record is the time average of the local PSDs, i.e. the average over the window's
  speed distribution.  DECISION: the expected PSD is averaged with equal weights over
  the speeds at the midpoints of ``n_speeds`` = 5 equal-probability bins of the
  window's speed samples (quantiles 0.1, 0.3, 0.5, 0.7, 0.9); one speed when the
  window's speed range is below 0.5 % of its median.
* **Log bias**: the features are logs of chi-square-like estimates, E[ln P_hat] =
  ln E[P_hat] + psi(nu / 2) - ln(nu / 2) (-0.27 at nu = 4, -0.03 at nu = 60), with
  nu the measured window's degrees of freedom (``WindowFeatures.dof``); the log RMS
  gets half of it with its Satterthwaite nu.  A simulation-based fit cancels this bias
  by construction (its features carry it too); the linear features add it explicitly.

The hybrid fit
--------------
:func:`fit_hybrid`: (a) fit with the linear features (no time simulation; the linear
model without the nonlinear effects, which it would linearise at rest); (b) at that
point, run the time simulator with the fit's seed and the first polishing seeds
(``realisations`` in all, each with the FeatureSpec's replicates) and take
per-feature offsets c = mean_seeds F_sim - F_lin (4 realisations by default); (c) refit with F_lin(theta) + c from
there; repeat (b)-(c) while the parameters still move (largest step over
``config.scale`` above ``move_tol``), at most ``corrections`` times.  The offsets carry
what the linear model lacks: nonlinear effects (leaf friction), segment transients and
neighbours seen by the other axles, the simulator's road grid and junctions, and the
Exudyn model's own small nonlinearity.
"""
from __future__ import annotations

import math
import time as _time

import numpy as np
from scipy.special import digamma

from eroad.errors import EroadInputError
from inverse.features import FeatureSet
from inverse.spectral import N0

#: quantile midpoints per window (module docstring: speed)
N_SPEEDS = 5
#: relative speed range below which one speed represents a window
SPEED_RANGE_TOL = 0.005
#: correction rounds when nonlinear effects are left out of the linear model: their
#: offsets depend on the road (luliang, leaf friction 2200 N: moves 2.0, 0.66, 0.30,
#: 0.11, 0.05 over rounds 1-5; the class A piece oscillates 39, 20, 27, 25, 26e-6 m^3)
CORRECTIONS_NONLINEAR = 4
#: Welch bins kept above the top band's upper edge on the kernel's fine grid
KERNEL_MARGIN_BINS = 8
#: points of the tabulated surface coherence (ln r from ln 1e-6 to ln 80)
COHERENCE_TABLE = 800


def band_matrix(features: FeatureSet, nperseg: int) -> np.ndarray:
    """Map from Welch bins to the FeatureSet's band powers, (n_bands, nperseg // 2 + 1).

    The same selection as :meth:`FeatureSet._band_powers`: bins with frequencies in
    [lower, upper) of each band (``searchsorted(..., side="left")`` on scipy's bin
    frequencies), times the bin width.  ``band_matrix(fs, n) @ welch_psd`` equals
    ``fs._band_powers(x, n)[0]`` (tested).
    """
    f = np.fft.rfftfreq(int(nperseg), 1.0 / features.fs)
    df = f[1] - f[0]
    i0 = np.searchsorted(f, features.lower, side="left")
    i1 = np.searchsorted(f, features.upper, side="left")
    B = np.zeros((features.lower.size, f.size))
    for b, (a, e) in enumerate(zip(i0, i1)):
        B[b, a:e] = df
    return B


def welch_kernel(fs: float, nperseg: int, oversample: int = 8):
    """Kernel of the expected Welch estimate with scipy's per-segment mean removal
    (:func:`vehicles.linear.welch_expectation` with ``detrend=True``).

    Returns
    -------
    (fk, ff, K) : bin frequencies [Hz], fine grid [Hz], kernel (n_bins, n_fine) with
        expected Welch PSD = K @ S(ff) for a one-sided PSD S [unit^2/Hz].
    """
    from vehicles.linear import welch_expectation

    fk, _, ff, _, K = welch_expectation(lambda f: np.zeros_like(f), fs, nperseg, "hann",
                                        oversample=oversample, return_kernel=True, detrend=True)
    return fk, ff, np.array(K, dtype=float)


def _edge_weights(ff: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Fraction of each fine cell [f - df/2, f + df/2] inside [lo, hi] (continuous in lo, hi)."""
    df = ff[1] - ff[0] if ff.size > 1 else 1.0
    a = np.maximum(ff - 0.5 * df, 0.0)
    b = ff + 0.5 * df
    return np.clip((np.minimum(b, hi) - np.maximum(a, lo)) / (b - a), 0.0, 1.0)


def window_speeds(v: np.ndarray, n_speeds: int = N_SPEEDS) -> np.ndarray:
    """Speeds representing a window: midpoints of ``n_speeds`` equal-probability bins."""
    v = np.asarray(v, dtype=float)
    med = float(np.median(v))
    if n_speeds <= 1 or (v.max() - v.min()) < SPEED_RANGE_TOL * med:
        return np.array([med])
    return np.quantile(v, (np.arange(n_speeds) + 0.5) / n_speeds)


def road_grid_lines(width: float, dy: float) -> np.ndarray:
    """Lateral grid lines [m] of a synthesised road of ``width`` and step ``dy``
    (roadlib's own axis, centred on y = 0)."""
    from roadlib.synthesis import _lateral_axis

    return _lateral_axis(float(width), float(dy))


def _tyre_lines(y: float, grid_y) -> list:
    """[(line y, weight)] whose weighted sum is the road height under a tyre at ``y``:
    itself, or the two neighbouring grid lines with bilinear weights
    (:meth:`roadlib.surface.RoadSurface.height`)."""
    if grid_y is None or len(grid_y) < 2:
        return [(float(y), 1.0)]
    g = np.asarray(grid_y, dtype=float)
    step = g[1] - g[0]
    fy = float(np.clip((y - g[0]) / step, 0.0, g.size - 1.0))
    iy = min(int(fy), g.size - 2)
    t = fy - iy
    out = [(float(g[iy]), 1.0 - t), (float(g[iy + 1]), t)]
    return [(yy, a) for yy, a in out if a > 1e-12]


def log_bias(dof) -> np.ndarray:
    """E[ln(P_hat / P)] of a chi-square estimate with ``dof`` degrees of freedom:
    psi(nu/2) - ln(nu/2) [-]."""
    h = 0.5 * np.asarray(dof, dtype=float)
    return digamma(h) - np.log(h)


def split_linear_effects(effects) -> tuple[dict, dict]:
    """Resolved effects split into the linear ones (kept by a linear model as they are)
    and the nonlinear ones (``Effect.nonlinear``), both in application order."""
    from vehicles.effects import EFFECTS, resolve_effects

    eff = resolve_effects(effects) if effects else {}
    linear = {k: v for k, v in eff.items() if not EFFECTS[k].nonlinear}
    return linear, {k: v for k, v in eff.items() if k not in linear}


def linear_model_for(vehicle, chassis: str = "rigid", effects=None):
    """The linear model of the fit: the vehicle with its LINEAR effects only.

    Effects flagged ``nonlinear`` (leaf friction, bump stops, asymmetric dampers) are
    left out: linearised at rest they would describe a stuck or mean suspension, not
    the one the time simulation drives; the hybrid fit's offsets carry them instead.

    Returns
    -------
    (LinearModel, list of str) : the model and the effects left out.
    """
    from vehicles.linear import linear_model
    from vehicles.params import load_vehicle

    keep, nonlinear = split_linear_effects(effects)
    return linear_model(load_vehicle(vehicle), chassis, effects=keep or None), sorted(nonlinear)


def features_for_simulator(features, speed, simulate, linear_model=None,
                           what: str = "linear fit: needs a linear model or a simulator with a vehicle") -> tuple:
    """The LinearFeatures a linear fit works on when its time simulations run on ``simulate``
    (an ``inverse.truck`` simulator): the simulator's vehicle, chassis and LINEAR effects
    (:func:`linear_model_for`) unless ``linear_model`` is given, its road grid's sinc^4 loss
    along x (``simulate.dx``), no lateral mix (every tyre reads the synthesised road's own
    line, ``roadlib.surface`` "Exact lines", as a real road is driven), its ``lam``; no offsets.
    ``what``: the one-line refusal when there is neither a model nor a vehicle.

    Returns
    -------
    (LinearFeatures, list of str) : the features and the nonlinear effects the linear model
    leaves out (empty when ``linear_model`` was given).
    """
    left_out = []
    if linear_model is None:
        if not hasattr(simulate, "vehicle"):
            raise EroadInputError(what)
        linear_model, left_out = linear_model_for(simulate.vehicle, getattr(simulate, "chassis", "rigid"),
                                                  getattr(simulate, "effects", None))
    lin = LinearFeatures(features, speed, linear_model, grid_dx=getattr(simulate, "dx", None),
                         grid_y=None, lam=getattr(simulate, "lam", 1.0))
    return lin, left_out


class LinearFeatures:
    """``features_fn(params, seed) -> list of K feature arrays`` from the linear model.

    Parameters
    ----------
    features : FeatureSet
        The measured features (windows, bands, noise, dof): the layout to reproduce.
    speed : float or (N,) array
        Speed on the record's time grid [m/s].
    linear_model : vehicles.linear.LinearModel
    n_speeds : int
        Speeds per window (module docstring).
    grid_dx : float, optional
        Road grid step [m] of a linearly interpolated road (the time simulator's,
        ``inverse.truck.SIM_DX``): multiplies the road PSD by sinc(n dx)^4.  None: the
        continuous road.
    grid_y : array, optional
        Lateral grid lines of such a road [m] (:func:`road_grid_lines`): a wheel
        between two lines sees their bilinear mix, whose power at short wavelengths,
        where neighbouring lines are little coherent, is lower (down to half midway);
        modelled exactly by letting each tyre's input be the weighted pair of lines.
        None: each tyre on its own track -- what the inversion uses since 2026-12-01,
        because its simulator's synthesised roads are read on each tyre's own line
        (``roadlib.surface`` "Exact lines") and so is a real road.
    lam : float
        Anisotropy of the surface's lateral coherence [-].
    bias : bool
        Add the log bias of the chi-square estimates (module docstring).
    offsets : list of K arrays, optional
        Added to the features (the hybrid fit's corrections).

    Everything that does not depend on the road parameters (FRFs on each window's
    fine grid, delays, tyre pairs per lateral distance, the band kernel) is computed
    here, once.
    """

    def __init__(self, features: FeatureSet, speed, linear_model, *, n_speeds: int = N_SPEEDS,
                 grid_dx: float | None = None, grid_y=None, lam: float = 1.0, bias: bool = True,
                 offsets=None):
        self.features = features
        self.lm = linear_model
        self.lam = float(lam)
        self.bias = bool(bias)
        self.offsets = None if offsets is None else [np.asarray(o, float) for o in offsets]
        self.extra = None
        self.n_evals = 0
        ch = list(features.spec.channels)
        missing = [c for c in ch if c not in linear_model.channel_names]
        if missing:
            raise EroadInputError(f"linear features: the linear model has no channel {', '.join(missing)}")
        v_all = np.broadcast_to(np.asarray(speed, dtype=float), (features.n_samples,))
        if not np.all(v_all > 0):
            raise EroadInputError("linear features: speed must be positive")
        # tyre pairs grouped by lateral distance (the surface coherence depends on |dy|
        # only); with a road grid, each tyre's input is a weighted pair of grid lines
        self._x = np.array([c["x"] for c in linear_model.contacts])
        lines = [_tyre_lines(c["y"], grid_y) for c in linear_model.contacts]
        nc = self._x.size
        acc = {}
        for c in range(nc):
            for d in range(nc):
                for yc, ac in lines[c]:
                    for yd, ad in lines[d]:
                        key = round(abs(yc - yd), 9)
                        acc.setdefault(key, np.zeros((nc, nc)))[c, d] += ac * ad
        self._dy = np.array(sorted(acc))
        self._masks = [acc[d] for d in self._dy]
        kern = {}
        self._win = []
        for wf in features.windows:
            logr = []
            if wf.nperseg not in kern:
                fk, ff, K = welch_kernel(features.fs, wf.nperseg)
                # the bands end at upper[-1]; the Hann kernel's leakage from beyond
                # KERNEL_MARGIN_BINS bins above is below 1e-6 of the in-band weight
                keep = ff <= features.upper[-1] + KERNEL_MARGIN_BINS * features.fs / wf.nperseg
                ff, K = ff[keep], K[:, keep]
                BK = band_matrix(features, wf.nperseg) @ K          # (n_bands, n_fine)
                H = linear_model.frf(ff, ch)                        # (n_fine, n_ch, n_contacts)
                kern[wf.nperseg] = (ff, BK, H)
            ff, BK, H = kern[wf.nperseg]
            speeds = window_speeds(v_all[wf.i0:wf.i1], n_speeds)
            nc = self._x.size
            Mst = np.array(self._masks).reshape(len(self._masks), nc * nc)
            T = np.empty((speeds.size, self._dy.size, len(ch), ff.size))
            for i, v in enumerate(speeds):
                Hd = H * np.exp(2j * np.pi * ff[:, None] * self._x[None, :] / v)[:, None, :]
                pair = (Hd[:, :, :, None] * Hd[:, :, None, :].conj()).real.reshape(-1, nc * nc)
                T[i] = (pair @ Mst.T).reshape(ff.size, len(ch), -1).transpose(2, 1, 0)
                n = ff / v
                filt = np.ones_like(n)
                if linear_model.footprint > 0:
                    filt *= np.sinc(n * linear_model.footprint) ** 2
                if grid_dx:
                    filt *= np.sinc(n * float(grid_dx)) ** 4
                T[i] *= filt[None, None, :]
                # ln r of the surface coherence, r = 2 pi n dy / lam, for every group with dy > 0
                logr.append(np.log(2 * np.pi * np.outer(self._dy[1:], n) / self.lam))
            df = features.fs / wf.nperseg
            bins = np.count_nonzero(band_matrix(features, wf.nperseg), axis=1)
            noise = np.array([features.noise_psd[c] * bins * df for c in ch])   # (n_ch, n_bands)
            # per channel: used bands, bands with a bin, and the log bias of each feature
            sl, pos = [], 0
            for c in ch:
                nb = wf.bands[c].size
                b_band = wf.dof[pos:pos + nb]
                pos += nb
                b_rms = None
                if features.spec.include_rms:
                    b_rms = wf.dof[pos]
                    pos += 1
                sl.append((wf.bands[c], wf._all_bands[c],
                           log_bias(b_band) if self.bias else np.zeros(nb),
                           0.5 * float(log_bias(b_rms)) if (self.bias and b_rms is not None) else 0.0))
            self._win.append({"ff": ff, "BK": BK, "speeds": speeds, "T": T, "noise": noise, "sel": sl,
                              "logr": np.array(logr)})          # (n_speeds, n_dy - 1, n_fine)
        if self._dy[0] != 0.0:  # pragma: no cover - a tyre always pairs with itself
            raise RuntimeError("linear features: expected the dy = 0 group first")
        self._gcache = {}

    def __getstate__(self):
        # for a process pool (the road-model choice runs a segment per worker): the
        # linear model is needed only to build the arrays above (and may hold Exudyn
        # objects, which do not pickle); the coherence cache is rebuilt on demand
        state = dict(self.__dict__)
        state["lm"] = None
        state["_gcache"] = {}
        return state

    @property
    def n_segments(self) -> int:
        return len(self._win)

    def with_offsets(self, offsets, extra=None) -> "LinearFeatures":
        """A copy sharing every precomputed array, with per-feature corrections.

        ``offsets``: per window, added to the log features (a gain); ``extra``: per
        window, a power [unit^2] added to each band's expected power before the log
        (an additive source the road does not drive; ignored for the log RMS)."""
        new = object.__new__(LinearFeatures)
        new.__dict__.update(self.__dict__)
        new.offsets = None if offsets is None else [np.asarray(o, float) for o in offsets]
        new.extra = None if extra is None else [np.asarray(e, float) for e in extra]
        new.n_evals = 0
        return new

    def band_totals(self, params) -> list:
        """Per window, the expected power + noise [unit^2] behind each feature (the
        band's, or the sum of the channel's bands for a log RMS), aligned with the
        features."""
        out = []
        for win, Pb in zip(self._win, self.band_powers(params)):
            tot = Pb + win["noise"]
            parts = []
            for j, (sel, allb, bb, br) in enumerate(win["sel"]):
                parts.append(tot[j, sel])
                if self.features.spec.include_rms:
                    parts.append(np.array([tot[j, allb].sum()]))
            out.append(np.concatenate(parts))
        return out

    def _coherence(self, k: int, w: float) -> np.ndarray:
        """gamma(n, dy_g) of window k at waviness w, (n_speeds, n_dy, n_fine).

        The closed form r^nu K_nu(r) / (Gamma(nu) 2^(nu-1)) (nu = w/2,
        :func:`vehicles.linear.surface_coherence`) is tabulated per w on
        ``COHERENCE_TABLE`` points log-spaced in r and interpolated linearly in ln r
        (largest error 4e-5 for w in 1.2-3.5, checked against the closed form on 1e5
        random r); cached per (window, w), since the fit's star design moves w in
        2 of its 8 samples."""
        from vehicles.linear import surface_coherence

        key = (k, float(w))
        out = self._gcache.get(key)
        if out is None:
            if len(self._gcache) > 256:
                self._gcache.clear()
            tab = self._gcache.get(("table", float(w)))
            xt = np.linspace(math.log(1e-6), math.log(80.0), COHERENCE_TABLE)
            if tab is None:
                tab = surface_coherence(np.exp(xt) / (2 * np.pi), 1.0, w, 1.0)  # at r = e^xt
                self._gcache[("table", float(w))] = tab
            lr = self._win[k]["logr"]
            g = np.interp(lr, xt, tab, left=1.0, right=0.0)
            out = np.concatenate([np.ones(lr.shape[:1] + (1,) + lr.shape[2:]), g], axis=1)
            self._gcache[key] = out
        return out

    def band_powers(self, params) -> list:
        """Expected noise-free band powers, per window (n_channels, n_bands) [unit^2].

        ``params`` is (K, 4) (Gq_n0, w, nmin, nmax) or (K, 6) with a two-slope road's
        ``w2`` [-] and ``n_break`` [cycles/m] in the last two columns (NaN there: one
        slope; :meth:`window_band_powers`)."""
        P = np.atleast_2d(np.asarray(params, dtype=float))
        if P.shape not in ((self.n_segments, 4), (self.n_segments, 6)):
            raise EroadInputError(f"linear features: params must have shape ({self.n_segments}, 4) or "
                                  f"({self.n_segments}, 6), got {P.shape}")
        return [self.window_band_powers(k, row) for k, row in enumerate(P)]

    def window_band_powers(self, k: int, row) -> np.ndarray:
        """Expected noise-free band powers of window ``k``, (n_channels, n_bands) [unit^2].

        ``row``: (Gq_n0, w, nmin, nmax) or (Gq_n0, w, nmin, nmax, w2, n_break).  A
        two-slope road (``roadlib.psd.two_slope_psd``: ``w`` below ``n_break``, ``w2``
        above, continuous) takes the surface coherence of the local waviness (the
        synthesis's lateral density, ``roadlib.synthesis``); with ``w2`` NaN or absent
        the one-slope expression is evaluated exactly as before the option existed."""
        win = self._win[k]
        Gq, w, nmin, nmax = (float(x) for x in row[:4])
        two = len(row) > 4 and math.isfinite(float(row[4]))
        ff = win["ff"]
        gams = self._coherence(k, w)
        if two:
            w2, nb = float(row[4]), float(row[5])
            gams2 = self._coherence(k, w2)
        S = np.zeros((win["T"].shape[2], ff.size))
        for i, v in enumerate(win["speeds"]):
            n = ff / v
            if not two:
                G = Gq * (n / N0) ** (-w) / v * _edge_weights(ff, nmin * v, nmax * v)
                gam = gams[i]                                        # (n_dy, n_fine)
            else:
                below = n <= nb
                shape = np.where(below, (n / N0) ** (-w), (nb / N0) ** (-w) * (n / nb) ** (-w2))
                G = Gq * shape / v * _edge_weights(ff, nmin * v, nmax * v)
                gam = np.where(below[None, :], gams[i], gams2[i])
            S += G[None, :] * np.einsum("gf,gof->of", gam, win["T"][i])
        S /= win["speeds"].size
        return S @ win["BK"].T                                       # (n_ch, n_bands)

    def window_features(self, k: int, row, Pb=None) -> np.ndarray:
        """Expected features of window ``k`` at one segment's parameters ``row`` (4 or
        6 values, :meth:`window_band_powers`), with this object's offsets -- what
        :meth:`__call__` returns for that window."""
        win = self._win[k]
        if Pb is None:
            Pb = self.window_band_powers(k, row)
        extra = getattr(self, "extra", None)
        tot = np.maximum(Pb + win["noise"], 1e-300)
        parts, pos = [], 0
        for j, (sel, allb, bb, br) in enumerate(win["sel"]):
            add = 0.0 if extra is None else extra[k][pos:pos + sel.size]
            parts.append(np.log(tot[j, sel] + add) + bb)
            pos += sel.size
            if self.features.spec.include_rms:
                parts.append(np.array([0.5 * math.log(tot[j, allb].sum()) + br]))
                pos += 1
        F = np.concatenate(parts)
        if self.offsets is not None:
            F = F + self.offsets[k]
        return F

    def __call__(self, params, seed=None) -> list:
        """Expected features of every window, aligned with ``features.windows[k].y``
        (``seed`` is ignored: the expectation has no realisation)."""
        self.n_evals += 1
        P = np.atleast_2d(np.asarray(params, dtype=float))
        return [self.window_features(k, P[k], Pb) for k, Pb in enumerate(self.band_powers(params))]


def simulated_features(simulate, features: FeatureSet, params, seeds, map_fn=map) -> list:
    """Time-simulated features at ``params``, log-averaged over ``seeds`` (each with the
    FeatureSpec's replicates, as :func:`fit_segments` evaluates them)."""
    from inverse.sensitivity import _apply, _Evaluator

    evs = [_Evaluator(simulate, features, s) for s in seeds]
    P = np.asarray(params, dtype=float)
    Fs = list(map_fn(_apply, [(ev, P) for ev in evs]))
    return [np.mean([F[k] for F in Fs], axis=0) for k in range(features.n_segments)]


def fit_hybrid(simulate, features: FeatureSet, params0, *, linear: LinearFeatures, seed: int = 0,
               bounds=None, config=None, prior=None, map_fn=None, progress=None,
               corrections: int = 2, move_tol: float = 0.1, linear_max_iter: int = 30,
               realisations: int = 4, additive_above: float | None = None):
    """Linear-model fit with simulation offsets (module docstring, "The hybrid fit").

    Parameters
    ----------
    simulate : callable or None
        Time simulator (contract of :mod:`inverse.sensitivity`); only called for the
        corrections (None with ``corrections=0``).
    features : FeatureSet
    params0 : (K, 4) array
    linear : LinearFeatures
        Built on ``features``.
    seed : int
        The fit's seed; the corrections simulate ``realisations`` road realisations:
        this seed and the first of :func:`inverse.sensitivity.polish_seeds` (the
        seeds of the simulation fit's polish).
    bounds, config, prior, progress
        As in :func:`inverse.sensitivity.fit_segments`; ``config.max_iter`` caps the
        corrected refits, ``linear_max_iter`` the first, linear-only fit (its
        iterations cost milliseconds).  Neither stage polishes: the offsets already
        average ``realisations`` realisations.
    map_fn : callable, optional
        Parallel map for the correction simulations (the linear evaluations run in
        this process).
    corrections : int
        Most simulate-and-refit rounds (0: the linear fit alone, no simulation).
    realisations : int
        Road realisations per correction round (default 4: two waves on two
        workers; the offsets' realisation scatter is psi'(nu/2) / 4 per feature,
        against psi'(nu/2) / 5 after the simulation fit's polish).
    additive_above : float, optional
        Band features whose offset exceeds this (in ln) are corrected by an added
        power E = (P_lin + N)(e^c - 1) instead of the gain e^c: an excess the road does
        not scale (transients, the response to speed changes; +3.4 in the 0.8 Hz
        suspension band of a class A piece after a class E one), whose feature then
        loses its false sensitivity to the road.  Equal at the correction point.
        Default None (all gains): 0.5 was tried on four null drives and luliang with
        leaf friction: unchanged except two class A pieces (|ln Gq| 0.71 -> 0.53 and
        0.17 -> 0.17), too little evidence for a default.
    move_tol : float
        A refit whose largest parameter change (in units of ``config.scale``: 1 in
        ln Gq_n0, 0.25 in w, ...) is below this ends the rounds: a further correction
        would move the parameters less still.

    Returns
    -------
    inverse.sensitivity.FitResult
        ``n_sims`` counts time simulations only; ``history`` holds every stage's
        iterations (``stage``: 'linear', 'corrected_1', ...; ``n_sims`` time
        simulations so far, ``n_evals`` linear evaluations of the stage) and one entry
        ``kind: 'correction'`` per simulation round (offsets' rms, largest |offset|).
        ``linear_features``: the :class:`LinearFeatures` of the last stage, with the
        offsets it was fitted with (``inverse.road_model`` uses them).
    """
    from dataclasses import replace

    from inverse.sensitivity import FitConfig, fit_segments, polish_seeds
    from inverse.spectral import ParamBounds

    t0 = _time.perf_counter()
    bounds = bounds or ParamBounds()
    config = config or FitConfig()
    prior = params0 if prior is None else prior
    if corrections > 0 and simulate is None:
        raise EroadInputError("fit_hybrid: corrections need a simulator")
    history = []
    n_sims = 0

    def stage(fn, name, p0, max_iter):
        cfg = replace(config, max_iter=int(max_iter), polish_replicates=0, n_workers=1)
        t_s = _time.perf_counter() - t0
        res = fit_segments(None, features, p0, seed=seed, bounds=bounds, config=cfg, prior=prior,
                           map_fn=map, features_fn=fn)
        for h in res.history:
            h.update(stage=name, n_evals=h["n_sims"], n_sims=n_sims, wall_s=t_s + h["wall_s"])
            history.append(h)
            if progress is not None:
                progress(h)
        return res

    res = stage(linear, "linear", params0, linear_max_iter)
    final = linear
    sim_seeds = ([int(seed)] + polish_seeds(seed, max(int(realisations) - 1, 0)))[:max(int(realisations), 1)]
    reps = features.spec.replicates
    for r in range(1, int(corrections) + 1):
        p_at = res.params
        Fsim = simulated_features(simulate, features, p_at, sim_seeds, map_fn or map)
        n_sims += len(sim_seeds) * reps
        base = linear.with_offsets(None)
        Flin = base(p_at)
        off = [fs - fl for fs, fl in zip(Fsim, Flin)]
        allo = np.concatenate(off)
        extra = None
        if additive_above is not None:
            # band features whose simulated power exceeds the linear one by more than
            # e^additive_above: an additive source (transients, the response to speed
            # changes) that the road level does not scale; carried as power E, so that
            # the feature's sensitivity to the road is P_lin / (P_lin + E), not 1
            tot = base.band_totals(p_at)
            extra, off2 = [], []
            for k, (o, t_) in enumerate(zip(off, tot)):
                rms = np.array([lab.endswith(":rms") for lab in features.windows[k].labels])
                add = (o > additive_above) & ~rms
                extra.append(np.where(add, t_ * np.expm1(np.where(add, o, 0.0)), 0.0))
                off2.append(np.where(add, 0.0, o))
            off = off2
        entry = {"iter": len(history), "kind": "correction", "stage": f"corrected_{r}",
                 "params": p_at.tolist(), "n_sims": n_sims, "seeds": sim_seeds,
                 "objective_simulated_segments": features.objective(Fsim).tolist(),
                 "offset_rms": float(np.sqrt(np.mean(allo ** 2))), "offset_max": float(np.max(np.abs(allo))),
                 "wall_s": _time.perf_counter() - t0}
        history.append(entry)
        if progress is not None:
            progress(entry)
        final = linear.with_offsets(off, extra)
        new = stage(final, f"corrected_{r}", p_at, config.max_iter)
        move = float(np.max(np.abs(new.theta - res.theta) / np.asarray(config.scale, float)))
        history[-1]["move"] = move
        res = new
        if move < move_tol:
            break
    res.history = history
    res.n_sims = n_sims
    res.wall_s = _time.perf_counter() - t0
    # the linear features of the last stage, with its offsets (inverse.road_model refits
    # the road's spectral form on them)
    res.linear_features = final
    return res
