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

def table2_channels(axle: int = 3) -> tuple:
    """Table 2 channels in order: one axle, left/right, acceleration first (the paper's axle 3;
    the reference axle of a drive logged on another, ``inverse.run.reference_axle``)."""
    return tuple(f"{q}_{axle}{side}" for q in ("axle_acc", "body_acc", "susp_disp") for side in "LR")


#: Table 2 channels of the paper (axle 3)
TABLE2_CHANNELS = table2_channels(3)


def class_identified(seg: dict) -> bool:
    """Whether a segment's ISO class is a result: its Gq(n0) identifiable (posterior variance at
    most ``id_ratio`` of the prior's, :mod:`inverse.sensitivity`); rows without the record count
    as identified (older summaries)."""
    ident = seg.get("identifiable")
    return not (isinstance(ident, dict) and ident.get("Gq_n0") is False)


def class_label(seg: dict) -> str:
    """The class as the tables and the CLI show it: ``"B"``, or ``"(B)"`` where Gq(n0) is not
    identifiable -- the data barely move the fit from its starting guess (the segmentation's
    RMS class), so the letter is that guess, not a result (:data:`UNIDENTIFIED_CLASS_NOTE`)."""
    c = str(seg.get("class", ""))
    return c if class_identified(seg) else f"({c})"


#: the note's sentence on a class in brackets (Table 1, where a segment has one)
UNIDENTIFIED_CLASS_NOTE = (
    "A class in brackets: Gq_n0 is not identifiable in that segment (the data leave more than a quarter "
    "of its prior variance, typically a segment shorter than about 1 s): the fit stays near its starting "
    "guess, the class the segmentation's RMS suggested, so the letter is not a result; its Gq_n0 interval "
    "says how little is known.")


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
        [1e-6 m^3], sd of ln G there) with the sd of ln Gq_n0 for comparison, the
        90 % intervals of Gq_n0 and w, and the fit-quality gate ('clean' / 'poor')
        with the misfit per feature (:mod:`inverse.uncertainty`); where the run chose
        a road model per segment (:mod:`inverse.road_model`): road_model
        ('one_slope' / 'two_slope'), w_low, w_high, n_break [cycles/m] and
        bic_gain_two_slope (ic_delta, > 0 chose two slopes); unresolved_3s_level_x, the level
        factor range of a 3 s stretch the segmentation leaves inside the segment as often as not
        (``unresolved``, '' where it does not apply).
    """
    rows = []
    for i, s in enumerate(segments):
        ident = s.get("identifiable") or {}
        held = [k for k, v in ident.items() if not v] if isinstance(ident, dict) else []
        rows.append({"segment": i + 1, "t_start_s": round(s["t_start"], 3), "t_end_s": round(s["t_end"], 3),
                     "proportion_pct": round(100 * s["proportion"], 2), "class": class_label(s),
                     "Gq_n0_1e-6m3": round(1e6 * s["Gq_n0"], 2), "w": round(s["w"], 3),
                     "nmin_cpm": round(s["nmin"], 4), "nmax_cpm": round(s["nmax"], 3),
                     "dx_m": s["dx"], "dy_m": s["dy"], "not_identifiable": " ".join(held),
                     **({"n_best_cpm": round(s["n_best"], 3), "G_n_best_1e-6m3": round(1e6 * s["G_n_best"], 4),
                         "sd_ln_G_n_best": round(s["sd_ln_G_n_best"], 3), "sd_ln_Gq_n0": round(s["sd"]["ln_Gq_n0"], 3)}
                        if "n_best" in s else {}),
                     **({"Gq_n0_90pct_1e-6m3": "{:.3g}-{:.3g}".format(*(1e6 * v for v in s["interval90"]["Gq_n0"])),
                         "w_90pct": "{:.2f}-{:.2f}".format(*s["interval90"]["w"])} if "interval90" in s else {}),
                     **({"fit": s["fit_quality"]["status"],
                         "misfit_per_feature": round(s["fit_quality"]["misfit_per_feature"], 2)}
                        if "fit_quality" in s else {}),
                     **(_road_model_columns(s) if "road_model" in s else {}),
                     **({"unresolved_3s_level_x": _factor_range((s["unresolved"] or {}).get("ln_level"))}
                        if "unresolved" in s else {})})
    return pd.DataFrame(rows)


def _factor_range(ln_level) -> str:
    """'0.29-2.5': the level ratio range of an ``unresolved`` row ('' where it does not apply)."""
    if not ln_level:
        return ""
    lo, hi = ln_level
    return "{}-{}".format("0" if lo is None else f"{np.exp(lo):.2g}", "inf" if hi is None else f"{np.exp(hi):.2g}")


#: the note's sentence on the segmentation's resolution (Table 1's unresolved column)
UNRESOLVED_NOTE = (
    "unresolved_3s_level_x: a 3 s stretch inside the segment whose road level lies within this factor "
    "range of the segment's is, as often as not, left in the segment by the segmentation (its "
    "criterion's expected resolution, docs/inverse.md section 1); the segment's values and intervals "
    "describe the segment as one road, so such a stretch's own level can lie outside them.")


def _road_model_columns(s: dict) -> dict:
    """Table 1's road-model columns of one segment row (the old columns stay the one-slope fit)."""
    nb, d = s.get("n_break"), s.get("ic_delta")
    return {"road_model": s["road_model"], "w_low": round(s["w_low"], 3), "w_high": round(s["w_high"], 3),
            "n_break_cpm": "" if nb is None else round(nb, 4),
            "bic_gain_two_slope": "" if d is None else round(d, 2)}


