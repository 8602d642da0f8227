"""diagnosis.blind.make_cases: the blind design's draws (no simulation).

Reference: the stated rules of the design -- dataset seeds 1000 S + 100 + i, a fifth of the
cases null, effects in turn -- and, for another vehicle, a payload change scaled by that
vehicle's nominal payload from its TOML (the e-tractor's kingpin load 10 t against the dump
truck's 16 t load), every other value unchanged.
"""
import pytest

from diagnosis.blind import STRENGTH_PAYLOAD_KG, make_cases, nominal_payload


def test_the_dump_truck_draws_are_unchanged_by_the_vehicle_option():
    a, b = make_cases(20, 5), make_cases(20, 5, vehicle="dump_truck_8x4")
    assert [c["value"] for c in a] == [c["value"] for c in b]
    assert [c["seed"] for c in a] == [1000 * 5 + 100 + i for i in range(20)]
    assert sum(c["effect"] == "none" for c in a) == 4


def test_another_vehicle_gets_the_same_draws_its_payload_scaled():
    assert nominal_payload("dump_truck_8x4") == STRENGTH_PAYLOAD_KG == 16000.0
    assert nominal_payload("e_tractor") == 10000.0
    a, b = make_cases(20, 5), make_cases(20, 5, vehicle="e_tractor")
    for x, y in zip(a, b):
        assert y["vehicle"] == "e_tractor" and (x["effect"], x["seed"]) == (y["effect"], y["seed"])
        if x["effect"] == "payload":
            assert y["value"] == pytest.approx(x["value"] * 10000.0 / 16000.0, rel=1e-12)
            assert abs(y["value"]) <= 10000.0          # inside the tractor's [-P, +P]
        else:
            assert y["value"] == x["value"]


def test_the_independent_truck_family_refuses_another_vehicle():
    with pytest.raises(ValueError, match="nominal family only"):
        make_cases(4, 1, family="second", vehicle="e_tractor")


def test_the_measured_road_family_drives_the_nominal_truck_on_the_profile():
    """Family ``measured``: every case on scenario ``null_measured`` (the nominal truck on the
    measured profile), half of them null, the nominal family's effects and strengths in turn,
    dataset seeds offset by 70000 so that no drive is another family's."""
    from diagnosis.blind import FAMILY_SEED_OFFSET

    m = make_cases(16, 431, family="measured")
    assert {c["scenario"] for c in m} == {"null_measured"} and {c["family"] for c in m} == {"measured"}
    assert sum(c["effect"] == "none" for c in m) == 8
    assert [c["seed"] for c in m] == [1000 * 431 + 70100 + i for i in range(16)]
    seeds = {f: {c["seed"] for c in make_cases(16, 431, family=f)} for f in FAMILY_SEED_OFFSET}
    assert not (seeds["measured"] & seeds["nominal"]) and not (seeds["measured"] & seeds["second"])
    effects = [c["effect"] for c in m if c["effect"] != "none"]
    assert len(set(effects)) == 8
