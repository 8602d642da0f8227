"""A step in the spatial-frequency spectrum of the axle accelerations: where a road may stop.

A road replica made from a profile sampled every ``dx`` metres (a rig, or a simulation driven on a
measured profile) holds nothing above ``1 / (2 dx)`` cycles/m.  Its axle accelerations, read against
spatial frequency ``n = f / v`` (each short window at its own speed), then step down at that ``n``
whatever the speed; the vehicle's own features (axle hop, a sensor low-pass, leaf-spring friction)
sit at fixed frequencies in Hz and are smeared over ``n`` when the speed varies.

:func:`trial_cut` reads that step off the measurement alone (no simulation): the pooled log power of
the axle accelerations in bands of a factor ``STEP_RATIO`` below and above each candidate cut ``g``,
the drop across ``g`` less the drop just below it (a curvature, so the truck's own smooth roll-off
counts little).  It is a trigger, not a decision: a tyre-enveloping notch (first zero at the
footprint length's inverse) and some full-band drives step as much (the design numbers at
:data:`STEP_MIN`); the diagnosis decides by the held-out gap of the whole pass on the cut road
(``diagnosis.pipeline.diagnose``, ``settings["joint_band"]``).
"""
from __future__ import annotations

import numpy as np

#: samples per window (1.28 s at 200 Hz): short enough that the speed is nearly constant
WINDOW = 256
#: a window is used when its top speed is within this factor of its lowest (and above 2 m/s)
SPEED_SPREAD = 1.1
#: half-width of the bands either side of a trial cut, as a factor in n
STEP_RATIO = 1.25
#: fewest periodogram bins (pooled over windows) a band needs
MIN_BINS = 6
#: the step statistic that makes a cut worth a trial.  Design set (stop 57, 32 drives of
#: results/diagnosis_blind/20261129-band-refit and five tyre / sensor drives made for it;
#: ``results/diagnosis_blind/20261129-joint-band/step_design.txt``): 1.06-2.05 at 2 cycles/m on
#: the seven measured-profile friction drives of the independent truck, 6.2 on the three without
#: an effect; up to 1.30 on full-band drives (a 6 Hz sensor at 1 cycle/m; 1.21 at 1.5 on a
#: 3.5 kN friction drive of the independent truck) and 1.7-2.2 at tyre-enveloping notches.  Low on
#: purpose: a trial costs time, a missed cut costs the verdict.
STEP_MIN = 1.0


def _window_spectra(sig, names):
    """Per usable window: (n [cycles/m], ln of the axle-acceleration periodogram summed over
    ``names``), bins below 0.45 fs."""
    x = np.stack([np.asarray(sig.channels[c], float) for c in names], 1)
    fs = float(sig.fs)
    f = np.fft.rfftfreq(WINDOW, 1.0 / fs)
    keep = (f > 0) & (f < 0.45 * fs)
    win = np.hanning(WINDOW)[:, None]
    out = []
    for i in range(0, x.shape[0] - WINDOW + 1, WINDOW // 2):
        v = np.asarray(sig.speed[i:i + WINDOW], float)
        if v.min() < 2.0 or v.max() > SPEED_SPREAD * v.min():
            continue
        seg = x[i:i + WINDOW] - x[i:i + WINDOW].mean(0)
        p = (np.abs(np.fft.rfft(seg * win, axis=0)) ** 2).sum(1)[keep]
        if np.all(p > 0):
            out.append((f[keep] / float(v.mean()), np.log(p)))
    return out


def _band_mean(spectra, lo: float, hi: float) -> float:
    """Mean log power over all windows' bins with ``lo <= n < hi`` (NaN with fewer than
    ``MIN_BINS``)."""
    s, c = 0.0, 0
    for n, lp in spectra:
        m = (n >= lo) & (n < hi)
        s += float(lp[m].sum())
        c += int(m.sum())
    return s / c if c >= MIN_BINS else float("nan")


def step_statistic(spectra, g: float, r: float = STEP_RATIO) -> float:
    """Drop of the pooled log power across ``g`` (bands ``[g/r, g)`` and ``[g, g r)``) less the
    drop across the band below (``[g/r^2, g/r)`` to ``[g/r, g)``): a step at ``g`` gives its
    height, a straight slope in ln-power gives nearly 0 (NaN where a band lacks bins)."""
    a = _band_mean(spectra, g / r ** 2, g / r)
    b = _band_mean(spectra, g / r, g / 1.01)
    c = _band_mean(spectra, g * 1.01, g * r)
    return (b - c) - (a - b)


def trial_cut(sig, grid, top: float) -> dict:
    """The step statistic at each value of ``grid`` below ``top`` and the trial cut.

    Parameters
    ----------
    sig : diagnosis.signals.Signals
        The measurement (axle accelerations ``axle_acc_*`` and speed).
    grid : sequence of float
        Candidate cuts [cycles/m] (``diagnosis.road_fit.NMAX_GRID``).
    top : float
        The default road's top frequency; only cuts below it are tried.

    Returns
    -------
    dict
        ``step`` ({g: statistic or None}), ``cut`` (the g of the largest statistic if it reaches
        ``STEP_MIN``, else None), ``windows`` (windows used), ``threshold``.
    """
    names = [c for c in sig.channels if c.startswith("axle_acc_")]
    spectra = _window_spectra(sig, names) if names else []
    step = {}
    for g in grid:
        if g < top and spectra:
            v = step_statistic(spectra, float(g))
            step[float(g)] = None if not np.isfinite(v) else round(float(v), 3)
    ok = {g: v for g, v in step.items() if v is not None}
    best = max(ok, key=ok.get) if ok else None
    return {"step": step, "cut": best if best is not None and ok[best] >= STEP_MIN else None,
            "windows": len(spectra), "threshold": STEP_MIN}
