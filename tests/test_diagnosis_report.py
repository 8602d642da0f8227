"""The diagnosis report folder (diagnosis.report): summary.json contract, figures, atomic write."""
import json

import numpy as np
import pytest

from diagnosis import toy
from diagnosis.compare import distribution_shape, front_rear, transmissibility
from diagnosis.report import plot_heatmap, write_report
from diagnosis.where import localize
from diagnosis.which import rank_effects
from eroad.errors import EroadInputError


@pytest.fixture(scope="module")
def results():
    truth = toy.make_state({"sensor": {"cutoff_hz": 15.0}})
    meas = toy.simulate_drive(truth, 60.0, 10.0, 3)
    sim = toy.simulate(toy.fit({}, [meas]), meas, 4)
    w = [meas.window(i * 20.0, (i + 1) * 20.0) for i in range(3)]
    rank = rank_effects(toy.TOY_CANDIDATES[2:], toy.fit, toy.simulate, w[:1] + w[2:], w[1:2],
                        seed=1, n_seeds=3, n_null=3, grid=4, refine=4, pairs=False)
    return dict(localization=localize(meas, sim, segments=[("S1", 0, 30), ("S2", 30, 60)]),
                transmissibility=transmissibility(meas, sim),
                front_rear=front_rear(meas, sim, wheelbase=4.0),
                shape=distribution_shape(meas, sim), ranking=rank)


def test_report_folder_and_summary_contract(tmp_path, results):
    """summary.json holds localization / ranking / verdict with the documented fields, is
    strict JSON (no NaN), every figure listed exists and is a PNG, report.md links them."""
    out = write_report(tmp_path / "run", meta={"dataset": "toy"}, **results)
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"] == results["ranking"].verdict
    assert isinstance(s["verdict"], str)
    loc = s["localization"]
    assert len(loc) == 3 * 6 * 21
    assert {"channel", "band_hz", "segment", "log_psd_ratio", "significant"} <= set(loc[0])
    assert len(loc[0]["band_hz"]) == 2
    for r in s["ranking"]:
        assert {"effect", "parameters", "heldout_gap_before", "heldout_gap_after",
                "shrink_fraction"} <= set(r)
    assert [r["effect"] for r in s["ranking"]] == [e.effect for e in results["ranking"].entries]
    md = (out / "report.md").read_text()
    for name, rel in s["figures"].items():
        assert (out / rel).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert rel in md
    assert {"heatmap", "segments", "transmissibility", "ranking", "shrink"} <= set(s["figures"])
    assert "## Where the gap lies" in md and "## Which effect" in md
    json.loads((out / "summary.json").read_text(), parse_constant=lambda c: pytest.fail(c))


def test_report_never_overwrites_without_force(tmp_path, results):
    """An existing non-empty folder is refused (one-line input error) and left untouched;
    with force it is replaced only after the new report is complete; no temp folder remains."""
    out = tmp_path / "run"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    with pytest.raises(EroadInputError, match="not empty"):
        write_report(out, localization=results["localization"])
    assert (out / "mine.txt").read_text() == "keep"
    write_report(out, localization=results["localization"], force=True)
    assert not (out / "mine.txt").exists() and (out / "summary.json").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_figures_replot_from_saved_summary(tmp_path, results):
    """Compute and plot apart: the heat map is drawn from summary.json alone."""
    out = write_report(tmp_path / "run", localization=results["localization"])
    s = json.loads((out / "summary.json").read_text())
    p = plot_heatmap(s, tmp_path / "again.png", segment="S2")
    assert p.stat().st_size > 1000
    assert s["verdict"] == "none" and s["ranking"] == []
    assert np.isfinite([r["log_psd_ratio"] for r in s["localization"]
                        if r["log_psd_ratio"] is not None]).all()


def _captured_figures(monkeypatch):
    """Keep every Figure that diagnosis.report saves (to look at what was drawn)."""
    from matplotlib.figure import Figure

    saved = []
    real = Figure.savefig

    def keep(self, *a, **k):
        saved.append(self)
        return real(self, *a, **k)

    monkeypatch.setattr(Figure, "savefig", keep)
    return saved