#: the note's sentence on the road-model columns (written when Table 1 has them)
ROAD_MODEL_NOTE = (
    "Gq_n0 and w are the one-slope ISO 8608 fit in every row. 'road_model' says whether the "
    "segment's response features are explained better by two slopes, w_low below n_break and "
    "w_high above (continuous at n_break), by enough to pay their two extra parameters: "
    "bic_gain_two_slope = BIC(one) - BIC(two) on the fit's weighted residual, two slopes when > 0 "
    "(docs/road_model.md); for one slope w_low = w_high = w. The road files, Table 2 and the "
    "studies use the two slopes where road_model says two_slope, else the one-slope fit.")


#: the sentence of Table 1's note per model-form state (:data:`inverse.uncertainty.MODEL_FORMS`)
MODEL_FORM_NOTE = {
    "open": ("Model-form term: 'open' -- a vehicle difference may be unaccounted for (the model was not "
             "checked against this drive, the diagnosis found a gap no library effect fully explains, or the "
             "effect this fit carries is the nearest one the diagnosis named without singling it out), so "
             "the intervals allow for it hiding in the road level (`eroad invert --effects auto` "
             "diagnoses first)."),
    "unexplained": ("Model-form term: 'unexplained' -- the diagnosis found a gap no library effect fully "
                    "explains (this fit carries the closest effect only where it acts on the vehicle and "
                    "explains most of the gap), so the intervals carry the term calibrated on such drives "
                    "of the closed loop (the open one where the fitted channels have none)."),
    "diagnosed": ("Model-form term: 'diagnosed' -- the diagnosis found no gap beyond noise, or named and "
                  "singled out the effect this fit carries, so the intervals carry the term calibrated on "
                  "diagnosed drives: smaller than the open one where the misfit is high, plus (axle-3 fit) a "
                  "floor whatever the misfit, because what a correction leaves can bias the level without "
                  "raising the misfit."),
}


def table1_note(fit_quality: dict | None = None, road_model: bool = True, segments=None,
                model_form: str | None = None, channels: tuple | None = None) -> str:
    """The paragraph under Table 1: what the uncertainty columns mean, and the gate's verdict;
    with ``road_model`` (default: every run reports it) also what the road-model columns
    mean (:data:`ROAD_MODEL_NOTE`); with ``model_form`` which model-form term the intervals
    carry (:data:`MODEL_FORM_NOTE`); with ``channels`` = (channel set, calibrated) which
    channels were fitted (:func:`channels_note`)."""
    from inverse.uncertainty import R_GATE

    gate = next((r["fit_quality"]["gate"] for r in segments or [] if "gate" in r.get("fit_quality", {})), R_GATE)
    note = ("The 90 % intervals and sd columns hold noise, realisation and model-form error, "
            "calibrated on blind drives (docs/inverse.md, section 11). 'fit' is the fit-quality gate: "
            f"'poor' where the misfit per feature exceeds {gate:g}, i.e. the model does not explain "
            "the segment's data and its numbers are not a clean result.")
    if any((r or {}).get("unresolved") for r in segments or []):
        note += " " + UNRESOLVED_NOTE
    if any(not class_identified(r or {}) for r in segments or []):
        note += " " + UNIDENTIFIED_CLASS_NOTE
    if model_form is not None:
        note += " " + MODEL_FORM_NOTE[model_form]
    if channels is not None:
        note += " " + channels_note(*channels)
    if fit_quality and fit_quality.get("status") == "poor":
        note = f"**POOR FIT**: {fit_quality['message']}.\n\n" + note
    if road_model:
        note += " " + ROAD_MODEL_NOTE
    pinned = [f"segment {i + 1}: {', '.join(r['at_bound'])}" for i, r in enumerate(segments or [])
              if r.get("at_bound")]
    if pinned:
        note += (" **On a bound**: " + "; ".join(pinned) + ". The data pushed these parameters to the edge "
                 "of the road model's range (docs/road_model.md): the road is outside it, and the value "
                 "is the bound's, not the road's.")
    return note


