"""The named channel sets of ``eroad invert --channels`` (inverse.run): what each holds and
how a fitted list is named back (the key of its uncertainty calibration)."""
from __future__ import annotations

import pytest

from eroad.errors import EroadInputError
from inverse.run import CHANNEL_SETS, axles_channels, channel_set, fit_channels

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
    assert channel_set(fit_channels(TRUCK, spec), TRUCK) == spec


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