def test_report_figures_read_right(tmp_path, results, monkeypatch):
    """segments.png is a grid, not a tall strip; the transmissibility interval says what
    its level is; the ranking's noise band lies behind the bars; the per-band shrink
    shows only bands where both gaps exist (no lone point)."""
    from PIL import Image

    from diagnosis.report import (plot_ranking, plot_segments, plot_shrink_bands,
                                  plot_transmissibility)

    out = write_report(tmp_path / "run", meta={"dataset": "toy"}, **results)
    s = json.loads((out / "summary.json").read_text())
    # four segments (the embedded drive's count): S1, S2 and copies of them as S3, S4
    s4 = json.loads(json.dumps(s))
    st = s4["localization_settings"]
    extra = {"S1": "S3", "S2": "S4"}
    s4["localization"] += [dict(r, segment=extra[r["segment"]]) for r in s4["localization"]
                           if r["segment"] in extra]
    st["windows_s"] = st["windows_s"] + [st["windows_s"][st["segments"].index(k)] for k in extra]
    st["segments"] = st["segments"] + list(extra.values())
    plot_segments(s4, tmp_path / "seg.png")
    with Image.open(tmp_path / "seg.png") as im:
        w, h = im.size
    assert h <= 1.2 * w, (w, h)
    saved = _captured_figures(monkeypatch)
    plot_transmissibility(s, tmp_path / "t.png")
    labels = [t.get_text() for lg in saved[-1].legends for t in lg.get_texts()]
    assert any("FCR-adjusted" in t and "q = " in t for t in labels), labels
    plot_ranking(s, tmp_path / "r.png")
    ax = saved[-1].axes[0]
    band = [p for p in ax.patches if p.get_label().startswith("nominal vs nominal")]
    bars = [p for p in ax.patches if p not in band]
    assert bars and band and max(p.get_zorder() for p in band) < min(p.get_zorder() for p in bars)
    # a band where the nominal gap is missing but the effect's is not
    s2 = json.loads(json.dumps(s))
    pb = s2["how_far"]["per_band"]
    pb[0]["gap_before"], pb[0]["gap_after"] = None, 1.0
    fc0 = pb[0]["band_centre_hz"]
    plot_shrink_bands(s2, tmp_path / "s.png")
    ax = saved[-1].axes[0]
    for line in ax.get_lines()[:2]:   # nominal and effect: neither shows the first band
        x = np.asarray(line.get_xdata(), float)
        assert fc0 not in x and np.isfinite(np.asarray(line.get_ydata(), float)).all()
    assert "no estimate at" in ax.get_title()


def test_segments_in_record_time(tmp_path, results, monkeypatch):
    """Issue 15 item 5: a dataset that is a window of a longer drive (first sample at 460 s)
    shows its segments in record time, as Table 1 of the inversion does, in the report's
    table, its segment list and the segments figure's titles; summary.json keeps the windows
    from the first sample (scripts read them) and says where that sample sits."""
    from diagnosis.report import plot_segments, segment_label

    out = write_report(tmp_path / "run", meta={"dataset": "toy", "record_t0_s": 460.0},
                       **results)
    s = json.loads((out / "summary.json").read_text())
    assert s["localization_settings"]["windows_s"] == [[0.0, 60.0], [0.0, 30.0], [30.0, 60.0]]
    assert segment_label(s, "S2") == "S2 (490.0-520.0 s)"
    assert segment_label(s, "all") == "all"
    md = (out / "report.md").read_text()
    assert "S1 (460.0-490.0 s), S2 (490.0-520.0 s)" in md
    flagged = [ln for ln in md.splitlines() if ln.startswith("| S")]
    assert flagged and all(" s) |" in ln for ln in flagged), flagged[:3]
    saved = _captured_figures(monkeypatch)
    plot_segments(s, tmp_path / "seg.png")
    titles = [ax.get_title() for ax in saved[-1].axes if ax.get_visible() and ax.get_title()]
    assert any(t.startswith("segment S1 (460.0-490.0 s)") for t in titles), titles
    # a summary written before the field existed reads from 0
    del s["meta"]["record_t0_s"]
    assert segment_label(s, "S1") == "S1 (0.0-30.0 s)"


