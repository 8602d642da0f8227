"""Is a gap's high band fixed in Hz or in cycles/m?  The speed test of the two low-passes.

What it is for: a sensor low-pass (``sensor``: a filter of the recorded channels) and a
spatial low-pass of the road input (``tyre_enveloping``, or a road whose short waves fall off
faster than the fitted road's) both take power off the top of the axle spectrum, act on the
axle and the body alike (every channel ratio cancels them) and fit the held-out gap about
equally well.  What tells them apart is speed: the sensor's roll-off stays at its cutoff in
Hz whatever the speed, a road's or a tyre's moves with speed (it sits at a spatial frequency
n, so at f = n v).  What it is not: a test of the vehicle (a vehicle difference is fixed in
Hz too; the transmissibility separates that).

The statistic
-------------
A record and a reference record (the nominal model on the fitted road, same speed profile,
another road phase) are cut into windows of ``WINDOW_S`` (hop ``HOP_S``); in each window the
channel-mean Welch PSD of the axle accelerations gives ln P(f) and the window's mean speed v.
The white noise floor of each record (the median over windows of its PSD at 0.8-0.95 of the
Nyquist frequency, an upper bound) is taken off and only cells at least ``SNR`` times above
both floors are kept: a floor is fixed in Hz and would read as a sensor.  With D = ln P_rec -
ln P_ref at fixed spatial frequency n (interpolated at f = n v in each window), the statistic
is the pooled slope of D against ln v, within road segments (both centred per segment and n),
over cells with f in [``F_LO``, ``F_HI``]:

* a road or tyre difference: D depends on n alone, slope 0 (a correct model against itself:
  0 with road-phase scatter);
* a 2nd-order Butterworth low-pass at fc: D = -ln(1 + (f/fc)^4), slope -4 x / (1 + x) with
  x = (f/fc)^4 at f = n v: negative, down to -4 well above the cutoff.

The record the verdict reads (``summary.json`` ``signature_hz``): the statistic of the
measurement against each of the nominal model's records on the signature's road phases
(mean), of each nominal record against the others (the correct model's scatter), and of each
low-pass candidate's record against the nominal records of the other phases.
"""
from __future__ import annotations

import math
from typing import Mapping, Sequence

import numpy as np
from scipy import signal

#: window length and hop [s]: short enough that the speed is near constant in one, long
#: enough for a 2 Hz resolution with 7 Welch averages
WINDOW_S = 2.0
HOP_S = 1.0
#: Welch segment [s] inside a window (2 Hz bins)
NPERSEG_S = 0.5
#: analysed band [Hz]: above the wheel hop (about 10-12 Hz, where the axle's own resonance
#: dominates) and below the anti-aliasing and noise region of a 200 Hz record; a sensor
#: cutoff above F_HI takes nothing the test can see
F_LO, F_HI = 20.0, 55.0
#: cells kept: power above SNR times the noise floor in both records
SNR = 3.0
#: spatial-frequency grid points over the analysed band
N_BINS = 24
#: least number of windows of one segment for it to enter the slope
MIN_WINDOWS = 3
#: effects the test is for
EFFECTS = ("sensor", "tyre_enveloping")
#: channels it reads
CHANNEL_PREFIX = "axle_acc_"
STATISTIC = "hz_fixed_slope"
MEASURE = ("pooled within-segment slope, against ln speed, of the record-minus-nominal log "
           "power of the axle accelerations at fixed spatial frequency, f = n v in "
           f"{F_LO:g}-{F_HI:g} Hz, noise floors taken off (0: fixed in cycles/m, as a road or "
           "a tyre; negative: a roll-off fixed in Hz, as a sensor low-pass)")


def window_log_psd(channels: Mapping[str, np.ndarray], speed, fs: float, names: Sequence[str],
                   window_s: float = WINDOW_S, hop_s: float = HOP_S, nperseg_s: float = NPERSEG_S):
    """Per window: the channel-mean Welch PSD (not logged), the window's mean speed and centre
    time.  Returns ``(f, P, v, t)`` with ``P`` of shape (windows, frequencies)."""
    x = np.array([np.asarray(channels[c], float) for c in names])
    n = x.shape[1]
    L, H = int(round(window_s * fs)), int(round(hop_s * fs))
    nper = min(int(round(nperseg_s * fs)), L)
    starts = list(range(0, n - L + 1, H))
    speed = np.asarray(speed, float)
    P, v, t = [], [], []
    f = None
    for s in starts:
        f, p = signal.welch(x[:, s:s + L], fs=fs, nperseg=nper, axis=-1)
        P.append(p.mean(axis=0))
        v.append(float(np.mean(speed[s:s + L])))
        t.append((s + 0.5 * L) / fs)
    if not starts:
        return np.zeros(0), np.zeros((0, 0)), np.zeros(0), np.zeros(0)
    return f, np.array(P), np.array(v), np.array(t)


def noise_floor(f, P, fs: float) -> float:
    """White floor of a record's window PSDs: median over windows of the mean PSD at 0.8-0.95
    of the Nyquist frequency (an upper bound: signal left there counts as floor)."""
    top = (f >= 0.8 * fs / 2) & (f <= 0.95 * fs / 2)
    if not top.any() or P.size == 0:
        return 0.0
    return float(np.median(P[:, top].mean(axis=1)))