def channels_note(channel_set: str, calibrated: bool) -> str:
    """One sentence under Table 1: which channels were fitted and whether the intervals were
    calibrated for them (``inverse.uncertainty.calibration_key``)."""
    what = {"axles": "axle accelerations of every axle and the suspension displacement of one axle (axle 3 "
                     "where logged)",
            "all": "every response channel",
            "axles_acc": "axle accelerations of every axle; the suspension displacements only segment the "
                         "drive"}.get(channel_set, "a list of the user's")
    if channel_set.startswith("axle") and channel_set[4:].isdigit():
        what = f"suspension displacement and axle acceleration of axle {channel_set[4:]}"
    if channel_set.startswith("axle") and channel_set.endswith("_acc") and channel_set[4:-4].isdigit():
        what = (f"axle acceleration of axle {channel_set[4:-4]}, both sides; the suspension displacements "
                f"only segment the drive")
    if calibrated:
        return (f"Fitted channels: '{channel_set}' ({what}); the intervals are calibrated for them (set or "
                f"checked on blind drives fitted on these channels).")
    return (f"Fitted channels: '{channel_set}' ({what}); **the intervals use the axle-3 calibration and were "
            f"not checked on blind drives with these channels**.")


#: unit of each Table 2 quantity by channel prefix
_UNITS = {"axle_acc": "m/s^2", "body_acc": "m/s^2", "susp_disp": "m"}

#: the note written under Table 2 (markdown)
TABLE2_NOTE = (
    "Headline: the median over the road realisations (random phases) of the fitted spectra, "
    "with the 16-84 % range over them; one realisation's RMS scatters by several per cent, so "
    "a single one is no measure of the fit. rect_mean is the rectified mean, mean |y - mean y| "
    "(the paper's 'mean acceleration': a gravity-free acceleration has zero mean). The "
    "'selected_' columns belong to the one realisation kept for the road files and Figures 8-9, "
    "chosen by its RMS nearness to the measurement: they are not an independent check. "
    "Units: 'unit' is that of the rms_meas, rms_sim_median, rect_mean_meas and selected_rms_sim "
    "columns; *_pct columns are per cent; the rest are dimensionless. "
    "Errors are (simulated - measured) / measured in %; rmse_eq6_norm is eq 6's RMSE over the "
    "measured RMS (about 1.4 for two signals of unrelated phase); W1_over_sd is the "
    "Wasserstein-1 distance of the amplitude distributions over the measured sd.")


def table2_note(axle: int = 3) -> str:
    """The note under Table 2; a drive whose Table 2 axle is not the paper's axle 3 says so."""
    if axle == 3:
        return TABLE2_NOTE
    return (f"Channels of axle {axle}, not of axle 3 (the paper's Table 2 axle): not comparable with the "
            f"paper's table. " + TABLE2_NOTE)


