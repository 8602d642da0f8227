"""Segmentation of a drive into road segments by the local RMS of the response (eq 1).

What it is for: finding where the road changes along a measured drive, and a
first ISO 8608 class per segment, from the suspension displacement alone.  What
it is not: the spectral fit of each segment (:mod:`inverse.sensitivity`).

Method
------
1. Denoise and detrend: zero-phase 4th-order Butterworth band-pass
   [``f_hp``, ``f_lp``] (defaults 3-20 Hz) of each displacement channel; the
   high-pass removes static offsets and slow drift (load transfer, speed) and
   the long-memory body modes (see :func:`segment`), the low-pass sensor noise.
2. Local RMS (eq 1): r(t) = sqrt(mean of x^2 over a centred window of ``window_s``
   seconds), per channel; the series segmented is the channel mean of ln r(t),
   decimated to ``rate_hz``.  In log a change of road level is a change of mean
   of about the same size wherever the level is.
3. Change points: exact optimal partitioning (dynamic programming) into K pieces,
   each at least ``min_len_s`` long, of either the block mean squares of the
   signal by the Gaussian likelihood of a change of scale (default,
   ``cost='variance'``: no smoothing window, so no boundary bias) or the log
   local RMS by least squares (``cost='mean'``, the literal eq 1 route, which
   puts boundaries early next to rough pieces; see :func:`segment`).
4. K, unless given: the K in 1..``k_max`` minimising a BIC-like penalised cost
   (n_eff / n) C_K + ``penalty`` * 2K ln(n_eff), two parameters per piece (its
   level and its start), where n_eff = 2 B_eff T is the number of independent
   samples of a mean square over the record (B_eff the statistical bandwidth
   of the filtered response, T its duration).  Counting every sample instead
   would over-segment, because neighbouring samples of a narrow-band response
   are strongly correlated.
5. Initial class: the segment's response RMS (displacement band-passed to
   ``class_band``, default 0.2-20 Hz, channel RMS averaged in power) against the RMS a linear model predicts for each ISO
   class at the segment's mean speed; since response RMS scales with
   sqrt(Gq_n0), the level Gq = Gq_ref (rms_meas / rms_pred(Gq_ref))^2 follows
   from one prediction and the class is the one nearest in log (the paper only
   ranks segments relative to each other).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.signal import butter, sosfiltfilt

from eroad.errors import EroadInputError
from inverse.spectral import ISO_CLASS_GD0, iso_class


def band_pass(x, fs: float, f_hp: float = 0.2, f_lp: float = 20.0, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth band-pass (denoise and detrend).

    Parameters
    ----------
    x : (N,) array
        Signal [unit].
    fs : float
        Sample rate [Hz].
    f_hp, f_lp : float
        Corner frequencies [Hz]; ``f_hp`` = 0 gives a low-pass after removing
        the linear trend.
    order : int
        Butterworth order (applied forward and backward).

    Returns
    -------
    ndarray, shape (N,)
    """
    x = np.asarray(x, dtype=float)
    if not (0 <= f_hp < f_lp < 0.5 * fs):
        raise EroadInputError(f"band_pass: need 0 <= f_hp < f_lp < fs/2, got {f_hp}, {f_lp}, fs={fs}")
    if f_hp > 0:
        sos = butter(order, [f_hp, f_lp], btype="bandpass", fs=fs, output="sos")
        return sosfiltfilt(sos, x - x.mean())
    t = np.arange(x.size)
    x = x - np.polyval(np.polyfit(t, x, 1), t)
    return sosfiltfilt(butter(order, f_lp, fs=fs, output="sos"), x)


def local_rms(x, fs: float, window_s: float = 1.0) -> np.ndarray:
    """Local RMS in a centred moving window (eq 1 of the paper).

    Parameters
    ----------
    x : (N,) array
        Denoised, detrended signal [unit].
    fs : float
        Sample rate [Hz].
    window_s : float
        Window length [s].

    Returns
    -------
    ndarray, shape (N,)
        [unit]; windows are shortened (mirrored) at the record ends.
    """
    n = max(1, int(round(window_s * fs)))
    return np.sqrt(uniform_filter1d(np.asarray(x, dtype=float) ** 2, n, mode="mirror"))


def _segment_cost_tables(y: np.ndarray):
    c1 = np.concatenate([[0.0], np.cumsum(y)])
    c2 = np.concatenate([[0.0], np.cumsum(y * y)])
    return c1, c2


