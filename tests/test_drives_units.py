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
from drives.plausibility import (G, check_signals, check_speed, check_units, delay_scale, kinematic_fit,
                                   kinematic_ratio, speed_delay_scale)
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


# --------------------------------------------------------------------------- body channel on its own

def test_body_channel_in_g_alone_is_refused_and_named():
    """Body accelerations in g with the axle ones in m/s^2: the ratio of (a_axle - a_body) moves
    by a few per cent only (above 4 Hz the body is a small part of it), so only the two-input fit
    over 1-15 Hz sees it: beta = 9.81 (exact identity here) -> fatal on the body column."""
    ch = _channels(station_frame(seed=6))
    bad = {k: (v / G if k.startswith("body") else v) for k, v in ch.items()}
    found = check_units(bad, FS)
    assert found and all(f.fatal for f in found)
    assert sorted(f.column for f in found) == ["body_acc_1L/R", "body_acc_3L/R"]
    assert all("body accelerations in g" in f.message for f in found)


def test_axle_channel_in_g_alone_is_named_as_the_axle():
    ch = _channels(station_frame(seed=7))
    bad = {k: (v / G if k.startswith("axle") else v) for k, v in ch.items()}
    found = check_units(bad, FS)
    assert len(found) == 2 and all(f.fatal and "axle accelerations in g, body accelerations in m/s^2"
                                   in f.message for f in found), [f.message for f in found]


def test_body_sign_flip_is_a_warning():
    ch = _channels(station_frame(seed=8, axles=(2,)))
    ch["body_acc_2L"], ch["body_acc_2R"] = -ch["body_acc_2L"], -ch["body_acc_2R"]
    found = check_units(ch, FS)
    assert len(found) == 1 and not found[0].fatal and "sign is flipped" in found[0].message


def test_kinematic_fit_factors_are_one_in_si():
    """alpha = beta = 1 within 5 % and R^2 > 0.98: the compact second difference reads
    (sin(pi f/fs)/(pi f/fs))^2 = 0.967 of s'' at 20 Hz, the top of the axle's 2-20 Hz motion here,
    so alpha comes out 0.961 and the frequency-dependent rest leaks into beta (0.974, R^2 0.985);
    the unit gates are factors 1.5 and 9.81 away."""
    ch = _channels(station_frame(seed=9))
    alpha, beta, r2, se = kinematic_fit(ch["susp_disp_1L"], ch["axle_acc_1L"], ch["body_acc_1L"], FS)
    assert 0 < se < 0.05
    assert alpha == pytest.approx(1.0, abs=0.05) and beta == pytest.approx(1.0, abs=0.05) and r2 > 0.98


def test_exudyn_drive_body_in_g_is_refused_on_every_axle(truck_drive):
    ch = {c: truck_drive.channels[c].to_numpy() for c in truck_drive.channel_names}
    found = check_units({k: (v / G if k.startswith("body") else v) for k, v in ch.items()},
                        truck_drive.sample_rate_hz)
    assert sorted(f.column for f in found if f.fatal and "body accelerations in g" in f.message) \
        == [f"body_acc_{a}L/R" for a in "1234"]


# --------------------------------------------------------------------------- speed from the axle delay

AXLE_X = {1: 0.0, 2: -1.8, 3: -5.0, 4: -6.35}   # the 8x4 truck's file


