"""Reported uncertainty and the fit-quality gate (inverse.uncertainty) and where they show."""
from __future__ import annotations

import math

import numpy as np
import pytest

from inverse import uncertainty as U
from inverse.report import table1, table1_note


def test_inflation_is_birge_ratio_above_the_reference_misfit():
    """At or below the reference misfit the Laplace sd is scaled by KAPPA only; above it by
    KAPPA sqrt(r / R_REF) (Birge's ratio): 4x the reference misfit doubles the sd."""
    nf = 100
    k = U.KAPPA["ln_Gq_n0"]
    assert U.inflation(0.5 * U.R_REF * nf, nf) == pytest.approx(k)
    assert U.inflation(U.R_REF * nf, nf) == pytest.approx(k)
    assert U.inflation(4 * U.R_REF * nf, nf) == pytest.approx(2 * k)
    assert U.inflation(4 * U.R_REF * nf, nf, "w") == pytest.approx(2 * U.KAPPA["w"])


def test_interval90_holds_90_percent_of_normal_draws():
    """The interval is +-1.645 sd: of 200000 normal draws 90.0 % fall inside (binomial sd
    0.07 %, so 0.3 % is over 4 sd)."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(200_000)
    lo, hi = U.interval90(0.0, 1.0, log=False)
    assert np.mean((x > lo) & (x < hi)) == pytest.approx(0.90, abs=0.003)
    lo, hi = U.interval90(2.0, 0.5, log=True)
    assert math.log(hi / 2.0) == pytest.approx(U.Z90 * 0.5) and math.log(2.0 / lo) == pytest.approx(U.Z90 * 0.5)


def test_gate_flags_misfit_above_the_gate_and_names_segments_with_times():
    segs = [{"t_start": 460.0, "t_end": 472.5, "fit_quality": U.fit_quality(U.R_GATE * 2 * 50, 50)},
            {"t_start": 472.5, "t_end": 490.0, "fit_quality": U.fit_quality(U.R_REF * 50, 50)}]
    assert segs[0]["fit_quality"]["status"] == "poor" and segs[1]["fit_quality"]["status"] == "clean"
    assert "run the diagnosis" in segs[0]["fit_quality"]["message"]
    o = U.overall_fit_quality(segs)
    assert o["status"] == "poor" and o["poor_segments"] == [1] and "460.0-472.5 s" in o["message"]
    assert U.overall_fit_quality(segs[1:])["status"] == "clean"
    note = table1_note(o)
    assert note.startswith("**POOR FIT**") and "460.0-472.5 s" in note


def test_honest_sd_scales_every_component_and_adds_the_model_form_term():
    """At 4x the reference misfit: sd^2 = (2 KAPPA sd_laplace)^2 + 3 BETA (excess r/R_REF - 1
    = 3); at or below the reference misfit only KAPPA scales, with no model-form term."""
    lap = {"ln_Gq_n0": 0.1, "w": 0.05, "ln_nmin": 0.3, "ln_nmax": 0.2}
    sd = U.honest_sd(lap, 0.04, objective=4 * U.R_REF * 10, n_features=10)
    for k, v in lap.items():
        kap = U.KAPPA.get(k, U.KAPPA["ln_Gq_n0"])
        beta = U.BETA.get(k, U.BETA["ln_Gq_n0"])
        assert sd[k] == pytest.approx(math.sqrt((2 * kap * v) ** 2 + 3 * beta))
    assert sd["ln_G_n_best"] == pytest.approx(math.sqrt((2 * U.KAPPA["ln_G_n_best"] * 0.04) ** 2
                                                        + 3 * U.BETA["ln_G_n_best"]))
    # the model-form term dominates where the Laplace sd is tiny: a long segment (sd 0.04) whose
    # misfit is 4x a correct model's must not claim better than sd 0.47 in ln G(n_best), the
    # spread of the errors on the model-gap drives it was set on (results/inverse_blind)
    assert sd["ln_G_n_best"] >= 0.47
    clean = U.honest_sd(lap, 0.04, objective=0.5 * U.R_REF * 10, n_features=10)
    assert clean["w"] == pytest.approx(U.KAPPA["w"] * 0.05) and clean["ln_G_n_best"] == pytest.approx(
        U.KAPPA["ln_G_n_best"] * 0.04)


def test_table1_shows_intervals_and_gate():
    seg = {"t_start": 0.0, "t_end": 10.0, "proportion": 1.0, "class": "C", "Gq_n0": 256e-6, "w": 2.0,
           "nmin": 0.05, "nmax": 5.0, "dx": 0.1, "dy": 0.1, "identifiable": {}, "sd": {"ln_Gq_n0": 0.2},
           "interval90": {"Gq_n0": [200e-6, 330e-6], "w": [1.8, 2.2]},
           "fit_quality": U.fit_quality(0.5, 1)}
    row = table1([seg]).iloc[0]
    assert row["Gq_n0_90pct_1e-6m3"] == "200-330" and row["w_90pct"] == "1.80-2.20"
    assert row["fit"] == "clean" and row["misfit_per_feature"] == 0.5


def test_each_fit_model_has_its_own_calibration():
    """The linear fit's constants (calibrated apart, inverse/uncertainty.py CALIBRATIONS)
    apply when it ran: its gate and its KAPPA; the simulation fit keeps the module
    constants; an unknown fit model is refused rather than given another's intervals."""
    lin = U.calibration("linear")
    assert U.calibration("simulation")["R_GATE"] == U.R_GATE
    r = 0.5 * (lin["R_GATE"] + U.R_GATE)        # between the two gates: poor only for the linear fit
    assert U.fit_quality(r * 50, 50, fit_model="linear")["status"] == "poor"
    assert U.fit_quality(r * 50, 50)["status"] == "clean"
    assert U.fit_quality(r * 50, 50, fit_model="linear")["gate"] == lin["R_GATE"]
    sd = U.honest_sd({"ln_Gq_n0": 0.1, "w": 0.05}, 0.04, objective=0.5 * lin["R_REF"] * 10, n_features=10,
                     fit_model="linear")
    assert sd["w"] == pytest.approx(lin["KAPPA"]["w"] * 0.05)
    assert sd["ln_G_n_best"] == pytest.approx(lin["KAPPA"]["ln_G_n_best"] * 0.04)
    with pytest.raises(ValueError, match="no uncertainty calibration"):
        U.calibration("quarter")