def _piece_cost(y: np.ndarray, kind: str, weights=None):
    """``cost(i, j)`` of the pieces [i, j) of ``y`` (arrays broadcast).

    kind 'mean': within-piece sum of squared deviations from the piece mean;
    kind 'variance': sum over pieces of m ln(mean of y over the piece), y > 0 (a
    Gaussian scale-change likelihood when y holds mean squares).  A 2-D ``y`` (n, J)
    with ``weights`` (J,) ('variance' only): J series, each with its own level per
    piece, costs summed with the weights (:func:`segment`, boundary bands).
    """
    if np.ndim(y) == 2:
        if kind != "variance":
            raise EroadInputError("several series are partitioned with cost 'variance' only")
        wts = np.ones(y.shape[1]) if weights is None else np.asarray(weights, dtype=float)
        cm = np.vstack([np.zeros(y.shape[1]), np.cumsum(y, axis=0)])

        def cost_multi(i, j):
            m = np.asarray(j - i)
            mm = np.where(m > 0, m, 1)
            mean = (cm[j] - cm[i]) / mm[..., None]
            return m * (np.log(np.maximum(mean, 1e-300)) @ wts)
        return cost_multi
    c1, c2 = _segment_cost_tables(y)
    if kind == "mean":
        def cost(i, j):
            m = j - i
            s = c1[j] - c1[i]
            return c2[j] - c2[i] - s * s / np.where(m > 0, m, 1)
    elif kind == "variance":
        def cost(i, j):
            m = j - i
            return m * np.log(np.maximum((c1[j] - c1[i]) / np.where(m > 0, m, 1), 1e-300))
    else:
        raise EroadInputError(f"unknown partition cost {kind!r}, use 'mean' or 'variance'")
    return cost


def penalised_partition(y, beta: float, min_len: int = 1, kind: str = "variance", weights=None) -> np.ndarray:
    """The partition of ``y`` minimising sum of piece costs + ``beta`` per piece, over every
    number of pieces (PELT: optimal partitioning with pruning, Killick, Fearnhead & Eckley,
    JASA 107 (2012) 1590-1598).

    Exact: the same optimum as :func:`optimal_partition` for every K followed by the choice of
    K, in about linear time instead of K times quadratic. A candidate last change tau is
    dropped at time t once F(tau) + C(tau, t) > F(t) (adding a change never raises the cost of
    these likelihood / least-squares costs); with a shortest piece ``min_len`` the drop only
    takes effect for ends t' >= t + min_len, where the piece [t, t') may follow.

    Returns
    -------
    bounds : ndarray of int
        0 = bounds[0] < ... < bounds[-1] = n.
    """
    y = np.asarray(y, dtype=float)
    n = y.shape[0]
    if n < min_len:
        raise EroadInputError(f"penalised_partition: {n} samples, shortest piece {min_len}")
    cost = _piece_cost(y, kind, weights)
    F = np.full(n + 1, np.inf)
    F[0] = -beta
    last = np.zeros(n + 1, dtype=np.intp)
    cand = np.array([0], dtype=np.intp)          # candidate last changes
    dropped_at = np.array([n + 1], dtype=np.intp)  # time at which each was found prunable
    for t in range(min_len, n + 1):
        ok = (cand <= t - min_len) & (dropped_at > t - min_len)
        if not ok.any():
            continue
        c = cand[ok]
        tot = F[c] + cost(c, t) + beta
        a = int(np.argmin(tot))
        F[t], last[t] = tot[a], c[a]
        # prune: F(tau) + C(tau, t) > F(t), effective from t + min_len on
        valid = cand <= t - min_len
        worse = np.zeros(cand.size, bool)
        worse[valid] = F[cand[valid]] + cost(cand[valid], t) > F[t]
        newly = worse & (dropped_at > n)
        dropped_at[newly] = t
        keep = dropped_at > t - min_len      # still usable for some end t' >= t + 1
        cand, dropped_at = cand[keep], dropped_at[keep]
        cand = np.append(cand, t)
        dropped_at = np.append(dropped_at, n + 1)
    if not np.isfinite(F[n]):
        raise EroadInputError(f"penalised_partition: no partition of {n} samples into pieces of >= {min_len}")
    bounds = [n]
    while bounds[-1] > 0:
        bounds.append(int(last[bounds[-1]]))
    return np.array(bounds[::-1])


