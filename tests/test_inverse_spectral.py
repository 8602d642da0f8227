"""Parameter layout, bounds, ISO classes and grid steps of the inverse fit.

Reference: ISO 8608:2016 Table 1, geometric means of Gd(n0) per class
(A 16e-6, B 64e-6, ..., H 262144e-6 m^3, a factor 4 per class; bounds a factor 2
either side), as quoted in issue 2.
"""
import math

import numpy as np
import pytest

from eroad.errors import EroadInputError
from inverse.spectral import (ISO_CLASS_GD0, ParamBounds, grid_spacing, iso_class, params_to_theta,
                              theta_to_params)


def test_iso_class_table():
    assert ISO_CLASS_GD0["A"] == pytest.approx(16e-6)
    assert ISO_CLASS_GD0["H"] == pytest.approx(262144e-6)
    assert iso_class(256e-6) == "C"
    assert iso_class(0.99 * 512e-6) == "C" and iso_class(1.01 * 512e-6) == "D"
    with pytest.raises(EroadInputError):
        iso_class(-1.0)


def test_theta_round_trip():
    p = np.array([[256e-6, 2.0, 0.05, 5.0], [1e-3, 1.6, 0.01, 3.0]])
    np.testing.assert_allclose(theta_to_params(params_to_theta(p)), p, rtol=1e-14)
    assert params_to_theta(p)[0, 0] == pytest.approx(math.log(256e-6))


def test_bounds_nyquist_cap_and_projection():
    b = ParamBounds().for_record(fs=200.0, v_max=11.28)
    assert b.nmax[1] == pytest.approx(200.0 / (2 * 11.28))
    th = b.clip_theta(params_to_theta([[1.0, 5.0, 0.19, 1.0]]))
    p = theta_to_params(th)[0]
    assert p[0] <= b.Gq_n0[1] * (1 + 1e-12) and p[1] == b.w[1] == 3.5
    assert p[3] / p[2] >= b.min_ratio * (1 - 1e-12)


def test_grid_spacing():
    """dx = largest nice step <= 1 / (4 nmax): nmax 5 -> 0.05 m, 8.87 -> 0.025 m."""
    assert grid_spacing(5.0) == 0.05
    assert grid_spacing(8.87) == 0.025
    assert grid_spacing(2.0) == 0.125


def test_parameters_on_a_bound_are_named_and_reach_table1_note():
    # a fit that ends on the w bound (the measured-road case of issue 14) is reported as such
    # in the segment row's at_bound and in the note under Table 1; inside the range: nothing
    from inverse.pipeline import at_bounds
    from inverse.report import table1_note
    from inverse.spectral import ParamBounds

    b = ParamBounds()
    assert at_bounds(100e-6, 2.0, b) == []
    hw = b.w[1]
    pinned = at_bounds(100e-6, hw - 0.001, b)
    assert pinned == [f"w = {hw:g} (upper bound)"]
    assert at_bounds(b.Gq_n0[0], 2.0, b) == [f"Gq_n0 = {b.Gq_n0[0]:g} m^3 (lower bound)"]
    # the upper bound is class E's mean (a class E road in its upper half reads low there): said
    from roadlib.psd import ISO_CLASSES
    assert b.Gq_n0[1] == ISO_CLASSES["E"].gd0
    (top,) = at_bounds(b.Gq_n0[1], 2.0, b)
    assert "upper bound, class E's mean" in top and "reads low" in top
    note = table1_note({"status": "clean"}, segments=[{"at_bound": []}, {"at_bound": pinned}])
    assert "On a bound" in note and "segment 2" in note and "segment 1" not in note
    assert "On a bound" not in table1_note({"status": "clean"}, segments=[{"at_bound": []}])


def test_the_segmentations_resolution_reaches_table1_and_its_note():
    """Each segment row's 'unresolved' becomes Table 1's factor column and one note sentence."""
    from inverse.report import table1, table1_note

    row = {"t_start": 0.0, "t_end": 12.0, "proportion": 1.0, "class": "C", "Gq_n0": 256e-6, "w": 2.0,
           "nmin": 0.01, "nmax": 5.0, "dx": 0.1, "dy": 0.1, "identifiable": {},
           "unresolved": {"piece_s": 3.0, "ln_level": [-1.2, 0.9]}}
    t = table1([row, dict(row, unresolved={"piece_s": 3.0, "ln_level": [None, 0.9]}), dict(row, unresolved=None)])
    assert list(t["unresolved_3s_level_x"]) == ["0.3-2.5", "0-2.5", ""]
    assert "unresolved_3s_level_x" in table1_note({"status": "clean"}, segments=[row])
    assert "unresolved_3s_level_x" not in table1_note({"status": "clean"}, segments=[dict(row, unresolved=None)])


def test_a_class_whose_level_is_not_identified_is_shown_in_brackets():
    """A segment whose Gq(n0) the data do not identify (a 0.5 s piece of a measured road: the fit
    stays near its starting guess) is not given a class as a result: Table 1 and the CLI show it in
    brackets and the note says why; an identified one, and an older row without the record, plain."""
    from inverse.report import class_identified, class_label, table1, table1_note

    row = {"t_start": 0.0, "t_end": 12.0, "proportion": 1.0, "class": "C", "Gq_n0": 256e-6, "w": 2.0,
           "nmin": 0.01, "nmax": 5.0, "dx": 0.1, "dy": 0.1,
           "identifiable": {"Gq_n0": True, "w": True, "nmin": False, "nmax": True}}
    short = dict(row, t_end=0.5, identifiable={"Gq_n0": False, "w": False, "nmin": False, "nmax": False})
    old = {k: v for k, v in row.items() if k != "identifiable"}
    assert [class_label(r) for r in (row, short, old)] == ["C", "(C)", "C"]
    assert [class_identified(r) for r in (row, short, old)] == [True, False, True]
    assert list(table1([row, short])["class"]) == ["C", "(C)"]
    assert "class in brackets" in table1_note({"status": "clean"}, segments=[row, short])
    assert "class in brackets" not in table1_note({"status": "clean"}, segments=[row, old])
