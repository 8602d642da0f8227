"""The lateral-structure sensitivity of the fitted level (inverse/lateral.py)."""
import math

import pytest

from eroad.errors import EroadInputError
from inverse import lateral

SEG = dict(Gq_n0=256e-6, w=2.0, nmin=0.02, nmax=5.0)


@pytest.fixture(scope="module")
def lm():
    from vehicles.linear import linear_model

    return linear_model("dump_truck_8x4")


def axle(lm):
    return [c for c in lm.channel_names if c.startswith("axle_acc")]


def test_assumed_structure_as_alternative_gives_one(lm, monkeypatch):
    # the assumed surface passed as an "alternative" must return factor 1: the two RMS
    # integrals are the same numbers (1e-9: round-off of two identical quadratures)
    monkeypatch.setattr(lateral, "alternatives", lambda w: {"same": lateral._surface(1.0, w)})
    s = lateral.level_sensitivity(lm, SEG, 10.0, axle(lm))
    assert s["same"]["factor"] == pytest.approx(1.0, abs=1e-9)


def test_factors_do_not_depend_on_the_level(lm):
    # response power is linear in Gd(n0): the factors are the same at a 16x higher level
    a = lateral.level_sensitivity(lm, SEG, 10.0, axle(lm))
    b = lateral.level_sensitivity(lm, dict(SEG, Gq_n0=16 * SEG["Gq_n0"]), 10.0, axle(lm))
    for k in a:
        assert b[k]["dln_Gq_n0"] == pytest.approx(a[k]["dln_Gq_n0"], abs=1e-9)


def test_duals_in_one_rut_lower_the_level_from_axle_accelerations(lm):
    # twin tyres 0.34 m apart average two partially coherent profiles: on one profile the
    # axle sees more short-wave power, so the same response needs a lower road level
    # (factor < 1 is the physics; 0.73-0.81 is what the linear truck gives at 6-14 m/s,
    # the bounds 0.6-0.9 leave +-0.1 for model changes that keep the physics)
    for v in (8.0, 12.0):
        f = lateral.level_sensitivity(lm, SEG, v, axle(lm))["duals in one rut"]["factor"]
        assert 0.6 < f < 0.9, (v, f)
    # anisotropy: a road more alike across (lam = 2, longer lateral correlation) gives
    # the axles more coherent input on the duals -> also a lower level; lam = 0.5 higher
    s = lateral.level_sensitivity(lm, SEG, 10.0, axle(lm))
    assert s["lam=2"]["factor"] < 1.0 < s["lam=0.5"]["factor"]
    assert "lam=2 x" in lateral.sensitivity_line(s)


def test_bad_input_one_line(lm):
    with pytest.raises(EroadInputError, match="none of the fitted channels"):
        lateral.level_sensitivity(lm, SEG, 10.0, ["nope"])
    with pytest.raises(EroadInputError, match="speed"):
        lateral.level_sensitivity(lm, SEG, -1.0, axle(lm))
    assert math.isfinite(lateral.level_sensitivity(lm, SEG, 10.0, axle(lm) + ["nope"])
                         ["lam=2"]["factor"])


def test_run_summary_and_note():
    import numpy as np

    t = np.arange(0, 20, 0.005)
    v = np.where(t < 10, 8.0, 12.0)
    segs = [dict(SEG, t_start=0.0, t_end=10.0), dict(SEG, t_start=10.0, t_end=20.0)]
    e = lateral.run_summary("dump_truck_8x4", segs, t, v, ["axle_acc_3L", "axle_acc_3R"])
    assert [r["speed_mps"] for r in e["segments"]] == pytest.approx([8.0, 12.0], abs=0.01)
    lo, hi = e["factor_range"]["duals in one rut"]
    assert lo <= hi < 1.0
    line = lateral.note_line(e)
    assert line.startswith("Lateral road structure assumed: isotropic") and "duals in one rut x" in line
    bad = lateral.run_summary("dump_truck_8x4", segs, t, v, ["nope"])
    assert "not computed" in bad["error"] and "not computed" in lateral.note_line(bad)


def test_twin_tyre_note_only_where_every_fitted_axle_has_twins(lm):
    import numpy as np

    # dump_truck_8x4: single tyres on axles 1-2, twins on 3-4 (vehicles/params/dump_truck_8x4.toml)
    assert lateral.twin_tyre_axles(lm) == [3, 4]
    assert lateral.fitted_axles(["susp_disp_3L", "axle_acc_12R", "speed"]) == [3, 12]
    t = np.arange(0, 10, 0.005)
    v = np.full_like(t, 10.0)
    segs = [dict(SEG, t_start=0.0, t_end=10.0)]
    rear = lateral.run_summary("dump_truck_8x4", segs, t, v, ["susp_disp_3L", "susp_disp_3R", "axle_acc_4L"])
    assert rear["twin_tyres_only"] and rear["fitted_axles"] == [3, 4] and rear["single_tyre_axles"] == [1, 2]
    line = lateral.note_line(rear)
    assert "twin tyres" in line and "fit axle 1 or 2 too" in line
    every = lateral.run_summary("dump_truck_8x4", segs, t, v, ["axle_acc_1L", "axle_acc_3L", "susp_disp_3L"])
    assert not every["twin_tyres_only"] and "twin tyres" not in lateral.note_line(every)