def table2(rows: list, spread: dict | None = None) -> pd.DataFrame:
    """Table 2: response RMS and rectified mean, measured and simulated.

    Parameters
    ----------
    rows : list of dict
        :func:`inverse.validation.response_table` rows of the selected realisation.
    spread : dict, optional
        Per channel error spread over the candidate realisations
        (:func:`inverse.realisation.select_realisation`); where given, the headline
        columns are its medians and 16-84 % ranges (see :data:`TABLE2_NOTE`).

    Returns
    -------
    DataFrame
        channel, unit, rms_meas [unit], then over realisations rms_sim_median [unit],
        rms_err_median_pct, rms_err_p16_pct, rms_err_p84_pct, rect_mean_meas [unit],
        rect_mean_err_median_pct, rect_mean_err_p16_pct, rect_mean_err_p84_pct,
        n_realisations, then the selected realisation's selected_rms_sim [unit],
        selected_rms_err_pct, selected_rect_mean_err_pct, selected_rmse_eq6_norm [-],
        selected_W1_over_sd [-], selected_KS [-].
    """
    out = []
    for r in rows:
        c = r["channel"]
        d = {"channel": c, "unit": _UNITS.get(c.rsplit("_", 1)[0], ""), "rms_meas": r["rms_meas"]}
        sp = (spread or {}).get(c)
        if sp:
            d.update({"rms_sim_median": r["rms_meas"] * (1 + sp["median"]),
                      "rms_err_median_pct": 100 * sp["median"], "rms_err_p16_pct": 100 * sp["p16"],
                      "rms_err_p84_pct": 100 * sp["p84"], "rect_mean_meas": r["mean_abs_meas"]})
            if "mean_abs_median" in sp:
                d.update({"rect_mean_err_median_pct": 100 * sp["mean_abs_median"],
                          "rect_mean_err_p16_pct": 100 * sp["mean_abs_p16"],
                          "rect_mean_err_p84_pct": 100 * sp["mean_abs_p84"]})
            d["n_realisations"] = int(sp.get("n", 0))
        else:
            d["rect_mean_meas"] = r["mean_abs_meas"]
        d.update({"selected_rms_sim": r["rms_sim"], "selected_rms_err_pct": 100 * r["rms_err"],
                  "selected_rect_mean_err_pct": 100 * r["mean_abs_err"],
                  "selected_rmse_eq6_norm": r["rmse_eq6_norm"], "selected_W1_over_sd": r["wasserstein"],
                  "selected_KS": r["ks"]})
        out.append(d)
    return pd.DataFrame(out)


def write_table(df: pd.DataFrame, stem: Path, floatfmt: str = ".4g", note: str = "") -> list:
    """Write ``stem.csv`` and ``stem.md`` (``note`` as a paragraph under the markdown
    table); returns the paths."""
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
    if note:
        lines += ["", note]
    stem.with_suffix(".md").write_text("\n".join(lines) + "\n")
    return [stem.with_suffix(".csv"), stem.with_suffix(".md")]


def write_figures(fig_dir: Path, *, time, measured: dict, simulated: dict | None, segmentation,
                  seg_signal, title: str = "", which: str = "689", axle: int = 3) -> list:
    """Figures 6, 8 and 9 as PNG and PDF (each drawn once, saved in both formats).

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
    which : str
        The figures to draw: any of "6", "8", "9" (Figure 6 needs the fit only, so it can be
        drawn before the realisation is chosen; ``simulated`` may then be None).
    axle : int
        The axle whose suspension displacements Figures 8 and 9 show (the run's reference axle).

    Returns
    -------
    list of Path
    """
    from inverse.segmentation import plot_segmentation
    from inverse.validation import plot_amplitude_distributions, plot_time_compare

    fig_dir = Path(fig_dir)
    fig_dir.mkdir(parents=True, exist_ok=True)
    chans = [c for c in (f"susp_disp_{axle}L", f"susp_disp_{axle}R") if c in measured and c in (simulated or {})]

    def both(stem):
        return [fig_dir / f"{stem}.png", fig_dir / f"{stem}.pdf"]

    out = []
    if "6" in which:
        plot_segmentation(segmentation, time, seg_signal, both("figure6_segmentation"),
                          title=f"Figure 6: segmentation {title}")
        out += both("figure6_segmentation")
    if "8" in which:
        plot_time_compare(time, measured, simulated, chans, both("figure8_time_compare"),
                          title=f"Figure 8: measured vs simulated, axle {axle} {title}\n"
                                "simulated on a random-phase road of the fitted spectra: "
                                "not a phase-true (waveform) comparison")
        out += both("figure8_time_compare")
    if "9" in which:
        plot_amplitude_distributions(measured, simulated, chans,
                                     both("figure9_amplitude_distributions"),
                                     title=f"Figure 9: amplitude distributions {title}")
        out += both("figure9_amplitude_distributions")
    return [Path(p) for p in out]