def test_verdict_line_gives_the_calibrated_value_with_its_unit_and_folds():
    # a named effect's value is what a user acts on: it stands in the verdict line, with the
    # library's unit and each fold's value (hand-made entry: the numbers are chosen)
    from pathlib import Path

    from diagnosis.report import _calibrated_value, render_markdown

    entry = {"effect": "bump_stop", "accepted": True,
             "parameters": {"bump_stop": {"gap": 0.00512, "stiffness": 2e6, "smoothing": 0.002}},
             "parameters_per_fold": [{"bump_stop": {"gap": 0.00608}}, {"bump_stop": {"gap": 0.00431}}]}
    s = {"ranking": [entry], "meta": {"search_ranges": {"bump_stop": {"gap": [0.001, 0.08, True]}}}}
    txt = _calibrated_value(s, "bump_stop")
    assert txt == ", calibrated bump_stop.gap = 0.00512 m (folds 0.00608, 0.00431)"
    assert _calibrated_value(s, "unexplained") == "" and _calibrated_value(s, "none") == ""
    # a saved summary of a blind drive (damper asymmetry 3.32, named at 3.42): in the verdict line
    saved = Path(__file__).resolve().parents[1] / "results" / "diagnosis_blind" / \
        "20261127-own-signature-fresh-40" / "nominal" / "case005-summary.json"
    line = render_markdown(json.loads(saved.read_text()), {}).splitlines()
    line = next(ln for ln in line if ln.startswith("**damper_asymmetry**"))
    assert "calibrated damper_asymmetry.ratio = 3.42" in line and "(folds 3.742, 3.127)" in line


def test_the_report_says_how_far_the_static_offset_is():
    """The static-offset paragraph: the offset in mm (recorded by the ranking; from z for older
    summaries: two windows at the 0.5 mm floor give offset = z * 0.5 mm), its sign in words, and the term's part of
    the nominal gap averaged over the folds as the gap is; nothing without the term."""
    from diagnosis.report import _static_offset_text

    fold = lambda z, w: {"static offset": {"z_nominal": [z, z], "weight": w,
                                           "sigma_heldout": [5e-4, 5e-4]}}
    s = {"nominal": {"settings": {"fold_settings": [fold(-40.0, 0.02), fold(-38.0, 0.01)]}}}
    txt = _static_offset_text(s)
    assert "19.5 mm above the measured one (the measured truck sits lower; z -39.0" in txt
    assert f"{(0.02 * 1600 + 0.01 * 1444) / 2:.3g} of the nominal held-out gap" in txt
    quiet = {"nominal": {"settings": fold(0.4, 0.02)}}
    assert "within noise" in _static_offset_text(quiet) and "+0.2 mm" in _static_offset_text(quiet)
    assert _static_offset_text({"nominal": {"settings": {}}}) == ""
    # a summary that records the mismatch itself (mean_rho_nominal, m) is read, not recovered
    # from z (windows of unequal sigma make the recovery approximate)
    f = fold(-40.0, 0.02)
    f["static offset"].update(mean_rho_nominal=[-0.0121, -0.0119], sigma_heldout=[5e-4, 9e-4])
    assert "12.0 mm above the measured one" in _static_offset_text({"nominal": {"settings": f}})


def test_the_ranking_figure_goes_log_when_a_static_load_dwarfs_the_noise():
    """A payload's static offset made a nominal gap of 35.7 against a noise band at 0.15-0.33
    and a winner at 0.99 (a seen independent-truck drive): on a linear axis the winner's bar and
    the band are slivers, so above a factor 20 the axis is logarithmic; the embedded drive's
    0.2-1.9 stays linear."""
    from diagnosis.report import _ranking_axis

    log, lo = _ranking_axis([35.7, 0.99, 27.8], 0.24, 0.046)
    assert log and lo == pytest.approx(0.5 * (0.24 - 2 * 0.046))
    assert _ranking_axis([1.46, 0.42, 1.94], 0.21, 0.031)[0] is False


