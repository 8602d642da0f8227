"""``eroad vehicle new`` and ``eroad vehicle check`` (vehicles.check).

References: the Exudyn static solution of the rigid model (static spring compressions),
the closed-form frequencies of a quarter car with a rigid tyre and with an infinitely
stiff spring, and the built-in vehicles (documented values, no warnings).
"""
from __future__ import annotations

import dataclasses
import json
import math
import re

import numpy as np
import pytest

from eroad.cli import main
from eroad.errors import EroadInputError
from vehicles.check import (RANGES, axle_table, check_vehicle, new_vehicle_file, quarter_car,
                            static_axle_loads)
from vehicles.params import load_vehicle


def _scaled(vp, axle, **factors):
    ax = list(vp.axles)
    ax[axle] = dataclasses.replace(ax[axle], **{k: getattr(ax[axle], k) * f
                                                for k, f in factors.items()})
    return dataclasses.replace(vp, axles=tuple(ax))


@pytest.mark.parametrize("vid", ["dump_truck_8x4", "e_tractor"])
def test_static_deflection_matches_the_exudyn_model(vid):
    """Spring deflections equal the Exudyn rigid model's static compressions within 1 % (the
    model adds geometric second-order effects, ~1e-5, and axle guides that carry no vertical
    load); the loads sum to the sprung weight."""
    from vehicles.builder import GRAVITY, build_model

    vp = load_vehicle(vid)
    model = build_model(vp, chassis="rigid")
    got = np.array([s.static_compression for s in model.suspensions]).reshape(-1, 2)
    want = np.array([r["spring_deflection_m"] for r in axle_table(vp)])
    np.testing.assert_allclose(got[:, 0], want, rtol=0.01)
    np.testing.assert_allclose(got[:, 1], want, rtol=0.01)
    sprung = vp.sprung_mass + (vp.dcdc.mass if vp.dcdc is not None else 0.0)
    assert static_axle_loads(vp).sum() == pytest.approx(sprung * GRAVITY, rel=1e-12)


def test_quarter_car_limits():
    """Closed forms: with a rigid tyre the body bounces at sqrt(k_s / m_s) / 2 pi and the
    damping ratio of that mode is c_s / (2 sqrt(k_s m_s)); with a rigid spring the axle and
    body move together on the tyre. 1e-3 relative for stiffness ratios of 1e6."""
    m_s, m_u, k_s, c_s = 3000.0, 400.0, 3e5, 1.2e4
    q = quarter_car(m_s, m_u, k_s, c_s, 1e12, 0.0)
    assert q["body_bounce_hz"] == pytest.approx(math.sqrt(k_s / m_s) / (2 * math.pi), rel=1e-3)
    assert q["body_damping_ratio"] == pytest.approx(c_s / (2 * math.sqrt(k_s * m_s)), rel=1e-3)
    assert q["suspension_damping_ratio"] == pytest.approx(c_s / (2 * math.sqrt(k_s * m_s)))
    q = quarter_car(m_s, m_u, 1e12, 0.0, 1e6, 0.0)
    assert q["body_bounce_hz"] == pytest.approx(math.sqrt(1e6 / (m_s + m_u)) / (2 * math.pi),
                                                rel=1e-3)


@pytest.mark.parametrize("vid", ["dump_truck_8x4", "e_tractor"])
def test_builtin_vehicles_have_no_warnings(vid):
    rep = check_vehicle(load_vehicle(vid))
    assert rep["warnings"] == []
    for r in rep["axles"]:
        assert RANGES["body_bounce_hz"][0] <= r["body_bounce_hz"] <= RANGES["body_bounce_hz"][1]
        assert 8.0 <= r["axle_hop_hz"] <= 15.0