def _partition_all(y: np.ndarray, k_max: int, min_len: int, kind: str = "mean", weights=None):
    """Dynamic programme for 1..k_max pieces; returns (back table, cost at n per k)
    (costs of :func:`_piece_cost`)."""
    n = y.shape[0]
    cost = _piece_cost(y, kind, weights)

    j_all = np.arange(n + 1)
    prev = np.full(n + 1, np.inf)
    prev[min_len:] = cost(np.zeros(n + 1 - min_len, dtype=np.intp), j_all[min_len:])
    back = np.zeros((k_max, n + 1), dtype=np.intp)
    final = [float(prev[n])]
    for piece in range(1, k_max):
        cur = np.full(n + 1, np.inf)
        for jj in range((piece + 1) * min_len, n + 1):
            i = np.arange(piece * min_len, jj - min_len + 1)
            tot = prev[i] + cost(i, jj)
            a = int(np.argmin(tot))
            cur[jj] = tot[a]
            back[piece, jj] = i[a]
        prev = cur
        final.append(float(prev[n]))
    return back, np.array(final)


def _backtrack(back: np.ndarray, k: int, n: int) -> np.ndarray:
    bounds = [n]
    for piece in range(k - 1, 0, -1):
        bounds.append(int(back[piece, bounds[-1]]))
    bounds.append(0)
    return np.array(bounds[::-1])


def optimal_partition(y, k: int, min_len: int = 1, kind: str = "mean", weights=None):
    """Exact optimal partition of a series into k pieces (dynamic programming).

    Parameters
    ----------
    y : (n,) array
        Series to segment (positive for ``kind='variance'``).
    k : int
        Number of pieces.
    min_len : int
        Smallest piece length [samples].
    kind : {'mean', 'variance'}
        'mean': minimise the within-piece sum of squared deviations from the
        piece mean (least squares on e.g. log local RMS); 'variance': minimise
        sum of m_i ln(mean_i y), the Gaussian likelihood of a change of scale
        when y are mean squares.

    Returns
    -------
    bounds : ndarray of int, shape (k + 1,)
        Piece boundaries, 0 = bounds[0] < ... < bounds[k] = n.
    cost : float
        The minimised cost.
    """
    y = np.asarray(y, dtype=float)
    n = y.shape[0]
    if k < 1 or k * min_len > n:
        raise EroadInputError(f"optimal_partition: cannot make {k} pieces of >= {min_len} from {n} samples")
    back, final = _partition_all(y, k, min_len, kind, weights)
    return _backtrack(back, k, n), float(final[k - 1])


@dataclass
class SegmentationResult:
    """Segments of a drive.

    Attributes
    ----------
    t_bounds : ndarray, shape (K + 1,)
        Segment boundaries [s] (first = record start, last = record end).
    classes : list of str
        Initial ISO class per segment ('' when no predictor was given).
    Gq_init : ndarray, shape (K,)
        Initial Gd(n0) [m^3] per segment from the RMS comparison (nan without a
        predictor).
    rms : ndarray, shape (K,)
        Measured displacement RMS per segment in ``class_band`` [m].
    speed : ndarray, shape (K,)
        Mean speed per segment [m/s].
    time, lrms : ndarray
        Decimated time [s] and local RMS [m] (channel geometric mean) series, in
        the boundary band ``band``.
    criterion : dict
        K -> penalised cost (when K was chosen), plus 'n_eff' and 'B_eff_hz'.
    band : tuple
        Band-pass [Hz] of ``lrms`` (and of the partitioned signal unless
        ``boundary_source`` names other series).
    boundary_source : str
        What the boundaries were located on (the series partitioned), in words.
    resolution : dict
        What the criterion needs to say which pieces it cannot resolve
        (:func:`unresolved_level`): n_eff, duration_s, penalty, n_par, series (how many
        series were partitioned; the bound is derived for one), k_given (K was given, not
        chosen by the criterion).
    """

    t_bounds: np.ndarray
    classes: list
    Gq_init: np.ndarray
    rms: np.ndarray
    speed: np.ndarray
    time: np.ndarray
    lrms: np.ndarray
    criterion: dict = field(default_factory=dict)
    band: tuple = (3.0, 20.0)
    boundary_source: str = "suspension displacement in 3-20 Hz"
    resolution: dict = field(default_factory=dict)

    @property
    def n_segments(self) -> int:
        return self.t_bounds.size - 1

    @property
    def proportions(self) -> np.ndarray:
        """Share of the record's duration per segment [-]."""
        d = np.diff(self.t_bounds)
        return d / d.sum()


