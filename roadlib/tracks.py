"""How many independent tracks a set of neighbouring road tracks is worth.

What this module is for: the uncertainty of a PSD averaged over the tracks of a
road surface.  Tracks 0.1 m apart are nearly the same profile at long
wavelengths, so averaging 41 of them does not divide the variance of the
estimate by 41.  :func:`effective_tracks` measures how much it is divided by,
from the coherence between the tracks.  What it is not: a PSD estimator
(``roadlib.metrics.profile_psd``) or a fit (``roadlib.metrics.fit_iso_psd``).

For Gaussian profiles the periodograms of tracks i and j at one frequency are
correlated by |gamma_ij|^2, their squared coherence, so the variance of the
track average is ``(1/m^2) sum_ij |gamma_ij|^2`` times one track's.  The
effective number of tracks is ``m^2 / sum_ij |gamma_ij|^2``, with each
|gamma_ij|^2 averaged over the fitted band with the weight each frequency has in
the fitted quantity (:func:`fit_weights`: the lowest frequencies, where
neighbouring tracks are nearly the same profile, decide Gd(n0)).  The estimated squared coherence of two
independent signals from a few Welch averages is well above 0 (about 1/K for K
independent segments, more with overlapping ones); that bias ``b`` is measured
on the same data, between each track and every track shifted by half the road
length (independent of it when the road is long against its correlation
length), and removed as ``(c - b) / (1 - b)``, clipped to 0..1, so independent
tracks count fully.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import signal

from eroad.errors import EroadInputError

__all__ = ["effective_tracks", "fit_weights"]

def fit_weights(n, n0: float = 0.1, free_w: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Influence of each frequency bin on the fitted ``ln Gd(n0)`` and ``w``.

    The ISO fit is (close to) a straight line ``ln G = ln Gd(n0) - w ln(n/n0)``
    through the log periodogram; a bin's deviation moves the intercept by ``a_k``
    and the slope by ``b_k`` (least-squares influence).  Low bins, far from the
    bins' mean log frequency, weigh most for ``Gd(n0)``.

    Parameters
    ----------
    n : array_like
        Spatial frequencies [cycles/m] of the fitted bins.
    n0 : float
        Reference frequency [cycles/m].
    free_w : bool
        Whether ``w`` is fitted (else only the level: every bin weighs the same).

    Returns
    -------
    (ndarray, ndarray)
        Squared influences ``a_k^2`` (for ``Gd(n0)``) and ``b_k^2`` (for ``w``).
    """
    x = np.log(np.asarray(n, float) / n0)
    m = x.size
    if not free_w or m < 3:
        return np.full(m, 1.0 / m ** 2), np.zeros(m)
    dxm = x - x.mean()
    sxx = float(np.sum(dxm ** 2))
    a = 1.0 / m - x.mean() * dxm / sxx
    b = dxm / sxx
    return a ** 2, b ** 2


def effective_tracks(z, dx: float, nperseg: int, band: tuple[float, float],
                     weights=None) -> float:
    """Effective number of independent tracks in a track-averaged PSD.

    Parameters
    ----------
    z : array_like, shape (nx, m)
        Heights [m] of ``m`` tracks sampled every ``dx``.
    dx : float
        Sample spacing [m].
    nperseg : int
        Welch segment length [samples], as used for the PSD.
    band : (float, float)
        Spatial-frequency band [cycles/m] of the fit.
    weights : callable, optional
        ``weights(n) -> w_k``: how much each bin's variance counts for the
        quantity whose uncertainty is wanted (e.g. ``lambda n: fit_weights(n)[0]``
        for ``Gd(n0)``); default every bin the same.

    Returns
    -------
    float
        Between 1 (all tracks the same profile) and ``m`` (independent tracks).
    """
    z = np.asarray(z, float)
    if z.ndim != 2:
        raise EroadInputError(f"effective_tracks: z must be (nx, tracks), got shape {z.shape}")
    m = z.shape[1]
    if m == 1:
        return 1.0
    nx = z.shape[0]
    step = nperseg // 2
    starts = range(0, nx - nperseg + 1, step)
    win = signal.windows.hann(nperseg, sym=False)
    n = np.fft.rfftfreq(nperseg, dx)
    sel = (n >= band[0]) & (n <= band[1])
    if not sel.any():
        raise EroadInputError(f"effective_tracks: no frequency of the PSD in the band {band}")
    def segments_fft(zz):
        return np.stack([np.fft.rfft(signal.detrend(zz[s:s + nperseg], axis=0, type="linear")
                                     * win[:, None], axis=0)[sel] for s in starts])   # (K, f, m)

    def coherence2(a, b):
        s_ab = np.einsum("kfi,kfj->fij", a, b.conj())
        pa = np.einsum("kfi,kfi->fi", a, a.conj()).real
        pb = np.einsum("kfj,kfj->fj", b, b.conj()).real
        return np.abs(s_ab) ** 2 / (pa[:, :, None] * pb[:, None, :])

    X = segments_fft(z)
    coh2 = coherence2(X, X)                                   # (f, m, m)
    bias = np.mean(coherence2(X, segments_fft(np.roll(z, nx // 2, axis=0))), axis=(1, 2))
    bias = np.clip(bias, 0.0, 0.9)[:, None, None]
    # averaged over the band before clipping: clipping each noisy bin at 0 would keep
    # the positive half of the noise and count independent tracks as correlated
    wk = np.ones(int(sel.sum())) if weights is None else np.asarray(weights(n[sel]), float)
    wk = wk / wk.sum()
    rho = np.clip(np.einsum("f,fij->ij", wk, (coh2 - bias) / (1.0 - bias)), 0.0, 1.0)   # (m, m)
    np.fill_diagonal(rho, 1.0)
    mean_sum = float(rho.sum())
    return float(min(m, max(1.0, m * m / mean_sum))) if math.isfinite(mean_sum) else 1.0
