"""The closed loop (diagnosis.closed_loop): which verdicts lead to a corrected inversion, and
the run folder it writes."""
from __future__ import annotations

import json

import pytest

from diagnosis.closed_loop import effects_from_diagnosis, invert_closed_loop

CLEAR = {"verdict": "leaf_friction", "verdict_confidence": "clear",
         "ranking": [{"effect": "payload", "parameters": {"payload": {"mass": 900.0}}},
                     {"effect": "leaf_friction", "parameters": {"leaf_friction": {"force": 2200.0}}}]}


@pytest.mark.parametrize("summary, expect", [
    (CLEAR, {"leaf_friction": {"force": 2200.0}}),
    ({**CLEAR, "verdict_confidence": "ambiguous"}, {"leaf_friction": {"force": 2200.0}}),
    ({**CLEAR, "verdict_confidence": "ambiguous", "verdict_detail": {"edge": ["leaf_friction.force"]}}, None),
    ({**CLEAR, "verdict": "none", "verdict_confidence": "none"}, None),
    ({**CLEAR, "verdict": "unexplained", "verdict_confidence": "clear"}, None),
    ({**CLEAR, "ranking": []}, None),
])
def test_a_named_effect_is_used_unless_its_value_is_a_bound(summary, expect):
    """The verdict's own ranking entry gives the parameters (not the first entry); a named
    effect is used whatever its confidence (the reason says which), except where it
    calibrates at its search range's edge; none, unexplained and a name without parameters
    keep the nominal model, with the reason in one line."""
    effects, reason = effects_from_diagnosis(summary)
    assert effects == expect
    assert "\n" not in reason and (("inverted with leaf_friction.force=2200" in reason) == bool(expect))
    if expect and summary["verdict_confidence"] == "ambiguous":
        assert "confidence 'ambiguous'" in reason
    if (summary.get("verdict_detail") or {}).get("edge"):
        assert "edge of its search range (leaf_friction.force)" in reason


def _unexplained(closest="leaf_friction", share=0.79, ranking="clear", edge=()):
    return {"verdict": "unexplained", "verdict_confidence": "none",
            "verdict_detail": {"closest": closest, "explained_share": share, "ranking_confidence": ranking,
                               "edge": list(edge), "signature_agrees": False},
            "ranking": [{"effect": "sensor", "parameters": {"sensor": {"cutoff": 10.3}}},
                        {"effect": "leaf_friction", "parameters": {"leaf_friction": {"force": 2138.0}}},
                        {"effect": "payload", "parameters": {"payload": {"mass": 900.0}}}]}


@pytest.mark.parametrize("summary, expect", [
    (_unexplained(), {"leaf_friction": {"force": 2138.0}}),
    (_unexplained("payload", 0.6), {"payload": {"mass": 900.0}}),
    ({**_unexplained(), "verdict_detail": {**_unexplained()["verdict_detail"], "signature_agrees": None}},
     {"leaf_friction": {"force": 2138.0}}),
    (_unexplained(share=0.59), None),                       # below CLOSEST_SHARE_MIN
    (_unexplained(ranking="ambiguous"), None),              # a rival within noise
    (_unexplained(edge=["leaf_friction.force"]), None),     # a bound, not an estimate
    (_unexplained("sensor", 0.85), None),                   # acts on the channels: a road cut looks alike
    (_unexplained("tyre_enveloping", 0.9), None),           # acts on the road input
    (_unexplained("nonexistent", 0.9), None),
    ({**_unexplained(), "verdict_detail": {}}, None),
])
def test_an_unexplained_gap_is_corrected_only_with_a_dominant_closest_effect_on_the_vehicle(summary, expect):
    """closest_vehicle_effect: an 'unexplained' verdict corrects with its closest effect only where
    it changes the vehicle itself (suspension terms or masses), explains >= CLOSEST_SHARE_MIN of
    the gap with a clear ranking and calibrates inside its range; the reason says the verdict,
    the share and that something beyond it remains; the intervals carry the 'unexplained' term."""
    from diagnosis.closed_loop import CLOSEST_SHARE_MIN, closest_vehicle_effect, model_form, singled_out

    assert CLOSEST_SHARE_MIN == 0.6
    effects, reason = effects_from_diagnosis(summary)
    assert effects == expect and "\n" not in reason
    assert (closest_vehicle_effect(summary) is not None) == bool(expect)
    if expect:
        assert "answered 'unexplained'" in reason and f"{100 * summary['verdict_detail']['explained_share']:.0f} %" in reason
        assert "something beyond it may remain" in reason
        assert ("signature does not agree" in reason) == (summary["verdict_detail"].get("signature_agrees") is False)
        assert model_form("unexplained", True, singled_out(summary)) == "unexplained"
    else:
        assert "nominal model is kept" in reason