def test_the_report_shows_the_road_the_diagnosis_assumed():
    """A user comparing with a test drive needs the road the diagnosis drove: one row per
    segment in record time (Gq, w, nmin, nmax), and what the fit made of the high band -- the
    road-cut veto in words where it fired, the cut where the road is cut, nothing without a
    road record (summaries written before it)."""
    from diagnosis.report import _road_text

    seg = lambda n, a, b, nmax: {"segment": n, "t_start_s": a, "t_end_s": b, "Gq_n0_m3": 2.5e-5,
                                 "w": 3.0, "nmin": 0.1, "nmax": nmax}
    meta = {"record_t0_s": 100.0, "road_fit": "levels", "road_w_range": [1.2, 3.0],
            "road_segments": [seg("S1", 0.0, 10.5, 5.0), seg("S2", 10.5, 30.0, 5.0)],
            "road_high_band": {"cut": [], "rolloff": ["S1"], "vetoed": True}}
    txt = "\n".join(_road_text({"meta": meta}))
    assert "| S2 | 110.5-130.0 | 2.5e-05 | 3.00 | 0.1 | 5 |" in txt
    assert "in S1 as a roll-off" in txt and "no segment is cut" in txt
    assert "w at a bound of the fit's range (1.2-3) in S1, S2" in txt
    meta["road_segments"][1]["nmax"] = 2.0
    meta["road_high_band"] = {"cut": ["S2"], "rolloff": [], "vetoed": False}
    txt = "\n".join(_road_text({"meta": meta}))
    assert "Cut road (nothing above nmax" in txt and "in S2" in txt and "no segment is cut" not in txt
    assert _road_text({"meta": {}}) == []


def test_how_far_does_not_call_an_accepted_candidate_not_accepted():
    """Read in a report of a drive answered `unexplained`: the ranking had accepted the sensor
    (the verdict refused to name it), yet "How far" said "NOT accepted". A saved blind summary
    of such a drive (pool set, our truck's case 9: tyre enveloping accepted, verdict
    unexplained) now says what happened."""
    from pathlib import Path

    from diagnosis.report import render_markdown

    saved = Path(__file__).resolve().parents[1] / "results" / "diagnosis_blind" / \
        "20261128-pool-fresh-40" / "nominal" / "case009-summary.json"
    s = json.loads(saved.read_text())
    txt = render_markdown(s, {})
    assert "accepted by the ranking but not named by the verdict" in txt
    assert "NOT accepted" not in txt


def test_what_is_left_names_whose_share_it_gives():
    """"What is left" gives the explained share of the gap: on an `unexplained` drive whose
    residual is the nominal model's (no candidate reduced the gap), the share is the closest
    effect's and is said to be (it read "The explained share ... is 7%" beside "the nominal
    model" written twice); where the residual is a candidate's, that candidate's.  Saved blind
    summaries of the independent truck (stop 63's fresh set: drives 6 and 1)."""
    from pathlib import Path

    from diagnosis.report import render_markdown

    root = Path(__file__).resolve().parents[1] / "results" / "diagnosis_blind" / \
        "20261130-fresh-40-stop63" / "second"

    def left(case):
        md = render_markdown(json.loads((root / f"case{case:03d}-summary.json").read_text()), {})
        return md.split("## What is left", 1)[1].split("##", 1)[0]

    txt = left(6)
    assert "Held-out gap of the nominal model:" in txt and txt.count("the nominal model:") == 1
    assert "The closest effect, speed_scale, explains 7% of the gap above a correct model's" in txt
    txt = left(1)
    assert "Held-out gap of the model with leaf_friction:" in txt and "the nominal model: " in txt
    assert "The effect, leaf_friction, explains 86% of the gap above a correct model's" in txt