def effective_bandwidth(x, fs: float) -> float:
    """Statistical bandwidth (int S)^2 / int S^2 of a signal [Hz].

    A mean square over T seconds of a Gaussian signal of this bandwidth is close
    to a chi-square variable with 2 B T degrees of freedom.

    Parameters
    ----------
    x : (N,) array
    fs : float
        Sample rate [Hz].

    Returns
    -------
    float
        B_eff [Hz].
    """
    from scipy.signal import welch

    nper = min(np.asarray(x).size, 1 << int(math.log2(max(8 * fs, 16))))
    f, p = welch(np.asarray(x, dtype=float), fs, nperseg=nper)
    df = f[1] - f[0]
    return float((p.sum() * df) ** 2 / max(np.sum(p ** 2) * df, 1e-300))


#: the largest K tried on a drive up to K_MAX_SHORT * K_SPAN_S long (the 30 s drives of the
#: paper and the benchmarks: unchanged since the method was calibrated)
K_MAX_SHORT = 8
#: on a longer drive the largest K grows by one per K_SPAN_S of record [s]: a road changes
#: surface every 100-200 m, 7-20 s at 10-15 m/s, so the cap stays above what the BIC picks
K_SPAN_S = 5.0


#: bands [Hz] of the axle accelerations whose powers locate the boundaries when they are
#: given (:func:`segment`, ``boundary_channels``): an octave each from 6 Hz, above the body
#: modes as the displacement band is, and reaching the wheelbase-scale and shorter waves
#: (0.5-5 cycles/m at 10 m/s) where a change of waviness shows
BOUNDARY_BANDS = ((6.0, 12.0), (12.0, 24.0), (24.0, 48.0))
#: shortest road waves [cycles/m] taken to reach the response: a band of ``boundary_channels``
#: is cut at this times the drive's 5th-percentile speed. Above it the road's own upper edge
#: (nmax, 5 cycles/m in the synthetic roads) or the tyre's footprint (0.2-0.3 m) takes the
#: road out, so the band's power no longer scales as v^(w-1) and the speed correction fails:
#: measured on the quarter truck, one road driven 6 -> 14 m/s, the 24-48 Hz band uncut split it
#: in 3 of 6 seeds at w = 2 and 6 of 6 at w = 2.5 (none with the road reaching 10 cycles/m)
BOUNDARY_NMAX = 5.0
#: a band cut to less than this ratio of its edges is left out
BAND_MIN_RATIO = 1.25


