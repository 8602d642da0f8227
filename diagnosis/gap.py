"""The gap scalar: how far a simulation is from a measurement, in one number and per band.

Definition
----------
For every estimable cell ``i`` (channel x third-octave band x window) let
``d_i = ln(P_sim,i / P_meas,i)`` be the log band-power ratio and
``v_i = 2 trigamma(nu_meas,i / 2)`` (about ``4 / nu``) the sampling variance that
``d_i`` would have for a correct model with as many averages as the measurement.
Then

    gap = sum_i w_i d_i^2 / sum_i w_i,      w_i = 1 / v_i,

an inverse-variance weighted mean squared log PSD ratio, in (log units)^2.  The
weights depend on the measured data only, so every model compared on the same data
is scored with the same weights, and ``shrink = 1 - gap_after / gap_before`` is a
ratio of two sums over the same cells.  For a correct model ``E[gap] = n / sum w``
(the ``floor``: the harmonic mean of the ``v_i``); ``sum w d^2`` is then about
chi-square with ``n`` degrees of freedom.  ``excess = gap - floor`` estimates the
part of the gap that is model error.  The per-band gap is the same weighted mean
over the cells of one band.

Cells enter where the measured EDOF is at least ``min_nu`` (default 6) on both
sides; windows shorter than about 20 s lose the lowest bands.

What it is not: the localisation test (``diagnosis.where``) or the ranking
(``diagnosis.which``); both use this.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from eroad.errors import EroadInputError

from .bandpower import BandSpectrum, band_powers, third_octave_bands, var_log_power
from .signals import as_signals

__all__ = ["Gap", "Reference", "reference", "band_gap", "sim_spectra"]


@dataclass(frozen=True)
class Gap:
    """A gap between simulated and measured band powers.

    Attributes
    ----------
    value : float, (log units)^2
        Inverse-variance weighted mean squared log PSD ratio.
    per_band : (nb,) array, (log units)^2
        The same per band (NaN where no cell).
    floor : float, (log units)^2
        Expected ``value`` for a correct model (sampling noise only).
    per_band_floor : (nb,) array, (log units)^2
        The same per band.
    n_cells : int
    bands : (nb, 3) array, Hz
    log_ratio : (nwin, nch, nb) array
        Cell log ratios (NaN where not estimable).
    weight : (nwin, nch, nb) array
        Cell weights (0 where not estimable).
    """

    value: float
    per_band: np.ndarray
    floor: float
    per_band_floor: np.ndarray
    n_cells: int
    bands: np.ndarray
    log_ratio: np.ndarray
    weight: np.ndarray

    @property
    def excess(self) -> float:
        """``value - floor``: the part above sampling noise (may be slightly negative)."""
        return self.value - self.floor


@dataclass(frozen=True)
class Reference:
    """Measured windows prepared once: band spectra and weights.

    Attributes
    ----------
    channels : list of str
    bands : (nb, 3) array, Hz
    spectra : list of BandSpectrum (one per window)
    lengths : list of int (samples per window)
    min_nu : float
    """

    channels: list
    bands: np.ndarray
    spectra: list
    lengths: list
    min_nu: float

    @property
    def weight(self) -> np.ndarray:
        """(nwin, nch, nb) inverse sampling variances of the log ratio (0: not used)."""
        w = []
        for bs in self.spectra:
            ok = (bs.nu >= self.min_nu) & np.isfinite(bs.power) & (bs.power > 0)
            w.append(np.where(ok, 1.0 / (2 * var_log_power(np.maximum(bs.nu, 1e-9))), 0.0))
        return np.array(w)


def reference(measured: Sequence, channels: Sequence[str] | None = None,
              bands: np.ndarray | None = None, *, min_nu: float = 6.0) -> Reference:
    """Prepare measured windows for repeated gap evaluations.

    Parameters
    ----------
    measured : sequence of Signals-like (or one)
    channels : sequence of str, optional
        Default: the channels of the first window.
    bands : (nb, 3) array, Hz, optional
    min_nu : float
        Minimum measured EDOF of a cell.
    """
    wins = [as_signals(m) for m in (measured if isinstance(measured, (list, tuple)) else [measured])]
    if not wins:
        raise EroadInputError("gap: no measured window")
    names = list(channels) if channels is not None else list(wins[0].channels)
    bands = third_octave_bands() if bands is None else np.asarray(bands, dtype=float)
    spectra = []
    for w in wins:
        miss = [c for c in names if c not in w.channels]
        if miss:
            raise EroadInputError(f"gap: measured window lacks channel(s) {', '.join(miss)}")
        spectra.append(band_powers(np.vstack([w.channels[c] for c in names]), w.fs, bands))
    return Reference(names, bands, spectra, [w.time.size for w in wins], float(min_nu))


def sim_spectra(simulated: Sequence, ref: Reference) -> list:
    """Band spectra of simulated windows analysed like ``ref``'s measured windows.

    Parameters
    ----------
    simulated : sequence of Signals-like, one per measured window (same order)
    ref : Reference

    Returns
    -------
    list of BandSpectrum (reusable against any reference of the same window lengths, e.g.
    the surrogate measurements of the noise reference)
    """
    sims = [as_signals(s) for s in (simulated if isinstance(simulated, (list, tuple)) else [simulated])]
    if len(sims) != len(ref.spectra):
        raise EroadInputError(f"gap: {len(sims)} simulated windows for {len(ref.spectra)} measured")
    out = []
    for s, bm in zip(sims, ref.spectra):
        miss = [c for c in ref.channels if c not in s.channels]
        if miss:
            raise EroadInputError(f"gap: simulated window lacks channel(s) {', '.join(miss)}")
        out.append(band_powers(np.vstack([s.channels[c] for c in ref.channels]), s.fs,
                               ref.bands, nperseg=bm.nperseg))
    return out


#: smallest simulated / measured band-power ratio a cell can show [-]: a band the simulation
#: leaves empty counts as this deficit (ln = -27.6) instead of dropping out of the gap
ZERO_POWER_RATIO = 1e-12


def band_gap(simulated: Sequence, ref: Reference, spectra: list | None = None) -> Gap:
    """Gap of simulated windows against a prepared measurement.

    Parameters
    ----------
    simulated : sequence of Signals-like, one per measured window (same order)
        Each analysed with the measured window's Welch segment lengths.
    ref : Reference
    spectra : list of BandSpectrum, optional
        :func:`sim_spectra` of ``simulated`` when already computed (``simulated`` is then
        not read).

    Returns
    -------
    Gap
    """
    if spectra is None:
        spectra = sim_spectra(simulated, ref)
    if len(spectra) != len(ref.spectra):
        raise EroadInputError(f"gap: {len(spectra)} simulated windows for {len(ref.spectra)} measured")
    d = []
    for bs, bm in zip(spectra, ref.spectra):
        if not np.array_equal(np.asarray(bs.nperseg), np.asarray(bm.nperseg)):
            raise EroadInputError("gap: simulated and measured windows analysed differently")
        ok = bs.nu >= ref.min_nu
        with np.errstate(divide="ignore", invalid="ignore"):
            # a simulated band with no power at all is a gap of 12 decades, not a cell to drop
            # (a model that outputs nothing on a channel must not score like a good one)
            ps = np.maximum(bs.power, ZERO_POWER_RATIO * bm.power)
            d.append(np.where(ok, np.log(ps / bm.power), np.nan))
    d = np.array(d)
    w = np.where(np.isfinite(d), ref.weight, 0.0)
    dz = np.where(w > 0, d, 0.0)
    sw = w.sum()
    if sw <= 0:
        raise EroadInputError("gap: no estimable cell (windows too short?)")
    swb = w.sum(axis=(0, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        per_band = np.where(swb > 0, (w * dz ** 2).sum(axis=(0, 1)) / swb, np.nan)
        pb_floor = np.where(swb > 0, (w > 0).sum(axis=(0, 1)) / swb, np.nan)
    n = int((w > 0).sum())
    return Gap(float((w * dz ** 2).sum() / sw), per_band, float(n / sw), pb_floor, n, ref.bands,
               np.where(w > 0, d, np.nan), w)
