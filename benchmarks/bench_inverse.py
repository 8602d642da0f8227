"""Benchmark: accuracy of ``eroad invert`` against the truth on blind random drives.

For seeds 1, 2, ... until N valid cases (a seed whose dataset the format refuses,
e.g. an acceleration over the plausibility limit on a class E road, is skipped and
listed): ``eroad synth --scenario random --seed S`` (30 s, the truth vehicle
with leaf friction, flexible frame and sensor noise: a model gap the nominal rigid
truck does not have), a copy WITHOUT ``truth/``, the inversion of that copy
(:func:`inverse.cli.run_inversion`, phases of the fit only: the realisation
selection does not change the parameters), then scoring with
``drives.synth.read_truth``:

* per true segment: the fitted segment that overlaps it most;
  |ln(Gq_fit / Gq_true)|, |w_fit - w_true|, class right (ISO class of Gq);
* boundary error [s]: each interior true boundary to the nearest fitted one;
* rows for all segments, segments >= 3 s and >= 8 s; median and worst.

Second truth family (``--scenario second``, docs/second_family.md): the drives come from
the independently written truck (drives/independent_truck.py), not from the nominal
model's builder.  With ``--measured-every 4`` every 4th seed (S - first seed = 0, 4, 8, ...)
drives the measured road profile instead (scenario ``second_measured``, as
diagnosis/blind.py MEASURED_EVERY does); ``--scenario second_measured`` runs only those.
A measured road has no true ISO parameters: ``read_truth`` gives one segment described by
a least-squares line through the log Welch PSD of the whole 544 m profile (0.05-2
cycles/m).  Here the truth of a measured drive is instead the profile the reference
axle actually drove over, :func:`measured_truth`: the Whittle ISO fit of its two wheel
tracks over the driven window and the same band (as :func:`oracle_fits` does for a
synthetic road), and, model-free, the profile's own periodogram at 1 cycle/m and at
each fitted segment's n_best (:func:`profile_scores`).

Run:  nice python benchmarks/bench_inverse.py --cases 20 [--workers 2] [--root DIR]
Per-case results are appended to ROOT/results.jsonl as they come (a rerun skips
cases already there); the table is printed at the end.  No pass/fail.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np


def oracle_fits(dataset: Path, truth: dict, track_y=(-0.9, 0.9)) -> list:
    """The true-road oracle: each true segment's (Gq_n0, w) fitted to the TRUE road.

    The road under the wheels (both wheel tracks of ``truth/road.npz`` between the
    segment's x_start and x_end), one full-length Hann periodogram per track,
    Whittle fit (:func:`roadlib.metrics.fit_iso_psd`) over the segment's own true
    band [nmin, nmax].  No response-based method can know more about a segment's
    spectrum than the exact profile it drove over; this fit is one estimator of it, not
    the information limit (on 3-5 s segments of `null` drives it gets the class right in
    79 % where the Cramer-Rao bound of the same profile allows 87-91 %,
    results/inverse_blind/20261129-class-bound/).
    """
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(Path(dataset) / "truth" / "road.npz")
    out = []
    for s in truth["segments"]:
        fit = _true_road_fit(road, s["x_start"], s["x_end"], (s["nmin"], s["nmax"]), track_y)
        out.append(None if fit is None else
                   dict(fit, dlnGq=abs(math.log(fit["Gq"] / s["Gq_n0"])), dw=abs(fit["w"] - s["w"])))
    return out


def _true_road_fit(road, x0: float, x1: float, band, track_y):
    """The one-slope Whittle fit (``Gq``, ``w``) of the true road's ``track_y`` tracks over
    [x0, x1) m in ``band`` (one full-length Hann periodogram per track); None for fewer than
    64 samples."""
    from roadlib.metrics import fit_iso_psd, profile_psd

    x = np.arange(x0, x1, road.dx)
    if x.size < 64:
        return None
    z = road.tracks(list(track_y), x).T
    fit = fit_iso_psd(profile_psd(z, road.dx, nperseg=x.size), band=band)
    return {"Gq": float(fit.Gd_n0), "w": float(fit.w)}


def _most_overlapping(seg: dict, fit: list) -> dict:
    """The fit segment that overlaps the true segment ``seg`` longest in time (the one it is
    scored with)."""
    ov = [max(0.0, min(seg["t_end"], f["t_end"]) - max(seg["t_start"], f["t_start"])) for f in fit]
    return fit[int(np.argmax(ov))]


def oracle_on_fit_windows(dataset: Path, truth: dict, summary: dict, track_y=(-0.9, 0.9)) -> list:
    """What the segmentation leaves: for each true segment, the one-slope fit (as
    :func:`oracle_fits`, in the true segment's band) to the TRUE road under the FIT segment
    that overlaps it most (the one :func:`score_case` scores it with).  ``summary``'s times
    must be on the truth's reference axle (:func:`on_truth_axle`).  Against
    :func:`oracle_fits` (the true segment's own window) this separates what the fit's
    boundaries cost from what the response-based estimate costs on the same windows."""
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(Path(dataset) / "truth" / "road.npz")
    out = []
    for s in truth["segments"]:
        f = _most_overlapping(s, summary["segments"])
        x0, x1 = reference_axle_x(truth, [f["t_start"], f["t_end"]])
        out.append(_true_road_fit(road, max(float(x0), 0.0), float(x1), (s["nmin"], s["nmax"]), track_y))
    return out


#: lateral positions [m] of the reference axle's wheel tracks (axle 3 of dump_truck_8x4:
#: track 1.86 m, vehicles/params/dump_truck_8x4.toml); the measured-road profile is read there
REF_TRACK_Y = (-0.93, 0.93)
#: half-width of the band over which the profile's periodogram is averaged around a
#: frequency n: [n / B, n B] with B = 2^(1/6), one third of an octave.  For a power law of
#: waviness 1.5-3.5 the band mean differs from the value at n by < 1.2 % (band_mean_bias).
THIRD_OCTAVE = 2.0 ** (1.0 / 6.0)


def band_mean_bias(w: float, b: float = THIRD_OCTAVE) -> float:
    """Mean of (n/n_c)^-w over [n_c / b, n_c b] (linear frequency), relative to its value at n_c."""
    if abs(w - 1.0) < 1e-12:
        return math.log(b * b) / (b - 1.0 / b)
    return (b ** (1.0 - w) - b ** (w - 1.0)) / ((1.0 - w) * (b - 1.0 / b))


def fitted_psd(f: dict, n: float) -> float:
    """A fitted segment's road PSD at ``n`` [cycles/m] [m^3]: the spectrum the segment
    reports (``inverse.road_model.segment_spectrum``: two slopes where the road model chose
    them, else the one-slope fit), as handed on to road.npz."""
    from inverse.road_model import segment_spectrum
    from roadlib.psd import road_psd

    return float(road_psd(n, *segment_spectrum(f)))


def reference_axle_x(truth: dict, t, axle: int | None = None) -> np.ndarray:
    """Road x [m] of the reference axle (or of ``axle``) at record times ``t`` [s].

    Rebuilt from ``truth.json`` exactly as drives.synth.plan_drive lays the drive out:
    PCHIP speed through the speed knots, sampled at the output rate from the run-in's
    start, integrated by the trapezoid rule, plus axle 1's start position and the
    reference axle's offset.
    """
    from scipy.interpolate import PchipInterpolator

    rec, sp = truth["record"], truth["speed"]
    fs, runin, T = float(rec["sample_rate_hz"]), float(rec["runin_s"]), float(rec["duration_s"])
    k = np.arange(-int(round(runin * fs)), int(round(T * fs)) + 1)
    t_rec = k / fs
    v = PchipInterpolator(np.asarray(sp["t_s"], float), np.asarray(sp["v_mps"], float))(t_rec)
    s = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t_rec))])
    ax = truth["vehicle"]["axle_x_m"][int(axle or rec["reference_axle"]) - 1]
    x = float(truth["road"]["x_axle1_at_sim_start_m"]) + ax + s
    return np.interp(np.asarray(t, float), t_rec, x)


def on_truth_axle(truth: dict, summary: dict) -> dict:
    """``summary`` with its segment times moved to the truth's reference axle: a fit on
    another axle (``fit.reference_axle``, a drive logged on axle 1) places its boundaries
    where THAT axle crosses them; the truth's are axle 3's, a few tenths of a second later."""
    a = int(summary.get("fit", {}).get("reference_axle") or truth["record"]["reference_axle"])
    if a == int(truth["record"]["reference_axle"]):
        return summary
    rec = truth["record"]
    tt = np.arange(-float(rec["runin_s"]), float(rec["duration_s"]) + 1.0, 0.01)
    x_ref = reference_axle_x(truth, tt)
    segs = []
    for f in summary["segments"]:
        x0, x1 = reference_axle_x(truth, [f["t_start"], f["t_end"]], axle=a)
        segs.append({**f, "t_start": float(np.interp(x0, x_ref, tt)), "t_end": float(np.interp(x1, x_ref, tt))})
    segs[0]["t_start"], segs[-1]["t_end"] = summary["segments"][0]["t_start"], summary["segments"][-1]["t_end"]
    return {**summary, "segments": segs}


def window_psd(road, x0: float, x1: float, track_y=REF_TRACK_Y):
    """One full-length Hann periodogram per wheel track over road x in [x0, x1], averaged."""
    from roadlib.metrics import profile_psd

    x = np.arange(x0, x1, road.dx)
    if x.size < 64:
        return None
    return profile_psd(road.tracks(list(track_y), x).T, road.dx, nperseg=x.size)


def band_mean(est, n: float, b: float = THIRD_OCTAVE) -> tuple[float, int]:
    """Mean periodogram over [n / b, n b] and the number of bins in it (per track)."""
    sel = (est.n >= n / b) & (est.n <= n * b)
    if not np.any(sel):
        return float("nan"), 0
    return float(np.mean(est.G[sel])), int(sel.sum())


def measured_truth(dataset: Path, truth: dict, track_y=REF_TRACK_Y) -> dict:
    """The truth of a measured-road drive: the profile actually driven, ISO-fitted.

    ``read_truth`` describes the measured profile as a whole (all 544 m, left edge,
    least-squares line through log Welch PSD).  The segment the reference axle drove
    (record time 0 to the end) is re-described here by the Whittle ISO fit
    (:func:`roadlib.metrics.fit_iso_psd`) of the two wheel tracks' periodograms over the
    driven window, in the truth's band [nmin, nmax]: the same rule :func:`oracle_fits`
    applies to a synthetic segment, so for this drive the inversion is scored against
    its oracle.  The whole-profile description is kept as ``Gq_n0_profile_file``,
    ``w_profile_file``.
    """
    from roadlib.metrics import fit_iso_psd
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(Path(dataset) / "truth" / "road.npz")
    out = dict(truth)
    segs = []
    for s in truth["segments"]:
        x0, x1 = reference_axle_x(truth, [s["t_start"], s["t_end"]])
        est = window_psd(road, x0, x1, track_y)
        fit = fit_iso_psd(est, band=(s["nmin"], s["nmax"]))
        segs.append(dict(s, Gq_n0=float(fit.Gd_n0), w=float(fit.w), x_start=float(x0), x_end=float(x1),
                         Gq_n0_profile_file=s["Gq_n0"], w_profile_file=s["w"],
                         truth_rule="Whittle ISO fit of the driven window's wheel tracks"))
    out["segments"] = segs
    return out


def profile_scores(dataset: Path, truth: dict, summary: dict, track_y=REF_TRACK_Y) -> list:
    """Each FITTED segment against the measured profile under it, model-free.

    For fitted segment [t_start, t_end]: the reference axle's road window, the wheel
    tracks' periodogram there (:func:`window_psd`), its third-octave mean at 1 cycle/m
    and at the segment's n_best (:func:`band_mean`), and the ISO fit of the window over
    the truth's band.  Errors are ln(fit / profile); the fit's PSD at 1 cycle/m is
    Gq_n0 (1 / 0.1)^-w (:func:`fitted_psd`: two slopes where the fit has them).
    """
    from roadlib.metrics import fit_iso_psd
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(Path(dataset) / "truth" / "road.npz")
    band = (truth["segments"][0]["nmin"], truth["segments"][0]["nmax"])
    rows = []
    for f in summary["segments"]:
        x0, x1 = reference_axle_x(truth, [f["t_start"], f["t_end"]])
        est = window_psd(road, x0, x1, track_y)
        r = {"t_start": f["t_start"], "t_end": f["t_end"], "duration_s": f["t_end"] - f["t_start"],
             "x_start": float(x0), "x_end": float(x1), "Gq_fit": f["Gq_n0"], "w_fit": f["w"],
             "objective": f.get("objective"), "n_features": f.get("n_features"),
             "fit_quality": f.get("fit_quality"), "sd_laplace": f.get("sd_laplace"),
             "sd_ln_Gq_n0": f.get("sd_ln_Gq_n0"), "sd_w": f["sd"]["w"]}
        if est is None:
            rows.append(r)
            continue
        try:
            iso = fit_iso_psd(est, band=band)
            r.update(Gq_prof=float(iso.Gd_n0), w_prof=float(iso.w))
        except Exception as exc:   # too few bins in the band on a very short window
            r["iso_fit_error"] = str(exc)
        g1, n1 = band_mean(est, 1.0)
        g1_fit = fitted_psd(f, 1.0)
        r.update(G1_prof=g1, G1_fit=g1_fit, G1_bins=n1, lnG_1cpm_err=math.log(g1_fit / g1))
        if "n_best" in f:
            gb, nb = band_mean(est, f["n_best"])
            r.update(n_best=f["n_best"], G_n_best_prof=gb, G_n_best_fit=f["G_n_best"], G_n_best_bins=nb,
                     lnG_n_best_err=math.log(f["G_n_best"] / gb), sd_ln_G_n_best=f["sd_ln_G_n_best"],
                     sd_ln_G_n_best_laplace=f.get("sd_ln_G_n_best_laplace"))
        rows.append(r)
    return rows


def score_case(truth: dict, summary: dict) -> dict:
    """Per-segment errors of one inversion against its truth."""
    from inverse.pipeline import segment_errors
    from roadlib.psd import class_of

    fit = summary["segments"]
    tf = np.array([fit[0]["t_start"]] + [s["t_end"] for s in fit])
    tsegs = truth["segments"]
    tt = np.array([tsegs[0]["t_start"]] + [s["t_end"] for s in tsegs])
    rows = []
    for s in tsegs:
        f = _most_overlapping(s, fit)
        rows.append({"duration_s": s["t_end"] - s["t_start"], "Gq_true": s["Gq_n0"], "Gq_fit": f["Gq_n0"],
                     "w_true": s["w"], "w_fit": f["w"], "dlnGq": abs(math.log(f["Gq_n0"] / s["Gq_n0"])),
                     "dw": abs(f["w"] - s["w"]), "class_true": class_of(s["Gq_n0"]),
                     "class_fit": class_of(f["Gq_n0"]),
                     # the PSD at 1 cycle/m (~10 Hz at 10 m/s, where the truck responds)
                     "dlnG_1cpm": abs(math.log(fitted_psd(f, 1.0) / (s["Gq_n0"] * 10.0 ** -s["w"]))),
                     "lnG_1cpm_err": math.log(fitted_psd(f, 1.0) / (s["Gq_n0"] * 10.0 ** -s["w"])),
                     # signed errors and what the fit reported, for the interval calibration
                     "lnGq_err": math.log(f["Gq_n0"] / s["Gq_n0"]), "w_err": f["w"] - s["w"],
                     "sd_ln_Gq_n0": f["sd"]["ln_Gq_n0"], "sd_w": f["sd"]["w"],
                     "sd_laplace": f.get("sd_laplace", f["sd"]),
                     **{key: f[key] for key in ("sd_robust", "consistency") if key in f},
                     "sd_ln_G_n_best_laplace": f.get("sd_ln_G_n_best_laplace", f.get("sd_ln_G_n_best")),
                     "fit_quality": f.get("fit_quality"),
                     "objective": f.get("objective"), "n_features": f.get("n_features"),
                     "fit_duration_s": f["t_end"] - f["t_start"],
                     **({"interval": f["interval"]} if "interval" in f else {}),
                     **({"n_best": f["n_best"], "sd_ln_G_n_best": f["sd_ln_G_n_best"],
                         "lnG_n_best_err": math.log(f["G_n_best"] / (s["Gq_n0"] * (f["n_best"] / 0.1) ** -s["w"])),
                         "dlnG_n_best": abs(math.log(f["G_n_best"] / (s["Gq_n0"] * (f["n_best"] / 0.1) ** -s["w"])))}
                        if "n_best" in f else {})})
    berr = segment_errors(tt, tf)
    return {"segments": rows, "boundary_err_s": [float(b) for b in np.abs(berr)],
            "K_true": len(tsegs), "K_fit": len(fit)}


def oracle_g1_errors(rows: list, key: str = "oracle") -> np.ndarray:
    """|ln(G_oracle(1 cycle/m) / G_true(1 cycle/m))| of the rows with an oracle: the
    oracle's one-slope fit (``oracle_fits``; ``key="oracle_fit_window"``: on the fit's own
    window, :func:`oracle_on_fit_windows`) against the segment's true ISO spectrum, both
    at n = 1 cycle/m (n0 = 0.1).  What the road under the wheels allows at the frequency the
    G(1 cycle/m) target asks about."""
    out = [abs(math.log(r[key]["Gq"] * 10.0 ** -r[key]["w"]
                        / (r["Gq_true"] * 10.0 ** -r["w_true"])))
           for r in rows if r.get(key) and r.get("Gq_true") and r.get("w_true") is not None]
    return np.asarray(out, float)


def table(cases: list) -> str:
    segs = [r for c in cases for r in c["segments"]]
    bnd = np.array([b for c in cases for b in c["boundary_err_s"]], float)
    lines = ["| segments | n | median abs ln(Gq) | worst | Gq within 20% | median abs w err | worst | "
             "w within 0.15 | class right | boundary err median / worst [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, lo in (("all", 0.0), (">= 3 s", 3.0), (">= 8 s", 8.0)):
        rs = [r for r in segs if r["duration_s"] >= lo]
        if not rs:
            continue
        g = np.array([r["dlnGq"] for r in rs])
        w = np.array([r["dw"] for r in rs])
        cl = np.mean([r["class_true"] == r["class_fit"] for r in rs])
        b = f"{np.nanmedian(bnd):.2f} / {np.nanmax(bnd):.2f}" if name == "all" and bnd.size else ""
        lines.append(f"| {name} | {len(rs)} | {np.median(g):.3f} | {g.max():.3f} | "
                     f"{100 * np.mean(g <= math.log(1.2)):.0f}% | {np.median(w):.3f} | {w.max():.3f} | "
                     f"{100 * np.mean(w <= 0.15):.0f}% | {100 * cl:.0f}% | {b} |")
        pairs = [(r, r["oracle"]) for r in rs if r.get("oracle")]   # rows without an oracle are skipped
        orc = [o for _, o in pairs]
        if orc:
            from roadlib.psd import class_of
            go = np.array([o["dlnGq"] for o in orc])
            wo = np.array([o["dw"] for o in orc])
            clo = np.mean([class_of(o["Gq"]) == r["class_true"] for r, o in pairs])
            lines.append(f"| {name}, true-road oracle | {len(orc)} | {np.median(go):.3f} | {go.max():.3f} | "
                         f"{100 * np.mean(go <= math.log(1.2)):.0f}% | {np.median(wo):.3f} | {wo.max():.3f} | "
                         f"{100 * np.mean(wo <= 0.15):.0f}% | {100 * clo:.0f}% | |")
    lines.append("\nThe fitted PSD where the truck sees the road (segments >= 3 s):")
    rs = [r for r in segs if r["duration_s"] >= 3.0]
    g1 = np.array([r["dlnG_1cpm"] for r in rs if "dlnG_1cpm" in r])
    if g1.size:
        lines.append(f"* at 1 cycle/m: median abs ln error {np.median(g1):.3f}, within 20% in "
                     f"{100 * np.mean(g1 <= math.log(1.2)):.0f}% of {g1.size}")
        e1 = np.array([r["lnG_1cpm_err"] for r in rs if "lnG_1cpm_err" in r])
        if e1.size:
            lines.append(f"  (signed ln error: mean {e1.mean():+.3f}, sd {e1.std(ddof=1):.3f}; "
                         "within 20% in 90% of segments asks an unbiased error of sd <= 0.11)")
        og = oracle_g1_errors(rs)
        if og.size:
            lines.append(f"* the true-road oracle at 1 cycle/m (its fit to the road under the wheels): "
                         f"median abs ln error {np.median(og):.3f}, within 20% in "
                         f"{100 * np.mean(og <= math.log(1.2)):.0f}% of {og.size}")
        ow = oracle_g1_errors(rs, "oracle_fit_window")
        if ow.size:
            lines.append(f"* the same oracle on the fit's own windows (the true road under the fit segment "
                         f"each true segment is scored with): median abs ln error {np.median(ow):.3f}, "
                         f"within 20% in {100 * np.mean(ow <= math.log(1.2)):.0f}% of {ow.size}")
            for name, sel in (("K right", True), ("K wrong", False)):
                sub = [r for c in cases for r in c["segments"] if r["duration_s"] >= 3.0
                       and (c["K_true"] == c["K_fit"]) == sel and "dlnG_1cpm" in r]
                if sub:
                    f1 = np.array([r["dlnG_1cpm"] for r in sub])
                    o1 = oracle_g1_errors(sub, "oracle_fit_window")
                    lines.append(f"  {name} ({len(sub)} segments): fit within 20% in "
                                 f"{100 * np.mean(f1 <= math.log(1.2)):.0f}%, the oracle on its windows in "
                                 + (f"{100 * np.mean(o1 <= math.log(1.2)):.0f}%" if o1.size else "-"))
    gb = [r for r in rs if "dlnG_n_best" in r]
    if gb:
        e = np.array([r["dlnG_n_best"] for r in gb])
        z = e / np.array([r["sd_ln_G_n_best"] for r in gb])
        nb = np.array([r["n_best"] for r in gb])
        lines.append(f"* at each segment's n_best (median {np.median(nb):.2f} cycles/m): median abs ln error "
                     f"{np.median(e):.3f}, within 20% in {100 * np.mean(e <= math.log(1.2)):.0f}%; "
                     f"error / reported sd: median {np.median(z):.2f} (0.67 if the sd is right)")
    kr = np.mean([c["K_true"] == c["K_fit"] for c in cases])
    lines.append(f"\n{len(cases)} cases, K right in {100 * kr:.0f}%, median wall "
                 f"{np.median([c['wall_s'] for c in cases]):.1f} s per inversion")
    return "\n".join(lines)


def score_run(ds: Path, scen: str, summ: dict) -> dict:
    """One inversion's ``summary.json`` scored against the truth of its dataset ``ds``."""
    from drives.synth import read_truth

    truth = read_truth(ds)
    summ = on_truth_axle(truth, summ)
    if scen == "second_measured":   # no true ISO segment: the driven profile, fitted (measured_truth)
        mtruth = measured_truth(ds, truth)
        case = score_case(mtruth, summ)
        for r, s0, s1 in zip(case["segments"], truth["segments"], mtruth["segments"]):
            r.update(oracle=None, Gq_profile_file=s0["Gq_n0"], w_profile_file=s0["w"],
                     x_start=s1["x_start"], x_end=s1["x_end"])
        case["profile"] = profile_scores(ds, truth, summ)
    else:
        case = score_case(truth, summ)
        for r, o, ow in zip(case["segments"], oracle_fits(ds, truth), oracle_on_fit_windows(ds, truth, summ)):
            r["oracle"] = o
            r["oracle_fit_window"] = ow
    case["fit_model"] = summ.get("fit", {}).get("model")
    case["solver"] = summ.get("timing", {}).get("solver")
    loop = summ.get("closed_loop")
    if loop is not None:
        case["closed_loop"] = {k: loop.get(k) for k in ("verdict", "confidence", "effects", "corrected",
                                                         "model_form")}
        if loop.get("corrected") and scen != "second_measured":
            case["nominal"] = score_case(truth, {"segments": loop["nominal_segments"]})["segments"]
    return case


def vehicle_tag(vehicle) -> str:
    """How a dataset name and a record name a vehicle: a built-in id, or a TOML file's stem."""
    return Path(vehicle).stem


def dataset_tag(scenario: str, vehicle=None) -> str:
    """The dataset folder's name before its seed: the scenario, with the vehicle where one was
    given (``--vehicle``), so that two vehicles' drives can share a data root."""
    return f"{scenario}-{vehicle_tag(vehicle)}" if vehicle else scenario


def rescore(root: Path, data_root: Path) -> list:
    """Score again every case of ROOT/results.jsonl from its saved ``run-SEED/summary.json``
    (e.g. after a change of the scoring); the new records go to ROOT/results-rescored.jsonl,
    the old file is kept."""
    cases = []
    for line in (root / "results.jsonl").read_text().splitlines():
        old = json.loads(line)
        if "skipped" in old:
            continue
        summ = json.loads((root / f"run-{old['seed']}" / "summary.json").read_text())
        case = score_run(data_root / f"{dataset_tag(old['scenario'], old.get('vehicle'))}-{old['seed']}",
                         old["scenario"], summ)
        case.update(seed=old["seed"], scenario=old["scenario"], wall_s=old["wall_s"],
                    **({"vehicle": old["vehicle"]} if old.get("vehicle") else {}))
        cases.append(case)
    with (root / "results-rescored.jsonl").open("w") as f:
        for c in cases:
            f.write(json.dumps(c) + "\n")
    return sorted(cases, key=lambda c: c["seed"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-iter", type=int, default=10)
    ap.add_argument("--channels", default=None,
                    help="as `eroad invert --channels` (default: axle 3; with --effects-auto chosen by the "
                         "verdict, diagnosis.closed_loop.loop_channels)")
    ap.add_argument("--root", default="/tmp/eroad-bench-inverse")
    ap.add_argument("--data-root", default=None,
                    help="where the synthetic datasets are made or found (default: ROOT); share "
                         "it between runs that compare settings on the same drives")
    ap.add_argument("--no-polish", action="store_true", help="switch off the fit's polishing step")
    ap.add_argument("--segment-on", default="displacement", choices=["displacement", "axle_acc"],
                    help="as `eroad invert --segment-on`: what locates the segment boundaries")
    ap.add_argument("--solver", default=None, choices=["linear", "exudyn"],
                    help="integrator of the inversion's time simulations, as run_inversion(solver=...) "
                         "(default inverse.truck.SIM_SOLVER)")
    ap.add_argument("--fit", default="linear", choices=["linear", "simulation"],
                    help="the fit's model, as `eroad invert --fit` (each record's fit_model field says which ran)")
    ap.add_argument("--known-noise", action="store_true",
                    help="give the inversion the sensor-noise levels (a data-sheet value a user "
                         "would know; read from truth/ noise, nothing else of the truth)")
    ap.add_argument("--scenario", default="random", choices=["random", "null", "second", "second_measured"],
                    help="random: the truth has leaf friction and a flexible frame the nominal "
                         "model lacks; null: the truth vehicle IS the nominal model (the method's "
                         "accuracy alone, with the finer step, finer road grid and sensor noise); "
                         "second: the independently written truck (docs/second_family.md) on a "
                         "synthetic ISO road; second_measured: the same truck on the measured profile")
    ap.add_argument("--measured-every", type=int, default=0, metavar="K",
                    help="with --scenario second: seeds S with (S - first seed) %% K == 0 drive the "
                         "measured profile (scenario second_measured); diagnosis/blind.py uses K = 4")
    ap.add_argument("--vehicle", default=None,
                    help="truth and model vehicle of scenarios random and null (built-in id or "
                         "TOML; default the scenario's, the dump truck); its datasets are named "
                         "SCENARIO-VEHICLE-SEED")
    ap.add_argument("--no-default-effects", action="store_true",
                    help="truth vehicle without the scenario's leaf friction (no model gap but the "
                         "flexible frame and the finer step): the method's accuracy alone")
    ap.add_argument("--effects-auto", action="store_true",
                    help="invert as `eroad invert --effects auto` does: diagnose each drive first and "
                         "invert with the effect a clear verdict names (the loop closed); the nominal "
                         "inversion of the same drive is scored beside it (`nominal` rows)")
    ap.add_argument("--diagnoses", default=None, metavar="ROOT",
                    help="with --effects-auto: use the diagnoses of an earlier --effects-auto root "
                         "(ROOT/run-SEED/diagnose) instead of diagnosing each drive again; the diagnosis "
                         "does not depend on the inversion's options (e.g. --fit)")
    ap.add_argument("--rescore", action="store_true",
                    help="score the saved runs of --root again against the truths under --data-root "
                         "(no inversion); writes ROOT/results-rescored.jsonl and prints the table")
    a = ap.parse_args(argv)
    if a.rescore:
        root = Path(a.root)
        print(report(rescore(root, Path(a.data_root) if a.data_root else root)))
        return 0
    if a.diagnoses and not a.effects_auto:
        ap.error("--diagnoses needs --effects-auto")
    if a.measured_every and a.scenario != "second":
        ap.error("--measured-every needs --scenario second")
    if a.measured_every < 0:
        ap.error("--measured-every must be >= 0")
    if a.vehicle and a.scenario not in ("random", "null"):
        ap.error("--vehicle is for scenarios random and null (the independent truck is the dump truck)")
    from drives.synth import copy_without_truth, read_truth, synth_command
    from eroad.errors import EroadInputError
    from inverse.cli import run_inversion

    root = Path(a.root)
    root.mkdir(parents=True, exist_ok=True)
    data_root = Path(a.data_root) if a.data_root else root
    data_root.mkdir(parents=True, exist_ok=True)
    res_file = root / "results.jsonl"
    done = {}
    if res_file.is_file():
        for line in res_file.read_text().splitlines():
            d = json.loads(line)
            done[d["seed"]] = d
    seed = a.first_seed
    valid = [d for d in done.values() if "skipped" not in d]
    while len(valid) < a.cases:
        if seed in done:
            seed += 1
            continue
        scen = a.scenario
        if a.measured_every and (seed - a.first_seed) % a.measured_every == 0:
            scen = "second_measured"
        tag = dataset_tag(scen, a.vehicle)
        ds = data_root / f"{tag}-{seed}"
        try:
            if not (ds / "truth" / "summary.json").is_file():
                synth_command(scenario=scen, seed=seed, out=ds, force=True, vehicle=a.vehicle,
                              default_effects=not a.no_default_effects)
        except EroadInputError as exc:   # e.g. a class E road overloads a sensor range
            case = {"seed": seed, "scenario": scen, "skipped": str(exc)}
            with res_file.open("a") as f:
                f.write(json.dumps(case) + "\n")
            done[seed] = case
            print(f"seed {seed}: skipped ({exc})", flush=True)
            seed += 1
            continue
        blind = data_root / f"blind-{tag}-{seed}"
        if not blind.exists():
            copy_without_truth(ds, blind)
        noise = None
        if a.known_noise:
            nz = read_truth(ds)["noise"]
            noise = {q: nz[key] for q, key in (("susp_disp", "susp_disp_m"), ("axle_acc", "axle_acc_mps2"),
                                                ("body_acc", "body_acc_mps2"))}
        t0 = time.perf_counter()
        inv = dict(workers=a.workers, seed=0, candidates=0, max_iter=a.max_iter, channels=a.channels,
                   force=True, polish=not a.no_polish, noise_sd=noise, fit_model=a.fit,
                   segment_on=a.segment_on, solver=a.solver)
        if a.effects_auto:
            from diagnosis.closed_loop import invert_closed_loop
            dg = Path(a.diagnoses) / f"run-{seed}" / "diagnose" if a.diagnoses else None
            if dg is not None and not (dg / "summary.json").is_file():
                raise SystemExit(f"--diagnoses: no diagnosis of seed {seed} at {dg}")
            summ = invert_closed_loop(blind, root / f"run-{seed}", progress=lambda _m: None, diagnosis=dg, **inv)
        else:
            summ = run_inversion(blind, root / f"run-{seed}", **inv)
        wall = time.perf_counter() - t0
        case = score_run(ds, scen, summ)
        case.update(seed=seed, scenario=scen, wall_s=wall,
                    **({"vehicle": vehicle_tag(a.vehicle)} if a.vehicle else {}))
        with res_file.open("a") as f:
            f.write(json.dumps(case) + "\n")
        done[seed] = case
        valid.append(case)
        print(f"seed {seed}: K {case['K_fit']}/{case['K_true']}, "
              f"dlnGq {[round(r['dlnGq'], 2) for r in case['segments']]}, {case['wall_s']:.0f} s", flush=True)
        seed += 1
    cases = sorted(valid, key=lambda c: c["seed"])[:a.cases]
    skipped = [d["seed"] for d in done.values() if "skipped" in d]
    if skipped:
        print(f"skipped seeds (dataset refused by the format's plausibility checks): {sorted(skipped)}")
    print(report(cases))
    return 0


def profile_table(cases: list, min_s: float = 3.0) -> str:
    """Measured-road drives: every fitted segment >= ``min_s`` against the profile under it."""
    from roadlib.psd import class_of

    rs = [r for c in cases for r in c.get("profile", []) if r["duration_s"] >= min_s and "lnG_1cpm_err" in r]
    if not rs:
        return ""
    g1 = np.abs([r["lnG_1cpm_err"] for r in rs])
    lines = [f"Measured road, each fitted segment >= {min_s:g} s against the profile under it "
             f"({len(rs)} segments of {len(cases)} drives; third-octave periodogram means, ISO fit "
             f"over the truth's band):",
             f"* G(1 cycle/m): median abs ln error {np.median(g1):.3f}, signed median "
             f"{np.median([r['lnG_1cpm_err'] for r in rs]):+.3f}, within 20% in "
             f"{100 * np.mean(g1 <= math.log(1.2)):.0f}%"]
    gb = [r for r in rs if "lnG_n_best_err" in r]
    if gb:
        e = np.array([r["lnG_n_best_err"] for r in gb])
        sd = np.array([r["sd_ln_G_n_best"] for r in gb])
        lines.append(f"* G(n_best): median abs ln error {np.median(np.abs(e)):.3f}, signed median "
                     f"{np.median(e):+.3f}, within 20% in {100 * np.mean(np.abs(e) <= math.log(1.2)):.0f}%, "
                     f"inside the reported 90 % interval in {100 * np.mean(np.abs(e) <= 1.6448536 * sd):.0f}%")
    iso = [r for r in rs if "Gq_prof" in r]
    if iso:
        dq = np.abs([math.log(r["Gq_fit"] / r["Gq_prof"]) for r in iso])
        dw = np.abs([r["w_fit"] - r["w_prof"] for r in iso])
        cl = np.mean([class_of(r["Gq_fit"]) == class_of(r["Gq_prof"]) for r in iso])
        lines.append(f"* ISO fit of the window: median abs ln Gq {np.median(dq):.3f}, median abs w err "
                     f"{np.median(dw):.3f}, profile w median {np.median([r['w_prof'] for r in iso]):.2f}, "
                     f"fitted w median {np.median([r['w_fit'] for r in iso]):.2f}, class right {100 * cl:.0f}%")
    poor = np.mean([(r.get("fit_quality") or {}).get("status") == "poor" for r in rs])
    lines.append(f"* flagged poor by the fit-quality gate: {100 * poor:.0f}%")
    return "\n".join(lines)


def report(cases: list) -> str:
    """The table over all cases; with several scenarios also one table per scenario."""
    scens = sorted({c.get("scenario", "") for c in cases})
    out = []
    if len(scens) > 1:
        out.append(f"## all {len(cases)} drives\n\n" + table(cases))
        for sc in scens:
            sub = [c for c in cases if c.get("scenario", "") == sc]
            out.append(f"## {sc}: {len(sub)} drives\n\n" + table(sub))
    else:
        out.append(table(cases))
    pt = profile_table(cases)
    if pt:
        out.append(pt)
    return "\n\n".join(out)


if __name__ == "__main__":
    sys.exit(main())