def _windows(channels: Mapping[str, np.ndarray], speed, fs: float, names: Sequence[str]):
    """A record's window PSDs, speeds, centre times and noise floor: what :func:`_slope` reads."""
    f, P, v, t = window_log_psd(channels, speed, fs, names)
    return f, P, v, t, noise_floor(f, P, fs)


def speed_slope(rec: Mapping[str, np.ndarray], ref: Mapping[str, np.ndarray], fs: float, speed,
                bounds, names: Sequence[str] | None = None, f_lo: float = F_LO,
                f_hi: float = F_HI, snr: float = SNR, n_bins: int = N_BINS) -> tuple[float, int]:
    """The statistic of ``rec`` against ``ref`` (both recorded at ``speed``; ``bounds`` the road
    segment edges in record time [s]).  Returns ``(slope, cells)``; slope NaN where no segment
    holds ``MIN_WINDOWS`` windows with usable cells or the speed does not vary."""
    names = list(names) if names is not None else [c for c in rec if c.startswith(CHANNEL_PREFIX)]
    if not names:
        return float("nan"), 0
    return _slope(_windows(rec, speed, fs, names), _windows(ref, speed, fs, names), fs, bounds,
                  f_lo, f_hi, snr, n_bins)


def _slope(wa, wb, fs: float, bounds, f_lo: float = F_LO, f_hi: float = F_HI, snr: float = SNR,
           n_bins: int = N_BINS) -> tuple[float, int]:
    """:func:`speed_slope` on two records' :func:`_windows`."""
    f, A, v, t, na = wa
    B, nb = wb[1], wb[4]
    f_hi = min(f_hi, 0.35 * fs)
    if f_hi <= f_lo or A.shape[0] < MIN_WINDOWS or np.ptp(v) <= 0:
        return float("nan"), 0
    pa, pb = A - na, B - nb
    ok = (pa > snr * na) & (pb > snr * nb) & (pa > 0) & (pb > 0)
    D = np.full(A.shape, np.nan)
    D[ok] = np.log(pa[ok]) - np.log(pb[ok])
    lnf = np.log(np.maximum(f, 1e-12))
    grid = np.exp(np.linspace(math.log(f_lo / v.max()), math.log(f_hi / max(v.min(), 1e-6)), n_bins))
    seg = np.searchsorted(np.asarray(bounds, float), t, side="right") - 1
    xs, ys = [], []
    for k in np.unique(seg):
        idx = np.flatnonzero(seg == k)
        if idx.size < MIN_WINDOWS:
            continue
        for nn in grid:
            fq = nn * v[idx]
            inb = (fq >= f_lo) & (fq <= f_hi)
            if inb.sum() < MIN_WINDOWS:
                continue
            d = np.array([np.interp(math.log(q), lnf, D[i]) for q, i in zip(fq[inb], idx[inb])])
            lv = np.log(v[idx[inb]])
            good = np.isfinite(d)
            if good.sum() < MIN_WINDOWS or np.ptp(lv[good]) <= 0:
                continue
            d, lv = d[good], lv[good]
            xs.append(lv - lv.mean())
            ys.append(d - d.mean())
    if not xs:
        return float("nan"), 0
    x, y = np.concatenate(xs), np.concatenate(ys)
    sxx = float(np.sum(x * x))
    if sxx <= 0:
        return float("nan"), 0
    return float(np.sum(x * y) / sxx), int(x.size)


def _mean_finite(vals) -> float | None:
    a = np.asarray([v for v in vals if v is not None and math.isfinite(v)], float)
    return float(a.mean()) if a.size else None


def hz_record(measured: Mapping[str, np.ndarray], nominal: Sequence[Mapping[str, np.ndarray]],
              models: Mapping[str, Sequence[Mapping[str, np.ndarray]]], fs: float, speed,
              bounds) -> dict | None:
    """The ``signature_hz`` record.  ``nominal``: the nominal model's records (with their noise)
    on the signature's road phases; ``models``: effect -> its records on the same phases (same
    order).  The measured value is the mean of its statistic against every nominal record; a
    nominal record's against the other nominal records (a correct model's scatter); a model
    record's against the nominal records of the other phases (no road phase shared).  None
    without axle accelerations."""
    names = [c for c in measured if c.startswith(CHANNEL_PREFIX)]
    if not names or len(nominal) < 2:
        return None
    win = lambda rec: _windows(rec, speed, fs, names)  # noqa: E731 -- each record's PSDs once
    refs = [win(r) for r in nominal]

    def stat(w, skip=None):
        return _mean_finite(_slope(w, ref, fs, bounds)[0] for j, ref in enumerate(refs) if j != skip)

    return {"statistic": STATISTIC, "measure": MEASURE, "band_hz": [F_LO, min(F_HI, 0.35 * fs)],
            "measured": stat(win(measured)),
            "nominal": [stat(w, skip=i) for i, w in enumerate(refs)],
            "models": {e: [stat(win(r), skip=i) for i, r in enumerate(recs)]
                       for e, recs in models.items()}}
