"""The named channel sets of ``eroad invert --channels`` (inverse.run): what each holds and
how a fitted list is named back (the key of its uncertainty calibration)."""
from __future__ import annotations

import pytest

from eroad.errors import EroadInputError
from inverse.run import CHANNEL_SETS, axles_channels, channel_set, fit_channels, fit_plan, reference_axle

TRUCK = ([f"susp_disp_{a}{s}" for a in range(1, 5) for s in "LR"]
         + [f"axle_acc_{a}{s}" for a in range(1, 5) for s in "LR"]
         + ["body_acc_front", "speed", "dcdc_z_P1"])


def test_axles_is_axle3_suspension_and_every_axle_acceleration():
    names = fit_channels(TRUCK, "axles")
    assert names[:2] == ["susp_disp_3L", "susp_disp_3R"]
    assert sorted(names[2:]) == sorted(f"axle_acc_{a}{s}" for a in range(1, 5) for s in "LR")
    assert names == axles_channels(TRUCK)


@pytest.mark.parametrize("spec", CHANNEL_SETS)
def test_a_named_set_is_named_back(spec):
    assert channel_set(fit_plan(TRUCK, spec)[1], TRUCK) == spec


def test_acceleration_sets_simulate_the_displacements_and_fit_the_accelerations():
    """'axle3_acc' / 'axles_acc': the simulated channels are those of 'axle3' / 'axles' (the
    segmentation needs axle 3's displacements), the fitted ones the axle accelerations alone; a
    comma list is fitted as listed, the displacement pair added for the segmentation is not."""
    for acc, base in (("axle3_acc", "axle3"), ("axles_acc", "axles")):
        sim, fitted = fit_plan(TRUCK, acc)
        assert sim == fit_channels(TRUCK, base) == fit_channels(TRUCK, acc)
        assert fitted == [c for c in sim if c.startswith("axle_acc_")] and len(fitted) == (2 if acc == "axle3_acc" else 8)
    sim, fitted = fit_plan(TRUCK, "axle_acc_3L,axle_acc_3R")
    assert sim[:2] == ["susp_disp_3L", "susp_disp_3R"] and fitted == ["axle_acc_3L", "axle_acc_3R"]
    assert channel_set(fitted, TRUCK) == "axle3_acc"
    for spec in (None, "axle3", "axles", "all", "susp_disp_3L,susp_disp_3R,axle_acc_3L,axle_acc_3R"):
        sim, fitted = fit_plan(TRUCK, spec)
        assert fitted == sim
    with pytest.raises(EroadInputError, match="no axle acceleration"):
        fit_plan(["susp_disp_3L", "susp_disp_3R", "speed"], "axle3_acc")


def test_the_acceleration_fit_has_its_own_calibration():
    """'axle3_acc' carries constants set on its own blind fits (inverse.uncertainty); 'axles_acc'
    falls back to the axle-3 ones and says it was not checked."""
    from inverse.report import channels_note
    from inverse.uncertainty import calibration_key

    assert calibration_key("linear", "axle3_acc") == ("linear/axle3_acc", True)
    assert calibration_key("linear", "axles_acc") == ("linear", False)
    note = channels_note("axle3_acc", True)
    assert "axle acceleration of axle 3" in note and "only segment" in note


def test_other_lists_are_custom_and_default_is_axle3():
    assert channel_set(fit_channels(TRUCK, "axle_acc_1L,axle_acc_1R"), TRUCK) == "custom"
    assert fit_channels(TRUCK, None) == fit_channels(TRUCK, "axle3")
    assert channel_set(list(reversed(fit_channels(TRUCK, "axle3"))), TRUCK) == "axle3"
    with pytest.raises(EroadInputError):
        fit_channels(TRUCK, "axle_acc_9L")


def test_table1_says_which_channels_and_whether_calibrated():
    from inverse.report import channels_note

    assert "calibrated for them" in channels_note("axles", True)
    n = channels_note("custom", False)
    assert "axle-3 calibration" in n and "not checked" in n and "\n" not in n


# A logger on other axles than axle 3 (the front axle is the usual one): the inversion fits the
# lowest-numbered axle logged on both sides, names the set after it, and the intervals say they
# carry the axle-3 calibration ("eroad invert needs column(s) susp_disp_3L, susp_disp_3R" before
# 2026-11-27).
FRONT = ["susp_disp_1L", "susp_disp_1R", "axle_acc_1L", "axle_acc_1R", "body_acc_1L", "speed"]


def test_a_drive_without_axle_3_is_fitted_on_its_logged_axle():
    assert reference_axle(FRONT) == 1
    assert fit_channels(FRONT, None) == ["susp_disp_1L", "susp_disp_1R", "axle_acc_1L", "axle_acc_1R"]
    assert channel_set(fit_channels(FRONT, None), FRONT) == "axle1"
    assert fit_channels(FRONT, "axles") == ["susp_disp_1L", "susp_disp_1R", "axle_acc_1L", "axle_acc_1R"]
    # axle 3 keeps the default where it is logged; another axle is chosen by name
    assert reference_axle(TRUCK) == 3
    assert channel_set(fit_channels(TRUCK, "axle2"), TRUCK) == "axle2"
    assert fit_channels(TRUCK, "axle2")[:2] == ["susp_disp_2L", "susp_disp_2R"]


def test_one_side_or_no_displacement_is_one_clear_error():
    one_side = ["susp_disp_1L", "axle_acc_1L", "speed"]
    with pytest.raises(EroadInputError, match=r"both sides of one axle.*present: axle_acc_1L, susp_disp_1L"):
        fit_channels(one_side, None)
    with pytest.raises(EroadInputError, match=r"--channels axle3: .*axles with both: 1"):
        fit_channels(FRONT, "axle3")


def test_a_list_without_a_displacement_pair_gets_the_reference_axles():
    assert fit_channels(FRONT, "axle_acc_1L")[:2] == ["susp_disp_1L", "susp_disp_1R"]


def test_selection_and_table2_follow_the_axle():
    from inverse.realisation import SELECT_WEIGHTS, select_channels, select_weights
    from inverse.report import TABLE2_CHANNELS, table2_channels, table2_note

    assert select_weights(3) == SELECT_WEIGHTS == {"axle_acc_3L": 1.0, "axle_acc_3R": 1.0,
                                                   "susp_disp_3L": 0.25, "susp_disp_3R": 0.25}
    assert set(select_channels(1)) == {"axle_acc_1L", "axle_acc_1R", "susp_disp_1L", "susp_disp_1R"}
    assert TABLE2_CHANNELS == ("axle_acc_3L", "axle_acc_3R", "body_acc_3L", "body_acc_3R",
                               "susp_disp_3L", "susp_disp_3R")
    assert table2_channels(1)[0] == "axle_acc_1L"
    assert "not comparable" in table2_note(1) and "not comparable" not in table2_note(3)