def test_effects_on_the_vehicle_are_told_from_effects_on_road_and_channels():
    """Effect.acts_on_vehicle follows the hooks an effect overrides: suspension terms or vehicle
    parameters only -> True; the road the tyres see or the recorded channels -> False."""
    from vehicles.effects import EFFECTS

    on_vehicle = {n for n, e in EFFECTS.items() if e.acts_on_vehicle}
    assert {"leaf_friction", "damper_asymmetry", "bump_stop", "frame_flex", "payload"} <= on_vehicle
    assert not on_vehicle & {"sensor", "tyre_enveloping", "speed_scale"}


@pytest.mark.parametrize("confidence, form", [("clear", "diagnosed"), ("ambiguous", "open")])
def test_run_folder_with_a_given_diagnosis(tmp_path, confidence, form):
    """With a diagnosis that names leaf friction (given, so the test exercises the loop and not
    the diagnosis): RUN holds the corrected inversion, nominal/ and diagnose/ beside it, the
    side-by-side table, and summary.json's closed_loop; the corrected fit ran with the effect
    (config.toml) and differs from the nominal one. A 'clear' name gives the corrected fit the
    smaller model-form term, an 'ambiguous' one (corrected too) keeps the open term."""
    from drives.synth import synth_command

    ds = tmp_path / "ds"
    synth_command(scenario="random", seed=5, duration=8.0, out=ds)
    diag = tmp_path / "diag"
    diag.mkdir()
    (diag / "summary.json").write_text(json.dumps({**CLEAR, "verdict_confidence": confidence}))
    (diag / "report.md").write_text("# given\n")
    run = tmp_path / "run"
    s = invert_closed_loop(ds, run, workers=1, seed=0, diagnosis=diag, progress=lambda m: None,
                           segments=1, max_iter=2, candidates=1)
    assert s["closed_loop"]["corrected"] and list(s["closed_loop"]["effects"]) == ["leaf_friction"]
    used = s["closed_loop"]["effects"]["leaf_friction"]["force"]
    from diagnosis import closed_loop

    if closed_loop.FRICTION_FROM_BALANCE:   # the body's force balance replaces the calibrated 2200 N
        fb = s["closed_loop"]["force_balance"]
        assert used == fb["force_N"] and abs(used / 2000.0 - 1.0) < 0.2     # the `random` truth: 2000 N
    else:
        assert used == 2200.0
    assert s["closed_loop"]["model_form"] == form and s["fit"]["model_form"] == form
    for f in ("summary.json", "config.toml", "road.npz", "nominal/summary.json", "diagnose/report.md",
              "tables/table1_nominal_vs_corrected.md", "tables/table1.md"):
        assert (run / f).is_file(), f
    assert "leaf_friction" in (run / "config.toml").read_text()
    assert "leaf_friction" not in json.loads((run / "nominal" / "summary.json").read_text()).get("closed_loop", {})
    nom = s["closed_loop"]["nominal_segments"][0]["Gq_n0"]
    assert s["segments"][0]["Gq_n0"] != nom
    assert json.loads((run / "summary.json").read_text())["closed_loop"]["reason"].startswith("the diagnosis named")
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".run.tmp")]