def road_drive(seed=0, duration=30.0, vary=2.0):
    """Axle signals as copies of one band-limited road profile z(s) under each axle (axle i at
    x_i sees z(s + x_i)), with a speed that varies 8-12 m/s in closed form: the delay holds in
    distance, not time. No vehicle model: the reference is kinematic."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * FS)) / FS
    v = 10.0 + vary * np.sin(0.3 * t)
    s = 10.0 * t - (vary / 0.3) * (np.cos(0.3 * t) - 1.0)
    n = rng.uniform(0.05, 2.0, 60)
    ph = rng.uniform(0, 2 * np.pi, 60)
    amp = 0.005 / n
    ch = {}
    for a, x in AXLE_X.items():
        for side, off in (("L", 0.0), ("R", 1.0)):
            ch[f"axle_acc_{a}{side}"] = (amp[:, None] * np.sin(2 * np.pi * n[:, None] * (s + x) + ph[:, None]
                                                              + off * rng.uniform(0, 1, 60)[:, None])).sum(0)
    return ch, v


@pytest.mark.parametrize("factor, fatal, expect", [
    (1.0, None, None),
    (3.6, True, "speed in km/h"),
    (1.0 / 3.6, True, "3.6x too small"),
    (2.2369362921, True, "speed in mph"),
    (1.25, False, "off by that factor"),
    (2.8, True, "no road could be identified"),
])
def test_speed_scale_from_the_axle_delay(factor, fatal, expect):
    """The correlation peak of two axles of a side sits at the axle spacing in distance
    integrated from the speed: a speed off by k puts it at k spacings. Named unit errors and
    any factor beyond 2 are fatal, a smaller one a warning, a right speed gives nothing (tolerance factor 1.1; the
    grid step 0.045-0.05 m is 1-4 % of a spacing)."""
    ch, v = road_drive()
    found = check_speed(ch, v * factor, FS, AXLE_X)
    if expect is None:
        assert found == []
        return
    assert len(found) == 1 and found[0].fatal is fatal and expect in found[0].message, found
    k, c = delay_scale(ch["axle_acc_1L"], ch["axle_acc_3L"], 5.0,
                       np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1])) * factor / FS]), FS)
    if factor > 0.5:   # the 5 m pair's lag at 1/3.6 is below the searched 0.2 spacings
        assert k == pytest.approx(factor, rel=0.02) and c > 0.9


def test_speed_level_without_two_axles_is_a_warning():
    ch, v = road_drive()
    one = {k: x for k, x in ch.items() if k.startswith("axle_acc_3")}
    assert check_speed(one, v, FS, AXLE_X) == [] and speed_delay_scale(one, v, FS, AXLE_X) is None
    found = check_speed(one, v * 3.6, FS, AXLE_X)
    assert len(found) == 1 and not found[0].fatal and "in km/h?" in found[0].message
    assert check_speed(ch, v * 3.6, FS, None)[0].fatal is False   # no vehicle file: level only


def test_independent_truck_drive_passes_and_its_kmh_speed_is_refused(tmp_path, capsys):
    """A drive of the independently written truck (not our model) reads clean; the same drive
    with its speed column in km/h is refused by the reader with one line and by `eroad data
    check` with exit 2; a meta.toml speed 3.6x off (no speed column) is refused naming meta.toml."""
    from drives.synth import synth_command
    out = tmp_path / "second"
    synth_command(scenario="second", seed=21, duration=10.0, out=out)
    d = read_drive(out)
    assert not any("speed" in w for w in d.warnings)
    assert d.speed_check["scale"] == pytest.approx(1.0, abs=0.03) and d.speed_check["agree"] >= 2
    assert d.summary()["speed_check"] == d.speed_check
    df = pd.read_csv(out / "channels.csv")
    df["speed"] = df["speed"] * 3.6
    df.to_csv(out / "channels.csv", index=False, float_format="%.17g")
    with pytest.raises(EroadInputError) as e:
        read_drive(out)
    msg = str(e.value)
    assert "\n" not in msg and "column 'speed'" in msg and "speed in km/h" in msg
    assert main(["data", "check", str(out)]) == 2
    assert "speed in km/h" in capsys.readouterr().err
    ch, v = road_drive(seed=3, duration=20.0, vary=0.0)
    frame = pd.DataFrame({"time": np.arange(v.size) / FS, **ch})
    path = write_drive(tmp_path / "meta-speed", frame, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    assert read_drive(path).warnings == ()
    (path / "meta.toml").write_text((path / "meta.toml").read_text().replace("speed_mps = 10.0", "speed_mps = 36.0"))
    with pytest.raises(EroadInputError, match=r"meta.toml.*speed_mps = 36.*speed in km/h"):
        read_drive(path)


# --------------------------------------------------------------------------- dead and clipped channels

def test_dead_and_clipped_channels_are_warnings(tmp_path):
    df = station_frame(seed=10, axles=(3,))
    df["axle_acc_3R"] = 0.0
    df["body_acc_3L"] = df["body_acc_3L"].clip(-0.05, 0.05)
    found = check_signals(_channels(df))
    assert {f.column for f in found} == {"axle_acc_3R", "body_acc_3L"} and not any(f.fatal for f in found)
    assert any("constant 0" in f.message for f in found) and any("clipped" in f.message for f in found)
    assert check_signals(_channels(station_frame(seed=10, axles=(3,)))) == []


def test_body_factor_rule_weighs_its_standard_error_and_the_noise_bias(monkeypatch):
    """The rule of the body factor, on given fit results: above the SI range by less than 3
    standard errors -> nothing; by more -> a warning; at 9.81 -> named and fatal; far below
    the range (a quiet body under sensor noise biases beta towards 0) -> nothing unless at the
    mm/s^2 factor 1/1000."""
    import drives.plausibility as pl

    def finding(beta, se):
        monkeypatch.setattr(pl, "kinematic_fit", lambda *a: (1.0, beta, 0.9, se))
        return pl._body_finding("3", np.zeros(2000), None, None, FS)

    assert finding(1.9, 0.2) is None                        # 1.5 + 3 x 0.2 = 2.1
    f = finding(1.9, 0.05)
    assert f is not None and not f.fatal and "scale error" in f.message
    f = finding(9.0, 0.3)
    assert f.fatal and "body accelerations in g" in f.message
    assert finding(0.05, 0.01) is None                      # below the range: attenuation, no finding
    f = finding(0.0011, 0.0001)
    assert f.fatal and "mm/s^2" in f.message
    f = finding(-1.0, 0.05)
    assert not f.fatal and "sign is flipped" in f.message
    assert finding(-0.1, 0.05) is None                      # sign not determined


def _with_columns(tmp_path, name, df, edit):
    """A valid dataset of ``df``, then its channels.csv replaced by ``edit(df)`` (a logger's
    file as it came: write_drive itself refuses such data)."""
    path = write_drive(tmp_path / name, df, {"vehicle": "dump_truck_8x4", "speed_mps": 10.0})
    edit(df.copy()).to_csv(path / "channels.csv", index=False, float_format="%.17g")
    return path


def _refusal(path) -> str:
    with pytest.raises(EroadInputError) as e:
        read_drive(path)
    return str(e.value)


@pytest.mark.parametrize("edit, expect", [
    # the displacement in mm: the unit hint, unchanged
    (lambda d: d.assign(susp_disp_1L=1000 * d["susp_disp_1L"]), "looks like millimetres"),
    # swapped with the station's axle or body acceleration: named, both columns
    (lambda d: d.rename(columns={"susp_disp_1L": "axle_acc_1L", "axle_acc_1L": "susp_disp_1L"}),
     "columns 'susp_disp_1L' and 'axle_acc_1L' look swapped"),
    (lambda d: d.rename(columns={"susp_disp_1L": "body_acc_1L", "body_acc_1L": "susp_disp_1L"}),
     "columns 'susp_disp_1L' and 'body_acc_1L' look swapped"),
    # one column mapped twice
    (lambda d: d.assign(susp_disp_1L=d["axle_acc_3R"]), "repeats column 'axle_acc_3R'"),
    # another station's acceleration, not a copy of a column of this file
    (lambda d: d.assign(susp_disp_1L=d["axle_acc_3R"] + 0.5 * d["axle_acc_1R"]),
     "check the column map"),
])
def test_a_displacement_column_too_large_for_metres_is_told_from_millimetres(tmp_path, edit, expect):
    """The range check's hint for a suspension displacement over 0.5 m: millimetres only where
    the column divided by 1000 obeys s'' = a_axle - a_body; a swap or a copy of an
    acceleration column (peaks of m/s^2 that read as millimetres) is named instead.  Closed-form
    station motions (no vehicle model); one line, and `eroad data check` exits 2.  Where the
    column divided by 1000 fails the identity but nothing is named, the millimetre hint
    stays with the finding beside it (a noisy station is no proof of another quantity)."""
    path = _with_columns(tmp_path, "x", station_frame(seed=6), edit)
    msg = _refusal(path)
    assert "\n" not in msg and "column 'susp_disp_1L'" in msg and expect in msg, msg
    if "swapped" in expect or "repeats" in expect:
        assert "millimetres" in msg and "looks like millimetres" not in msg   # "not millimetres"
    assert main(["data", "check", str(path)]) == 2


def test_millimetres_on_both_truck_families_keep_the_unit_hint(truck_drive, tmp_path):
    """Every displacement channel of our truck (Exudyn, null seed 11) and of the independently
    written truck (second_measured seed 4) in mm: each still reads "looks like millimetres"
    (one side alone passes the kinematic test in mm: the single-side tolerance, factor 3)."""
    from drives.plausibility import large_displacement_cause
    from drives.synth import synth_command

    other = tmp_path / "second"
    synth_command(scenario="second_measured", seed=4, duration=8.0, out=other)
    for drive in (truck_drive, read_drive(other)):
        ch = {c: drive.channels[c].to_numpy() for c in drive.channel_names}
        mm = {k: (1000 * v if k.startswith("susp_disp") else v) for k, v in ch.items()}
        for c in mm:
            if c.startswith("susp_disp"):
                assert large_displacement_cause(c, mm, drive.sample_rate_hz) is None, c


@pytest.mark.parametrize("other", ["axle_acc_3L", "body_acc_3L"])
def test_a_displacement_swapped_with_an_acceleration_inside_every_range_is_refused(tmp_path, other):
    """Displacements of centimetres in an acceleration column and accelerations below 0.5 m/s^2
    in the displacement column pass every range check; the identity with the two columns
    exchanged names the swap (fatal, one line, the pair named); the other axle says nothing."""
    df = station_frame(seed=7)
    k = 0.4 / max(df[c].abs().max() for c in df.columns if "acc" in c)   # a smooth road
    df = df.assign(**{c: k * df[c] for c in df.columns if c != "time"})   # the identity is linear
    path = _with_columns(tmp_path, "s", df,
                         lambda d: d.rename(columns={"susp_disp_3L": other, other: "susp_disp_3L"}))
    msg = _refusal(path)
    assert "\n" not in msg and f"columns 'susp_disp_3L' and '{other}' look swapped" in msg, msg
    ch = _channels(pd.read_csv(path / "channels.csv"))
    found = check_units(ch, FS)
    assert [f.column for f in found] == ["susp_disp_3L"] and found[0].fatal
    assert check_units(_channels(df), FS) == []
