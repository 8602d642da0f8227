"""Writer -> reader round trip and the writer's atomic, non-destructive behaviour."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drives.format import Drive, check_drive, read_drive, write_drive
from eroad.errors import EroadInputError


def frame(n=300, fs=200.0, seed=1, speed=True):
    rng = np.random.default_rng(seed)
    df = pd.DataFrame({"time": 460.0 + np.arange(n) / fs})
    for name, scale in [("susp_disp_3L", 0.01), ("susp_disp_3R", 0.01), ("axle_acc_3L", 3.0),
                        ("body_acc_1R", 0.5), ("dcdc_y_P1", 0.02), ("dcdc_z_P4", 0.03)]:
        df[name] = scale * rng.standard_normal(n)
    if speed:
        df["speed"] = 9.5 + rng.uniform(-1, 1, n)
    return df


def listing(folder: Path):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_round_trip_is_exact(tmp_path):
    """Values survive CSV exactly (shortest round-trip float text), including the time
    column with an offset start (460 s, as in the paper's window)."""
    df = frame()
    out = write_drive(tmp_path / "d", df, {"name": "rt", "vehicle": "dump_truck_8x4",
                                           "start_time_s": 460.0})
    d = read_drive(out)
    assert isinstance(d, Drive)
    np.testing.assert_array_equal(d.time, df["time"].to_numpy())
    for c in d.channel_names:
        np.testing.assert_array_equal(d.channels[c].to_numpy(), df[c].to_numpy())
    np.testing.assert_array_equal(d.speed, df["speed"].to_numpy())
    assert d.sample_rate_hz == pytest.approx(200.0, rel=1e-12)
    assert d.meta["start_time_s"] == 460.0 and d.name == "rt"
    assert d.vehicle == "dump_truck_8x4"
    assert d.units["dcdc_y_P1"] == "m" and d.units["axle_acc_3L"] == "m/s^2"
    pd.testing.assert_frame_equal(d.to_dataframe(), df)


def test_constant_speed_from_meta_and_window(tmp_path):
    df = frame(speed=False)
    d = read_drive(write_drive(tmp_path / "d", df, {"vehicle": "e_tractor", "speed_mps": 8.0}))
    assert d.speed_source == "meta" and np.all(d.speed == 8.0)
    w = d.window(460.5, 461.0)
    assert w.n_samples == 100 and w.time[0] == pytest.approx(460.5)
    with pytest.raises(EroadInputError, match="fewer than 2 samples"):
        d.window(0, 1)
    with pytest.raises(EroadInputError, match="needs column\\(s\\) body_acc_3L"):
        d.require(["susp_disp_3L", "body_acc_3L"], purpose="test")


def test_vehicle_file_copied_and_add_files(tmp_path):
    vf = tmp_path / "my_truck.toml"
    vf.write_text("# nominal\n")

    def add(tmp):
        (tmp / "truth").mkdir()
        (tmp / "truth" / "x.txt").write_text("t")

    out = write_drive(tmp_path / "d", frame(), {}, vehicle_file=vf, add_files=add)
    assert listing(out) == ["channels.csv", "meta.toml", "truth", "truth/x.txt", "vehicle.toml"]
    assert read_drive(out).vehicle == (out / "vehicle.toml").resolve()


def test_refuses_non_empty_target_and_overwrite_replaces(tmp_path):
    target = tmp_path / "d"
    target.mkdir()
    (target / "precious.txt").write_text("keep me")
    with pytest.raises(EroadInputError, match="exists and is not empty"):
        write_drive(target, frame(), {"vehicle": "dump_truck_8x4"})
    assert listing(target) == ["precious.txt"]
    write_drive(target, frame(), {"vehicle": "dump_truck_8x4"}, overwrite=True)
    assert listing(target) == ["channels.csv", "meta.toml"]
    assert listing(tmp_path) == ["d", "d/channels.csv", "d/meta.toml"]  # no temp left


def test_empty_existing_folder_is_used(tmp_path):
    (tmp_path / "d").mkdir()
    write_drive(tmp_path / "d", frame(), {"vehicle": "dump_truck_8x4"})
    assert check_drive(tmp_path / "d") == []


@pytest.mark.parametrize("mutate,msg", [
    (lambda df: df.assign(susp_disp_3L=np.r_[np.nan, df.susp_disp_3L.to_numpy()[1:]]),
     "NaN value"),
    (lambda df: df.assign(susp_disp_3L=df.susp_disp_3L * 1000), "looks like millimetres"),
    (lambda df: df.rename(columns={"body_acc_1R": "bodyacc"}), "does not parse"),
    (lambda df: df.drop(columns="time"), "first column is 'time'"),
])
def test_writer_refuses_bad_frames_and_writes_nothing(tmp_path, mutate, msg):
    """The writer validates with the reader's checks; on failure neither the target nor
    a temporary folder remains, and an existing folder is untouched."""
    with pytest.raises(EroadInputError, match=msg):
        write_drive(tmp_path / "d", mutate(frame()), {"vehicle": "dump_truck_8x4"})
    assert listing(tmp_path) == []
    keep = tmp_path / "old"
    write_drive(keep, frame(), {"vehicle": "dump_truck_8x4"})
    before = (keep / "channels.csv").read_bytes()
    with pytest.raises(EroadInputError, match=msg):
        write_drive(keep, mutate(frame()), {"vehicle": "dump_truck_8x4"}, overwrite=True)
    assert (keep / "channels.csv").read_bytes() == before
    assert listing(tmp_path) == ["old", "old/channels.csv", "old/meta.toml"]


def test_writer_message_names_target_not_temp(tmp_path):
    df = frame()
    df.loc[5, "axle_acc_3L"] = np.inf
    with pytest.raises(EroadInputError) as exc:
        write_drive(tmp_path / "d", df, {"vehicle": "dump_truck_8x4"})
    assert str(tmp_path / "d" / "channels.csv") in str(exc.value)
    assert ".tmp-" not in str(exc.value)
    assert "column 'axle_acc_3L', row 7" in str(exc.value)


def test_same_frame_same_bytes(tmp_path):
    a = write_drive(tmp_path / "a", frame(), {"name": "x", "vehicle": "dump_truck_8x4"})
    b = write_drive(tmp_path / "b", frame(), {"name": "x", "vehicle": "dump_truck_8x4"})
    for f in ("channels.csv", "meta.toml"):
        assert (a / f).read_bytes() == (b / f).read_bytes()


def test_the_displacement_zero_declaration(tmp_path):
    """``[dataset] susp_disp_zero``: optional, "nominal_static" or "unknown"; anything else is
    refused with one line naming meta.toml and the key."""
    d = read_drive(write_drive(tmp_path / "a", frame(), {"vehicle": "dump_truck_8x4",
                                                         "susp_disp_zero": "nominal_static"}))
    assert d.meta["susp_disp_zero"] == "nominal_static"
    assert "susp_disp_zero" not in read_drive(write_drive(tmp_path / "b", frame(),
                                                          {"vehicle": "dump_truck_8x4"})).meta
    write_drive(tmp_path / "c", frame(), {"vehicle": "dump_truck_8x4"})
    meta = tmp_path / "c" / "meta.toml"
    meta.write_text(meta.read_text() + 'susp_disp_zero = "laden"\n')
    probs = check_drive(tmp_path / "c")
    assert len(probs) == 1 and "meta.toml" in probs[0] and "susp_disp_zero = 'laden'" in probs[0]
    assert '"nominal_static", "unknown"' in probs[0]


def test_data_check_says_what_the_displacement_zero_is(tmp_path, capsys):
    """`eroad data check` prints the declaration in one line (and in --json), so a user sees
    whether the mean displacement will count as evidence."""
    from eroad.cli import main

    a = write_drive(tmp_path / "a", frame(), {"vehicle": "dump_truck_8x4",
                                              "susp_disp_zero": "nominal_static"})
    b = write_drive(tmp_path / "b", frame(), {"vehicle": "dump_truck_8x4"})
    assert main(["data", "check", str(a)]) == 0
    out = capsys.readouterr().out
    assert "disp zero the nominal vehicle at rest (declared)" in out
    assert main(["data", "check", str(b)]) == 0
    assert "disp zero unknown: the mean displacement is not used" in capsys.readouterr().out
    assert main(["data", "check", str(b), "--json"]) == 0
    import json

    assert json.loads(capsys.readouterr().out)["susp_disp_zero"] == "unknown"