def segment(time, channels, speed, *, k=None, k_max: int | None = None, window_s: float = 1.0,
            min_len_s: float = 0.5, rate_hz: float = 20.0, penalty: float = 1.0,
            cost: str = "variance", f_hp: float = 3.0, f_lp: float = 20.0,
            class_band=(0.2, 20.0), predict_rms=None, w_init: float = 2.0,
            speed_exponent: float | None = None, boundary_channels=None,
            boundary_bands=BOUNDARY_BANDS) -> SegmentationResult:
    """Segment a drive by the local RMS of its suspension displacement.

    Parameters
    ----------
    time : (N,) array
        Uniform time [s].
    channels : (N,) array or mapping of name -> (N,) array
        Suspension displacement(s) [m] (e.g. ``susp_disp_3L`` and ``susp_disp_3R``).
    speed : float or (N,) array
        Vehicle speed [m/s].
    k : int, optional
        Number of segments; chosen by the penalised cost when absent.
    k_max : int, optional
        Largest K tried; default :data:`K_MAX_SHORT` (8), one more per :data:`K_SPAN_S` s of
        a longer drive. Above 8 the K is found by :func:`penalised_partition` (the same
        optimum, in about linear time).
    window_s : float
        Local RMS window [s] (eq 1; the figure, and the series of ``cost='mean'``).
    min_len_s : float
        Shortest segment [s].
    rate_hz : float
        Rate of the series that is partitioned [Hz] (sets the boundary resolution).
    penalty : float
        Multiplier of the BIC penalty (1 = BIC).
    cost : {'variance', 'mean'}
        'variance' (default): partition the block mean squares of the signal
        (blocks of 1 / rate_hz s, channels averaged) by the Gaussian likelihood
        of a change of scale, sum m_i ln(mean square_i); no smoothing window,
        so no boundary bias.  'mean': least squares on the log local RMS (the
        literal eq 1 route); a centred window puts a boundary between a quiet
        and a rough piece early, because ln of a window's mean power follows the
        rough part (measured: 0.3 s early for a 1 s window and a 16x power step).
    f_hp, f_lp : float
        Band-pass corners [Hz] of the signal whose local RMS is partitioned (see
        :func:`band_pass`).  The default 3-20 Hz lies above the body modes: a
        lightly damped body mode keeps ringing after the vehicle leaves a rough
        piece, which puts rough-to-smooth boundaries late (quarter truck,
        factor 16 in power: +0.6 s with 0.2-20 Hz, +0.2 s with 3-20 Hz), and the
        wider statistical bandwidth gives more independent samples (a factor 4
        level change was found in 20 of 20 records with 3-20 Hz, 4 of 20 with
        0.2-20 Hz).
    class_band : (float, float)
        Band-pass corners [Hz] of the signal whose segment RMS gives the initial
        class; the default 0.2-20 Hz keeps the body modes, whose road wavelengths
        lie near n0 = 0.1 cycles/m, so an error in the assumed waviness matters
        little.
    predict_rms : callable, optional
        ``predict_rms(Gq_n0 [m^3], w [-], speed [m/s]) -> rms [m]``: the RMS, in
        ``class_band``, of the same displacement signal (power-averaged over
        the given channels) that a linear vehicle model predicts for a road of
        that spectrum, e.g. :meth:`inverse.quarter.QuarterTruck.predict_rms`
        with ``f_band=class_band``.  Gives the initial class and level.
    w_init : float
        Waviness assumed in the class prediction [-].
    speed_exponent : float, optional
        The mean squares partitioned are divided by (v(t) / mean v) ** e, default
        e = ``w_init`` - 1.  Why: a road with Gd(n) ~ n^-w driven at speed v
        puts the temporal PSD Gd(n0) n0^w f^-w v^(w-1) into the wheel, so any
        linear response's power in a fixed frequency band grows as v^(w-1)
        with the road unchanged; a speed change inside one segment would look
        like a road change (a factor 2 in speed is a factor 2 in power for
        w = 2, half an ISO class).  With the true w in 1.5-2.5 and e = 1 the
        residual is v^(+-0.5).  0 switches the correction off.
    boundary_channels : mapping of name -> (N,) array, optional
        Signals whose band powers locate the boundaries instead of ``channels`` (which
        then give the initial class, the local RMS of Figure 6 and nothing else), e.g.
        ``axle_acc_3L`` and ``axle_acc_3R``.  Each channel in each band of
        ``boundary_bands`` is its own series, with its own level per piece: the cost is
        the sum over series of (n_eff_j / n) times its scale-change likelihood, the
        penalty (J + 1) K ln(sum_j n_eff_j) for J series (a level per series and a
        start per piece; J = 1 is the single-series criterion below).  Why: the
        displacement's 3-20 Hz power is dominated by its low end (about 0.3 cycles/m at
        10 m/s), so two road pieces whose spectra cross there -- a change of waviness at
        an unchanged level near 0.3 cycles/m -- look alike to it; separate octave bands
        of the axle acceleration see such a change as opposite moves.  Measured on 100
        blind `null` drives of our truck (docs/inverse.md, section 1): interior boundaries
        found within 0.5 s 218 -> 230 of 292, but no gain on the independent truck and
        no road-estimate gain beyond noise, so the inversion does not use it by default
        (``InversionConfig.segment_on``).  Needs ``cost='variance'``.
    boundary_bands : sequence of (float, float)
        Bands [Hz] of ``boundary_channels`` (default :data:`BOUNDARY_BANDS`), each cut at
        0.45 fs and at :data:`BOUNDARY_NMAX` cycles/m times the drive's 5th-percentile
        speed; a band left narrower than :data:`BAND_MIN_RATIO` of its lower edge is
        left out.

    Returns
    -------
    SegmentationResult

    Notes
    -----
    The penalised cost is (n_eff / n) C_K + penalty * 2 K ln(n_eff), C_K the
    partition cost ('variance': the likelihood term; 'mean': n ln(SSE_K / n)),
    n the series length and n_eff = 2 B_eff T the number of independent
    samples of a mean square over the record (B_eff from
    :func:`effective_bandwidth` of the filtered signal, T the duration).
    """
    t = np.asarray(time, dtype=float)
    if isinstance(channels, dict):
        sigs = [np.asarray(v, dtype=float) for v in channels.values()]
    else:
        sigs = [np.asarray(channels, dtype=float)]
    if not sigs or any(s.shape != t.shape for s in sigs):
        raise EroadInputError("segment: every channel must have the shape of time")
    fs = 1.0 / float(np.mean(np.diff(t)))
    v = np.broadcast_to(np.asarray(speed, dtype=float), t.shape)
    filt = [band_pass(s, fs, f_hp, f_lp) for s in sigs]
    logr = np.mean([np.log(np.maximum(local_rms(x, fs, window_s), 1e-300)) for x in filt], axis=0)
    step = max(1, int(round(fs / rate_hz)))
    nb = t.size // step
    e = (w_init - 1.0) if speed_exponent is None else float(speed_exponent)
    vnorm = (np.maximum(v, 1e-3) / max(float(np.mean(v)), 1e-3)) ** e
    duration = t[-1] - t[0] + 1.0 / fs
    weights = None
    series_label = f"{', '.join(channels) if isinstance(channels, dict) else 'the signal'} in {f_hp:g}-{f_lp:g} Hz"
    if boundary_channels is not None:
        if cost != "variance":
            raise EroadInputError("segment: boundary_channels need cost 'variance'")
        bsigs = [np.asarray(x, dtype=float) for x in boundary_channels.values()]
        if not bsigs or any(x.shape != t.shape for x in bsigs):
            raise EroadInputError("segment: every boundary channel must have the shape of time")
        # the top of every band stays below the shortest waves that still reach the response
        # at the drive's slow end (BOUNDARY_NMAX): above them a band's power stops scaling as
        # v^(w-1), and a speed change would read as a road change
        f_top = min(0.45 * fs, BOUNDARY_NMAX * float(np.percentile(v, 5)))
        bands = [(float(a), min(float(b), f_top)) for a, b in boundary_bands
                 if min(float(b), f_top) >= BAND_MIN_RATIO * float(a)]
        if not bands:
            raise EroadInputError(f"segment: no boundary band below {f_top:g} Hz (0.45 fs and "
                                  f"{BOUNDARY_NMAX:g} cycles/m at the drive's slow end)")
        cols, n_effs = [], []
        for x in bsigs:
            for a, b in bands:
                xf = band_pass(x, fs, a, b)
                cols.append(((xf ** 2) / vnorm)[: nb * step].reshape(nb, step).mean(axis=1))
                n_effs.append(max(2.0 * effective_bandwidth(xf, fs) * duration, 2.0))
        y = np.column_stack(cols)
        n_effs = np.asarray(n_effs)
        weights = n_effs / nb
        series_label = (f"{', '.join(boundary_channels)} in "
                        + ", ".join(f"{a:g}-{b:g}" for a, b in bands) + " Hz")
    elif cost == "variance":
        sq = np.mean([x ** 2 for x in filt], axis=0) / vnorm
        y = sq[: nb * step].reshape(nb, step).mean(axis=1)
    elif cost == "mean":
        y = (logr - 0.5 * np.log(vnorm))[: nb * step].reshape(nb, step).mean(axis=1)
    else:
        raise EroadInputError(f"segment: unknown cost {cost!r}, use 'variance' or 'mean'")
    n = y.shape[0]
    min_len = max(1, int(round(min_len_s * fs / step)))
    if weights is None:
        # one series: the cost is scaled by n_eff / n below, two parameters per piece
        b_eff = float(np.mean([effective_bandwidth(x, fs) for x in filt]))
        n_eff = max(2.0 * b_eff * duration, 2.0)
        scale, n_par = n_eff / n, 2
    else:
        # J series: their weights n_eff_j / n are in the cost already, J + 1 parameters per piece
        n_eff = float(n_effs.sum())
        b_eff = n_eff / (2.0 * duration)
        scale, n_par = 1.0, y.shape[1] + 1
    criterion = {"n_eff": n_eff, "B_eff_hz": b_eff}
    if k is None:
        cap = k_max if k_max is not None else max(K_MAX_SHORT, math.ceil(duration / K_SPAN_S))
        kk_max = max(1, min(int(cap), n // min_len))
        bounds = None
        if kk_max > K_MAX_SHORT and cost == "variance":
            # a long drive: the penalised optimum over every K directly (exact, about linear
            # time); the table over K = 1..kk_max would cost kk_max quadratic passes
            beta = penalty * n_par * math.log(n_eff) / scale
            bounds = penalised_partition(y, beta, min_len, cost, weights)
            kb = bounds.size - 1
            if kb <= kk_max:
                c_k = float(np.sum(_piece_cost(y, cost, weights)(bounds[:-1], bounds[1:])))
                criterion.update({kb: scale * c_k + penalty * n_par * kb * math.log(n_eff)})
            else:
                bounds = None                      # more pieces than the cap: the capped table
        if bounds is None:
            back, final = _partition_all(y, kk_max, min_len, cost, weights)
            if cost == "mean":
                final = n * np.log(np.maximum(final, 1e-300) / n)
            crit = [scale * c + penalty * n_par * (i + 1) * math.log(n_eff) for i, c in enumerate(final)]
            criterion.update({i + 1: float(c) for i, c in enumerate(crit)})
            bounds = _backtrack(back, int(np.argmin(crit)) + 1, n)
    else:
        if int(k) * min_len > n:
            raise EroadInputError(f"--segments {int(k)}: a drive of {duration:.1f} s holds at most "
                                  f"{n // min_len} segments of at least {min_len_s:g} s")
        bounds, _ = optimal_partition(y, int(k), min_len, cost, weights)
    # block boundaries -> times (a block b covers [t[b*step], t[(b+1)*step]) )
    tb = np.array([t[0]] + [t[b * step] for b in bounds[1:-1]] + [t[-1] + 1.0 / fs])
    K = tb.size - 1
    filt_c = [band_pass(s, fs, class_band[0], class_band[1]) for s in sigs]
    rms = np.empty(K)
    vmean = np.empty(K)
    for i in range(K):
        sel = (t >= tb[i]) & (t < tb[i + 1])
        rms[i] = math.sqrt(np.mean([np.mean(x[sel] ** 2) for x in filt_c]))
        vmean[i] = float(np.mean(v[sel]))
    classes, Gq = [], np.full(K, np.nan)
    if predict_rms is not None:
        for i in range(K):
            Gq[i], cls = classify(rms[i], vmean[i], predict_rms, w_init)
            classes.append(cls)
    else:
        classes = [""] * K
    resolution = {"n_eff": float(n_eff), "duration_s": float(duration), "penalty": float(penalty), "n_par": n_par,
                  "series": 1 if weights is None else int(y.shape[1]), "k_given": k is not None}
    return SegmentationResult(tb, classes, Gq, rms, vmean, t[::step], np.exp(logr[::step]), criterion,
                              (f_hp, f_lp), series_label, resolution)


#: the shortest piece whose level the inversion's accuracy targets score (issue 14: segments >= 3 s)
#: and for which each segment reports the level change the segmentation cannot resolve [s]
UNRESOLVED_PIECE_S = 3.0


def unresolved_level(piece_s: float, segment_s: float, resolution: dict) -> tuple | None:
    """The range of ln level a piece of ``piece_s`` seconds inside a segment of ``segment_s``
    seconds can have, against the segment's mean level, and still not be split off by the
    penalised criterion of :func:`segment` (expected values).

    Derivation (cost 'variance', one series): splitting a piece of m of the segment's s blocks
    whose mean square is r times the rest's lowers the partition cost by
    s ln(1 + f (r - 1)) - m ln r (f = m / s; the rest keeps its mean), scaled by n_eff / n in
    the criterion; a piece inside the segment adds two pieces, i.e. 2 * penalty * n_par *
    ln(n_eff). The piece stays unresolved while the first is below the second
    (:func:`unresolved_ratio_to_rest` solves for the ln r where they are equal). Against the
    segment's mean square, which a fit of the whole segment matches, the piece then lies
    ln r - ln(1 + f (r - 1)) away: the returned (lo, hi), lo < 0 < hi (-inf / inf where no
    ratio is enough). For a linear response at one waviness and speed a response power ratio is
    a road level ratio, so (lo, hi) bound how far the level of an unresolved stretch can lie
    from its segment's fitted level.

    Returns None where it does not apply: the segment is not longer than the piece, the number
    of segments was given (no criterion chose it), or several series were partitioned
    (``segment_on`` 'axle_acc': each series sees the change differently).
    """
    r = unresolved_ratio_to_rest(piece_s, segment_s, resolution)
    if r is None:
        return None
    f = piece_s / segment_s

    def to_segment(x):
        return x if not math.isfinite(x) else x - math.log1p(f * math.expm1(x))
    return tuple(float(to_segment(x)) for x in r)


def unresolved_ratio_to_rest(piece_s: float, segment_s: float, resolution: dict) -> tuple | None:
    """(lo, hi): the ln power ratios of a piece against the REST of its segment at which the
    criterion's gain from splitting it off equals the penalty (:func:`unresolved_level`)."""
    from scipy.optimize import brentq

    if (not resolution or resolution.get("series", 1) != 1 or resolution.get("k_given")
            or segment_s <= piece_s):
        return None
    n_eff, dur = float(resolution["n_eff"]), float(resolution["duration_s"])
    s_eff, m_eff, f = n_eff * segment_s / dur, n_eff * piece_s / dur, piece_s / segment_s
    pen = 2.0 * float(resolution["penalty"]) * float(resolution["n_par"]) * math.log(n_eff)

    def excess(x):     # criterion gain of splitting the piece off, less the penalty
        return s_eff * math.log1p(f * math.expm1(x)) - m_eff * x - pen

    lim = 30.0
    hi = brentq(excess, 0.0, lim) if excess(lim) > 0 else math.inf
    lo = brentq(excess, -lim, 0.0) if excess(-lim) > 0 else -math.inf
    return float(lo), float(hi)


def classify(rms: float, speed: float, predict_rms, w: float = 2.0, ref_class: str = "C"):
    """Road level and ISO class from a measured response RMS.

    Parameters
    ----------
    rms : float
        Measured response RMS [m].
    speed : float
        Mean speed [m/s].
    predict_rms : callable
        ``predict_rms(Gq_n0, w, speed) -> rms``, proportional to sqrt(Gq_n0).
    w : float
        Waviness assumed [-].
    ref_class : str
        Class whose level is used for the one prediction needed.

    Returns
    -------
    Gq : float
        Level [m^3] that reproduces ``rms``.
    cls : str
        Class nearest in log, i.e. the one whose bounds contain ``Gq``.
    """
    g_ref = ISO_CLASS_GD0[ref_class]
    r_ref = float(predict_rms(g_ref, w, speed))
    if not (r_ref > 0 and rms > 0):
        raise EroadInputError("classify: predicted and measured RMS must be positive")
    Gq = g_ref * (rms / r_ref) ** 2
    return Gq, iso_class(Gq)


def plot_segmentation(result: SegmentationResult, time, signal, path, title: str = "",
                      truth_bounds=None):
    """Figure 6: the record, its local RMS, the segment boundaries and classes.

    Parameters
    ----------
    result : SegmentationResult
    time : (N,) array
        [s].
    signal : (N,) array
        Suspension displacement to show [m] (e.g. axle 3 left).
    path : str or Path, or a list of them
        Output file(s) (.png or .pdf); the figure is drawn once and saved to each.
        Returns the first.
    title : str
    truth_bounds : array, optional
        Known boundaries [s] (synthetic data) drawn dashed.

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6.2), sharex=True)
    a1.plot(time, 1e3 * np.asarray(signal), lw=0.5, color="0.3")
    a1.set_ylabel("suspension displacement [mm]")
    a2.semilogy(result.time, 1e3 * result.lrms, color="C0", lw=1.0, label="local RMS (eq 1)")
    for i in range(result.n_segments):
        a, b = result.t_bounds[i], result.t_bounds[i + 1]
        sel = (result.time >= a) & (result.time < b)
        level = np.sqrt(np.mean(result.lrms[sel] ** 2)) if np.any(sel) else np.nan
        a2.hlines(1e3 * level, a, b, color="C3", lw=2, label="segment RMS" if i == 0 else None)
        # numbered as Table 1's 'segment' column (the fitted class is Table 1's)
        a1.text(0.5 * (a + b), 1.0, f"{i + 1}", transform=a1.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=9, fontweight="bold")
    for ax in (a1, a2):
        for j, tb in enumerate(result.t_bounds[1:-1]):
            ax.axvline(tb, color="C3", lw=1, label=f"boundary found (speed-corrected power: "
                       f"{result.boundary_source})" if (ax is a2 and j == 0) else None)
        if truth_bounds is not None:
            for j, tb in enumerate(np.asarray(truth_bounds)[1:-1]):
                ax.axvline(tb, color="k", lw=0.8, ls="--", label="true boundary" if (ax is a2 and j == 0) else None)
    a2.set_ylabel(f"local RMS, {result.band[0]:g}-{result.band[1]:g} Hz [mm]")
    # plain numbers on the log axis ("0.3", "2"; the default gave "2 x 10^0" and LogFormatter
    # "3e-01"), on the ticks matplotlib's LogFormatter chooses to label
    class PlainLog(matplotlib.ticker.LogFormatter):
        def _num_to_string(self, x, vmin, vmax):
            return f"{x:.3g}"

    a2.yaxis.set_major_formatter(PlainLog())
    a2.yaxis.set_minor_formatter(PlainLog(labelOnlyBase=False))
    a2.set_xlabel("time [s]")
    # below the axes: inside, any corner can sit on the local RMS of some drive (the
    # reference run's last seconds were hidden under it)
    a2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.28), ncol=2, fontsize=8, frameon=False)
    if title:
        fig.suptitle(title)
    fig.text(0.01, 0.005, "Numbers above the record: segments as numbered in Table 1 (its "
             "'segment' column), where each segment's fitted class and parameters are.",
             fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    from eroad.figures import save_figure

    return save_figure(fig, path, dpi=150)[0]
