"""Road-independent comparisons of simulation and measurement, and time-history metrics.

What it is for: isolating model error from road error.  The road identified by the
inverse fit is only known in distribution, so band powers (``diagnosis.where``)
mix model and road errors.  Ratios between channels of one record cancel the road:

* :func:`transmissibility` - axle to body per wheel position, ``|H1| = |Pxy| / Pxx``
  per frequency bin, averaged as ``ln|H1|`` over the bins of each third-octave band,
  measured against simulated.  Standard error per bin (Bendat and Piersol 2010,
  eq. 9.90): ``var ln|H| = (1 - g2) / (2 g2 n_d)`` with ``g2`` the coherence and
  ``n_d = nu / 2`` the number of independent averages, reduced by the number of
  independent bins in the band (from the EDOF of ``diagnosis.bandpower``), both
  sides added, plus a floor ``se_floor`` (default 0.01, 1 %) for the window-leakage
  bias of a noise-free record.  Flags: Benjamini-Hochberg over all pair x band cells
  on the normal z-test; intervals FCR-adjusted (``diagnosis.fdr``).
* :func:`front_rear` - coherence between axle 1 and a rear axle of one side (same
  track, delayed road) per band, compared through Fisher's ``atanh|g|``
  (``var = 1 / (2 n_d - 2)`` per bin), and the delay between them from the peak of a
  band-limited SCOT-weighted generalised cross-correlation (Carter 1987), per time
  block.  The delay of the measurement against ``wheelbase / speed`` and against
  the simulation's delay exposes speed-signal scale errors (the simulation is
  driven by the recorded speed) and wheelbase errors; block-to-block spread gives a
  t-interval.
* :func:`distribution_shape` - skewness, excess kurtosis and the Kolmogorov-Smirnov
  distance between standardised amplitude distributions, for nonlinear effects
  (friction, bump stops, damper asymmetry) that leave second-order spectra nearly
  unchanged.  Sampling variances for serially correlated Gaussian records:
  ``var g1 = 6/N sum_k rho_k^3``, ``var g2 = 24/N sum_k rho_k^4`` (Lomnicki 1961),
  and the KS test with an effective sample size ``N / f``, ``f`` the largest
  variance inflation of the empirical CDF of a standardised Gaussian process over
  the levels -2..2 standard deviations (bivariate-normal indicator covariances less
  their mean and variance terms, which standardisation removes), at least 1, and
  Kolmogorov's distribution rescaled for standardised samples
  (``KS_STANDARDISED_SCALE``, Monte Carlo).  Under
  heavy-tailed data these variances are too small: treat flags as indicative.

Time-history metrics (:func:`sprague_geers`, :func:`russell`) compare two signals
sample by sample.  Use them ONLY where the road under the wheels is known or
reconstructed (synthetic data with truth, or a simulation over a measured profile):
on independent random-road realisations they score phase noise (two independent
signals have Sprague-Geers phase error near 0.5), not model quality.  Sprague and
Geers (2004) magnitude error is ``M = sqrt(psi_cc / psi_mm) - 1``; one public
implementation drops the square root and reports ``psi_cc / psi_mm - 1``, which
doubles small magnitude errors.

What it is not: the band-power localisation (``diagnosis.where``).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy import signal, stats

from eroad.errors import EroadInputError

from .bandpower import band_nperseg, third_octave_bands, welch_edof
from .fdr import benjamini_hochberg, fcr_level
from .signals import as_signals

__all__ = ["Transmissibility", "transmissibility", "FrontRear", "front_rear", "Shape",
           "distribution_shape", "sprague_geers", "russell", "gcc_delay"]


# ----------------------------------------------------------------------------- helpers
def _num(v):
    return None if v is None or not np.isfinite(v) else float(v)


def _cross(x, y, fs, L):
    """One-sided Welch Pxx, Pyy, Pxy (conj(X) Y) with Hann, 50 % overlap."""
    kw = dict(fs=fs, window="hann", nperseg=L, noverlap=L - L // 2, detrend="constant")
    f, pxx = signal.welch(x, **kw)
    _, pyy = signal.welch(y, **kw)
    _, pxy = signal.csd(x, y, **kw)
    return f, pxx, pyy, pxy


def _band_bins(f, lo, hi):
    return np.flatnonzero((f >= lo) & (f < hi) & (np.arange(f.size) >= 2))


def _bin_counts(idx, L, K):
    """(n_d per bin, independent bins in band) from the Welch EDOF."""
    nu1 = float(welch_edof(np.ones(1), idx[:1], L, K))
    nub = float(welch_edof(np.ones(idx.size), idx, L, K))
    return nu1 / 2.0, max(1.0, nub / nu1)


def _z_interval(d, se, level):
    zq = stats.norm.ppf(0.5 + level / 2)
    return d - zq * se, d + zq * se


def _flag(d, se, q):
    """BH flags and FCR-adjusted normal intervals for estimates d with standard errors se."""
    ok = np.isfinite(d) & np.isfinite(se) & (se > 0)
    p = np.where(ok, 2 * stats.norm.sf(np.abs(np.where(ok, d, 0)) / np.where(ok, se, 1)), np.nan)
    sig = benjamini_hochberg(p, q) & ok
    level = fcr_level(int(sig.sum()), int(ok.sum()), q)
    lo, hi = _z_interval(d, se, level)
    return p, sig, np.where(ok, lo, np.nan), np.where(ok, hi, np.nan), level


def _pos(name: str):
    """'body_acc_3L' -> ('body_acc', '3', 'L')."""
    q, _, pos = name.rpartition("_")
    return q, pos[:-1], pos[-1:]


# ----------------------------------------------------------------------------- transmissibility
@dataclass(frozen=True)
class Transmissibility:
    """Axle-to-body transmissibility, measured against simulated, per band.

    Attributes
    ----------
    pairs : list of (input, output) channel names
    bands : (nb, 3) array, Hz
    log_mag_meas, log_mag_sim : (npair, nb) arrays
        Band mean of ``ln|H1|`` (H1 in (m/s^2)/(m/s^2)).
    coherence_meas, coherence_sim : (npair, nb) arrays
        Band mean of the magnitude-squared coherence.
    log_ratio, se : (npair, nb) arrays
        ``ln|H_sim| - ln|H_meas|`` and its standard error.
    ci_lo, ci_hi : FCR-adjusted interval at ``ci_level``
    p_value, significant : arrays
    q, ci_level : float
    """

    pairs: list
    bands: np.ndarray
    log_mag_meas: np.ndarray
    log_mag_sim: np.ndarray
    coherence_meas: np.ndarray
    coherence_sim: np.ndarray
    log_ratio: np.ndarray
    se: np.ndarray
    ci_lo: np.ndarray
    ci_hi: np.ndarray
    p_value: np.ndarray
    significant: np.ndarray
    q: float
    ci_level: float

    def records(self) -> list[dict]:
        """JSON-ready list, one dict per pair x band."""
        out = []
        for i, (a, b) in enumerate(self.pairs):
            for j, (lo, fc, hi) in enumerate(self.bands):
                out.append({"input": a, "output": b, "band_hz": [float(lo), float(hi)],
                            "band_centre_hz": float(fc),
                            "log_mag_meas": _num(self.log_mag_meas[i, j]),
                            "log_mag_sim": _num(self.log_mag_sim[i, j]),
                            "coherence_meas": _num(self.coherence_meas[i, j]),
                            "coherence_sim": _num(self.coherence_sim[i, j]),
                            "log_ratio": _num(self.log_ratio[i, j]), "ci_lo": _num(self.ci_lo[i, j]),
                            "ci_hi": _num(self.ci_hi[i, j]), "p_value": _num(self.p_value[i, j]),
                            "significant": bool(self.significant[i, j])})
        return out


def _log_h1(x, y, fs, bands, Ls, min_coherence):
    nb = len(bands)
    T, V, G = np.full(nb, np.nan), np.full(nb, np.nan), np.full(nb, np.nan)
    n = x.size
    for L in np.unique(Ls):
        L = int(L)
        K = 1 + (n - L) // (L // 2)
        f, pxx, pyy, pxy = _cross(x, y, fs, L)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.abs(pxy) / pxx
            g2 = np.clip(np.abs(pxy) ** 2 / (pxx * pyy), 1e-12, 1.0)
        for b in np.flatnonzero(Ls == L):
            idx = _band_bins(f, bands[b, 0], bands[b, 2])
            if idx.size == 0:
                continue
            nd, m_eff = _bin_counts(idx, L, K)
            G[b] = g2[idx].mean()
            if G[b] < min_coherence or not np.all(np.isfinite(h[idx])) or np.any(h[idx] <= 0):
                continue
            T[b] = np.log(h[idx]).mean()
            V[b] = np.mean((1 - g2[idx]) / (2 * g2[idx] * nd)) / m_eff
    return T, V, G


def transmissibility(measured, simulated, *, pairs: Sequence[tuple[str, str]] | None = None,
                     bands: np.ndarray | None = None, q: float = 0.05, min_coherence: float = 0.3,
                     se_floor: float = 0.01, bins_per_band: int = 8,
                     min_averages: int = 8) -> Transmissibility:
    """Axle-to-body transmissibility per band, simulated against measured.

    Parameters
    ----------
    measured, simulated : Signals-like
    pairs : sequence of (input, output), optional
        Default: ``(axle_acc_<pos>, body_acc_<pos>)`` for every wheel position with
        both channels on both sides.
    bands : (nb, 3) array, Hz, optional
    q : float
        FDR of the flags.
    min_coherence : float
        Bands whose mean coherence is below this on either side are not tested.
    se_floor : float
        Added standard error (log units) per side for window-leakage bias.
    bins_per_band, min_averages : int
        Welch segment-length policy.

    Returns
    -------
    Transmissibility
    """
    meas, sim = as_signals(measured), as_signals(simulated)
    if pairs is None:
        pairs = []
        for c in meas.channels:
            qn, ax, side = _pos(c)
            if qn == "axle_acc":
                out = f"body_acc_{ax}{side}"
                if out in meas.channels and c in sim.channels and out in sim.channels:
                    pairs.append((c, out))
    if not pairs:
        raise EroadInputError("transmissibility: no axle_acc/body_acc pair in both records")
    bands = third_octave_bands() if bands is None else np.asarray(bands, dtype=float)
    res = {k: [] for k in ("Tm", "Vm", "Gm", "Ts", "Vs", "Gs")}
    for a, b in pairs:
        for tag, s in (("m", meas), ("s", sim)):
            if a not in s.channels or b not in s.channels:
                raise EroadInputError(f"transmissibility: missing {a} or {b}")
            Ls = band_nperseg(bands, s.fs, s.time.size, bins_per_band=bins_per_band,
                              min_averages=min_averages)
            T, V, G = _log_h1(s.channels[a], s.channels[b], s.fs, bands, Ls, min_coherence)
            res["T" + tag].append(T)
            res["V" + tag].append(V)
            res["G" + tag].append(G)
    r = {k: np.array(v) for k, v in res.items()}
    d = r["Ts"] - r["Tm"]
    se = np.sqrt(r["Vs"] + r["Vm"] + 2 * se_floor ** 2)
    p, sig, lo, hi, level = _flag(d, se, q)
    return Transmissibility(list(map(tuple, pairs)), bands, r["Tm"], r["Ts"], r["Gm"], r["Gs"], d, se,
                            lo, hi, p, sig, float(q), float(level))


# ----------------------------------------------------------------------------- front to rear
def gcc_delay(x: np.ndarray, y: np.ndarray, fs: float, *, max_lag: float, f_lo: float = 1.0,
              f_hi: float = 30.0, nperseg: int | None = None, min_lag: float = 0.0) -> float:
    """Delay of ``y`` behind ``x`` (s) from a SCOT-weighted generalised cross-correlation.

    Parameters
    ----------
    x, y : (N,) arrays
        ``y(t) ~ x(t - tau)`` plus other content.
    fs : float, Hz
    max_lag : float, s
        Search ``0 < tau <= max_lag``.
    f_lo, f_hi : float, Hz
        Band used (the weighting is zero outside).
    nperseg : int, optional
        Welch segment length; default the power of two >= 4 max_lag fs, at most N/2.
    min_lag : float, s
        Search ``min_lag <= tau`` only (default 0: from one sample).

    Returns
    -------
    float
        Delay in s (parabolic interpolation of the peak); NaN if the record is too short.
    """
    n = x.size
    if nperseg is None:
        L = int(2 ** np.ceil(np.log2(max(16, 4 * max_lag * fs))))
        L = min(L, int(2 ** np.floor(np.log2(max(16, n // 2)))))
    else:
        L = int(nperseg)
    kmax = min(int(np.ceil(max_lag * fs)), L // 2 - 2)
    if L > n or kmax < 2:
        return float("nan")
    f, pxx, pyy, pxy = _cross(x, y, fs, L)
    w = np.where((f >= f_lo) & (f <= f_hi) & (pxx > 0) & (pyy > 0), 1.0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.where(w > 0, pxy / np.sqrt(pxx * pyy), 0.0)
    r = np.fft.irfft(g, L)
    kmin = max(1, int(np.floor(min_lag * fs)))
    if kmin >= kmax:
        return float("nan")
    k = kmin + int(np.argmax(r[kmin:kmax + 1]))
    if 1 <= k < L - 1:
        a, b, c = r[k - 1], r[k], r[k + 1]
        den = a - 2 * b + c
        off = 0.5 * (a - c) / den if den != 0 else 0.0
    else:
        off = 0.0
    return float((k + np.clip(off, -0.5, 0.5)) / fs)


def distance_lag(x: np.ndarray, y: np.ndarray, speed: np.ndarray, fs: float, *,
                 max_lag: float, min_lag: float = 0.0, f_lo: float = 1.0, f_hi: float = 30.0,
                 strict: bool = False) -> float:
    """Lag of ``y`` behind ``x`` in RECORDED DISTANCE (m): both resampled onto a uniform grid
    of ``s(t) = integral of speed`` (step ``min(speed) / fs``: no sample is dropped), then
    :func:`gcc_delay` with ``f_lo``-``f_hi`` (Hz) mapped to ``f / mean(speed)`` cycles/m.

    Two axles ``d`` apart see the same road ``d`` apart in true distance, so the lag is
    ``factor * d`` for a speed signal reading ``factor`` x the true speed, whatever the
    speed does; a delay in time runs from ``d / v_max`` to ``d / v_min`` through a record
    whose speed changes and smears the correlation peak.

    Parameters
    ----------
    x, y : (N,) arrays
    speed : (N,) array, m/s
        Recorded speed, > 0 throughout (else NaN is returned).
    fs : float, Hz
    max_lag, min_lag : float, m
        Search range.
    strict : bool
        NaN when ``max_lag`` does not fit the longest GCC segment of the record (instead of
        searching the part that fits).
    """
    v = np.asarray(speed, float)
    if v.size != np.size(x) or not np.all(v > 0):
        return float("nan")
    dist = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) / fs)])
    ds = float(v.min()) / fs
    grid = np.arange(0.0, dist[-1], ds)
    fs_x = 1.0 / ds
    if strict:
        L = int(2 ** np.floor(np.log2(max(16, grid.size // 2))))     # gcc_delay's longest segment
        if max_lag * fs_x > L // 2 - 2:
            return float("nan")
    v_mean = float(v.mean())
    xa = np.interp(grid, dist, np.asarray(x, float))
    xb = np.interp(grid, dist, np.asarray(y, float))
    return gcc_delay(xa, xb, fs_x, max_lag=max_lag, min_lag=min_lag, f_lo=f_lo / v_mean,
                     f_hi=f_hi / v_mean)


@dataclass(frozen=True)
class FrontRear:
    """Front-to-rear coherence and delay, measured against simulated.

    Attributes
    ----------
    pairs : list of (front channel, rear channel)
    bands : (nb, 3) array, Hz
    coherence_meas, coherence_sim : (npair, nb) arrays
        Band coherence (back-transformed mean Fisher z).
    z_diff, se, ci_lo, ci_hi, p_value, significant : (npair, nb) arrays
        Difference of Fisher z (sim - meas), FCR-adjusted interval, BH flags.
    delay_meas, delay_sim : (npair,) arrays, s
        Whole-record GCC delay; with speed signals the lag in recorded distance
        (:func:`distance_lag`) over the mean recorded speed.
    delay_expected : float, s
        ``wheelbase / mean(speed)`` (NaN without wheelbase or speed).
    delay_ratio, delay_ratio_lo, delay_ratio_hi : (npair,) arrays
        Measured / simulated delay, mean over blocks with t-interval (95 %).
    speed_scale, speed_scale_lo, speed_scale_hi : (npair,) arrays
        ``expected / measured delay`` = apparent true / recorded speed (95 %).
    delay_significant : (npair,) bool
        The delay-ratio interval excludes 1.
    wheelbase : float or None, m
    q, ci_level : float
    """

    pairs: list
    bands: np.ndarray
    coherence_meas: np.ndarray
    coherence_sim: np.ndarray
    z_diff: np.ndarray
    se: np.ndarray
    ci_lo: np.ndarray
    ci_hi: np.ndarray
    p_value: np.ndarray
    significant: np.ndarray
    delay_meas: np.ndarray
    delay_sim: np.ndarray
    delay_expected: float
    delay_ratio: np.ndarray
    delay_ratio_lo: np.ndarray
    delay_ratio_hi: np.ndarray
    speed_scale: np.ndarray
    speed_scale_lo: np.ndarray
    speed_scale_hi: np.ndarray
    delay_significant: np.ndarray
    wheelbase: float | None
    q: float
    ci_level: float

    def records(self) -> dict:
        """JSON-ready dict: ``coherence`` (pair x band list) and ``delay`` (per pair)."""
        coh, dl = [], []
        for i, (a, b) in enumerate(self.pairs):
            for j, (lo, fc, hi) in enumerate(self.bands):
                coh.append({"front": a, "rear": b, "band_hz": [float(lo), float(hi)],
                            "band_centre_hz": float(fc),
                            "coherence_meas": _num(self.coherence_meas[i, j]),
                            "coherence_sim": _num(self.coherence_sim[i, j]),
                            "fisher_z_diff": _num(self.z_diff[i, j]), "ci_lo": _num(self.ci_lo[i, j]),
                            "ci_hi": _num(self.ci_hi[i, j]), "p_value": _num(self.p_value[i, j]),
                            "significant": bool(self.significant[i, j])})
            dl.append({"front": a, "rear": b, "delay_meas_s": _num(self.delay_meas[i]),
                       "delay_sim_s": _num(self.delay_sim[i]),
                       "delay_expected_s": _num(self.delay_expected),
                       "delay_ratio_meas_over_sim": _num(self.delay_ratio[i]),
                       "delay_ratio_ci95": [_num(self.delay_ratio_lo[i]), _num(self.delay_ratio_hi[i])],
                       "apparent_speed_scale": _num(self.speed_scale[i]),
                       "apparent_speed_scale_ci95": [_num(self.speed_scale_lo[i]),
                                                     _num(self.speed_scale_hi[i])],
                       "significant": bool(self.delay_significant[i])})
        return {"coherence": coh, "delay": dl, "wheelbase_m": self.wheelbase}


def _fisher_band(x, y, fs, bands, Ls):
    nb = len(bands)
    Z, V = np.full(nb, np.nan), np.full(nb, np.nan)
    n = x.size
    for L in np.unique(Ls):
        L = int(L)
        K = 1 + (n - L) // (L // 2)
        f, pxx, pyy, pxy = _cross(x, y, fs, L)
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.sqrt(np.clip(np.abs(pxy) ** 2 / (pxx * pyy), 0.0, 1 - 1e-9))
        for b in np.flatnonzero(Ls == L):
            idx = _band_bins(f, bands[b, 0], bands[b, 2])
            if idx.size == 0 or not np.all(np.isfinite(g[idx])):
                continue
            nd, m_eff = _bin_counts(idx, L, K)
            if nd <= 1.5:
                continue
            Z[b] = np.arctanh(g[idx]).mean()
            V[b] = 1.0 / (2 * nd - 2) / m_eff
    return Z, V


def _blocks(n, n_blocks):
    edges = np.linspace(0, n, n_blocks + 1).astype(int)
    return list(zip(edges[:-1], edges[1:]))


def front_rear(measured, simulated, *, front: str = "1", rear: str = "3",
               sides: Sequence[str] = ("L", "R"), quantity: str = "axle_acc",
               wheelbase: float | None = None, bands: np.ndarray | None = None,
               f_lo: float = 1.0, f_hi: float = 30.0, max_lag: float | None = None,
               n_blocks: int = 5, q: float = 0.05, bins_per_band: int = 8,
               min_averages: int = 8) -> FrontRear:
    """Front-to-rear coherence and delay per side, simulated against measured.

    Parameters
    ----------
    measured, simulated : Signals-like
        The measured speed (``speed``) is used for the expected delay.
    front, rear : str
        Axle numbers.
    sides : sequence of str
        Sides analysed where both channels exist on both records.
    quantity : str
        Channel quantity (``axle_acc`` follows the road most directly).
    wheelbase : float, m, optional
        Distance front to rear axle; enables the expected delay and speed scale.
    bands : (nb, 3) array, Hz, optional
    f_lo, f_hi : float, Hz
        Band of the delay estimate.
    max_lag : float, s, optional
        Delay search range; default ``2 * wheelbase / min(speed)`` or 2 s.
    n_blocks : int
        Time blocks for the delay interval (>= 3).
    q : float
        FDR of the coherence flags.

    Returns
    -------
    FrontRear
    """
    meas, sim = as_signals(measured), as_signals(simulated)
    pairs = [(f"{quantity}_{front}{s}", f"{quantity}_{rear}{s}") for s in sides
             if all(c in r.channels for c in (f"{quantity}_{front}{s}", f"{quantity}_{rear}{s}")
                    for r in (meas, sim))]
    if not pairs:
        raise EroadInputError(f"front_rear: no {quantity} pair of axles {front} and {rear} in both records")
    bands = third_octave_bands() if bands is None else np.asarray(bands, dtype=float)
    speed = meas.speed
    # with a speed signal on both records the lags are taken in recorded distance
    # (:func:`distance_lag`, no smearing while the speed changes) and reported as delays over
    # the record's (block's) mean recorded speed; without one, in time
    ssp = sim.speed if sim.speed is not None else speed
    in_dist = (speed is not None and ssp is not None and np.all(np.asarray(speed) > 0)
               and np.all(np.asarray(ssp) > 0) and np.size(ssp) == sim.time.size)
    expected = float("nan")
    if wheelbase is not None and in_dist:
        expected = float(wheelbase / np.mean(speed))
    if max_lag is None:
        max_lag = 2 * wheelbase / float(np.min(speed)) if np.isfinite(expected) else 2.0

    def lag(s, v, a, b, i0=0, i1=None):
        """Delay (s) of channel b behind a on samples i0:i1 of record s with speed v."""
        x, y = s.channels[a][i0:i1], s.channels[b][i0:i1]
        if not in_dist:
            return gcc_delay(x, y, s.fs, max_lag=max_lag, f_lo=f_lo, f_hi=f_hi)
        vb = np.asarray(v, float)[i0:i1]
        vm = float(vb.mean())
        # the time search range at the block's slowest speed, as a distance at its mean
        return distance_lag(x, y, vb, s.fs, max_lag=max_lag * float(vb.min()), f_lo=f_lo,
                            f_hi=f_hi) / vm
    Z = {"m": [], "s": []}
    V = {"m": [], "s": []}
    dm, ds, rr, rlo, rhi, sc, sclo, schi, dsig = ([] for _ in range(9))
    tq = stats.t.ppf(0.975, max(1, n_blocks - 1))
    for a, b in pairs:
        for tag, s in (("m", meas), ("s", sim)):
            Ls = band_nperseg(bands, s.fs, s.time.size, bins_per_band=bins_per_band,
                              min_averages=min_averages)
            z, v = _fisher_band(s.channels[a], s.channels[b], s.fs, bands, Ls)
            Z[tag].append(z)
            V[tag].append(v)
        dm.append(lag(meas, speed, a, b))
        ds.append(lag(sim, ssp, a, b))
        ratios, scales = [], []
        n = min(meas.time.size, sim.time.size)
        for i0, i1 in _blocks(n, n_blocks):
            tm, ts = lag(meas, speed, a, b, i0, i1), lag(sim, ssp, a, b, i0, i1)
            ratios.append(tm / ts)
            if np.isfinite(expected):
                scales.append(wheelbase / float(np.mean(speed[i0:i1])) / tm)
        ratios = np.array(ratios)
        ratios = ratios[np.isfinite(ratios)]
        if ratios.size >= 2:
            mu, se = ratios.mean(), ratios.std(ddof=1) / np.sqrt(ratios.size)
            rr.append(mu), rlo.append(mu - tq * se), rhi.append(mu + tq * se)
            dsig.append(bool(mu - tq * se > 1 or mu + tq * se < 1))
        else:
            rr.append(np.nan), rlo.append(np.nan), rhi.append(np.nan), dsig.append(False)
        scales = np.array(scales)
        scales = scales[np.isfinite(scales)]
        if scales.size >= 2:
            mu, se = scales.mean(), scales.std(ddof=1) / np.sqrt(scales.size)
            sc.append(mu), sclo.append(mu - tq * se), schi.append(mu + tq * se)
        else:
            sc.append(np.nan), sclo.append(np.nan), schi.append(np.nan)
    zm, zs = np.array(Z["m"]), np.array(Z["s"])
    d = zs - zm
    se = np.sqrt(np.array(V["m"]) + np.array(V["s"]))
    p, sig, lo, hi, level = _flag(d, se, q)
    arr = lambda v: np.array(v, dtype=float)  # noqa: E731
    return FrontRear(pairs, bands, np.tanh(zm) ** 2, np.tanh(zs) ** 2, d, se, lo, hi, p, sig,
                     arr(dm), arr(ds), expected, arr(rr), arr(rlo), arr(rhi), arr(sc), arr(sclo),
                     arr(schi), np.array(dsig, dtype=bool), wheelbase, float(q), float(level))


# ----------------------------------------------------------------------------- distributions
@dataclass(frozen=True)
class Shape:
    """Amplitude-distribution shape, measured against simulated, per channel.

    Attributes
    ----------
    channels : list of str
    skew_meas, skew_sim, kurt_meas, kurt_sim : (nch,) arrays
        Sample skewness and EXCESS kurtosis (0 for a Gaussian).
    se_skew, se_kurt : (nch,) arrays
        Standard errors of the differences (Gaussian, serially correlated).
    ks_distance : (nch,) array
        Two-sample KS statistic between the standardised distributions.
    n_eff_meas, n_eff_sim : (nch,) arrays
        Effective sample sizes of the KS test.
    p_skew, p_kurt, p_ks : (nch,) arrays
    significant_skew, significant_kurt, significant_ks : (nch,) bool arrays
        Benjamini-Hochberg over all three tests of all channels.
    q : float
    """

    channels: list
    skew_meas: np.ndarray
    skew_sim: np.ndarray
    kurt_meas: np.ndarray
    kurt_sim: np.ndarray
    se_skew: np.ndarray
    se_kurt: np.ndarray
    ks_distance: np.ndarray
    n_eff_meas: np.ndarray
    n_eff_sim: np.ndarray
    p_skew: np.ndarray
    p_kurt: np.ndarray
    p_ks: np.ndarray
    significant_skew: np.ndarray
    significant_kurt: np.ndarray
    significant_ks: np.ndarray
    q: float

    @property
    def significant(self) -> np.ndarray:
        """Any of the three tests flagged, per channel."""
        return self.significant_skew | self.significant_kurt | self.significant_ks

    def records(self) -> list[dict]:
        """JSON-ready list, one dict per channel."""
        out = []
        for i, c in enumerate(self.channels):
            out.append({"channel": c, "skew_meas": _num(self.skew_meas[i]),
                        "skew_sim": _num(self.skew_sim[i]),
                        "kurtosis_meas": _num(self.kurt_meas[i]), "kurtosis_sim": _num(self.kurt_sim[i]),
                        "se_skew": _num(self.se_skew[i]), "se_kurtosis": _num(self.se_kurt[i]),
                        "ks_distance": _num(self.ks_distance[i]), "p_skew": _num(self.p_skew[i]),
                        "p_kurtosis": _num(self.p_kurt[i]), "p_ks": _num(self.p_ks[i]),
                        "significant_skew": bool(self.significant_skew[i]),
                        "significant_kurtosis": bool(self.significant_kurt[i]),
                        "significant_ks": bool(self.significant_ks[i]),
                        "significant": bool(self.significant[i])})
        return out


def _autocorr(x, max_lag):
    n = x.size
    m = int(2 ** np.ceil(np.log2(2 * n)))
    X = np.fft.rfft(x - x.mean(), m)
    r = np.fft.irfft(np.abs(X) ** 2, m)[: max_lag + 1]
    return r / r[0]


_KS_LEVELS = np.linspace(-2.0, 2.0, 9)


def _indicator_cov_table(n_theta: int = 721):
    """C(x, rho) = cov(1[X0 <= x], 1[Xk <= x]) for standard Gaussians with correlation rho.

    ``dC/drho = exp(-x^2 / (1 + rho)) / (2 pi sqrt(1 - rho^2))``; with ``rho = sin t`` the
    integrand is smooth: ``C = int_0^asin(rho) exp(-x^2 / (1 + sin t)) / (2 pi) dt``.
    Returns the grid of ``t`` and the table (levels x grid)."""
    t = np.linspace(-np.pi / 2, np.pi / 2, n_theta)
    with np.errstate(divide="ignore", over="ignore"):
        g = np.exp(-_KS_LEVELS[:, None] ** 2 / np.maximum(1 + np.sin(t)[None, :], 1e-300)) / (2 * np.pi)
    cum = np.concatenate([np.zeros((len(_KS_LEVELS), 1)),
                          np.cumsum(0.5 * (g[:, 1:] + g[:, :-1]) * np.diff(t), axis=1)], axis=1)
    zero = np.array([np.interp(0.0, t, c) for c in cum])
    return t, cum - zero[:, None]


_T_GRID, _C_TABLE = _indicator_cov_table()


#: quantile ratio of the two-sample KS statistic of two STANDARDISED iid Gaussian samples to
#: Kolmogorov's limit (a Lilliefors-type effect): Monte Carlo, 3000 pairs, N = 1000 and 8000,
#: 0.90 / 0.95 / 0.99 quantiles 0.68 / 0.66-0.68 / 0.65-0.66; 0.68 is on the safe side.
KS_STANDARDISED_SCALE = 0.68


def _ks_factor(rho: np.ndarray) -> float:
    """Variance inflation of the empirical CDF of a standardised record, max over levels.

    For a Gaussian process the covariance of the level-``x`` indicators at lag ``k`` is
    ``C(x, rho_k)`` (Mehler series ``sum_j rho^j / j! (phi(x) He_{j-1}(x))^2``).
    Standardising by the sample mean and standard deviation removes the ``j = 1, 2``
    terms, so the inflation is ``sum_k C3(x, rho_k) / C3(x, 1)`` with
    ``C3 = C - phi^2 (rho + x^2 rho^2 / 2)``, maximised over ``x`` in -2..2, at least 1.
    Checked on the toy quarter-car: 1.3-1.5 times the Monte Carlo inflation (safe side)."""
    th = np.arcsin(np.clip(rho, -1.0, 1.0))
    fac = []
    for i, x in enumerate(_KS_LEVELS):
        ph2 = stats.norm.pdf(x) ** 2
        c3 = np.interp(th, _T_GRID, _C_TABLE[i]) - ph2 * (rho + x * x * rho ** 2 / 2)
        fac.append((c3[0] + 2 * c3[1:].sum()) / c3[0])
    return max(1.0, float(max(fac)))


def _moments(x, fs, max_lag_s):
    z = (x - x.mean()) / x.std()
    n = z.size
    rho = _autocorr(z, min(n // 10, int(max_lag_s * fs)))
    two = lambda v: v[0] + 2 * v[1:].sum()  # noqa: E731  (sum over k = -M..M)
    var_s = 6.0 / n * max(two(rho ** 3), 1e-12)
    var_k = 24.0 / n * max(two(rho ** 4), 1e-12)
    return z, float(np.mean(z ** 3)), float(np.mean(z ** 4) - 3), var_s, var_k, n / _ks_factor(rho)


def _ks_stat(a, b):
    a, b = np.sort(a), np.sort(b)
    allv = np.concatenate([a, b])
    fa = np.searchsorted(a, allv, side="right") / a.size
    fb = np.searchsorted(b, allv, side="right") / b.size
    return float(np.max(np.abs(fa - fb)))


def distribution_shape(measured, simulated, *, channels: Sequence[str] | None = None,
                       q: float = 0.05, max_lag_s: float = 5.0) -> Shape:
    """Skewness, kurtosis and KS distance of standardised amplitude distributions.

    Parameters
    ----------
    measured, simulated : Signals-like
    channels : sequence of str, optional
        Default: all channels the two share.
    q : float
        FDR over all tests.
    max_lag_s : float, s
        Autocorrelation lags summed for the effective sample sizes.

    Returns
    -------
    Shape
    """
    meas, sim = as_signals(measured), as_signals(simulated)
    names = list(channels) if channels is not None else [c for c in meas.channels if c in sim.channels]
    if not names:
        raise EroadInputError("distribution_shape: no common channel")
    rows = []
    for c in names:
        zm, sm, km, vsm, vkm, nm = _moments(meas.channels[c], meas.fs, max_lag_s)
        zs, ss, ks, vss, vks, ns = _moments(sim.channels[c], sim.fs, max_lag_s)
        D = _ks_stat(zm, zs)
        en = np.sqrt(nm * ns / (nm + ns))
        rows.append((sm, ss, km, ks, np.sqrt(vsm + vss), np.sqrt(vkm + vks), D, nm, ns,
                     float(stats.kstwobign.sf(D * en / KS_STANDARDISED_SCALE))))
    a = np.array(rows, dtype=float).T
    sm, ss, km, ks, se_s, se_k, D, nm, ns, pks = a
    p_s = 2 * stats.norm.sf(np.abs(ss - sm) / se_s)
    p_k = 2 * stats.norm.sf(np.abs(ks - km) / se_k)
    sig = benjamini_hochberg(np.vstack([p_s, p_k, pks]), q)
    return Shape(names, sm, ss, km, ks, se_s, se_k, D, nm, ns, p_s, p_k, pks, sig[0], sig[1], sig[2],
                 float(q))


# ----------------------------------------------------------------------------- time-history metrics
def sprague_geers(measured: np.ndarray, computed: np.ndarray) -> tuple[float, float, float]:
    """Sprague-Geers magnitude, phase and combined errors (Sprague and Geers 2004).

    ``M = sqrt(psi_cc / psi_mm) - 1``, ``P = arccos(psi_cm / sqrt(psi_cc psi_mm)) / pi``,
    ``C = sqrt(M^2 + P^2)``, with ``psi_ab`` the mean of ``a * b`` over the record.
    Only meaningful where the excitation (road under the wheels) of both signals is the
    same; see the module docstring.

    Parameters
    ----------
    measured, computed : (N,) arrays, same unit and time base

    Returns
    -------
    M, P, C : float (dimensionless; ``M = 0.1`` is 10 % too large in RMS)
    """
    m = np.asarray(measured, dtype=float)
    c = np.asarray(computed, dtype=float)
    if m.shape != c.shape or m.size == 0:
        raise EroadInputError("sprague_geers: signals must have the same non-zero length")
    pmm, pcc, pcm = np.mean(m * m), np.mean(c * c), np.mean(c * m)
    M = float(np.sqrt(pcc / pmm) - 1.0)
    P = float(np.arccos(np.clip(pcm / np.sqrt(pcc * pmm), -1.0, 1.0)) / np.pi)
    return M, P, float(np.hypot(M, P))


def russell(measured: np.ndarray, computed: np.ndarray) -> tuple[float, float, float]:
    """Russell (1997) magnitude, phase and comprehensive errors.

    ``m = (A - B) / sqrt(A B)`` with ``A = sum c^2``, ``B = sum m^2``;
    ``RM = sign(m) log10(1 + |m|)``, ``RP = arccos(sum c m / sqrt(A B)) / pi``,
    ``RC = sqrt(pi / 4 (RM^2 + RP^2))``.  Same restriction as :func:`sprague_geers`.

    Parameters
    ----------
    measured, computed : (N,) arrays

    Returns
    -------
    RM, RP, RC : float
    """
    m = np.asarray(measured, dtype=float)
    c = np.asarray(computed, dtype=float)
    if m.shape != c.shape or m.size == 0:
        raise EroadInputError("russell: signals must have the same non-zero length")
    A, B = np.sum(c * c), np.sum(m * m)
    mm = (A - B) / np.sqrt(A * B)
    RM = float(np.sign(mm) * np.log10(1 + abs(mm)))
    RP = float(np.arccos(np.clip(np.sum(c * m) / np.sqrt(A * B), -1, 1)) / np.pi)
    return RM, RP, float(np.sqrt(np.pi / 4 * (RM ** 2 + RP ** 2)))
