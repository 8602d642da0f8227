"""Vehicle parameter files: loading, strictness, round trip, documentation."""
import re
import tomllib
from dataclasses import replace
from pathlib import Path

import pytest

from eroad.errors import EroadInputError
from vehicles.params import (PARAMS_DIR, VehicleParams, builtin_ids, field_table, load_vehicle,
                             save_vehicle, vehicle_to_dict)

DOCS = Path(__file__).resolve().parents[1] / "docs" / "vehicles.md"


def _write(tmp_path, doc, name="v.toml"):
    import tomli_w

    p = tmp_path / name
    p.write_bytes(tomli_w.dumps(doc).encode())
    return p


def test_builtins_load():
    ids = builtin_ids()
    assert "dump_truck_8x4" in ids and "e_tractor" in ids
    dt = load_vehicle("dump_truck_8x4")
    assert isinstance(dt, VehicleParams)
    assert dt.n_axles == 4 and [a.tyres_per_side for a in dt.axles] == [1, 1, 2, 2]
    assert [a.steered for a in dt.axles] == [True, True, False, False]
    assert dt.dcdc is None
    tr = load_vehicle("e_tractor")
    assert tr.dcdc is not None and tr.dcdc.mass == pytest.approx(2300.0)
    # plausibility of the totals (engineering estimates in docs/vehicles.md)
    assert 28e3 < dt.total_mass < 32e3
    assert 18e3 < tr.total_mass < 26e3


def test_unknown_field_is_refused_naming_field_and_file(tmp_path):
    doc = vehicle_to_dict(load_vehicle("dump_truck_8x4"))
    doc["axle"][2]["spring_stifness"] = 1.0
    p = _write(tmp_path, doc)
    with pytest.raises(EroadInputError, match=r"v\.toml.*unknown field 'axle\[2\]\.spring_stifness'"):
        load_vehicle(p)


def test_missing_field_is_refused_naming_field_and_file(tmp_path):
    doc = vehicle_to_dict(load_vehicle("e_tractor"))
    del doc["dcdc"]["mount_vertical_stiffness"]
    p = _write(tmp_path, doc)
    with pytest.raises(EroadInputError, match=r"v\.toml.*missing field 'dcdc\.mount_vertical_stiffness'"):
        load_vehicle(p)
    doc = vehicle_to_dict(load_vehicle("e_tractor"))
    del doc["frame"]
    with pytest.raises(EroadInputError, match="missing table 'frame'"):
        load_vehicle(_write(tmp_path, doc, "w.toml"))


def test_wrong_type_and_implausible_value_refused(tmp_path):
    doc = vehicle_to_dict(load_vehicle("dump_truck_8x4"))
    doc["axle"][0]["tyre_stiffness"] = "stiff"
    with pytest.raises(EroadInputError, match=r"axle\[0\]\.tyre_stiffness.*number"):
        load_vehicle(_write(tmp_path, doc))
    doc = vehicle_to_dict(load_vehicle("dump_truck_8x4"))
    doc["axle"][1]["spring_stiffness"] = -5.0
    with pytest.raises(EroadInputError, match=r"axle\[1\]\.spring_stiffness.*positive"):
        load_vehicle(_write(tmp_path, doc, "b.toml"))


def test_missing_file_and_unknown_id_refused(tmp_path):
    with pytest.raises(EroadInputError, match="no such vehicle file"):
        load_vehicle(tmp_path / "nothing.toml")
    with pytest.raises(EroadInputError, match="unknown vehicle 'truck9'"):
        load_vehicle("truck9")
    bad = tmp_path / "bad.toml"
    bad.write_text("[vehicle\nid = 1")
    with pytest.raises(EroadInputError, match="not valid TOML"):
        load_vehicle(bad)


def test_round_trip_and_variants(tmp_path):
    vp = load_vehicle("e_tractor")
    v2 = replace(vp, frame=replace(vp.frame, segments=6))
    p = save_vehicle(v2, tmp_path / "t.toml")
    back = load_vehicle(p)
    assert back == v2 and back.frame.segments == 6


def test_every_field_has_unit_and_is_documented():
    """docs/vehicles.md lists every field of every table, with its unit."""
    text = DOCS.read_text()
    rows = field_table()
    assert rows
    for r in rows:
        assert r["unit"] and r["doc"], r
        assert re.search(rf"`{r['field']}`", text), f"{r['table']}.{r['field']} missing in docs/vehicles.md"


def test_builtin_files_have_no_extra_keys():
    """Every built-in file parses strictly (no unknown keys) and every value is used."""
    for vid in builtin_ids():
        with open(PARAMS_DIR / f"{vid}.toml", "rb") as fh:
            doc = tomllib.load(fh)
        assert vehicle_to_dict(load_vehicle(vid)).keys() == doc.keys()
