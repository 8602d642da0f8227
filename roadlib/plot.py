"""Figures of a saved road: profile, surface map, PSD against the ISO 8608 classes.

What this module is for: looking at a road file (``eroad road plot``).  It only
reads a :class:`roadlib.surface.RoadSurface`; it never generates one.  What it
is not: a report generator for vehicle results.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from roadlib.metrics import default_band, fit_iso_psd, profile_psd
from roadlib.psd import ISO_CLASSES, N0


def plot_road(surface, out, track: float = 0.0, max_map_points: int = 2_000_000) -> dict:
    """Write a PNG with the track profile, the height map and the PSD vs ISO classes.

    Parameters
    ----------
    surface : RoadSurface
        The road.
    out : str or Path
        PNG file to write (written to a temporary name, then renamed).
    track : float
        Lateral position [m] of the profile and PSD track.
    max_map_points : int
        The map is decimated along x to at most this many cells.

    Returns
    -------
    dict
        The PSD fit of the track (``Gd_n0`` [m^3], ``w``, ``class``).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out)
    zt = surface.track(track)
    est = profile_psd(zt, surface.dx)
    band = default_band(est)
    p = surface.meta.get("params") if isinstance(surface.meta, dict) else None
    if isinstance(p, dict) and "nmin" in p and "nmax" in p:
        band = (max(band[0], float(p["nmin"])), min(band[1], 0.97 * float(p["nmax"])))
    fit = fit_iso_psd(est, band=band)

    fig = plt.figure(figsize=(11, 8.5), layout="constrained")
    gs = fig.add_gridspec(2, 2, height_ratios=[1, 1.3])
    ax_p = fig.add_subplot(gs[0, :])
    z_mean = float(np.mean(zt))
    ax_p.plot(surface.x, 1000 * (zt - z_mean), lw=0.6, color="C0")
    ax_p.set_xlabel("x along the road [m]")
    ax_p.set_ylabel("height z - mean [mm]")
    ax_p.set_title(f"track at y = {track:g} m (mean height {z_mean:.4g} m)")
    ax_p.grid(alpha=0.3)

    ax_m = fig.add_subplot(gs[1, 0])
    if surface.y.size > 1:
        step = max(1, int(np.ceil(surface.z.size / max_map_points)))
        zm = 1000 * surface.z[::step].T
        lim = np.percentile(np.abs(zm), 99.5)
        im = ax_m.imshow(zm, origin="lower", aspect="auto", cmap="RdBu_r", vmin=-lim, vmax=lim,
                         extent=(surface.x[0], surface.x[-1], surface.y[0], surface.y[-1]),
                         interpolation="nearest")
        fig.colorbar(im, ax=ax_m, label="height z [mm]")
        ax_m.set_ylabel("y lateral, left positive [m]")
        ax_m.set_title("surface map")
    else:
        ax_m.hist(1000 * (zt - z_mean), bins=60, color="C0")
        ax_m.set_ylabel("count [-]")
        ax_m.set_title("single track: height histogram")
    ax_m.set_xlabel("x along the road [m]" if surface.y.size > 1 else "height z - mean [mm]")

    ax_s = fig.add_subplot(gs[1, 1])
    nn = np.logspace(np.log10(0.005), np.log10(0.5 / surface.dx), 100)
    sel = est.n > 0
    in_band = sel & (est.n >= fit.band[0]) & (est.n <= fit.band[1])
    y_lo = max(0.1 * est.G[in_band].min(), 1e-14) if in_band.any() else 1e-12
    y_hi = 5.0 * est.G[sel].max() if sel.any() else 1e-2
    n_lab = 0.6 * nn[-1]
    for c in ISO_CLASSES.values():
        ax_s.loglog(nn, c.gd0 * (nn / N0) ** -2, color="0.55", lw=0.8, ls="--")
        ax_s.loglog(nn, 2.0 * c.gd0 * (nn / N0) ** -2, color="0.85", lw=0.6)
        y_lab = c.gd0 * (n_lab / N0) ** -2
        if y_lo < y_lab < y_hi:
            ax_s.text(n_lab, y_lab, c.name, fontsize=8, color="0.35", va="bottom", ha="center")
    ax_s.loglog(est.n[sel], est.G[sel], color="C0", lw=0.8, label="Welch estimate")
    nb = np.logspace(np.log10(fit.band[0]), np.log10(fit.band[1]), 50)
    ax_s.loglog(nb, fit.Gd_n0 * (nb / N0) ** -fit.w, color="C3", lw=1.5,
                label=f"fit: Gd(n0) = {fit.Gd_n0 * 1e6:.1f}e-6 m^3, w = {fit.w:.2f} (class {fit.iso_class})")
    ax_s.set_ylim(y_lo, y_hi)
    ax_s.set_xlim(nn[0], nn[-1])
    ax_s.set_xlabel("spatial frequency n [cycles/m]")
    ax_s.set_ylabel("displacement PSD Gd(n) [m^3]")
    ax_s.set_title("PSD vs ISO 8608 classes\n(dashed: class means, light: bounds, w = 2)", fontsize=10)
    ax_s.legend(fontsize=8, loc="lower left")
    ax_s.grid(alpha=0.3, which="major")

    tmp = out.with_name(f".{out.name}.{os.getpid()}.tmp.png")
    try:
        fig.savefig(tmp, dpi=110)
        os.replace(tmp, out)
    finally:
        plt.close(fig)
        if tmp.exists():
            tmp.unlink()
    return fit.to_dict()
