"""Physical unit checks of a measured drive (drives.plausibility, wired into the reader).

Reference: the kinematic identity s'' = a_axle - a_body of a wheel station, built here from
two independent smooth motions with closed-form second derivatives (no vehicle model),
and one short drive of the Exudyn truck (the simulator's own channels must pass).
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from drives.format import read_drive, write_drive
from drives.plausibility import G, check_units, kinematic_ratio
from eroad.cli import main
from eroad.errors import EroadInputError

FS = 200.0


def _motion(rng, t, f_lo, f_hi, amp):
    """Sum of 30 sines in [f_lo, f_hi] Hz: position and its exact second derivative."""
    f = rng.uniform(f_lo, f_hi, 30)
    ph = rng.uniform(0, 2 * np.pi, 30)
    a = amp * rng.uniform(0.5, 1.0, 30) / np.sqrt(30)
    z = (a[:, None] * np.sin(2 * np.pi * f[:, None] * t + ph[:, None])).sum(0)
    z2 = (-(2 * np.pi * f[:, None]) ** 2 * a[:, None] * np.sin(2 * np.pi * f[:, None] * t + ph[:, None])).sum(0)
    return z, z2


def station_frame(seed=0, duration=20.0, axles=(1, 3), sides="LR", body=True):
    """Channels of wheel stations from independent body (0.5-4 Hz) and axle (2-20 Hz)
    motions; every channel obeys s'' = a_axle - a_body exactly (SI units)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FS)) / FS
    df = {"time": t}
    for a in axles:
        for s in sides:
            zb, zb2 = _motion(rng, t, 0.5, 4.0, 0.01)
            za, za2 = _motion(rng, t, 2.0, 20.0, 0.005)
            df[f"susp_disp_{a}{s}"] = za - zb
            df[f"axle_acc_{a}{s}"] = za2
            if body:
                df[f"body_acc_{a}{s}"] = zb2
    return pd.DataFrame(df)


def _channels(df):
    return {c: df[c].to_numpy() for c in df.columns if c != "time"}


def test_kinematic_ratio_is_one_in_si_units():
    """Ratio 1 within 3 %: the band-pass is the same on both sides, so only the compact
    second difference differs from the exact s'' (at 15 Hz and 200 Hz sampling it reads
    (sin(pi f/fs)/(pi f/fs))^2 = 0.984 of it, closer to 1 at lower frequencies)."""
    ch = _channels(station_frame())
    r, c = kinematic_ratio(ch["susp_disp_1L"], ch["axle_acc_1L"], ch["body_acc_1L"], FS)
    assert r == pytest.approx(1.0, abs=0.03) and c > 0.99
    assert check_units(ch, FS) == []


@pytest.mark.parametrize("edit, expect", [
    (lambda c: {k: (v / G if "acc" in k else v) for k, v in c.items()}, "accelerations in g"),
    (lambda c: {k: (v * 1000 if "susp" in k else v) for k, v in c.items()}, "displacement in mm"),
    (lambda c: {k: (v / G if "acc" in k else v * 1000) for k, v in c.items()}, "in g and suspension displacement in mm"),
    (lambda c: {k: (v * 1000 if "acc" in k else v) for k, v in c.items()}, "mm/s^2"),
    (lambda c: {k: (v - G if "acc" in k else v) for k, v in c.items()}, "gravity left in"),
    (lambda c: {k: (v + G if k.startswith("body") else v) for k, v in c.items()}, "gravity left in"),
])
def test_wrong_units_are_fatal(edit, expect):
    """g, mm, both, mm/s^2 and gravity (either sign, body accelerometers only) are named."""
    found = check_units(edit(_channels(station_frame(seed=1))), FS)
    assert found and all(f.fatal for f in found)
    assert any(expect in f.message for f in found), [f.message for f in found]


def test_one_side_and_no_body_channel():
    """A single side without body acceleration: the axle acceleration alone stands in
    (the body, 0.5-4 Hz here, is mostly below the 4-15 Hz band); SI passes, g is named."""
    ch = _channels(station_frame(seed=2, axles=(3,), sides="L", body=False))
    assert check_units(ch, FS) == []
    g = check_units({k: (v / G if "acc" in k else v) for k, v in ch.items()}, FS)
    assert len(g) == 1 and g[0].fatal and "in g" in g[0].message and g[0].column == "susp_disp_3L"


