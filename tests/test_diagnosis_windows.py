"""The diagnosis's calibration / held-out windows, and local road features cut out of them
(``diagnosis.pipeline.windows``, ``local_features``, ``window_pieces``; stop 65).

No simulation: the windows are cut from a synthetic record.
"""
import numpy as np
import pytest

from diagnosis.pipeline import (LOCAL_FEATURE_MAX_S, MIN_WINDOW_PIECE_S, local_features,
                                window_pieces, windows)
from diagnosis.signals import Signals
from eroad.errors import EroadInputError


def _record(T=30.0, fs=200.0):
    t = np.arange(int(T * fs)) / fs
    return Signals(t, {"susp_disp_3L": np.sin(t)}, {"susp_disp_3L": "m"}, np.full(t.size, 9.0),
                   {"dataset": "x"})


def test_local_features_are_the_segments_shorter_than_one_period_of_the_lowest_fit_band():
    # the segments of blind case 0 of the measured-road family (seed 431): a half-second piece
    # around a local road feature, then two long segments
    bounds = [0.0, 1.05, 1.55, 23.3, 30.0]
    assert LOCAL_FEATURE_MAX_S == pytest.approx(1.0)
    assert local_features(bounds) == [(1.05, 1.55)]
    assert local_features([0.0, 12.0, 30.0]) == []


def test_window_pieces_cut_out_the_features_and_drop_short_rests():
    assert window_pieces(0.0, 7.5) == [(0.0, 7.5)]
    # the 1.05 s left before the feature is shorter than a usable piece: dropped
    assert window_pieces(0.0, 7.5, [(1.05, 1.55)]) == [(1.55, 7.5)]
    assert window_pieces(0.0, 7.5, [(3.0, 3.5)]) == [(0.0, 3.0), (3.5, 7.5)]
    # features outside the window, or straddling its edge
    assert window_pieces(7.5, 15.0, [(1.05, 1.55), (14.8, 15.3)]) == [(7.5, 14.8)]
    assert window_pieces(0.0, 7.5, [(2.0, 3.0), (4.0, 4.6)]) == [(0.0, 2.0), (4.6, 7.5)]
    assert all(b - a >= MIN_WINDOW_PIECE_S for a, b in window_pieces(0.0, 7.5, [(1.9, 2.1)]))


def test_windows_carry_their_pieces_times_and_samples():
    sig = _record()
    cal, held, edges, cal_e, held_e = windows(sig, 4)
    assert np.allclose(edges, [0, 7.5, 15, 22.5, 30])
    assert cal_e == [(0.0, 7.5), (15.0, 22.5)] and held_e == [(7.5, 15.0), (22.5, 30.0)]
    cal, held, edges, cal_e, held_e = windows(sig, 4, [(1.05, 1.55), (10.0, 10.5)])
    assert cal_e == [(1.55, 7.5), (15.0, 22.5)]
    assert held_e == [(7.5, 10.0), (10.5, 15.0), (22.5, 30.0)]
    for w, (a, b) in zip(cal + held, cal_e + held_e):
        assert w.meta["t0"] == a
        assert w.time.size == pytest.approx((b - a) * sig.fs, abs=1)
        # the piece's samples are the record's from its start
        i0 = int(round(a * sig.fs))
        assert np.array_equal(w.channels["susp_disp_3L"], sig.channels["susp_disp_3L"][i0:i0 + w.time.size])
    assert [w.meta["window"] for w in held] == [2, 2, 4]


def test_a_record_whose_held_out_windows_are_all_features_is_refused_in_one_line():
    sig = _record(T=8.0)
    with pytest.raises(EroadInputError, match="no calibration or no held-out window") as e:
        windows(sig, 4, [(2.0, 4.0), (6.0, 8.0)])
    assert "\n" not in str(e.value)


def test_the_report_names_a_left_out_local_feature():
    from diagnosis.report import _road_text, segment_label

    rows = [{"segment": f"S{k + 1}", "t_start_s": a, "t_end_s": b, "Gq_n0_m3": 1e-4, "w": 3.0,
             "nmin": 0.1, "nmax": 2.0} for k, (a, b) in enumerate([(0.0, 1.05), (1.05, 1.55), (1.55, 30.0)])]
    summary = {"meta": {"record_t0_s": 100.0, "local_road_features_s": [[1.05, 1.55]],
                        "road_segments": rows},
               "localization_settings": {"segments": ["all", "S1", "S2", "S3"],
                                         "windows_s": [[0.0, 30.0], [0.0, 1.05], [1.05, 1.55], [1.55, 30.0]]}}
    assert segment_label(summary, "S2") == "S2 (101.0-101.5 s, local road feature)"
    assert segment_label(summary, "S3") == "S3 (101.5-130.0 s)"
    text = "\n".join(_road_text(summary))
    assert "Local road feature(s) at 101.0-101.5 s" in text and "left out" in text
    summary["meta"]["local_road_features_s"] = []
    assert "Local road feature" not in "\n".join(_road_text(summary))
    assert segment_label(summary, "S2") == "S2 (101.0-101.5 s)"


def test_window_edges_lie_on_samples_so_the_simulation_matches_the_window():
    """A record of 8001 samples (``eroad simulate --duration 40`` writes both ends) cut in four
    put edges between samples (20.0025 s); the simulated window then started one sample after the
    measured one and the ranking stopped on '1999 samples, time has 2000' (stop 65, found as a
    new user)."""
    sig = _record(T=40.005)
    assert sig.time.size == 8001
    cal, held, edges, cal_e, held_e = windows(sig, 4, [(4.75, 5.30), (13.05, 13.55)])
    for w, (a, b) in zip(cal + held, cal_e + held_e):
        i0, i1 = round(a * sig.fs), round(b * sig.fs)
        assert abs(a * sig.fs - i0) < 1e-9 and abs(b * sig.fs - i1) < 1e-9
        # what diagnosis.truck_model.Simulate takes: t0 and the window's own length
        t1 = w.meta["t0"] + w.time.size / sig.fs
        assert round(t1 * sig.fs) - round(w.meta["t0"] * sig.fs) == w.time.size
        assert w.time[0] == sig.time[i0]


def test_a_segment_without_a_fit_takes_its_nearest_fitted_neighbours_value():
    from diagnosis.road_fit import WAVINESS_FILL, nearest_fill

    assert WAVINESS_FILL
    bounds = [0.0, 1.05, 1.55, 23.3, 30.0]
    w = nearest_fill([2.0, 2.0, 3.0, 2.6], [False, False, True, True], bounds)
    # the two short ones take S3's (middle 12.4 s nearer than S4's 26.6 s)
    assert list(w) == [3.0, 3.0, 3.0, 2.6]
    assert list(nearest_fill([2.0, 2.0], [False, False], [0, 1, 2])) == [2.0, 2.0]
    assert list(nearest_fill([2.5, 1.5], [True, True], [0, 1, 2])) == [2.5, 1.5]
