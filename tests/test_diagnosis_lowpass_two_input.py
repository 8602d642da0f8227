"""diagnosis.verdict LOWPASS_TWO_INPUT: a low-pass named on the gap and the two-input transmissibility.

A sensor low-pass or a tyre's enveloping acts on the axle and the body acceleration alike, so it
leaves every channel ratio where the nominal model had it; on a four-axle truck the single-input
axle-to-body ratio moves with the road and can stay off for a right low-pass.  The rule names such
a winner (`ambiguous`, never identified) when it takes the whole gap AND the nominal model's
two-input transmissibility is within what a correct model reaches against itself.  The saved
summary is a blind drive of our Exudyn truck with a true tyre enveloping of 0.227 m (seed 631,
nominal case 20), answered `unexplained` on the single-input ratio before the rule; the other
cases are that summary with one input changed, so each condition is seen to matter.
"""
import copy
import json
from pathlib import Path

import pytest

from diagnosis import verdict
from diagnosis.report import render_markdown
from diagnosis.verdict import decide

SAVED = (Path(__file__).resolve().parents[1]
         / "results/diagnosis_blind/20261130-fresh-stop67-final/nominal/case020-summary.json")


@pytest.fixture
def summary():
    return json.loads(SAVED.read_text())


def test_saved_tyre_enveloping_is_named_ambiguous_on_the_two_input_transmissibility(summary, monkeypatch):
    monkeypatch.setattr(verdict, "LOWPASS_TWO_INPUT", False)
    assert decide(summary)["verdict"] == "unexplained"
    monkeypatch.setattr(verdict, "LOWPASS_TWO_INPUT", True)
    d = decide(summary)
    assert d["verdict"] == "tyre_enveloping", d["reason"]
    assert d["confidence"] == "ambiguous" and not d["identified"]
    assert d["named_on"] == "two_input"
    assert "two-input transmissibility is within what a correct model reaches" in d["reason"]
    # the low-pass caveat no longer claims the transmissibility agrees
    assert "the transmissibility agrees because" not in d["reason"]
    # the report renders the name and the reason
    s = dict(summary, verdict=d["verdict"], verdict_confidence=d["confidence"], verdict_reason=d["reason"],
             verdict_detail=d)
    md = render_markdown(s, {})
    assert "named on the gap and the two-input transmissibility" in md
    # "What is left" says the two-input record was used, not "not used by the verdict"
    two_line = next(ln for ln in md.splitlines() if ln.strip().startswith("Two-input axle-to-body"))
    assert "the verdict named the low-pass on its nominal value" in two_line, two_line


def test_a_nominal_two_input_beyond_a_correct_models_own_is_not_named(summary):
    s = copy.deepcopy(summary)
    two = s["signature_two_input"]
    two["chi2_nominal"] = 1.05 * max(two["chi2_correct_model"])
    assert decide(s)["verdict"] == "unexplained"


def test_without_the_correct_models_two_input_record_nothing_is_named(summary):
    s = copy.deepcopy(summary)
    s["signature_two_input"].pop("chi2_correct_model")
    assert decide(s)["verdict"] == "unexplained"
    s.pop("signature_two_input")
    assert decide(s)["verdict"] == "unexplained"


def test_a_gap_left_beyond_a_correct_models_is_not_named(summary):
    """The winner's held-out gap must be a correct model's (within FULL_GAP_Z sd)."""
    s = copy.deepcopy(summary)
    win = next(e for e in s["ranking"] if e["effect"] == "tyre_enveloping")
    res = verdict.residual(s, win)
    win["heldout_gap_after"] = res["correct_model_gap"] + 2.5 * verdict.FULL_GAP_Z * res["correct_model_sd"]
    assert decide(s)["verdict"] == "unexplained"


def test_a_vehicle_effect_is_not_named_by_this_rule(summary):
    """The rule is for effects that leave the channel ratios alone; relabelled as a frame
    flexibility (a vehicle effect, inside its search range) the same numbers stay unexplained."""
    s = copy.deepcopy(summary)
    for e in s["ranking"]:
        if e["effect"] == "tyre_enveloping":
            e["effect"] = "frame_flex"
            e["parameters"] = {"frame_flex": {"stiffness_factor": 0.5}}
    s["ranking_decision"]["verdict"] = "frame_flex"
    d = decide(s)
    assert d["verdict"] == "unexplained" and d["closest"] == "frame_flex", d["reason"]


def test_paired_re_decision_with_decide_with_on_the_fresh_set():
    """diagnosis.blind.decide_with switches a verdict setting for one call and restores it: the
    committed fresh low-pass set re-decided without and with the rule changes exactly the one
    drive the rule named (case 1, tyre enveloping 0.284 m), none from right to wrong."""
    from diagnosis.blind import decide_with, paired

    folder = SAVED.parents[2] / "20261130-lowpass-two-input-stop68/lowpass-nominal"
    keep = verdict.LOWPASS_TWO_INPUT
    lines = []
    t = paired([folder], decide_with(LOWPASS_TWO_INPUT=False), decide_with(LOWPASS_TWO_INPUT=True),
               "tyre_enveloping", out=lines.append)
    assert verdict.LOWPASS_TWO_INPUT is keep
    assert t["drives"] == 16 and t["changed"] == 1 and t["right_to_wrong"] == 0
    assert t["focus"][1] == t["focus"][0] + 1
    assert any("case 1 truth tyre_enveloping" in x and "-> tyre_enveloping (ambiguous)" in x for x in lines)
    with pytest.raises(ValueError, match="no setting"):
        decide_with(NO_SUCH_RULE=True)
