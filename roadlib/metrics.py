"""Road metrics in the spatial-frequency domain: Welch PSD, ISO 8608 fit, class.

What this module is for: estimating the displacement PSD of a measured or
generated profile (one-sided, cycles/m, m^3), fitting the ISO 8608 line
Gd(n) = Gd(n0) (n/n0)^-w to it *in linear space*, and naming its class.  What
it is not: the target spectra (``roadlib.psd``) or IRI (``roadlib.iri``).

Why not a straight line through log10 of the periodogram: a Welch estimate
with K averages is distributed as G chi2_2K / (2K); E[log] of that is below log
G (by about 14 % for a raw periodogram, K = 1: exp(-gamma) = 0.56 in G, and
still several percent for K ~ 10), so log-averaging underestimates Gd(n0).
``fit_iso_psd`` maximises the Whittle likelihood of the Welch estimates
instead::

    minimise  sum_i [ log G(n_i) + Ghat_i / G(n_i) ]    over Gd(n0), w

which for fixed w gives Gd(n0) = mean(Ghat_i / (n_i/n0)^-w) exactly (an
unbiased linear-space estimate), leaving a 1D search over w.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, signal

from eroad.errors import EroadInputError
from roadlib.psd import ISO_BAND, N0, class_of

#: equivalent noise bandwidth of the Hann window in bins: neighbouring Welch
#: bins are correlated, so the number of independent bins is n_bins / 1.5
HANN_ENBW_BINS = 1.5


@dataclass
class PsdEstimate:
    """A Welch estimate of a one-sided displacement PSD.

    Attributes
    ----------
    n : ndarray
        Spatial frequency [cycles/m], from 0 to 1/(2 dx).
    G : ndarray
        One-sided PSD [m^3] (m^2 per cycle/m).
    n_averages : float
        Number of (50 % overlapping Hann) segments averaged, times the number
        of tracks.
    nperseg : int
        Segment length [samples].
    dx : float
        Sample spacing [m].

    Unpacks as ``n, G = profile_psd(...)``.
    """

    n: np.ndarray
    G: np.ndarray
    n_averages: float
    nperseg: int
    dx: float

    def __iter__(self):
        return iter((self.n, self.G))

    @property
    def dof(self) -> float:
        """Equivalent chi-square degrees of freedom per bin (Welch: Hann, 50 % overlap)."""
        # Welch (1967): 50 % overlapped Hann segments are correlated by c = 0.167
        # (the averages count 1/(1 + 2 c^2) = 0.95 as independent) -- per track.
        return 2.0 * self.n_averages / (1.0 + 2.0 * 0.167**2)


def profile_psd(z, dx: float, nperseg: int | None = None, segment_length: float | None = None,
                detrend: str = "linear") -> PsdEstimate:
    """Welch estimate of the one-sided displacement PSD of a profile (or tracks).

    Parameters
    ----------
    z : array_like, shape (nx,) or (nx, ny)
        Heights [m] sampled every ``dx``; with 2 dimensions every column is a
        track and their periodograms are averaged.
    dx : float
        Sample spacing [m].
    nperseg : int, optional
        Welch segment length [samples].
    segment_length : float, optional
        Welch segment length [m] (alternative to ``nperseg``).  Default: the
        power of two nearest below nx / 4.5, i.e. about 8 half-overlapping
        segments.
    detrend : {"linear", "constant"}
        Per-segment detrending.

    Returns
    -------
    PsdEstimate
        ``n`` [cycles/m], ``G`` [m^3].
    """
    z = np.asarray(z, float)
    if z.ndim == 1:
        z = z[:, None]
    if z.ndim != 2:
        raise EroadInputError(f"profile_psd: z must be 1-D or 2-D, got shape {z.shape}")
    if not (isinstance(dx, (int, float, np.floating)) and math.isfinite(dx) and dx > 0):
        raise EroadInputError(f"profile_psd: dx must be a positive number of metres, got {dx!r}")
    if not np.all(np.isfinite(z)):
        raise EroadInputError("profile_psd: the profile contains NaN or inf")
    nx = z.shape[0]
    if segment_length is not None:
        nperseg = int(round(segment_length / dx))
    if nperseg is None:
        nperseg = 2 ** int(math.floor(math.log2(max(nx / 4.5, 8))))
    nperseg = int(nperseg)
    if nperseg < 8 or nperseg > nx:
        raise EroadInputError(
            f"profile_psd: Welch segment of {nperseg} samples does not fit a profile of {nx} samples "
            "(need 8 <= nperseg <= nx)")
    n, G = signal.welch(z, fs=1.0 / dx, window="hann", nperseg=nperseg, noverlap=nperseg // 2,
                        detrend=detrend, scaling="density", axis=0)
    k = (nx - nperseg) // (nperseg // 2) + 1
    return PsdEstimate(n=n, G=G.mean(axis=1), n_averages=float(k * z.shape[1]), nperseg=nperseg, dx=float(dx))


@dataclass
class IsoFit:
    """Result of :func:`fit_iso_psd`.

    Attributes
    ----------
    Gd_n0 : float
        Fitted Gd(n0) [m^3] at n0 = 0.1 cycles/m.
    w : float
        Fitted (or fixed) waviness [-].
    iso_class : str
        ISO 8608 class of ``Gd_n0``.
    band : tuple of float
        Frequency band used [cycles/m].
    n_bins : int
        Number of Welch bins in the band.
    Gd_n0_rel_se, w_se : float
        Approximate standard errors (relative for Gd(n0)) from the Whittle
        Fisher information with the Welch degrees of freedom and Hann bin
        correlation; statistical only, not model error.
    """

    Gd_n0: float
    w: float
    iso_class: str
    band: tuple
    n_bins: int
    Gd_n0_rel_se: float
    w_se: float

    def to_dict(self) -> dict:
        return {"Gd_n0": self.Gd_n0, "w": self.w, "class": self.iso_class, "band": list(self.band),
                "n_bins": self.n_bins, "Gd_n0_rel_se": self.Gd_n0_rel_se, "w_se": self.w_se}


def default_band(est: PsdEstimate) -> tuple[float, float]:
    """Fit band [cycles/m]: the ISO band 0.011-2.83 clipped to >= 10 Welch bins, <= 0.8 Nyquist
    and below where the road's content ends (:func:`content_top`, two bins short of it).

    The lower limit keeps the Hann window's smoothing bias of a n^-2 spectrum
    below ~1.5 % (relative bias ~ w (w+1)/2 * 0.5 (bin/n)^2).  For records too
    short for that (the band would shrink below an octave) it drops to 2 bins.  The content
    limit: a road made of a profile measured every 0.25 m ends at 2 cycles/m; fitted up to
    2.83 cycles/m its empty bins read as a steep spectrum (w 4.06, class D, for the measured
    profile of ../shared/data/iri, whose own fit is w 3.24, class C).
    """
    dn = 1.0 / (est.nperseg * est.dx)
    nyq = 0.5 / est.dx
    hi = min(ISO_BAND[1], 0.8 * nyq)
    top = content_top(est)
    if top < nyq:
        hi = min(hi, top - 2.0 * dn)
    lo = max(ISO_BAND[0], 10.0 * dn)
    if lo > 0.5 * hi:  # short record: accept more smoothing bias rather than no fit
        lo = max(ISO_BAND[0], 2.0 * dn)
    return lo, hi


def fit_iso_psd(psd, band: tuple[float, float] | None = None, w: float | None = None,
                dof: float | None = None) -> IsoFit:
    """Fit Gd(n) = Gd(n0) (n/n0)^-w to a PSD estimate by Whittle maximum likelihood.

    Parameters
    ----------
    psd : PsdEstimate or tuple (n, G)
        Spatial frequency [cycles/m] and one-sided PSD [m^3].
    band : (float, float), optional
        Frequencies [cycles/m] used; default :func:`default_band` (a tuple
        input defaults to the ISO band 0.011-2.83).
    w : float, optional
        Fix the waviness [-] (e.g. 2 for the ISO class definition) and fit only
        the level.
    dof : float, optional
        Degrees of freedom per bin for the standard errors (default from the
        PsdEstimate, else 2).

    Returns
    -------
    IsoFit
    """
    if isinstance(psd, PsdEstimate):
        n, G = psd.n, psd.G
        band = default_band(psd) if band is None else band
        dof = psd.dof if dof is None else dof
    else:
        try:
            n, G = (np.asarray(a, float) for a in psd)
        except (TypeError, ValueError):
            raise EroadInputError("fit_iso_psd: expected a PsdEstimate or a pair (n, G)") from None
        band = ISO_BAND if band is None else band
        dof = 2.0 if dof is None else dof
    lo, hi = (float(b) for b in band)
    if not (0 < lo < hi):
        raise EroadInputError(f"fit_iso_psd: band must satisfy 0 < low < high, got {band!r}")
    sel = (n >= lo) & (n <= hi) & np.isfinite(G)
    n_i, g_i = n[sel], G[sel]
    if n_i.size < 3:
        raise EroadInputError(f"fit_iso_psd: only {n_i.size} PSD bins in the band {lo:g}-{hi:g} cycles/m")
    if np.any(g_i <= 0):
        raise EroadInputError("fit_iso_psd: PSD has zero or negative values in the fit band")
    ln = np.log(n_i / N0)

    def level(wv):
        return float(np.mean(g_i * np.exp(wv * ln)))

    def objective(wv):  # Whittle: M log Gd0(w) - w sum(ln) (+ M, constant)
        return n_i.size * math.log(level(wv)) - wv * float(np.sum(ln))

    if w is None:
        res = optimize.minimize_scalar(objective, bounds=(0.2, 5.8), method="bounded",
                                       options={"xatol": 1e-7})
        w_hat = float(res.x)
    else:
        w_hat = float(w)
    gd0 = level(w_hat)
    m_eff = n_i.size / HANN_ENBW_BINS
    # Fisher information of (log Gd0, w) per bin: dof/2 * [1, -ln; -ln, ln^2]
    if w is None:
        var_ln = float(np.var(ln))
        rel_se = math.sqrt(2.0 / dof / m_eff * (1.0 + np.mean(ln) ** 2 / var_ln))
        w_se = math.sqrt(2.0 / dof / m_eff / var_ln)
    else:
        rel_se = math.sqrt(2.0 / dof / m_eff)
        w_se = 0.0
    return IsoFit(Gd_n0=gd0, w=w_hat, iso_class=class_of(gd0), band=(lo, hi), n_bins=int(n_i.size),
                  Gd_n0_rel_se=rel_se, w_se=w_se)


def identify_class(z, dx: float, band=None) -> str:
    """ISO 8608 class of a profile [m] sampled every ``dx`` [m] (Welch + w = 2 level fit).

    ISO 8608 defines the classes for w = 2, so the level is fitted with w fixed.
    """
    return fit_iso_psd(profile_psd(z, dx), band=band, w=2.0).iso_class


#: how far [decades] a road's PSD must fall below its own power law to count as ending there
#: (:func:`content_top`): a generated road's band edge drops 4-10 decades within one Welch bin;
#: a random road's bins scatter about the power law by a chi-square of tens of degrees of freedom
#: (0.1-0.2 decades sd), so 2 decades is never reached by chance where the road has content
CONTENT_DROP_DECADES = 2.0


def content_top(psd: PsdEstimate, drop_decades: float = CONTENT_DROP_DECADES) -> float:
    """Highest spatial frequency [cycles/m] up to which a road carries content: the last Welch
    bin before the PSD falls ``drop_decades`` below the power law of the octave beneath it,
    else the grid's Nyquist frequency 1/(2 dx).

    Why: a road synthesised over ISO 8608's band ends at nmax (2.83 cycles/m by default), and a
    grid of step dx holds nothing above 1/(2 dx); a vehicle driven over it at v m/s gets no road
    input above ``content_top * v`` Hz, so what its spectra show there is not a response to the
    road.  Local, so that a road of two slopes or one whose level changes along it is read
    right: at each bin a straight line in log-log is fitted (least squares) to the octave below
    it, and the edge is where the median of the next five bins lies ``drop_decades`` below that
    line's extrapolation.

    Parameters
    ----------
    psd : PsdEstimate
        Welch estimate of a profile or of several tracks (:func:`profile_psd`).
    drop_decades : float
        Fall below the local power law that marks the end [decades] (default
        :data:`CONTENT_DROP_DECADES`).

    Returns
    -------
    float
        [cycles/m], at most the Nyquist frequency of the estimate's grid.
    """
    n, G = np.asarray(psd.n, float), np.asarray(psd.G, float)
    nyq = 0.5 / psd.dx
    ok = n > 0
    n, G = n[ok], G[ok]
    ln, lg = np.log10(n), np.log10(np.maximum(G, 1e-300))
    drop = float(drop_decades)
    # least-squares line over the octave [n_i / 2, n_i) from prefix sums: O(1) per bin
    c = [np.concatenate([[0.0], np.cumsum(v)]) for v in (np.ones_like(ln), ln, lg, ln * ln, ln * lg)]
    start = np.searchsorted(n, 0.5 * n, side="left")
    for i in range(n.size - 1):
        a = int(start[i])
        k, sx, sy, sxx, sxy = (float(ci[i] - ci[a]) for ci in c)
        if k < 4:
            continue
        det = k * sxx - sx * sx
        if det <= 0:
            continue
        slope = (k * sxy - sx * sy) / det
        icpt = (sy - slope * sx) / k
        ahead = slice(i, min(i + 5, n.size))
        if np.median(lg[ahead] - (icpt + slope * ln[ahead])) < -drop:
            j = i
            while lg[j] - (icpt + slope * ln[j]) >= -drop and j < n.size - 1:
                j += 1
            return float(n[max(j - 1, 0)])
    return float(nyq)


def surface_content_top(road, n_tracks: int = 5) -> float:
    """:func:`content_top` of a road surface [cycles/m]: the Welch PSD averaged over up to
    ``n_tracks`` grid lines spread evenly across the road (grid lines, so that no interpolation
    between lines removes short waves), or its one track."""
    y = np.asarray(road.y, float)
    cols = np.unique(np.linspace(0, y.size - 1, min(int(n_tracks), y.size)).round().astype(int))
    z = np.asarray(road.z, float)[:, cols]
    return content_top(profile_psd(z, float(road.dx)))


#: how to make a road whose input reaches further up (the project's development road's band):
#: the hint the studies print where a road's input ends inside their bands
SHORT_WAVE_ROAD_HINT = "eroad road generate --nmax 5 --dx 0.05"


def road_input_band(road, speed: float) -> dict:
    """Where a road's input to a vehicle ends: ``road_content_top_cpm``, the highest spatial
    frequency the road carries (:func:`surface_content_top`: a synthesis band's nmax, or the
    grid's Nyquist frequency), and ``road_input_top_hz`` = that times ``speed`` [m/s].  Above it
    a vehicle's responses hold no response to the road (a road made with ISO 8608's default
    band, nmax 2.83 cycles/m, ends at 28.3 Hz at 10 m/s)."""
    n_top = float(surface_content_top(road))
    return {"road_content_top_cpm": n_top, "road_input_top_hz": n_top * float(speed)}
