"""diagnosis.verdict.delay_test: a speed error is tested on the front-to-rear delay it scales.

The rule (``DELAY_RULE``): a speed_scale winner is confirmed where every front/rear pair's
interval of measured/simulated delay excludes 1, their mean lies at least ``DELAY_MIN`` from 1
and the calibrated factor lies within ``DELAY_AGREE`` of the intervals; refuted where the
intervals lie within ``DELAY_MIN`` of 1, or are narrow and contradict the factor; not decided
where the intervals are wide (the transmissibility rules stand).  Hand-built records check
each branch; two saved blind summaries (one made by the Exudyn truck with a 5.4 % speed error
that the verdict had answered `unexplained`, one by the independently written truck with no
speed error) check the rule on what the pipeline writes.
"""
import json
from pathlib import Path

import pytest

from diagnosis import verdict
from diagnosis.report import render_markdown
from diagnosis.verdict import DELAY_AGREE, DELAY_MIN, decide, delay_test

ROOT = Path(__file__).resolve().parents[1] / "results/diagnosis_blind"


def _fr(*pairs):
    """A ``front_rear`` record with one delay row per (ratio, lo, hi)."""
    return {"front_rear": {"delay": [
        {"front": f"axle_acc_1{s}", "rear": f"axle_acc_3{s}", "delay_ratio_meas_over_sim": r,
         "delay_ratio_ci95": [lo, hi]} for s, (r, lo, hi) in zip("LR", pairs)]}}


def test_a_measured_speed_error_the_factor_matches_is_confirmed():
    res = delay_test(_fr((1.054, 1.048, 1.059), (1.056, 1.053, 1.059)), 1.0537)
    assert res["powered"] and res["agrees"] is True and res["why"] == "confirms"
    assert res["ratio"] == pytest.approx((1.054 * 1.056) ** 0.5, rel=1e-12)
    assert res["ci"] == pytest.approx([1.048, 1.059])


def test_a_delay_within_DELAY_MIN_of_one_refutes_whatever_the_factor():
    # the independent truck reads up to 1 % off with no speed error: its geometry is not ours
    res = delay_test(_fr((0.994, 0.990, 0.998), (0.995, 0.991, 0.999)), 0.965)
    assert res["powered"] and res["agrees"] is False and res["why"] == "no_speed_error"


def test_a_narrow_delay_that_contradicts_the_factor_refutes():
    f = 1.05 * (1 + 2 * DELAY_AGREE)      # outside the envelope widened by DELAY_AGREE
    res = delay_test(_fr((1.05, 1.046, 1.054), (1.05, 1.047, 1.053)), f)
    assert res["powered"] and res["agrees"] is False and res["why"] == "contradicts"
    # the same factor inside the widened envelope is confirmed
    assert delay_test(_fr((1.05, 1.046, 1.054), (1.05, 1.047, 1.053)), 1.06)["agrees"] is True


def test_wide_intervals_decide_nothing():
    # the measured road profile: intervals 0.47 and 2.3 wide on saved drives
    res = delay_test(_fr((0.93, 0.46, 1.40), (0.92, 0.40, 3.2)), 0.93)
    assert res["powered"] is False and res["agrees"] is None
    # one pair's interval containing 1 keeps a confirmation out too
    res = delay_test(_fr((1.03, 0.995, 1.06), (1.03, 1.025, 1.035)), 1.03)
    assert res["agrees"] is None
    # no record, no factor: nothing
    assert delay_test({}, 1.05)["powered"] is False
    assert delay_test(_fr((1.05, 1.04, 1.06)), None)["powered"] is False


def test_a_speed_error_inside_DELAY_MIN_cannot_be_confirmed():
    r = 1.0 + 0.8 * DELAY_MIN
    res = delay_test(_fr((r, r - 0.003, r + 0.003), (r, r - 0.003, r + 0.003)), r)
    assert res["agrees"] is not True


def test_saved_speed_error_drive_is_named_with_the_delay(monkeypatch):
    """Seed 607 nominal case 18 (truth factor 1.0536): the transmissibility stayed off (mean z^2
    2.29 > 2) and the remaining gap was 3.1 sd above a correct model's, so without the delay test
    the verdict is `unexplained`; the delay (1.0549 over both sides) confirms the calibrated
    1.0537, and the report says so."""
    s = json.loads((ROOT / "20261130-speed-test-stop66/nominal/case018-summary.json").read_text())
    monkeypatch.setattr(verdict, "DELAY_RULE", False)
    assert decide(s)["verdict"] == "unexplained"
    monkeypatch.setattr(verdict, "DELAY_RULE", True)
    d = decide(s)
    assert d["verdict"] == "speed_scale" and d["signature_agrees"] is True, d["reason"]
    assert "front-to-rear delay" in d["reason"] and "reads +5.5% off the true one" in d["reason"]
    md = render_markdown(dict(s, verdict=d["verdict"], verdict_confidence=d["confidence"],
                              verdict_reason=d["reason"], verdict_detail=d), {})
    assert "Front-to-rear delay test of the speed error" in md and "confirms" in md


def test_saved_independent_truck_drive_without_speed_error_is_not_named():
    """The independently written truck, no library effect, ranked speed_scale at 0.9965 (20261124
    set, case 6; named wrongly before NEGLIGIBLE existed): its delay reads 0.998, inside
    DELAY_MIN, so the delay refutes the speed error on top of NEGLIGIBLE."""
    s = json.loads((ROOT / "20261124-second-18/case006-summary.json").read_text())
    assert s["ranking_decision"]["verdict"] == "speed_scale"
    d = decide(s)
    assert d["verdict"] == "unexplained"
    assert d["signature_own"]["why"] == "no_speed_error"
    assert "no speed error" in d["reason"]


def test_paired_re_decision_of_a_saved_set(monkeypatch):
    """diagnosis.blind.paired on the committed seed-607 nominal set: with and without the delay
    rule only the missed speed error changes (case 18, named; case 7 was named clear already), none goes from
    right to wrong; deciding twice with one rule changes nothing."""
    from diagnosis.blind import paired

    def rule(on):
        def run(s):
            monkeypatch.setattr(verdict, "DELAY_RULE", on)
            return decide(s)
        return run

    lines = []
    folder = ROOT / "20261130-speed-test-stop66/nominal"
    t = paired([folder], rule(False), rule(True), "speed_scale", out=lines.append)
    assert t["drives"] == 22 and t["focus"] == [1, 2, 2] and t["right_to_wrong"] == 0
    assert any("case 18 truth speed_scale" in x and "-> speed_scale" in x for x in lines)
    assert t["changed"] == 1
    same = paired([folder], rule(True), rule(True), "speed_scale", out=lambda x: None)
    assert same["changed"] == 0 and same["effect"][0] == same["effect"][1]
