"""Diagnostics of an identified road: eq (6) RMSE, amplitude distributions, Table 2.

What it is for: comparing a measured drive with the nominal model driven over the
identified road, the way section 4 of the paper does (time histories, amplitude
distributions, RMS and mean per channel), and Figures 8 and 9.  What it is not:
the fit's objective.  Eq (6) compares two records sample by sample; a road
synthesised with random phases can never reproduce the measured phases, so the
RMSE of two independent records with equal spectra is sqrt(2) times the RMS of
either, and it is smallest (1 times) for no road at all.  These numbers are
reported as diagnostics only; the fit minimises :mod:`inverse.features`.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.stats import ks_2samp, wasserstein_distance

from eroad.errors import EroadInputError


def _pair(measured, simulated):
    m = np.asarray(measured, dtype=float)
    s = np.asarray(simulated, dtype=float)
    if m.shape != s.shape or m.ndim != 1 or m.size == 0:
        raise EroadInputError(f"measured and simulated must be 1-D arrays of one length, got {m.shape}, {s.shape}")
    return m, s


def rmse_eq6(measured, simulated, normalise: bool = False) -> float:
    """Time-domain RMSE of eq (6): sqrt(mean((y_meas - y_sim)^2)).

    Parameters
    ----------
    measured, simulated : (N,) array
        Same channel on the same time grid [unit].
    normalise : bool
        Divide by the measured RMS (then 1.0 is the value for a zero simulation
        and sqrt(2) for an independent record of equal spectrum).

    Returns
    -------
    float
        [unit], or [-] when normalised.  A diagnostic only (see module doc).
    """
    m, s = _pair(measured, simulated)
    r = math.sqrt(float(np.mean((m - s) ** 2)))
    return r / math.sqrt(float(np.mean(m ** 2))) if normalise else r


def amplitude_distance(measured, simulated, kind: str = "wasserstein") -> float:
    """Distance between the amplitude distributions of two records.

    Parameters
    ----------
    measured, simulated : (N,) array
        [unit]; each has its mean removed first (static offsets are not road).
    kind : {'wasserstein', 'ks'}
        'wasserstein': Wasserstein-1 (earth mover's) distance divided by the
        measured standard deviation [-]; 'ks': two-sample Kolmogorov-Smirnov
        statistic (largest difference of the empirical distribution functions) [-].

    Returns
    -------
    float
        0 for identical distributions; phase-free, so a random-phase road of the
        right spectrum scores low and no road scores high.
    """
    m, s = _pair(measured, simulated)
    m = m - m.mean()
    s = s - s.mean()
    if kind == "wasserstein":
        sd = float(np.std(m))
        return float(wasserstein_distance(m, s)) / sd if sd > 0 else float("inf")
    if kind == "ks":
        # the statistic only: the asymptotic p-value avoids the exact method's warnings (same statistic)
        return float(ks_2samp(m, s, method="asymp").statistic)
    raise EroadInputError(f"amplitude_distance: unknown kind {kind!r}, use 'wasserstein' or 'ks'")


def response_table(measured: dict, simulated: dict, channels=None) -> list:
    """Table 2 style comparison per channel: RMS and mean, measured and simulated.

    Parameters
    ----------
    measured, simulated : dict
        Channel name -> (N,) array on one time grid [SI units].
    channels : list of str, optional
        Channels to compare; default all common ones, sorted.

    Returns
    -------
    list of dict
        Per channel: 'channel', 'rms_meas', 'rms_sim', 'rms_err' (relative,
        (sim - meas) / meas), 'mean_meas', 'mean_sim' (signed means),
        'mean_abs_meas', 'mean_abs_sim' (mean of |y - mean y|, the rectified mean
        the paper's "mean acceleration" can only be, since gravity-free
        accelerations have zero mean), 'mean_abs_err' (relative), 'rmse_eq6',
        'rmse_eq6_norm', 'wasserstein', 'ks'.  RMS is about the mean
        (standard deviation).
    """
    if channels is None:
        channels = sorted(set(measured) & set(simulated))
    rows = []
    for c in channels:
        if c not in measured or c not in simulated:
            raise EroadInputError(f"response_table: channel {c} missing from measured or simulated data")
        m, s = _pair(measured[c], simulated[c])
        rm, rs = float(np.std(m)), float(np.std(s))
        am, as_ = float(np.mean(np.abs(m - m.mean()))), float(np.mean(np.abs(s - s.mean())))
        rows.append({
            "channel": c, "rms_meas": rm, "rms_sim": rs,
            "rms_err": (rs - rm) / rm if rm > 0 else float("nan"),
            "mean_meas": float(m.mean()), "mean_sim": float(s.mean()),
            "mean_abs_meas": am, "mean_abs_sim": as_,
            "mean_abs_err": (as_ - am) / am if am > 0 else float("nan"),
            "rmse_eq6": rmse_eq6(m - m.mean(), s - s.mean()),
            "rmse_eq6_norm": rmse_eq6(m - m.mean(), s - s.mean(), normalise=True),
            "wasserstein": amplitude_distance(m, s, "wasserstein"),
            "ks": amplitude_distance(m, s, "ks"),
        })
    return rows


def plot_time_compare(time, measured: dict, simulated: dict, channels, path, window=None,
                      title: str = ""):
    """Figure 8: measured and simulated time histories, one panel per channel.

    Parameters
    ----------
    time : (N,) array
        [s].
    measured, simulated : dict
        Channel -> (N,) array.
    channels : list of str
        E.g. ['susp_disp_3L', 'susp_disp_3R'].
    path : str or Path
        Output file.
    window : (float, float), optional
        Time range shown [s].
    title : str

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(time)
    sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
    fig, axes = plt.subplots(len(channels), 1, figsize=(9, 2.4 * len(channels)), sharex=True, squeeze=False)
    for ax, c in zip(axes[:, 0], channels):
        scale, unit = (1e3, "mm") if c.startswith("susp_disp") else (1.0, "m/s$^2$")
        ax.plot(t[sel], scale * np.asarray(measured[c])[sel], lw=0.6, color="0.2", label="measured")
        ax.plot(t[sel], scale * np.asarray(simulated[c])[sel], lw=0.6, color="C3", alpha=0.8,
                label="simulated (one random-phase road of the fitted spectra)")
        ax.set_ylabel(f"{c} [{unit}]")
        ax.legend(loc="upper right", fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    if title:
        fig.suptitle(title)
    fig.text(0.01, 0.005, "The simulated road has the fitted spectra but random phases: compare level and "
             "character, not the waveform (two unrelated signals give eq 6 RMSE about 1.4).",
             fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    from eroad.figures import save_figure

    return save_figure(fig, path, dpi=150)[0]


def plot_amplitude_distributions(measured: dict, simulated: dict, channels, path, bins: int = 60,
                                 title: str = ""):
    """Figure 9: amplitude distributions (probability density), measured and simulated.

    Parameters
    ----------
    measured, simulated : dict
        Channel -> (N,) array.
    channels : list of str
    path : str or Path
    bins : int
    title : str

    Returns
    -------
    Path
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(channels), figsize=(4.2 * len(channels), 3.4), squeeze=False)
    for ax, c in zip(axes[0], channels):
        scale, unit = (1e3, "mm") if c.startswith("susp_disp") else (1.0, "m/s$^2$")
        m = scale * (np.asarray(measured[c]) - np.mean(measured[c]))
        s = scale * (np.asarray(simulated[c]) - np.mean(simulated[c]))
        lim = np.percentile(np.abs(np.concatenate([m, s])), 99.9)
        edges = np.linspace(-lim, lim, bins + 1)
        ax.hist(m, edges, density=True, histtype="step", color="0.2", label="measured")
        ax.hist(s, edges, density=True, histtype="step", color="C3", label="simulated")
        w1 = amplitude_distance(m, s, "wasserstein")
        ax.set_title(f"{c}  (W1/sd = {w1:.3f})", fontsize=9)
        ax.set_xlabel(f"amplitude [{unit}]")
        ax.set_ylabel(f"probability density [1/{unit}]")
        ax.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.text(0.01, 0.005, "W1/sd: Wasserstein-1 (earth mover's) distance between the measured and "
             "simulated amplitude\ndistributions over the measured standard deviation (0: identical). "
             "Simulated: one random-phase road of the fitted spectra.", fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    from eroad.figures import save_figure

    return save_figure(fig, path, dpi=150)[0]