def test_a_diagnosed_drive_carries_the_smaller_model_form_term():
    """Above the reference misfit the misfit-scaled model-form variance is BETA_DIAGNOSED where
    the diagnosis found no gap or the fit carries the named effect, BETA where a vehicle
    difference may be left ('open', the default); at or below it neither adds anything; the
    axle-3 fit's 'diagnosed' state adds FLOOR_DIAGNOSED whatever the misfit (a corrected gap
    leaves level bias the misfit does not show, stop 49); an unknown state is refused. The
    diagnosed BETA is smaller for every quantity (the term exists because an unchecked model can
    hide a vehicle difference in the road level)."""
    lin = U.calibration("linear")
    fl = lin["FLOOR_DIAGNOSED"]
    lap = {"ln_Gq_n0": 0.1, "w": 0.05}
    hi = dict(objective=4 * lin["R_REF"] * 10, n_features=10, fit_model="linear")
    op = U.honest_sd(lap, 0.04, **hi)
    dg = U.honest_sd(lap, 0.04, model_form="diagnosed", **hi)
    for q, v in (("ln_Gq_n0", 0.1), ("w", 0.05), ("ln_G_n_best", 0.04)):
        assert lin["BETA_DIAGNOSED"][q] < lin["BETA"][q]
        assert 0 < fl[q] < 3 * lin["BETA"][q]
        assert dg[q] == pytest.approx(math.sqrt((2 * lin["KAPPA"][q] * v) ** 2 + 3 * lin["BETA_DIAGNOSED"][q] + fl[q]))
        assert op[q] == pytest.approx(math.sqrt((2 * lin["KAPPA"][q] * v) ** 2 + 3 * lin["BETA"][q]))
    lo = dict(objective=0.5 * lin["R_REF"] * 10, n_features=10, fit_model="linear")
    op_lo, dg_lo = U.honest_sd(lap, 0.04, **lo), U.honest_sd(lap, 0.04, model_form="diagnosed", **lo)
    for q in ("ln_Gq_n0", "w", "ln_G_n_best"):
        assert dg_lo[q] == pytest.approx(math.sqrt(op_lo[q] ** 2 + fl[q]))
    # no floor on a channel set without one ('axles': the 'none' verdict's fit)
    ax = dict(lo, fit_model="linear/axles")
    assert U.honest_sd(lap, 0.04, model_form="diagnosed", **ax) == U.honest_sd(lap, 0.04, **ax)
    with pytest.raises(ValueError, match="model_form"):
        U.honest_sd(lap, 0.04, model_form="closed", **lo)
    assert "'diagnosed'" in table1_note({"status": "clean"}, model_form="diagnosed")
    assert "'open'" in table1_note({"status": "clean"}, model_form="open")


