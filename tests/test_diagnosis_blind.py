"""Scoring of the blind check (diagnosis.blind.score) on hand-made results."""
import pytest

from diagnosis.blind import Z_PAIRED, format_confusion, score


def _r(case, effect, verdict, conf, true_shrink=None, z=None):
    return dict(case=case, effect=effect, verdict=verdict, confidence=conf,
                correct=(verdict == effect),
                confident_wrong=(verdict not in (effect, "none") and conf == "clear"),
                localisation_hit=True, n_flagged=3, predicted_shrink=0.3 if verdict == effect else 0.0,
                true_shrink=true_shrink, true_paired_z=z, heldout_gap_before=0.5, null_sd=0.05)


def test_score_counts_detectable_cases_by_the_paired_gate():
    """A case is detectable when the truth effect at its true strength has a positive
    held-out shrink and a paired z above Z_PAIRED (the ranking's own gate); a strong z with
    a negative shrink (the truth does not close the gap in the diagnosis model) is not."""
    res = [_r(0, "none", "none", "none"),
           _r(1, "payload", "payload", "clear", 0.3, Z_PAIRED + 2),
           _r(2, "bump_stop", "payload", "ambiguous", -0.05, Z_PAIRED + 2),      # not detectable
           _r(3, "sensor", "none", "none", 0.08, Z_PAIRED - 1),                  # not detectable
           _r(4, "frame_flex", "tyre_enveloping", "clear", 0.2, Z_PAIRED + 5)]   # confident wrong
    sc = score(res)
    assert sc["n_detectable"] == 2
    assert sc["detectable_top1_accuracy"] == pytest.approx(0.5)
    assert sc["top1_accuracy"] == pytest.approx(2 / 5)
    assert sc["confident_wrong"] == 1
    assert sc["null_none_rate"] == 1.0
    assert sc["undetectable_none_rate"] == pytest.approx(0.5)
    assert "payload" in format_confusion(sc)


def test_judge_counts_unexplained_right_only_without_a_library_effect():
    from diagnosis.blind import judge, param_ratio

    none_case = {"effect": "none"}
    assert judge(none_case, "unexplained", "none")["correct"]
    assert judge(none_case, "none", "none")["correct"]
    assert judge(none_case, "payload", "clear") == {"correct": False, "confident_wrong": True}
    eff = {"effect": "payload", "param": "mass", "value": -8000.0}
    assert judge(eff, "unexplained", "none") == {"correct": False, "confident_wrong": False}
    assert judge(eff, "payload", "ambiguous")["correct"]
    # calibrated / true, same sign asked by the caller's 1/1.5..1.5 window
    assert param_ratio(eff, {"effect": "payload", "parameters": {"payload": {"mass": -6000.0}}}) == 0.75
    assert param_ratio(eff, {"effect": "sensor", "parameters": {}}) is None


@pytest.mark.slow
def test_out_of_library_drive_is_unexplained(tmp_path):
    """A drive of the independent truck (scenario ``second``, seed 50100: roll centres,
    anti-roll bars, a cab on mounts, progressive tyres, axle-guide geometry; no library
    effect) diagnosed with the whole library at the blind settings is not attributed to a
    library effect (blind benchmark case 0 of the second family: 'unexplained')."""
    from diagnosis.blind import BLIND_SETTINGS
    from diagnosis.pipeline import diagnose
    from drives.synth import copy_without_truth, synth_command

    ds = tmp_path / "d"
    synth_command(scenario="second", seed=50100, out=ds)
    blind = copy_without_truth(ds, tmp_path / "blind")
    s = diagnose(blind, tmp_path / "run", settings=dict(BLIND_SETTINGS), progress=lambda m: None)
    assert s["verdict"] in ("none", "unexplained"), s["verdict_reason"]


