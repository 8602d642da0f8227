"""Figures 4 and 5 of the paper for a measurement dataset.

Figure 4: the third-axle left suspension displacement over the whole record,
with the selected window shaded, and the window alone.  Figure 5: its spectrum
(Welch PSD, one-sided, m^2/Hz) over the whole record and over the window.

What it is for: looking at a dataset before inverting it, and the paper's
figures.  What it is not: it never simulates, and it never reads ``truth/``.
"""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
from scipy.signal import welch

from drives.format import Drive, read_drive, swap_into_place, temp_folder_beside
from eroad.errors import EroadInputError

#: Welch segment length [s]: 0.2 Hz resolution, enough averages in a 10 s window
WELCH_SEGMENT_S = 5.0


def response_psd(x: np.ndarray, fs: float, segment_s: float = WELCH_SEGMENT_S):
    """One-sided Welch PSD of a detrended signal.

    Parameters
    ----------
    x : (N,) array
        Signal (unit u).
    fs : float
        Sample rate [Hz].
    segment_s : float
        Segment length [s] (Hann window, 50 % overlap); shortened to the
        record when the record is shorter.

    Returns
    -------
    f : ndarray
        Frequency [Hz].
    psd : ndarray
        PSD [u^2/Hz].
    n_avg : int
        Number of (overlapping) averages.
    """
    nper = int(min(round(segment_s * fs), x.size))
    f, p = welch(x, fs=fs, nperseg=nper, detrend="linear")
    n_avg = max(1, 1 + (x.size - nper) // (nper // 2))
    return f, p, n_avg


def plot_figures(drive: Drive, out_dir, *, window=None, channel: str = "susp_disp_3L"):
    """Draw Figures 4 and 5 into ``out_dir`` (PNG and PDF).

    Parameters
    ----------
    drive : Drive
        The dataset.
    out_dir : str or Path
        Existing folder.
    window : (float, float), optional
        Window [s] on the drive's time axis; default the whole record.
    channel : str
        Channel to plot (default ``susp_disp_3L``, metres).

    Returns
    -------
    dict
        Summary: files, window, RMS [m] of record and window, Welch averages.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    drive.require([channel], purpose="eroad data figures")
    out_dir = Path(out_dir)
    t = drive.time
    if window is None:
        window = (float(t[0]), float(t[-1]) + drive.dt)
    t0, t1 = float(window[0]), float(window[1])
    if not t1 > t0:
        raise EroadInputError(f"--window {t0:g} {t1:g}: T1 must be greater than T0")
    win = drive.window(t0, t1)
    x = drive.channels[channel].to_numpy()
    xw = win.channels[channel].to_numpy()
    scale, unit = (1e3, "mm") if drive.units.get(channel) == "m" else (1.0, drive.units[channel])

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 5.5), constrained_layout=True)
    ax1.plot(t, x * scale, lw=0.5, color="C0")
    ax1.axvspan(t0, t1, color="C1", alpha=0.15, label=f"window {t0:g}-{t1:g} s")
    ax1.set_xlabel("time [s]")
    ax1.set_ylabel(f"{channel} [{unit}]")
    ax1.set_title(f"{drive.name}: {channel}, whole record")
    ax1.legend(loc="upper right", fontsize=8)
    ax1.set_xlim(t[0], t[-1])
    ax2.plot(win.time, xw * scale, lw=0.6, color="C1")
    ax2.set_xlabel("time [s]")
    ax2.set_ylabel(f"{channel} [{unit}]")
    ax2.set_title(f"selected window {t0:g}-{t1:g} s")
    ax2.set_xlim(win.time[0], win.time[-1])
    fig4 = [out_dir / "figure4_displacement.png", out_dir / "figure4_displacement.pdf"]
    for f in fig4:
        fig.savefig(f, dpi=150)
    plt.close(fig)

    fs = drive.sample_rate_hz
    f_all, p_all, n_all = response_psd(x, fs)
    f_win, p_win, n_win = response_psd(xw, fs)
    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    sel_a, sel_w = f_all > 0, f_win > 0
    ax.loglog(f_all[sel_a], p_all[sel_a], lw=0.9, label=f"whole record ({n_all} average{'s' * (n_all != 1)})")
    ax.loglog(f_win[sel_w], p_win[sel_w], lw=0.9,
              label=f"window {t0:g}-{t1:g} s ({n_win} average{'s' * (n_win != 1)})")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"PSD of {channel} [{drive.units[channel]}$^2$/Hz]")
    ax.set_title(f"{drive.name}: spectrum before and after slicing")
    ax.set_xlim(f_all[sel_a][0], fs / 2)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=8)
    fig5 = [out_dir / "figure5_spectrum.png", out_dir / "figure5_spectrum.pdf"]
    for f in fig5:
        fig.savefig(f, dpi=150)
    plt.close(fig)
    return {
        "dataset": drive.name,
        "channel": channel,
        "window_s": [t0, t1],
        "rms_record": float(np.std(x)),
        "rms_window": float(np.std(xw)),
        "welch_segment_s": WELCH_SEGMENT_S,
        "welch_averages": {"record": n_all, "window": n_win},
        "files": [f.name for f in fig4 + fig5],
    }


def figures_command(dataset, out, *, window=None, channel="susp_disp_3L", force=False) -> dict:
    """``eroad data figures``: read, plot into a temporary folder, rename into place.

    Parameters
    ----------
    dataset : str or Path
        Dataset folder.
    out : str or Path
        Output folder; must be new or empty unless ``force``.
    window : (float, float), optional
        Window [s].
    channel : str
        Channel to plot.
    force : bool
        Replace a non-empty ``out``.

    Returns
    -------
    dict
        The summary also written to ``out/summary.json`` (``files`` as paths).
    """
    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; choose another --out or use --force")
    drive = read_drive(dataset)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_folder_beside(out)
    try:
        summary = plot_figures(drive, tmp, window=window, channel=channel)
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        swap_into_place(tmp, out)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    summary["files"] = [str(out / f) for f in summary["files"]]
    return summary