def test_an_unexplained_drive_takes_its_own_term_where_the_channels_have_one():
    """'unexplained' uses BETA_UNEXPLAINED of the calibration (axle 3's accelerations, the loop's
    channels for such drives: smaller than the open term for ln Gq(n0) and ln G(n_best),
    results/inverse_blind/20261128-beta-unexplained-pooled/pool_unexplained.py) and the open BETA
    where the channel set has none; Table 1's note names the state."""
    acc = U.calibration("linear/axle3_acc")
    assert U.model_form_beta("linear/axle3_acc", "unexplained") == acc["BETA_UNEXPLAINED"]
    assert acc["BETA_UNEXPLAINED"]["ln_Gq_n0"] < acc["BETA"]["ln_Gq_n0"]
    assert acc["BETA_UNEXPLAINED"]["ln_G_n_best"] < acc["BETA"]["ln_G_n_best"]
    assert U.model_form_beta("linear", "unexplained") == U.calibration("linear")["BETA"]
    lap = {"ln_Gq_n0": 0.1, "w": 0.05}
    hi = dict(objective=4 * acc["R_REF"] * 10, n_features=10, fit_model="linear/axle3_acc")
    un, op = U.honest_sd(lap, 0.04, model_form="unexplained", **hi), U.honest_sd(lap, 0.04, **hi)
    assert un["ln_Gq_n0"] < op["ln_Gq_n0"] and un["ln_G_n_best"] < op["ln_G_n_best"]
    assert "'unexplained'" in table1_note({"status": "clean"}, model_form="unexplained")


@pytest.mark.parametrize("verdict, corrected, singled, form", [
    ("none", False, True, "diagnosed"), ("leaf_friction", True, True, "diagnosed"),
    ("leaf_friction", True, False, "open"),
    ("unexplained", False, True, "unexplained"), ("unexplained", True, False, "unexplained"),
    ("leaf_friction", False, True, "open")])
def test_closed_loop_model_form(verdict, corrected, singled, form):
    """Only a drive the diagnosis found no gap in, or one inverted with an effect it named and
    singled out (clear or identified), gets the smaller term; an unexplained gap gets its own
    state, corrected with its closest effect or not; a name not acted on, or a correction with an
    'ambiguous' name keeps the open one."""
    from diagnosis.closed_loop import model_form, singled_out
    assert model_form(verdict, corrected, singled) == form
    assert singled_out({"verdict_confidence": "clear"}) and not singled_out({"verdict_confidence": "ambiguous"})
    assert singled_out({"verdict_confidence": "ambiguous", "verdict_detail": {"identified": True}})


