"""Where the gap lies: simulated versus measured band power per channel x band x segment.

What it is for: the first answer of a diagnosis, a table (and heat map) of
``ln(P_sim / P_meas)`` in third-octave bands 0.5-50 Hz for every channel, over the
whole record and over each road segment, with a confidence interval from the number
of averages and a flag only where the gap exceeds statistical noise.

Statistics
----------
Each band power is ``S * chi2(nu) / nu`` with ``nu`` its equivalent degrees of
freedom (``diagnosis.bandpower``).  Simulated and measured records are independent
(the simulated road is a fresh random-phase realisation of the identified road), so
``(P_sim / S_sim) / (P_meas / S_meas) ~ F(nu_sim, nu_meas)`` and the exact interval
for the true log ratio ``ln(S_sim / S_meas)`` at level ``1 - a`` is
``[d - ln F_{1-a/2}, d - ln F_{a/2}]`` with ``d`` the estimated log ratio
(variances of both sides add: ``var d = trigamma(nu_sim/2) + trigamma(nu_meas/2)``,
about ``2/nu_sim + 2/nu_meas``).  The p-value of "no gap" is the two-sided F-test.
Cells are flagged by Benjamini-Hochberg at FDR ``q`` over all estimable cells of the
table (whole record and segments together); the reported ``ci_lo``/``ci_hi`` are the
matching FCR-adjusted intervals (``diagnosis.fdr``), so a cell is flagged exactly
where its interval excludes zero.  Marginal 95 % intervals are kept as
``ci95_lo``/``ci95_hi``.  A cell is estimable where both EDOFs are at least
``min_nu`` (default 6); short segments make the lowest bands non-estimable.

Segments are time windows in s from the first sample of each record; simulated and
measured records are assumed to cover the same drive (same speed profile).  Both sides
of a cell use the same Welch segment lengths (chosen on the measured side) where the
sample rates agree.

What it is not: proof that the model is wrong where flagged; a road misfit shows up
here as well (broadband, often all channels alike).  ``diagnosis.compare`` gives the
road-independent view.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy import stats

from eroad.errors import EroadInputError

from .bandpower import BandSpectrum, band_powers, third_octave_bands
from .fdr import benjamini_hochberg, fcr_level
from .signals import Segment, Signals, as_segments, as_signals

__all__ = ["Localization", "localize", "log_ratio_interval", "common_channels", "WHOLE"]

#: label of the whole-record row
WHOLE = "all"


def common_channels(a: Signals, b: Signals, channels: Sequence[str] | None = None) -> list[str]:
    """Channels present in both records (order of ``a``), or check a requested list.

    Raises
    ------
    EroadInputError
        When a requested channel is missing or no channel is common.
    """
    if channels is not None:
        for side, s in (("measured", a), ("simulated", b)):
            miss = [c for c in channels if c not in s.channels]
            if miss:
                raise EroadInputError(f"{side} data lack channel(s): {', '.join(miss)}")
        return list(channels)
    out = [c for c in a.channels if c in b.channels]
    if not out:
        raise EroadInputError("measured and simulated data share no channel")
    return out


def log_ratio_interval(d: np.ndarray, nu_sim: np.ndarray, nu_meas: np.ndarray,
                       level: float | np.ndarray = 0.95):
    """Exact F interval for the true log PSD ratio.

    Parameters
    ----------
    d : array
        Estimated ``ln(P_sim / P_meas)``.
    nu_sim, nu_meas : array
        Equivalent degrees of freedom of the simulated and measured band powers.
    level : float or array
        Confidence level.

    Returns
    -------
    lo, hi, p : arrays
        Interval bounds (log units) and the two-sided p-value of ``d == 0``.
    """
    a = 1.0 - np.asarray(level, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = (nu_sim > 0) & (nu_meas > 0) & np.isfinite(d)
        ns = np.where(ok, nu_sim, 1.0)
        nm = np.where(ok, nu_meas, 1.0)
        dd = np.where(ok, d, 0.0)
        lo = dd - np.log(stats.f.ppf(1 - a / 2, ns, nm))
        hi = dd - np.log(stats.f.ppf(a / 2, ns, nm))
        F = np.exp(dd)
        p = np.minimum(1.0, 2 * np.minimum(stats.f.cdf(F, ns, nm), stats.f.sf(F, ns, nm)))
    nan = np.nan
    return np.where(ok, lo, nan), np.where(ok, hi, nan), np.where(ok, p, nan)


@dataclass(frozen=True)
class Localization:
    """Gap table: arrays indexed ``[segment, channel, band]``.

    Attributes
    ----------
    channels : list of str
    bands : (nb, 3) array, Hz (lower edge, centre, upper edge)
    segments : list of str
        ``"all"`` (whole record) first when computed, then segment labels.
    log_ratio : array
        ``ln(P_sim / P_meas)`` (natural log; +0.69 = simulation has twice the power).
    ci_lo, ci_hi : array
        FCR-adjusted interval at level ``ci_level``; excludes 0 exactly where flagged.
    ci95_lo, ci95_hi : array
        Marginal 95 % interval.
    p_value : array
        Two-sided F-test of no gap; NaN where not estimable.
    nu_sim, nu_meas : array
        Equivalent degrees of freedom.
    significant, estimable : bool arrays
    q : float
        FDR level.
    ci_level : float
        Level of ``ci_lo``/``ci_hi``.
    windows : list of (t_start, t_end)
        Time window of each row, s.
    """

    channels: list
    bands: np.ndarray
    segments: list
    log_ratio: np.ndarray
    ci_lo: np.ndarray
    ci_hi: np.ndarray
    ci95_lo: np.ndarray
    ci95_hi: np.ndarray
    p_value: np.ndarray
    nu_sim: np.ndarray
    nu_meas: np.ndarray
    significant: np.ndarray
    estimable: np.ndarray
    q: float
    ci_level: float
    windows: list

    @property
    def n_tested(self) -> int:
        """Number of estimable cells (the BH family size)."""
        return int(self.estimable.sum())

    @property
    def n_flagged(self) -> int:
        """Number of flagged cells."""
        return int(self.significant.sum())

    def records(self) -> list[dict]:
        """One JSON-ready dict per cell, as in ``summary.json["localization"]``.

        Keys: channel, band_hz [lo, hi], band_centre_hz, segment, t_start_s, t_end_s,
        log_psd_ratio, ci_lo, ci_hi, ci95_lo, ci95_hi, p_value, nu_sim, nu_meas,
        significant, estimable.  Non-estimable numbers are None.
        """
        def num(v):
            return None if not np.isfinite(v) else float(v)

        out = []
        for s, seg in enumerate(self.segments):
            for c, ch in enumerate(self.channels):
                for b in range(len(self.bands)):
                    lo, fc, hi = self.bands[b]
                    out.append({
                        "channel": ch, "band_hz": [float(lo), float(hi)],
                        "band_centre_hz": float(fc), "segment": seg,
                        "t_start_s": float(self.windows[s][0]), "t_end_s": float(self.windows[s][1]),
                        "log_psd_ratio": num(self.log_ratio[s, c, b]),
                        "ci_lo": num(self.ci_lo[s, c, b]), "ci_hi": num(self.ci_hi[s, c, b]),
                        "ci95_lo": num(self.ci95_lo[s, c, b]), "ci95_hi": num(self.ci95_hi[s, c, b]),
                        "p_value": num(self.p_value[s, c, b]),
                        "nu_sim": float(self.nu_sim[s, c, b]), "nu_meas": float(self.nu_meas[s, c, b]),
                        "significant": bool(self.significant[s, c, b]),
                        "estimable": bool(self.estimable[s, c, b]),
                    })
        return out

    def flagged_bands(self, segment: str = WHOLE) -> dict:
        """``{channel: [band centre Hz, ...]}`` of flagged cells in one row."""
        s = self.segments.index(segment)
        return {ch: [float(self.bands[b, 1]) for b in np.flatnonzero(self.significant[s, c])]
                for c, ch in enumerate(self.channels)}


def _spectra(sig: Signals, names, t0, t1, bands, **kw) -> BandSpectrum:
    w = sig.window(t0, t1) if (t0 > 0 or t1 < sig.duration) else sig
    x = np.vstack([w.channels[c] for c in names])
    return band_powers(x, w.fs, bands, **kw)


def _same_rate(a: Signals, b: Signals) -> bool:
    return abs(a.fs - b.fs) <= 1e-6 * a.fs


def localize(measured, simulated, *, segments: Sequence[Segment | tuple] | None = None,
             channels: Sequence[str] | None = None, bands: np.ndarray | None = None,
             q: float = 0.05, whole: bool = True, min_nu: float = 6.0,
             bins_per_band: int = 8, min_averages: int = 3) -> Localization:
    """Gap per channel x third-octave band x segment, flagged beyond noise.

    Parameters
    ----------
    measured, simulated : Signals or Drive-/SimResult-like (see ``as_signals``)
        The same drive, measured and simulated (independent road phases).
    segments : sequence of Segment or (label, t_start, t_end), optional
        Time windows in s from each record's first sample (road segments).
    channels : sequence of str, optional
        Default: all channels the two share.
    bands : (nb, 3) array, Hz, optional
        Default third octaves 0.5-50 Hz.
    q : float
        False discovery rate of the flags (Benjamini-Hochberg over all cells).
    whole : bool
        Also analyse the whole record (row ``"all"``, first).
    min_nu : float
        Minimum EDOF on each side for a cell to be tested.
    bins_per_band, min_averages : int
        Welch segment-length policy (``diagnosis.bandpower.band_nperseg``).

    Returns
    -------
    Localization
    """
    meas = as_signals(measured)
    sim = as_signals(simulated)
    names = common_channels(meas, sim, channels)
    bands = third_octave_bands() if bands is None else np.asarray(bands, dtype=float)
    dur = min(meas.duration, sim.duration)
    rows = ([(WHOLE, 0.0, dur)] if whole else []) + \
        [(s.label, s.t_start, s.t_end) for s in as_segments(segments, dur)]
    if not rows:
        raise EroadInputError("localize: no segment to analyse (whole=False and no segments)")
    kw = dict(bins_per_band=bins_per_band, min_averages=min_averages)
    shape = (len(rows), len(names), len(bands))
    d = np.full(shape, np.nan)
    nus = np.zeros(shape)
    num = np.zeros(shape)
    for i, (_, t0, t1) in enumerate(rows):
        bm = _spectra(meas, names, t0, t1, bands, **kw)
        # the same Welch segment lengths on both sides (same leakage), where the rates agree
        bs = _spectra(sim, names, t0, t1, bands, nperseg=bm.nperseg, **kw) if _same_rate(meas, sim) \
            else _spectra(sim, names, t0, t1, bands, **kw)
        with np.errstate(divide="ignore", invalid="ignore"):
            d[i] = np.log(bs.power / bm.power)
        nus[i], num[i] = bs.nu, bm.nu
    est = (nus >= min_nu) & (num >= min_nu) & np.isfinite(d)
    d = np.where(est, d, np.nan)
    _, _, p = log_ratio_interval(d, nus, num, 0.95)
    sig = benjamini_hochberg(np.where(est, p, np.nan), q)
    level = fcr_level(int(sig.sum()), int(est.sum()), q)
    lo, hi, _ = log_ratio_interval(d, nus, num, level)
    lo95, hi95, _ = log_ratio_interval(d, nus, num, 0.95)
    return Localization(names, bands, [r[0] for r in rows], d, lo, hi, lo95, hi95, p, nus, num,
                        sig & est, est, float(q), float(level), [(r[1], r[2]) for r in rows])