def test_sign_flip_is_a_warning_not_a_refusal():
    """A displacement recorded positive in extension correlates at -1: reported, not refused
    (no unit is wrong), naming the station."""
    ch = _channels(station_frame(seed=3, axles=(2,)))
    ch["susp_disp_2L"], ch["susp_disp_2R"] = -ch["susp_disp_2L"], -ch["susp_disp_2R"]
    found = check_units(ch, FS)
    assert len(found) == 1 and not found[0].fatal and "sign flipped" in found[0].message


def test_reader_refuses_g_with_one_line_and_check_lists_it(tmp_path, capsys):
    """read_drive: one line naming channels.csv and the column; `eroad data check`: exit 2;
    the SI version reads with no warning."""
    df = station_frame(seed=4)
    ok = write_drive(tmp_path / "si", df, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    assert read_drive(ok).warnings == ()
    bad = df.copy()
    for c in bad.columns:
        if "acc" in c:
            bad[c] = bad[c] / G
    with pytest.raises(EroadInputError, match="not written.*accelerations in g"):
        write_drive(tmp_path / "g", bad, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    path = write_drive(tmp_path / "g", df, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    bad.to_csv(path / "channels.csv", index=False, float_format="%.17g")   # a logger's g file
    with pytest.raises(EroadInputError) as e:
        read_drive(path)
    msg = str(e.value)
    assert "\n" not in msg and "channels.csv" in msg and "column 'susp_disp_1L/R'" in msg and "in g" in msg
    assert main(["data", "check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "accelerations in g" in err


def test_warning_shown_by_data_check(tmp_path, capsys):
    df = station_frame(seed=5, axles=(3,))
    df["susp_disp_3L"], df["susp_disp_3R"] = -df["susp_disp_3L"], -df["susp_disp_3R"]
    path = write_drive(tmp_path / "flip", df, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    assert main(["data", "check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "warning" in out and "sign flipped" in out


@pytest.fixture(scope="module")
def truck_drive(tmp_path_factory):
    from drives.synth import synth_command
    out = tmp_path_factory.mktemp("units") / "ds"
    synth_command(scenario="null", seed=11, duration=8.0, out=out)
    return read_drive(out)


def test_exudyn_drive_passes_and_its_g_version_is_refused(truck_drive):
    """The truck's own channels (sensor noise 0.1 mm, 0.03 m/s^2) pass with no finding, the
    side-averaged ratio within 10 % of 1 on every axle (measured 1.02-1.06: noise and the
    finite difference), and the same record in g is refused on every axle."""
    ch = {c: truck_drive.channels[c].to_numpy() for c in truck_drive.channel_names}
    assert check_units(ch, truck_drive.sample_rate_hz) == []
    for a in "1234":
        m = {q: 0.5 * (ch[f"{q}_{a}L"] + ch[f"{q}_{a}R"]) for q in ("susp_disp", "axle_acc", "body_acc")}
        r, c = kinematic_ratio(m["susp_disp"], m["axle_acc"], m["body_acc"], truck_drive.sample_rate_hz)
        assert r == pytest.approx(1.0, abs=0.1) and c > 0.95, (a, r, c)
    g = check_units({k: (v / G if "acc" in k else v) for k, v in ch.items()}, truck_drive.sample_rate_hz)
    assert sum(f.fatal and "in g" in f.message for f in g) == 4


def test_a_scale_error_of_two_is_a_warning_on_every_axle(truck_drive):
    """Axle accelerations twice too large (a wrong sensitivity, no named unit): with the two
    sides of each axle averaged the ratio is about 2, above the pair tolerance 1.5 and far
    from the g and mm windows, so each of the 4 axles gets one warning and none is fatal."""
    ch = {c: truck_drive.channels[c].to_numpy() for c in truck_drive.channel_names}
    found = check_units({k: (2 * v if k.startswith("axle_acc") else v) for k, v in ch.items()},
                        truck_drive.sample_rate_hz)
    assert sorted(f.column for f in found) == [f"susp_disp_{a}L/R" for a in "1234"]
    assert not any(f.fatal for f in found) and all("scale error" in f.message for f in found)