def test_beta_diagnosed_rule_picks_the_smallest_value_that_covers_90_percent():
    """benchmarks/calibrate_uncertainty.py's rule on rows with a known error spread: errors of
    sd 0.3 in ln units, Laplace sd 0.01 and misfit 2 R_REF, so the reported sd is about
    sqrt(BETA); 90 % coverage needs 1.645 sqrt(BETA) >= the 90 % quantile of |error| (0.49),
    BETA >= 0.089: the rule must pick 0.1 from its grid, not 0.05 (78 %) and not more. Open
    rows are not used."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import calibrate_uncertainty as C

    rng = np.random.default_rng(3)
    const = {k: (dict(v) if isinstance(v, dict) else v) for k, v in U.calibration("linear").items()}
    e = 0.3 * rng.standard_normal(4000)
    rows = [{"objective": 2 * const["R_REF"] * 10, "n_features": 10, "model_form": "diagnosed",
             "lnGq_err": x, "w_err": x, "lnG_n_best_err": x, "sd_laplace": {"ln_Gq_n0": 0.01, "w": 0.01},
             "sd_ln_G_n_best_laplace": 0.01} for x in e]
    rows += [dict(r, model_form="open", lnGq_err=10.0, w_err=10.0, lnG_n_best_err=10.0) for r in rows[:500]]
    assert C.choose_beta_diagnosed(rows, const) == {"ln_Gq_n0": 0.1, "w": 0.1, "ln_G_n_best": 0.1}


def test_scoring_reads_an_unexplained_loop_in_todays_state(tmp_path):
    """benchmarks/calibrate_uncertainty.py: a closed-loop record with verdict 'unexplained' is scored
    in the 'unexplained' state even where it recorded 'open' (records before stop 48), and its
    interval then takes BETA_UNEXPLAINED of the constants given; a record without a loop stays
    'open'."""
    import json
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import calibrate_uncertainty as C

    seg = {"duration_s": 5.0, "lnGq_err": 0.1, "w_err": 0.0, "lnG_n_best_err": 0.1, "sd_ln_Gq_n0": 0.1,
           "sd_w": 0.1, "sd_ln_G_n_best": 0.1, "objective": 40.0, "n_features": 10}
    recs = [{"seed": 1, "segments": [dict(seg)], "closed_loop": {"verdict": "unexplained", "corrected": False,
                                                                  "model_form": "open"}},
            {"seed": 2, "segments": [dict(seg)]}]
    (tmp_path / "results.jsonl").write_text("\n".join(json.dumps(r) for r in recs))
    rows = C.load(tmp_path)
    assert [r["model_form"] for r in rows] == ["unexplained", "open"]
    const = U.calibration("linear/axle3_acc")
    sd_u = C.reported_sd(rows[0], "ln_Gq_n0", 0.1, const)
    sd_o = C.reported_sd(dict(rows[0], model_form="open"), "ln_Gq_n0", 0.1, const)
    assert sd_u < sd_o


def test_calibration_key_per_channel_set():
    """Each channel set takes its own constants where they were calibrated (the 'axles' set of
    the linear fit: its correlated channels need a larger KAPPA); any other list falls back to
    the fit model's axle-3 constants and says it was not calibrated for them."""
    assert U.calibration_key("linear", "axle3") == ("linear", True)
    assert U.calibration_key("linear", "axles") == ("linear/axles", True)
    assert U.calibration_key("linear", "custom") == ("linear", False)
    assert U.calibration_key("simulation", "axles") == ("simulation", False)
    ax, lin = U.calibration("linear/axles"), U.calibration("linear")
    assert all(ax["KAPPA"][q] > lin["KAPPA"][q] for q in lin["KAPPA"])
    assert ax["R_GATE"] == pytest.approx(5 * ax["R_REF"], rel=0.01)
    with pytest.raises(ValueError):
        U.calibration_key("quarter", "axle3")
