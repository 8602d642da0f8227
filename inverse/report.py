"""Tables and figures of an inversion run (Tables 1-2, Figures 6, 8, 9).

What this module is for: writing what ``eroad invert`` reports from arrays and
dicts already computed -- Table 1 (fitted parameters per segment) and Table 2
(response statistics, measured and simulated) as CSV and markdown, and the
figures as PNG and PDF.  It never simulates (compute and plot apart).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

#: Table 2 channels in order (axle 3 left/right; acceleration first)
TABLE2_CHANNELS = ("axle_acc_3L", "axle_acc_3R", "body_acc_3L", "body_acc_3R", "susp_disp_3L", "susp_disp_3R")


def table1(segments: list) -> pd.DataFrame:
    """Table 1: fitted spectral parameters per segment.

    Parameters
    ----------
    segments : list of dict
        ``summary.json`` segment rows.

    Returns
    -------
    DataFrame
        segment, t_start, t_end [s], proportion [%], class, Gq_n0 [1e-6 m^3], w,
        nmin, nmax [cycles/m], dx, dy [m], not identifiable (names), and where
        present the best-determined level (n_best [cycles/m], G_n_best
        [1e-6 m^3], sd of ln G there) with the sd of ln Gq_n0 for comparison.
    """
    rows = []
    for i, s in enumerate(segments):
        ident = s.get("identifiable") or {}
        held = [k for k, v in ident.items() if not v] if isinstance(ident, dict) else []
        rows.append({"segment": i + 1, "t_start_s": round(s["t_start"], 3), "t_end_s": round(s["t_end"], 3),
                     "proportion_pct": round(100 * s["proportion"], 2), "class": s["class"],
                     "Gq_n0_1e-6m3": round(1e6 * s["Gq_n0"], 2), "w": round(s["w"], 3),
                     "nmin_cpm": round(s["nmin"], 4), "nmax_cpm": round(s["nmax"], 3),
                     "dx_m": s["dx"], "dy_m": s["dy"], "not_identifiable": " ".join(held),
                     **({"n_best_cpm": round(s["n_best"], 3), "G_n_best_1e-6m3": round(1e6 * s["G_n_best"], 4),
                         "sd_ln_G_n_best": round(s["sd_ln_G_n_best"], 3), "sd_ln_Gq_n0": round(s["sd"]["ln_Gq_n0"], 3)}
                        if "n_best" in s else {})})
    return pd.DataFrame(rows)


def table2(rows: list, spread: dict | None = None) -> pd.DataFrame:
    """Table 2: RMS and mean (rectified) of the responses, measured and simulated.

    Parameters
    ----------
    rows : list of dict
        :func:`inverse.validation.response_table` rows of the selected realisation.
    spread : dict, optional
        Per channel RMS-error spread over the candidate realisations
        (:func:`inverse.realisation.select_realisation`).

    Returns
    -------
    DataFrame
    """
    out = []
    for r in rows:
        d = {"channel": r["channel"], "rms_meas": r["rms_meas"], "rms_sim": r["rms_sim"],
             "rms_err_pct": 100 * r["rms_err"], "mean_meas": r["mean_abs_meas"], "mean_sim": r["mean_abs_sim"],
             "mean_err_pct": 100 * r["mean_abs_err"], "rmse_eq6_norm": r["rmse_eq6_norm"],
             "W1_over_sd": r["wasserstein"], "KS": r["ks"]}
        if spread and r["channel"] in spread:
            sp = spread[r["channel"]]
            d.update({"cand_median_err_pct": 100 * sp["median"], "cand_p16_pct": 100 * sp["p16"],
                      "cand_p84_pct": 100 * sp["p84"], "cand_median_abs_pct": 100 * sp["median_abs"]})
        out.append(d)
    return pd.DataFrame(out)


def write_table(df: pd.DataFrame, stem: Path, floatfmt: str = ".4g") -> list:
    """Write ``stem.csv`` and ``stem.md``; returns the paths."""
    stem = Path(stem)
    df.to_csv(stem.with_suffix(".csv"), index=False)
    cols = list(df.columns)
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for _, r in df.iterrows():
        cells = []
        for c in cols:
            v = r[c]
            cells.append(format(v, floatfmt) if isinstance(v, (float, np.floating)) else str(v))
        lines.append("| " + " | ".join(cells) + " |")
    stem.with_suffix(".md").write_text("\n".join(lines) + "\n")
    return [stem.with_suffix(".csv"), stem.with_suffix(".md")]


def write_figures(fig_dir: Path, *, time, measured: dict, simulated: dict, segmentation, seg_signal,
                  title: str = "") -> list:
    """Figures 6, 8 and 9 as PNG and PDF.

    Parameters
    ----------
    fig_dir : Path
    time : (N,) array [s]
    measured, simulated : dict
        Channel -> (N,) array (simulated: the selected realisation).
    segmentation : inverse.segmentation.SegmentationResult
    seg_signal : (N,) array
        The displacement shown in Figure 6 [m].
    title : str

    Returns
    -------
    list of Path
    """
    from inverse.segmentation import plot_segmentation
    from inverse.validation import plot_amplitude_distributions, plot_time_compare

    fig_dir = Path(fig_dir)
    fig_dir.mkdir(parents=True, exist_ok=True)
    chans = [c for c in ("susp_disp_3L", "susp_disp_3R") if c in measured and c in simulated]
    out = []
    for ext in ("png", "pdf"):
        out.append(plot_segmentation(segmentation, time, seg_signal, fig_dir / f"figure6_segmentation.{ext}",
                                     title=f"Figure 6: segmentation {title}"))
        out.append(plot_time_compare(time, measured, simulated, chans, fig_dir / f"figure8_time_compare.{ext}",
                                     title=f"Figure 8: measured vs simulated, axle 3 {title}"))
        out.append(plot_amplitude_distributions(measured, simulated, chans,
                                                fig_dir / f"figure9_amplitude_distributions.{ext}",
                                                title=f"Figure 9: amplitude distributions {title}"))
    return [Path(p) for p in out]