def test_cli_refuses_auto_with_explicit_effects(tmp_path, capsys):
    from eroad.cli import main

    assert main(["invert", str(tmp_path), "--out", str(tmp_path / "r"), "--effects", "auto",
                 "--effect", "leaf_friction=2000"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("eroad: error:") and "cannot be combined" in err and "\n" not in err
    assert not (tmp_path / "r").exists()


def test_a_corrected_fit_that_stays_poor_says_what_is_left():
    """After the correction the gate's advice ('run the diagnosis') has been followed: the
    message names the effect tried and the segments, and no longer sends the user back."""
    from diagnosis.closed_loop import still_poor_message

    m = still_poor_message({"status": "poor", "poor_segments": [1, 3]}, {"leaf_friction": {"force": 2221.0}})
    assert "1, 3" in m and "even with leaf_friction" in m and "run the diagnosis" not in m


@pytest.mark.parametrize("verdict, given, expect", [
    ("none", None, "axles"),
    ("unexplained", None, "axle3_acc"),
    ("leaf_friction", None, None),
    (None, None, None),
    ("none", "axle3", "axle3"),
    ("leaf_friction", "all", "all"),
])
def test_channels_follow_the_verdict_unless_given(verdict, given, expect):
    """Every axle's accelerations only where the diagnosis found no gap; a vehicle difference
    left in the model would reach more channels (friction drives: G(1) 80 % -> 63 %); where the
    gap is unexplained, axle 3's accelerations alone; a caller's choice is kept and then no
    reason is added."""
    from diagnosis.closed_loop import loop_channels

    chans, why = loop_channels(verdict, given)
    assert chans == expect
    assert bool(why) == (given is None and verdict in ("none", "unexplained"))


def test_an_unexplained_verdict_fits_axle_3_accelerations_only_where_axle_3_is_the_reference():
    """On the truck: 'axle3_acc' (its own calibration key); a drive logged on the front axle, or
    one without axle 3's accelerations, keeps its default channels."""
    from diagnosis.closed_loop import loop_channels
    from inverse.run import fit_plan
    from inverse.uncertainty import calibration_key

    truck = [f"{q}_{a}{s}" for q in ("susp_disp", "axle_acc") for a in range(1, 5) for s in "LR"]
    chans, why = loop_channels("unexplained", None, truck)
    assert chans == "axle3_acc" and "axle accelerations" in why
    sim, fitted = fit_plan(truck, chans)
    assert set(fitted) == {"axle_acc_3L", "axle_acc_3R"} and {"susp_disp_3L", "susp_disp_3R"} <= set(sim)
    assert calibration_key("linear", "axle3_acc") == ("linear/axle3_acc", True)
    front = ["susp_disp_1L", "susp_disp_1R", "axle_acc_1L", "axle_acc_1R", "speed"]
    assert loop_channels("unexplained", None, front) == (None, "")
    # displacements of axle 1 only (the reference) but every axle's accelerations: not axle 3's set
    front_acc = ["susp_disp_1L", "susp_disp_1R"] + [f"axle_acc_{a}{s}" for a in range(1, 5) for s in "LR"]
    assert loop_channels("unexplained", None, front_acc) == (None, "")
    no_acc3 = [c for c in truck if c not in ("axle_acc_3L", "axle_acc_3R")]
    assert loop_channels("unexplained", None, no_acc3) == (None, "")


def test_a_one_axle_drive_keeps_its_default_channels_and_says_why():
    """'axles' on a drive logged on one axle is that axle's default set: the loop keeps the
    default (and its calibration key) and does not claim to fit every axle."""
    from diagnosis.closed_loop import loop_channels

    front = ["susp_disp_1L", "susp_disp_1R", "axle_acc_1L", "axle_acc_1R", "body_acc_1L", "speed"]
    chans, why = loop_channels("none", None, front)
    assert chans is None and "one axle" in why and "every axle" not in why
    truck = [f"{q}_{a}{s}" for q in ("susp_disp", "axle_acc") for a in range(1, 5) for s in "LR"]
    assert loop_channels("none", None, truck)[0] == "axles"


def test_a_none_verdict_fits_every_axle_with_its_own_calibration(tmp_path):
    """A diagnosis answering 'none' (given): the nominal inversion fits the 'axles' set, records
    it and the calibration it used, and says so in the reason."""
    from drives.synth import synth_command
    from inverse.run import axles_channels

    ds = tmp_path / "ds"
    synth_command(scenario="null", seed=3, duration=8.0, out=ds)
    diag = tmp_path / "diag"
    diag.mkdir()
    (diag / "summary.json").write_text(json.dumps({"verdict": "none", "verdict_confidence": "none"}))
    s = invert_closed_loop(ds, tmp_path / "run", workers=1, seed=0, diagnosis=diag, progress=lambda m: None,
                           segments=1, max_iter=2, candidates=1)
    fit = s["fit"]
    assert fit["channel_set"] == "axles" and s["closed_loop"]["channel_set"] == "axles"
    assert fit["uncertainty_calibration"] == "linear/axles" and fit["uncertainty_calibrated_for_channels"]
    assert fit["channels"] == axles_channels(fit["channels"]) and len(fit["channels"]) == 10
    assert fit["model_form"] == "diagnosed" and not s["closed_loop"]["corrected"]
    assert "channel set 'axles'" in s["closed_loop"]["reason"]
    assert "Fitted channels: 'axles'" in (tmp_path / "run" / "tables" / "table1.md").read_text()
