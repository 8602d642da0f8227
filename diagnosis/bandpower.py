"""Third-octave band powers from Welch estimates, with their equivalent degrees of freedom.

What it is for: the one place where the diagnosis turns a time history into band
powers and says how sure it is of each one.  Every gap, interval and test of the
diagnosis starts here.

Method
------
* Bands: base-10 third octaves (IEC 61260-1), centres ``10**(k/10)`` Hz, edges
  ``fc * 10**(+-1/20)``; 0.5-50 Hz gives 21 bands (0.447-56.2 Hz).
* For each band a Welch estimate (periodic Hann window, 50 % overlap, mean removed
  per segment) whose segment length ``L`` is the power of two giving about
  ``bins_per_band`` bins inside the band, shortened where needed so that the
  record holds at least ``min_averages`` segments.  Band power is the sum of the
  one-sided PSD over the bins with ``lo <= f < hi`` (bins 0 and 1 excluded) times
  the bin width.
* Equivalent degrees of freedom (EDOF) ``nu`` of each band power, exactly for a
  Gaussian process whose spectrum is flat within each bin's window main lobe: the
  band power is a quadratic form ``x' A x`` of the record, so
  ``nu = 2 E^2 / Var = tr(A)^2 / tr(A^2)``.  ``tr(A^2)`` is assembled from the
  overlaps of the windowed complex exponentials of neighbouring bins and segments
  (the Hann window overlaps only with the next segment at 50 %), weighted by the
  estimated PSD of each bin (Satterthwaite).  One bin, ``K`` disjoint segments:
  ``nu = 2K``; Hann at 50 % overlap: ``nu = 2K / (1 + 2 * 0.167^2)``, Welch's
  (1967) result.  The band power is then modelled as ``S * chi2(nu) / nu``.

What it is not: a general spectrum analyser; no cross spectra (see
``diagnosis.compare``).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import signal, special

from .welch import welch

__all__ = ["third_octave_bands", "BandSpectrum", "band_powers", "band_nperseg",
           "welch_edof", "var_log_power"]


def third_octave_bands(f_min: float = 0.5, f_max: float = 50.0) -> np.ndarray:
    """Base-10 third-octave bands whose centres lie in ``[f_min, f_max]``.

    Parameters
    ----------
    f_min, f_max : float, Hz
        Lowest and highest nominal centre (rounded to the nearest third octave).

    Returns
    -------
    (nb, 3) array, Hz
        Columns: lower edge, exact centre ``10**(k/10)``, upper edge.
    """
    k0 = int(round(10 * np.log10(f_min)))
    k1 = int(round(10 * np.log10(f_max)))
    fc = 10.0 ** (np.arange(k0, k1 + 1) / 10.0)
    g = 10.0 ** (1 / 20)
    return np.column_stack([fc / g, fc, fc * g])


def band_nperseg(bands: np.ndarray, fs: float, n: int, *, bins_per_band: int = 8,
                 min_averages: int = 3) -> np.ndarray:
    """Welch segment length per band.

    Parameters
    ----------
    bands : (nb, 3) array, Hz
    fs : float, Hz
    n : int
        Samples in the record.
    bins_per_band : int
        Target number of frequency bins inside a band.
    min_averages : int
        Minimum number of 50 %-overlapping segments; caps the length.

    Returns
    -------
    (nb,) int array
        Power-of-two segment lengths (samples), at least 16 and at most ``n``.
    """
    width = bands[:, 2] - bands[:, 0]
    want = np.ceil(np.log2(bins_per_band * fs / width))
    cap_len = 2.0 * n / (min_averages + 1)          # K = 2n/L - 1 segments at 50 %
    cap = np.floor(np.log2(max(cap_len, 16)))
    cap = min(cap, np.floor(np.log2(n)))
    return (2 ** np.clip(want, 4, cap)).astype(int)


@lru_cache(maxsize=64)
def _overlap_kernels(L: int):
    """|sum_m w(m) w(m + dH) exp(2 pi i D m / L)| for d = 0, 1, all D (mod L); Hann, H = L/2."""
    w = signal.get_window("hann", L)
    H = L // 2
    c0 = np.abs(np.fft.fft(w * w))
    p = np.zeros(L)
    p[: L - H] = w[: L - H] * w[H:]
    c1 = np.abs(np.fft.fft(p))
    return c0, c1, float(np.sum(w * w))


def welch_edof(weights: np.ndarray, bins: np.ndarray, L: int, K: int) -> np.ndarray:
    """Equivalent degrees of freedom of a Welch band sum.

    Parameters
    ----------
    weights : (..., m) array
        PSD (any unit) at the ``m`` bins summed; the EDOF is scale free.
    bins : (m,) int array
        FFT bin indices (``f = bins * fs / L``).
    L : int
        Segment length (samples); Hann window, hop ``L // 2``.
    K : int
        Number of segments averaged.

    Returns
    -------
    (...) array
        ``nu = tr(A)^2 / tr(A^2)`` (see module docstring); 0 where ``m == 0``.
    """
    weights = np.asarray(weights, dtype=float)
    if bins.size == 0 or K < 1:
        return np.zeros(weights.shape[:-1])
    c0, c1, w2 = _overlap_kernels(L)
    dj = np.subtract.outer(bins, bins) % L
    sj = np.add.outer(bins, bins) % L
    M = K * (c0[dj] ** 2 + c0[sj] ** 2) + 2 * (K - 1) * (c1[dj] ** 2 + c1[sj] ** 2)
    # the EDOF is scale free: normalise per band so that tiny powers do not underflow in
    # F (s^2); a band with no power at all gets the EDOF of a flat spectrum
    top = np.max(weights, axis=-1, keepdims=True)
    s = np.where(top > 0, np.maximum(weights, 0.0) / np.where(top > 0, top, 1.0), 1.0)
    s = np.maximum(s, 1e-150)
    E = K * w2 * s.sum(axis=-1)
    F = np.einsum("...i,ij,...j->...", s, M, s)
    return 2 * E ** 2 / F


def var_log_power(nu: np.ndarray) -> np.ndarray:
    """Variance of ``ln(chi2(nu)/nu)`` = trigamma(nu/2); about ``2/nu`` for large nu."""
    nu = np.asarray(nu, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(nu > 0, special.polygamma(1, np.maximum(nu, 1e-300) / 2), np.inf)


@dataclass(frozen=True)
class BandSpectrum:
    """Band powers of several channels.

    Attributes
    ----------
    bands : (nb, 3) array, Hz
        Lower edge, centre, upper edge.
    power : (nch, nb) array, unit^2
        Band power (mean square of the band-limited signal); NaN where no bin fell
        in the band.
    nu : (nch, nb) array
        Equivalent degrees of freedom; 0 where not estimable.
    nbins : (nb,) int array
        Bins summed per band.
    nperseg : (nb,) int array
        Welch segment length per band (samples).
    n_avg : (nb,) int array
        Welch segments averaged per band.
    """

    bands: np.ndarray
    power: np.ndarray
    nu: np.ndarray
    nbins: np.ndarray
    nperseg: np.ndarray
    n_avg: np.ndarray


def band_powers(x: np.ndarray, fs: float, bands: np.ndarray | None = None, *,
                bins_per_band: int = 8, min_averages: int = 3,
                nperseg: np.ndarray | None = None) -> BandSpectrum:
    """Third-octave band powers and their EDOF (see module docstring).

    Parameters
    ----------
    x : (N,) or (nch, N) array
        Signals (any unit), uniformly sampled.
    fs : float, Hz
    bands : (nb, 3) array, Hz, optional
        Default :func:`third_octave_bands` (0.5-50 Hz).
    bins_per_band, min_averages : int
        Segment-length policy, see :func:`band_nperseg`.
    nperseg : (nb,) int array, optional
        Force the segment length per band (e.g. to analyse two records alike).

    Returns
    -------
    BandSpectrum
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    bands = third_octave_bands() if bands is None else np.asarray(bands, dtype=float)
    n = x.shape[1]
    Ls = band_nperseg(bands, fs, n, bins_per_band=bins_per_band, min_averages=min_averages) \
        if nperseg is None else np.minimum(np.asarray(nperseg, dtype=int), n)
    nb = len(bands)
    power = np.full((x.shape[0], nb), np.nan)
    nu = np.zeros((x.shape[0], nb))
    nbins = np.zeros(nb, dtype=int)
    n_avg = np.zeros(nb, dtype=int)
    for L in np.unique(Ls):
        L = int(L)
        H = L // 2
        K = 1 + (n - L) // H
        f, P = welch(x, fs, L, hop=H)
        df = fs / L
        for b in np.flatnonzero(Ls == L):
            lo, _, hi = bands[b]
            idx = np.flatnonzero((f >= lo) & (f < hi) & (np.arange(f.size) >= 2))
            n_avg[b] = K
            nbins[b] = idx.size
            if idx.size == 0:
                continue
            power[:, b] = P[:, idx].sum(axis=1) * df
            nu[:, b] = welch_edof(P[:, idx], idx, L, K)
    return BandSpectrum(bands, power, nu, nbins, Ls, n_avg)