def test_two_rules_are_scored_from_the_first_pass_kept_beside_the_final_verdict():
    """A second-pass option (joint road band, band refit) keeps the first pass's verdict in the
    case record; the counts of each rule come from it, and a case without it counts the same
    for both (its first pass was final)."""
    from diagnosis.blind import first_pass_result, two_rule_counts, two_rule_lines

    case = dict(case=0, effect="leaf_friction", param="force", value=1000.0)
    summ = {"verdict": "leaf_friction", "verdict_confidence": "clear",
            "ranking": [{"effect": "leaf_friction", "parameters": {"leaf_friction": {"force": 1200.0}}}],
            "meta": {"joint_band": {"trial_cut": 2.0, "chosen": "cut", "time_s": 70.0,
                                    "first_pass": {"verdict": "unexplained", "verdict_confidence": "none",
                                                   "ranking": []}}}}
    fp = first_pass_result(case, summ, "joint_band")
    assert fp["verdict"] == "unexplained" and not fp["correct"] and fp["param_ratio"] is None
    assert first_pass_result(case, summ) is None            # no band refit in this summary
    rs = [dict(case, verdict="leaf_friction", confidence="clear", correct=True, confident_wrong=False,
               param_ratio=1.2, joint_band=fp, diagnose_s=150.0),
          dict(case=1, effect="none", param=None, value=None, verdict="payload", confidence="ambiguous",
               correct=False, confident_wrong=False, param_ratio=None, joint_band=None, diagnose_s=90.0)]
    first, final = two_rule_counts(rs, "joint_band", "first"), two_rule_counts(rs, "joint_band")
    assert (first["named"], first["valued"], first["wrong"]) == (0, 0, 1)
    assert (final["named"], final["within_1p5"], final["wrong"]) == (1, 1, 1)
    assert first["no_effect"] == final["no_effect"] == 1 and first["no_effect_right"] == 0
    score, times = two_rule_lines(rs, "joint_band")
    assert "named right 0/1" in score[0] and "named right 1/1" in score[1]
    assert "max 90.0 s, over 120 s: 0" in times[0] and "max 150.0 s, over 120 s: 1" in times[1]


def test_the_oracle_runs_on_the_band_the_reported_pass_ran_on():
    """The true shrink of a case is measured on the road the reported verdict's pass used: the
    joint band's cut where it was chosen, else a band refit that moved nmax, else the fitted
    band (stop 65: measured-road case 3 of seed 439 read -1.24 on the uncut road)."""
    from diagnosis.blind import reported_nmax

    assert reported_nmax({"meta": {}}) is None
    cut = {"chosen": "cut", "nmax_before": [3.0, 5.0], "nmax_after": [2.0, 2.0]}
    assert reported_nmax({"meta": {"joint_band": cut}}) == [2.0, 2.0]
    kept = dict(cut, chosen="fitted")
    assert reported_nmax({"meta": {"joint_band": kept}}) is None
    refit = {"changed": True, "nmax_before": [5.0, 5.0], "nmax_after": [2.5, 5.0]}
    assert reported_nmax({"meta": {"joint_band": kept, "band_refit": refit}}) == [2.5, 5.0]
    assert reported_nmax({"meta": {"joint_band": cut, "band_refit": refit}}) == [2.0, 2.0]
    assert reported_nmax({"meta": {"band_refit": dict(refit, changed=False)}}) is None


def test_the_oracle_of_each_truck():
    """Our truck's oracle is its truth's own effects (a sensor without the noise floor the nominal
    model carries); the independent truck's is the library effect at the truth's strength (its own
    effects are its model, not ours), so detectable() can be read for both trucks (stop 71)."""
    from diagnosis.blind import detectable, oracle_effects

    truth = {"vehicle": {"truth": {"effects": {"sensor": {"cutoff": 12.0, "acc_noise": 0.02}}}}}
    eff, kind = oracle_effects({"family": "nominal", "effect": "sensor"}, truth)
    assert kind == "truth" and eff == {"sensor": {"cutoff": 12.0, "acc_noise": 0.0, "disp_noise": 0.0}}
    assert truth["vehicle"]["truth"]["effects"]["sensor"]["acc_noise"] == 0.02   # not modified
    second = {"family": "second", "effect": "leaf_friction", "param": "force", "value": 602.3}
    eff, kind = oracle_effects(second, {"vehicle": {"truth": {"effects": {"anything": {}}}}})
    assert kind == "library" and eff == {"leaf_friction": {"force": 602.3}}
    assert oracle_effects(dict(second, effect="none"), {}) == ({}, "library")
    assert oracle_effects({"family": "nominal", "effect": "none"}, {}) == ({}, "truth")
    # the gate detectable() applies is the same for both
    shown = dict(_r(0, "leaf_friction", "unexplained", "none", true_shrink=0.25, z=5.2), oracle="library")
    assert detectable(shown) and not detectable(dict(shown, true_paired_z=2.9))
