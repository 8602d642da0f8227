"""Statistical response features of a road segment and the fit's objective.

What it is for: turning a measured (or simulated) drive into, per road segment, a
vector of log band powers of the response PSDs in third-octave bands plus the log
RMS per channel, with a weight per feature from its statistical variance, so that
the inverse fit compares statistics of responses and never phases.  What it is
not: the diagnostics of eq (6) and of amplitude distributions
(:mod:`inverse.validation`), nor the fit (:mod:`inverse.sensitivity`).

Features of one segment window and one channel
----------------------------------------------
* Welch PSD (Hann window, 50% overlap, mean removed) with segments of
  ``min(nperseg_s, window / 2)`` seconds rounded down to a power-of-two number of
  samples;
* band power P_b = sum of PSD bins with centre frequency in the third-octave band
  b, times the bin width; base-10 bands (IEC 61260) with centres 10^(k/10) Hz,
  edges a factor 10^(1/20) either side, from ``f_lo`` to ``f_hi``;
* a band is used when it holds at least one bin, its degrees of freedom reach
  ``min_dof`` and the measured power stands above the noise: P_b >= ``snr_min`` N_b;
* feature ln(P_b); the simulated counterpart is ln(P_b,sim + N_b), the estimated
  measurement-noise power N_b added to the noise-free simulation, so noise biases
  neither side;
* log RMS: 0.5 ln(sum of the power of all bands between f_lo and f_hi that hold a
  bin), simulated with the noise power added in the same way.

Noise: white measurement noise per channel, its PSD either given or estimated
from the spectrum between 0.6 and 0.95 of the Nyquist frequency, where a vehicle
response carries little power (:func:`estimate_noise_psd`; documented
assumption: an overestimate of the noise biases w upwards, measured +0.1 on a
quarter truck whose road reached 80 Hz, so give known sensor noise when the road
content reaches that band).

Weights
-------
A band power from K Welch averages of m bins is close to a chi-square variable
with nu degrees of freedom, nu = 2 K_eff m_eff, with K_eff = K / (1 + 2 c^2 (K-1)/K)
(c = 0.167 for 50%-overlapped Hann windows, Welch 1967) and m_eff = m^2 /
(m + 2 (m-1) r1 + 2 (m-2) r2) (r1 = 0.444, r2 = 0.028: correlation of neighbouring
Hann-windowed periodogram bins).  Then var(ln P) = psi'(nu/2) (trigamma), about
2 / nu.  The measured and the simulated estimate each carry that variance (the
simulation averaged over R replicates: 1/R of it), so a residual has variance
(1 + 1/R) psi'(nu/2) + sigma_model^2 (a floor for model error), and the weight
is its inverse.  (Checked on white noise: predicted and observed variances of
the log band powers agree within the 10% scatter of 400 records.)  The log RMS gets the Satterthwaite degrees of freedom
of its sum of bands.  Correlation between channels (both sides see similar road
levels, not the same phases) is ignored, which overstates the information when
many channels of one wheel are used.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.signal import welch
from scipy.special import polygamma

from eroad.errors import EroadInputError

#: correlation of 50%-overlapped Hann segments (Welch 1967)
_C_OVERLAP = 0.167
#: correlation of neighbouring / next-neighbouring Hann periodogram bins
_R1, _R2 = 0.444, 0.028


def third_octave_bands(f_lo: float = 0.5, f_hi: float = 50.0):
    """Base-10 third-octave bands whose nominal centres lie in [f_lo, f_hi].

    Parameters
    ----------
    f_lo, f_hi : float
        Range of nominal band centres [Hz] (the exact centre 10^(k/10) of the
        nominal 50 Hz band is 50.12 Hz; k = round(10 log10 f)).

    Returns
    -------
    centres, lower, upper : ndarray
        [Hz]; centres 10^(k/10), edges centre * 10^(-+1/20).
    """
    if not (0 < f_lo < f_hi):
        raise EroadInputError(f"third_octave_bands: need 0 < f_lo < f_hi, got {f_lo}, {f_hi}")
    k = np.arange(round(10 * math.log10(f_lo)), round(10 * math.log10(f_hi)) + 1)
    c = 10.0 ** (k / 10.0)
    return c, c * 10 ** (-0.05), c * 10 ** 0.05


def welch_dof(n_avg: int, n_bins) -> np.ndarray:
    """Equivalent chi-square degrees of freedom of a Welch band power.

    Parameters
    ----------
    n_avg : int
        Number of 50%-overlapped Hann segments averaged.
    n_bins : int or array
        Number of frequency bins summed in the band.

    Returns
    -------
    ndarray
        nu [-] (see the module docstring).
    """
    m = np.asarray(n_bins, dtype=float)
    k_eff = n_avg / (1.0 + 2.0 * _C_OVERLAP ** 2 * (n_avg - 1) / max(n_avg, 1))
    var = m + 2 * np.maximum(m - 1, 0) * _R1 + 2 * np.maximum(m - 2, 0) * _R2
    m_eff = np.where(m > 0, m ** 2 / np.where(var > 0, var, 1.0), 0.0)
    return 2.0 * k_eff * m_eff


def log_power_variance(dof) -> np.ndarray:
    """Variance of ln of a chi-square power estimate with ``dof`` degrees of freedom.

    Parameters
    ----------
    dof : array_like
        nu > 0.

    Returns
    -------
    ndarray
        psi'(nu / 2) [-], about 2 / nu for large nu.
    """
    return polygamma(1, 0.5 * np.asarray(dof, dtype=float))


def estimate_noise_psd(x, fs: float, band=(0.6, 0.95), block_s: float = 4.0) -> float:
    """White-noise PSD of a record, from the top of its spectrum.

    The record is cut into blocks of ``block_s`` seconds; in each, the median
    Welch PSD (1 s Hann segments) between ``band`` fractions of the Nyquist
    frequency is taken, and the smallest block value is returned: where the road
    has content up into that band in some stretches (high speed, high nmax), the
    quietest stretch still shows the noise floor.

    Parameters
    ----------
    x : (N,) array
        Signal [unit].
    fs : float
        Sample rate [Hz].
    band : (float, float)
        Fractions of the Nyquist frequency to take the median PSD over.
    block_s : float
        Block length [s].

    Returns
    -------
    float
        One-sided PSD [unit^2/Hz].  Still an overestimate where the response has
        power in that band throughout the record; pass known sensor noise to
        :meth:`FeatureSet.from_measurement` then.
    """
    x = np.asarray(x, dtype=float)
    nb = max(1, int(x.size // max(block_s * fs, 16)))
    L = x.size // nb
    nper = min(L, 1 << int(math.log2(max(fs, 16))))
    nyq = 0.5 * fs
    vals = []
    for i in range(nb):
        f, p = welch(x[i * L:(i + 1) * L], fs, nperseg=nper)
        sel = (f >= band[0] * nyq) & (f <= band[1] * nyq)
        if np.any(sel):
            vals.append(float(np.median(p[sel])))
    return min(vals) if vals else 0.0


@dataclass(frozen=True)
class FeatureSpec:
    """How features are computed.

    Parameters
    ----------
    channels : tuple of str
        Channels used (at least both sides of axle 3; all present ones is best).
    f_lo, f_hi : float
        Band centres range [Hz]; default 0.5-50 Hz.
    nperseg_s : float
        Longest Welch segment [s] (sets the lowest usable band).
    min_dof : float
        Smallest degrees of freedom of a band to be used.
    snr_min : float
        Smallest ratio of measured band power to noise power for a band to be used.
    model_sigma : float
        Floor on the standard deviation of a log feature residual (model error) [-].
    include_rms : bool
        Add the log RMS of each channel.
    margin_s : float
        Transient margin skipped on each side of an interior segment boundary and
        at the record start [s]; covers the vehicle's memory (body-mode decay) and
        the wheelbase delay between axles.
    margin_frac : float
        At most this fraction of a segment is skipped on each side (short segments
        keep some data).
    noise_band : (float, float)
        Fractions of the Nyquist frequency used to estimate white noise.
    replicates : int
        Number of simulations with different road phases whose log features are
        averaged per evaluation (R); the residual variance is (1 + 1/R) psi'(nu/2),
        so R > 1 shrinks the simulation's share of the scatter at R times the cost.
    station_weighting : bool
        Divide the weights of a channel by the number of used channels at its
        wheel station (same axle and side, the name's last token such as '3L'):
        displacement and accelerations of one wheel see the same road track, so
        in one band they carry nearly the same information (measured: residuals
        of the three channels of one side agree within 0.3 in log), and counting
        each as independent would triple the data's weight against the prior.
    """

    channels: tuple
    f_lo: float = 0.5
    f_hi: float = 50.0
    nperseg_s: float = 4.0
    min_dof: float = 4.0
    snr_min: float = 2.0
    model_sigma: float = 0.05
    include_rms: bool = True
    margin_s: float = 0.75
    margin_frac: float = 0.2
    noise_band: tuple = (0.6, 0.95)
    replicates: int = 1
    station_weighting: bool = True

    def __post_init__(self):
        if not self.channels:
            raise EroadInputError("FeatureSpec: no channels given")
        if int(self.replicates) < 1:
            raise EroadInputError("FeatureSpec.replicates must be >= 1")
        object.__setattr__(self, "channels", tuple(self.channels))


@dataclass
class WindowFeatures:
    """Feature layout and measured values of one segment window.

    Attributes
    ----------
    i0, i1 : int
        Sample range [i0, i1) of the window.
    nperseg : int
        Welch segment length [samples].
    bands : dict
        Channel -> indices of the used bands into ``FeatureSet.centres``.
    labels : list of str
        One label per feature, e.g. 'susp_disp_3L@2.00Hz' or 'susp_disp_3L:rms'.
    y : ndarray
        Measured features [-] (natural logs of W or m^2-like units).
    weight : ndarray
        1 / variance of each residual [-].
    dof : ndarray
        Degrees of freedom of each feature.
    """

    i0: int
    i1: int
    nperseg: int
    bands: dict
    labels: list
    y: np.ndarray
    weight: np.ndarray
    dof: np.ndarray
    _all_bands: dict = field(default_factory=dict, repr=False)


class FeatureSet:
    """Measured features per segment, and the same features of a simulation.

    Build with :meth:`from_measurement`; then :meth:`evaluate` maps simulated
    channels to per-segment feature vectors aligned with the measured ones, and
    :meth:`objective` gives the weighted squared distance.
    """

    def __init__(self, spec: FeatureSpec, fs: float, n_samples: int, windows: list,
                 noise_psd: dict, centres, lower, upper):
        self.spec = spec
        self.fs = float(fs)
        self.n_samples = int(n_samples)
        self.windows = windows
        self.noise_psd = noise_psd
        self.centres, self.lower, self.upper = centres, lower, upper

    @property
    def n_segments(self) -> int:
        """Number of segment windows K."""
        return len(self.windows)

    @staticmethod
    def segment_windows(t_bounds, time, spec: FeatureSpec) -> list:
        """Sample ranges of the segment windows, margins removed.

        Parameters
        ----------
        t_bounds : (K + 1,) array
            Segment boundaries [s] on the record's time axis.
        time : (N,) array
            [s].
        spec : FeatureSpec

        Returns
        -------
        list of (int, int)
            [i0, i1) per segment.
        """
        t = np.asarray(time, dtype=float)
        tb = np.asarray(t_bounds, dtype=float)
        if tb.ndim != 1 or tb.size < 2 or np.any(np.diff(tb) <= 0):
            raise EroadInputError("t_bounds must be K+1 increasing times")
        out = []
        for k in range(tb.size - 1):
            a, b = max(tb[k], t[0]), min(tb[k + 1], t[-1] + (t[1] - t[0]))
            span = b - a
            m_left = min(spec.margin_s, spec.margin_frac * span)
            m_right = 0.0 if k == tb.size - 2 else min(spec.margin_s, spec.margin_frac * span)
            i0 = int(np.searchsorted(t, a + m_left - 1e-9))
            i1 = int(np.searchsorted(t, b - m_right - 1e-9))
            if i1 - i0 < 16:
                raise EroadInputError(f"segment {k} ({tb[k]:.2f}-{tb[k + 1]:.2f} s) is too short for features")
            out.append((i0, i1))
        return out

    @classmethod
    def from_measurement(cls, time, channels, t_bounds, spec: FeatureSpec, noise_psd=None):
        """Measured features per segment.

        Parameters
        ----------
        time : (N,) array
            Uniform time [s].
        channels : mapping
            Channel name -> (N,) array (SI units); must contain ``spec.channels``.
        t_bounds : (K + 1,) array
            Segment boundaries [s].
        spec : FeatureSpec
        noise_psd : dict, optional
            Channel -> white noise one-sided PSD [unit^2/Hz]; estimated from the
            top of each channel's spectrum when absent.

        Returns
        -------
        FeatureSet
        """
        t = np.asarray(time, dtype=float)
        missing = [c for c in spec.channels if c not in channels]
        if missing:
            raise EroadInputError(f"features: channels missing from the data: {', '.join(missing)}")
        fs = 1.0 / float(np.mean(np.diff(t)))
        centres, lower, upper = third_octave_bands(spec.f_lo, spec.f_hi)
        if upper[-1] >= 0.5 * fs:
            raise EroadInputError(f"features: the top band reaches {upper[-1]:.1f} Hz, above the Nyquist "
                                  f"frequency {fs / 2} Hz; lower f_hi")
        noise = {}
        for c in spec.channels:
            if noise_psd is not None and c in noise_psd:
                noise[c] = float(noise_psd[c])
            else:
                noise[c] = estimate_noise_psd(channels[c], fs, spec.noise_band)
        self = cls(spec, fs, t.size, [], noise, centres, lower, upper)
        for i0, i1 in cls.segment_windows(t_bounds, t, spec):
            self.windows.append(self._measure_window(channels, i0, i1))
        return self

    def _nperseg(self, n: int) -> int:
        cap = min(self.spec.nperseg_s * self.fs, n / 2.0)
        return 1 << max(3, int(math.floor(math.log2(max(cap, 8)))))

    def _band_powers(self, x, nperseg: int):
        """Band powers [unit^2], bin counts and Welch averages of one window."""
        n = x.size
        f, p = welch(x, self.fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2,
                     detrend="constant", scaling="density")
        df = f[1] - f[0]
        n_avg = 1 + (n - nperseg) // (nperseg - nperseg // 2)
        idx = np.searchsorted(f, self.lower, side="left"), np.searchsorted(f, self.upper, side="left")
        cs = np.concatenate([[0.0], np.cumsum(p)])
        power = (cs[idx[1]] - cs[idx[0]]) * df
        bins = idx[1] - idx[0]
        return power, bins, n_avg, df

    def _measure_window(self, channels, i0: int, i1: int) -> WindowFeatures:
        spec = self.spec
        nper = self._nperseg(i1 - i0)
        labels, ys, ws, dofs, bands, all_bands = [], [], [], [], {}, {}
        station = [c.rsplit("_", 1)[-1] for c in spec.channels]
        for c, st in zip(spec.channels, station):
            share = station.count(st) if spec.station_weighting else 1
            x = np.asarray(channels[c], dtype=float)[i0:i1]
            power, bins, n_avg, df = self._band_powers(x, nper)
            dof = welch_dof(n_avg, bins)
            noise = self.noise_psd[c] * bins * df
            has = bins > 0
            use = has & (dof >= spec.min_dof) & (power >= spec.snr_min * noise) & (power > 0)
            sel = np.flatnonzero(use)
            bands[c] = sel
            all_bands[c] = np.flatnonzero(has)
            both = 1.0 + 1.0 / spec.replicates  # measured + averaged simulated scatter
            var = both * log_power_variance(dof[sel]) + spec.model_sigma ** 2
            labels += [f"{c}@{self.centres[b]:.3g}Hz" for b in sel]
            ys.append(np.log(power[sel]))
            ws.append(1.0 / (var * share))
            dofs.append(dof[sel])
            if spec.include_rms:
                a = all_bands[c]
                tot = power[a].sum()
                if tot <= 0:
                    raise EroadInputError(f"features: channel {c} has no power in samples {i0}-{i1}")
                nu = tot ** 2 / np.sum(power[a] ** 2 / np.maximum(dof[a], 1e-9))
                var_rms = 0.25 * both * log_power_variance(nu) + spec.model_sigma ** 2
                labels.append(f"{c}:rms")
                ys.append(np.array([0.5 * math.log(tot)]))
                ws.append(np.array([1.0 / (var_rms * share)]))
                dofs.append(np.array([nu]))
        wf = WindowFeatures(i0, i1, nper, bands, labels, np.concatenate(ys), np.concatenate(ws),
                            np.concatenate(dofs))
        wf._all_bands = all_bands
        return wf

    def evaluate(self, sim_channels) -> list:
        """Features of a simulation on the measured layout.

        Parameters
        ----------
        sim_channels : mapping
            Channel name -> (N,) array on the measured time grid (noise-free).

        Returns
        -------
        list of ndarray
            One feature vector per segment, aligned with ``windows[k].y``.
        """
        spec = self.spec
        out = []
        for wf in self.windows:
            parts = []
            for c in spec.channels:
                if c not in sim_channels:
                    raise EroadInputError(f"simulator did not return channel {c}")
                x = np.asarray(sim_channels[c], dtype=float)
                if x.size != self.n_samples:
                    raise EroadInputError(f"simulator channel {c} has {x.size} samples, the record {self.n_samples}")
                power, bins, _, df = self._band_powers(x[wf.i0:wf.i1], wf.nperseg)
                total = power + self.noise_psd[c] * bins * df
                sel = wf.bands[c]
                parts.append(np.log(np.maximum(total[sel], 1e-300)))
                if spec.include_rms:
                    parts.append(np.array([0.5 * math.log(max(total[wf._all_bands[c]].sum(), 1e-300))]))
            out.append(np.concatenate(parts))
        return out

    def objective(self, feats) -> np.ndarray:
        """Weighted squared feature distance per segment.

        Parameters
        ----------
        feats : list of ndarray
            Output of :meth:`evaluate`.

        Returns
        -------
        ndarray, shape (K,)
            sum_j weight_j (y_j - f_j)^2 [-]; when the model fits within the
            statistical scatter, about the number of features divided by the
            channels per wheel station (with ``station_weighting``), i.e. about
            the number of independent features.
        """
        return np.array([float(np.sum(wf.weight * (wf.y - f) ** 2)) for wf, f in zip(self.windows, feats)])

    def n_features(self) -> np.ndarray:
        """Number of features per segment, shape (K,)."""
        return np.array([wf.y.size for wf in self.windows])