def test_spring_1000x_too_soft_says_so():
    vp = _scaled(load_vehicle("dump_truck_8x4"), 0, spring_stiffness=1e-3)
    rep = check_vehicle(vp)
    first = rep["warnings"][0]
    assert first["axle"] == 1 and "far too soft" in first["message"]
    assert "spring_stiffness = 320 N/m" in first["message"]
    assert "unit slip" in first["message"] and "1000x" in first["message"]
    # the factor stated: against the 1 Hz spring for the axle's equal-stiffness share
    assert re.search(r"\b3\d\dx softer than", first["message"]), first["message"]
    # it sheds its load to the other axles, and the message says so
    assert "carries 0.191 kN of its 44.7 kN share" in first["message"]


def test_spring_1000x_too_stiff_and_damping_and_tyre():
    vp = load_vehicle("dump_truck_8x4")
    msgs = [w["message"] for w in check_vehicle(_scaled(vp, 2, spring_stiffness=1e3))["warnings"]]
    assert any(m.startswith("axle 3: spring_stiffness = 7e+08 N/m is far too stiff") for m in msgs)
    msgs = [w["message"] for w in check_vehicle(_scaled(vp, 1, damping=1e-2))["warnings"]]
    assert msgs == ["axle 2: damping = 120 N s/m per side gives a suspension damping ratio of "
                    "0.00219, far too low (heavy trucks 0.05-0.5 with leaf springs; 0.25 would "
                    "be 1.37e+04 N s/m with this spring and load)"]
    msgs = [w["message"] for w in check_vehicle(_scaled(vp, 3, tyre_stiffness=1e-2))["warnings"]]
    assert any(m.startswith("axle 4: tyre_stiffness = 1e+04 N/m per tyre is far too soft") for m in msgs)


def test_modest_changes_stay_quiet():
    """Within the ranges, no warning: a spring 30 % softer or a damper 30 % stronger."""
    vp = load_vehicle("e_tractor")
    assert check_vehicle(_scaled(vp, 0, spring_stiffness=0.7, damping=1.3))["warnings"] == []


def test_new_writes_a_commented_copy_that_loads_back(tmp_path):
    out = tmp_path / "my_truck.toml"
    new_vehicle_file("dump_truck_8x4", out)
    text = out.read_text()
    assert "eroad vehicle check my_truck.toml" in text
    assert "spring_stiffness = 3.2e+05" in text and "# [N/m] vertical suspension stiffness" in text
    mine, orig = load_vehicle(out), load_vehicle("dump_truck_8x4")
    assert mine.id == "my_truck"
    assert dataclasses.replace(mine, id=orig.id) == orig
    # refuses to overwrite, untouched
    with pytest.raises(EroadInputError, match="exists; refusing to overwrite"):
        new_vehicle_file("e_tractor", out)
    assert out.read_text() == text
    new_vehicle_file("e_tractor", tmp_path / "t.toml")
    assert dataclasses.replace(load_vehicle(tmp_path / "t.toml"), id="e_tractor") == \
        load_vehicle("e_tractor")


def test_cli(tmp_path, capsys):
    out = tmp_path / "mine.toml"
    assert main(["vehicle", "new", "--from", "dump_truck_8x4", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["vehicle", "new", "--from", "dump_truck_8x4", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "refusing to overwrite" in err
    assert main(["vehicle", "check", str(out)]) == 0
    assert "no warnings" in capsys.readouterr().out
    out.write_text(out.read_text().replace("spring_stiffness = 3.2e+05", "spring_stiffness = 320.0", 1))
    assert main(["vehicle", "check", str(out)]) == 0          # warnings, exit 0
    text = capsys.readouterr().out
    assert "warning   axle 1: spring_stiffness = 320 N/m is far too soft" in text
    assert main(["vehicle", "check", str(out), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["warnings"][0]["axle"] == 1 and rep["warnings"][0]["range"] == [1.0, 3.0]
    assert len(rep["axles"]) == 4 and rep["ranges"]["axle_hop_hz"]["low"] == 8.0
    # the loader's refusals stay: exit 2, one line
    out.write_text(out.read_text().replace("spring_stiffness = 320.0", "spring_stiffness = -1.0", 1))
    assert main(["vehicle", "check", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "spring_stiffness' must be positive" in err
