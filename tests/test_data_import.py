"""``eroad data import``: logger CSV + column map -> a measurement dataset (drives.importer).

Reference dataset: wheel stations built from sums of sines with closed-form second
derivatives (s'' = a_axle - a_body holds exactly, so the contract's unit checks pass), plus
white noise on the accelerations (a sensor's noise reaches the Nyquist frequency, which is
where resampling errs most). The logger file is made from it the way a logger would have
recorded it: semicolon-delimited, time in ms, displacements in mm, accelerations in g with
gravity on the body accelerations, its own column names, each sample taken at a time
jittered by up to 0.1 % of the step (the value there is the original signal's not-a-knot
cubic spline at that time).

Tolerances (relative = max |imported - original| / max |original|, per channel):
* cubic round trip: 1e-6. The first- and second-order terms in the jitter e cancel
  between making and resampling; what is left comes from the two splines having their
  knots at different times, largest for content near the Nyquist frequency. Measured:
  up to 8.5e-7 on the luliang virtual drive (5 jitter seeds x 24 channels, body
  accelerations with sensor noise worst), below 1e-7 here (10 seeds).
* linear round trip: above 1e-5 (slope error O(h x'') times e): linear cannot reach 1e-6.
* against an exact signal sampled at jittered times (not a round trip): e (s' - x'), about
  j (2 pi f / fs)^4 / 24 of the amplitude for a sine at f (j = 1e-3): 6.5e-6 at 20 Hz and
  200 Hz; bounded here at 1e-5 for content up to 20 Hz.
"""
from __future__ import annotations

import hashlib
import re
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicSpline

from drives.format import check_drive, read_drive, write_drive
from drives.importer import G, import_logger, read_map, template_text
from eroad.cli import main
from eroad.errors import EroadInputError

FS = 200.0
JITTER = 1e-3          # 0.1 % of the step


def _motion(rng, t, f_lo, f_hi, amp, n=20):
    f = rng.uniform(f_lo, f_hi, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    a = amp * rng.uniform(0.5, 1.0, n) / np.sqrt(n)
    arg = 2 * np.pi * f[:, None] * t + ph[:, None]
    return (a[:, None] * np.sin(arg)).sum(0), (-(2 * np.pi * f[:, None]) ** 2
                                                 * a[:, None] * np.sin(arg)).sum(0)


def station_frame(t, seed=0, noise=0.02):
    """Axle 3, both sides: s = z_axle - z_body, a_axle = z_axle'', a_body = z_body'' (+ noise)."""
    rng = np.random.default_rng(seed)
    df = {"time": t}
    for s in "LR":
        zb, zb2 = _motion(rng, t, 0.5, 4.0, 0.01)
        za, za2 = _motion(rng, t, 2.0, 20.0, 0.005)
        df[f"susp_disp_3{s}"] = za - zb
        df[f"axle_acc_3{s}"] = za2 + noise * np.std(za2) * rng.standard_normal(t.size)
        df[f"body_acc_3{s}"] = zb2 + noise * np.std(zb2) * rng.standard_normal(t.size)
    df["speed"] = 9.5 + 0.5 * np.sin(2 * np.pi * 0.05 * t)
    return pd.DataFrame(df)


LOGGER_NAMES = {"susp_disp_3L": "Weg_HA3_li", "susp_disp_3R": "Weg_HA3_re",
                "axle_acc_3L": "aAchse_3_li", "axle_acc_3R": "aAchse_3_re",
                "body_acc_3L": "aRahmen_3_li", "body_acc_3R": "aRahmen_3_re", "speed": "v_kmh"}

MAP = """
[source]
delimiter = ";"
[time]
column = "Zeit_ms"
unit = "ms"
[channels]
susp_disp_3L = { column = "Weg_HA3_li", unit = "mm" }
susp_disp_3R = { column = "Weg_HA3_re", unit = "mm" }
axle_acc_3L = { column = "aAchse_3_li", unit = "g" }
axle_acc_3R = { column = "aAchse_3_re", unit = "g" }
body_acc_3L = { column = "aRahmen_3_li", unit = "g", gravity = "g" }
body_acc_3R = { column = "aRahmen_3_re", unit = "g", gravity = "g" }
speed = { column = "v_kmh", unit = "km/h" }
[resample]
method = "{method}"
[dataset]
name = "own-drive"
vehicle = "dump_truck_8x4"
"""


@pytest.fixture(scope="module")
def original(tmp_path_factory):
    """A contract dataset: 8 s at 200 Hz starting at t = 460 s."""
    folder = tmp_path_factory.mktemp("orig") / "orig"
    t = 460.0 + np.arange(int(8 * FS)) / FS
    write_drive(folder, station_frame(t), {"vehicle": "dump_truck_8x4"})
    return read_drive(folder)


def logger_frame(drive, seed=0, jitter=JITTER):
    """The logger's view of a drive: jittered times, own names, ms, mm, g, gravity on bodies."""
    t = drive.time
    e = np.random.default_rng(seed).uniform(-jitter, jitter, t.size) * drive.dt
    e[0] = 0.0                      # the logger's clock starts on its first sample
    tj = t + e
    cols = {"Zeit_ms": tj * 1000.0}
    frame = drive.to_dataframe()
    for c, name in LOGGER_NAMES.items():
        y = CubicSpline(t, frame[c].to_numpy())(tj)
        if c.startswith("susp"):
            y = y * 1000.0
        elif c.startswith("axle"):
            y = y / G
        elif c.startswith("body"):
            y = y / G + 1.0         # gravity in: +1 g at rest
        else:
            y = y * 3.6
        cols[name] = y
    cols["Temperatur"] = np.full(t.size, 21.5)   # a column the map does not use
    return pd.DataFrame(cols)


def write_logger(df, path: Path, sep=";", decimal="."):
    df.to_csv(path, sep=sep, index=False, decimal=decimal)
    return path


def write_map(path: Path, method="cubic", extra="") -> Path:
    text = MAP.replace("{method}", method)
    if extra:
        text = text.replace("[dataset]", extra + "\n[dataset]")
    path.write_text(text)
    return path


def rel_errors(a, b) -> dict:
    fa, fb = a.to_dataframe(), b.to_dataframe()
    return {c: float(np.max(np.abs(fa[c] - fb[c])) / np.max(np.abs(fa[c])))
            for c in fa.columns if c != "time"}


# --------------------------------------------------------------------------- the target

def test_round_trip_within_1e6(original, tmp_path):
    """The logger file imports to the original dataset within 1e-6 relative, every channel,
    same time grid, and passes the contract check."""
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    out = tmp_path / "imported"
    s = import_logger(raw, write_map(tmp_path / "map.toml"), out)
    assert check_drive(out) == []
    got = read_drive(out)
    assert got.n_samples == original.n_samples
    assert np.max(np.abs(got.time - original.time)) < 1e-9
    assert got.sample_rate_hz == FS and s["rate_hz"] == FS   # 1 / mean step, 4 digits
    err = rel_errors(original, got)
    assert set(err) == set(LOGGER_NAMES)
    assert max(err.values()) < 1e-6, err
    assert got.meta["start_time_s"] == pytest.approx(460.0)
    assert got.speed_source == "column"


def test_linear_cannot_reach_1e6(original, tmp_path):
    """Straight lines err at first order in the jitter (slope error O(h x'')): far above 1e-6."""
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    import_logger(raw, write_map(tmp_path / "map.toml", method="linear"), tmp_path / "lin")
    err = rel_errors(original, read_drive(tmp_path / "lin"))
    assert max(err.values()) > 1e-5


def test_jitter_against_exact_signal(tmp_path):
    """Not a round trip: an exact signal sampled at jittered times, resampled, against its exact
    values on the grid. Cubic: within 1e-5 for content up to 20 Hz at 200 Hz (estimate
    j (2 pi f/fs)^4 / 24 = 6.5e-6 at 20 Hz); linear: above 1e-4 (j (2 pi f/fs)^2 / 2 = 2e-4)."""
    n = int(6 * FS)
    t = np.arange(n) / FS
    tj = t + np.r_[0.0, np.random.default_rng(3).uniform(-JITTER, JITTER, n - 1) / FS]
    exact_on = {}
    for name, times in (("grid", t), ("jit", tj)):
        exact_on[name] = station_frame(times, seed=5, noise=0.0)
    ex = exact_on["jit"]
    df = pd.DataFrame({"Zeit_ms": tj * 1000.0})
    for c, name in LOGGER_NAMES.items():
        df[name] = {"susp": ex[c] * 1000.0, "axle": ex[c] / G, "body": ex[c] / G + 1.0,
                    "speed": ex[c] * 3.6}[c.split("_")[0]]
    raw = write_logger(df, tmp_path / "logger.csv")
    worst = {}
    for method in ("cubic", "linear"):
        import_logger(raw, write_map(tmp_path / f"{method}.toml", method=method),
                      tmp_path / method)
        got = read_drive(tmp_path / method).to_dataframe()
        ref = exact_on["grid"]
        worst[method] = max(float(np.max(np.abs(got[c] - ref[c])) / np.max(np.abs(ref[c])))
                            for c in LOGGER_NAMES)
    assert worst["cubic"] < 1e-5, worst
    assert worst["linear"] > 1e-4, worst


@pytest.mark.slow
def test_round_trip_on_virtual_drive(tmp_path):
    """The same target on a virtual drive of the truck (sensor noise, 24 channels): 1e-6."""
    from drives.synth import synth_command

    synth_command(scenario="luliang", seed=0, effects=[], vehicle=None, duration=5.0,
                  config=None, out=tmp_path / "lul", force=False, default_effects=True)
    d = read_drive(tmp_path / "lul")
    t = d.time
    e = np.random.default_rng(0).uniform(-JITTER, JITTER, t.size) * d.dt
    e[0] = 0.0
    df = pd.DataFrame({"t_ms": (t + e) * 1000.0})
    lines = ['[time]', 'column = "t_ms"', 'unit = "ms"', '[channels]']
    for c in d.channels.columns:
        y = CubicSpline(t, d.channels[c].to_numpy())(t + e)
        unit, k, grav = (("mm", 1000.0, "none") if c.startswith("susp") else
                         ("g", 1 / G, "g" if c.startswith("body") else "none"))
        df["L_" + c] = y * k + (1.0 if grav == "g" else 0.0)
        lines.append(f'{c} = {{ column = "L_{c}", unit = "{unit}", gravity = "{grav}" }}')
    df["kmh"] = CubicSpline(t, d.speed)(t + e) * 3.6
    lines += ['speed = { column = "kmh", unit = "km/h" }', '[dataset]',
              'vehicle = "dump_truck_8x4"']
    (tmp_path / "m.toml").write_text("\n".join(lines))
    import_logger(write_logger(df, tmp_path / "l.csv"), tmp_path / "m.toml", tmp_path / "imp")
    err = rel_errors(d, read_drive(tmp_path / "imp"))
    assert max(err.values()) < 1e-6, max(err.items(), key=lambda kv: kv[1])


# --------------------------------------------------------------------------- provenance

def test_import_table_records_every_conversion(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    import_logger(raw, mp, tmp_path / "imp")
    doc = tomllib.loads((tmp_path / "imp" / "meta.toml").read_text())
    imp = doc["import"]
    assert imp["source_sha256"] == hashlib.sha256(raw.read_bytes()).hexdigest()
    assert imp["map_sha256"] == hashlib.sha256(mp.read_bytes()).hexdigest()
    assert imp["delimiter"] == ";" and imp["time"] == {"column": "Zeit_ms", "unit": "ms",
                                                        "factor": 1e-3}
    cols = imp["columns"]
    assert cols["susp_disp_3L"]["factor"] == 1e-3 and cols["susp_disp_3L"]["column"] == "Weg_HA3_li"
    assert cols["axle_acc_3L"]["factor"] == G and cols["axle_acc_3L"]["gravity_removed_mps2"] == 0.0
    assert cols["body_acc_3R"]["gravity"] == "g" and cols["body_acc_3R"]["gravity_removed_mps2"] == G
    assert cols["speed"]["factor"] == pytest.approx(1 / 3.6)
    assert "cubic spline" in imp["resampling"]["rule"]
    assert imp["resampling"]["gaps"] == [] and imp["ignored_columns"] == ["Temperatur"]
    assert doc["dataset"]["name"] == "own-drive"


def test_gravity_mean_rule(original, tmp_path):
    """gravity = "mean" subtracts the record mean: the result has mean 0 exactly and differs
    from the original by the original's own mean only."""
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = tmp_path / "map.toml"
    mp.write_text(MAP.replace("{method}", "cubic").replace('gravity = "g"', 'gravity = "mean"'))
    import_logger(raw, mp, tmp_path / "imp")
    got = read_drive(tmp_path / "imp").channels["body_acc_3L"].to_numpy()
    ref = original.channels["body_acc_3L"].to_numpy()
    assert abs(np.mean(got)) < 1e-12
    assert np.max(np.abs(got - (ref - ref.mean()))) < 1e-6 * np.max(np.abs(ref))


# --------------------------------------------------------------------------- gaps

def _with_gap(original, start=500, n=20):
    return logger_frame(original).drop(index=range(start, start + n)).reset_index(drop=True)


def test_gap_refused_naming_row_and_time(original, tmp_path):
    raw = write_logger(_with_gap(original), tmp_path / "gappy.csv")
    out = tmp_path / "imp"
    with pytest.raises(EroadInputError) as ei:
        import_logger(raw, write_map(tmp_path / "map.toml"), out)
    msg = str(ei.value)
    # the sample after the gap is original index 520, file row 500 + 2 (header is row 1)
    assert f"{raw}, column 'Zeit_ms', row 502: gap in time" in msg
    assert re.search(r"from t = 462\.49\d* s to 462\.(59|60)\d* s is 21 median steps", msg), msg
    assert "on_gap = \"split\"" in msg and "\n" not in msg
    assert not out.exists()


def test_gap_split_into_parts(original, tmp_path):
    """on_gap = "split": one dataset per piece, on the file's one time grid, each passing the
    contract check, equal to the original within 1e-6 except the 3 samples at each side of
    the gap: there the piece's spline ends, its end slope differs from the whole record's by
    O(h^3 times the fourth derivative), the jitter multiplies that, and the difference decays
    by the spline's factor 2 - sqrt(3) = 0.27 per sample into the piece (measured over 10
    seeds: 3.0e-5, 1.2e-5, 3.1e-6, 6.8e-7 at 0, 1, 2, 3 samples from the cut; 1e-4
    allowed). The record's own first and last samples are within 1e-6."""
    raw = write_logger(_with_gap(original), tmp_path / "gappy.csv")
    out = tmp_path / "imp"
    s = import_logger(raw, write_map(tmp_path / "map.toml"), out, split_gaps=True)
    parts = sorted(p.name for p in out.iterdir())
    assert parts == ["part01", "part02"] and len(s["datasets"]) == 2
    full = original.to_dataframe()
    for p, (i0, n) in zip(parts, ((0, 500), (520, original.n_samples - 520))):
        assert check_drive(out / p) == []
        d = read_drive(out / p)
        assert d.n_samples == n and d.meta["start_time_s"] == pytest.approx(460.0 + i0 / FS)
        ref = full.iloc[i0:i0 + n].reset_index(drop=True)
        got = d.to_dataframe()
        cut = [n - 3, n - 2, n - 1] if p == "part01" else [0, 1, 2]
        inner = np.setdiff1d(np.arange(n), cut)
        for c in LOGGER_NAMES:
            err = np.abs(got[c] - ref[c]).to_numpy() / np.max(np.abs(ref[c]))
            assert err[inner].max() < 1e-6 and err[cut].max() < 1e-4, (p, c)
        imp = tomllib.loads((out / p / "meta.toml").read_text())["import"]
        assert imp["resampling"]["gaps"] == [{"row": 502, "from_s": pytest.approx(462.495),
                                              "to_s": pytest.approx(462.6)}]
        assert imp["piece"]["parts"] == 2


def test_split_leaves_out_short_pieces(original, tmp_path):
    df = logger_frame(original).drop(index=list(range(300, 310)) + list(range(400, 410)))
    raw = write_logger(df.reset_index(drop=True), tmp_path / "gappy.csv")
    s = import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp", split_gaps=True)
    assert len(s["datasets"]) == 2   # the 0.45 s piece between the gaps is below 1 s
    assert len(s["skipped_pieces"]) == 1 and s["skipped_pieces"][0]["samples"] == 90


def test_window(original, tmp_path):
    """The window keeps the grid points in [461, 463] s; the interpolation uses samples beyond
    its ends, so its edges match the original within 1e-6 like its middle; a gap outside the
    window does not matter."""
    raw = write_logger(_with_gap(original, start=1000), tmp_path / "logger.csv")
    import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp", window=(461.0, 463.0))
    d = read_drive(tmp_path / "imp")
    assert d.time[0] == 461.0 and d.time[-1] == pytest.approx(463.0) and d.n_samples == 401
    assert d.meta["start_time_s"] == 461.0
    err = rel_errors(original.window(461.0, 463.001), d)
    assert max(err.values()) < 1e-6, err
    with pytest.raises(EroadInputError, match="no continuous piece .* in the window \\[470, 480\\]"):
        import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp2",
                      window=(470.0, 480.0))
    with pytest.raises(EroadInputError, match="row 1002: gap in time"):
        import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp3",
                      window=(461.0, 466.0))


# --------------------------------------------------------------------------- refusals

@pytest.mark.parametrize("edit, expect", [
    (lambda p: p.write_text(""), "row 1: file is empty (0 bytes)"),
    (lambda p: p.write_text(p.read_text().splitlines()[0] + "\n"), "header but no data rows"),
    (lambda p: p.write_text(p.read_text().replace("Weg_HA3_re", "Weg3R", 1)),
     "column 'Weg_HA3_re', row 1: missing; the map map.toml maps it to susp_disp_3R"),
    (lambda p: p.write_text("\n".join(ln + ";0" if i == 6 else ln
                                      for i, ln in enumerate(p.read_text().splitlines()))),
     "row 7: 10 fields where the header has 9"),
])
def test_bad_files_refused_nothing_written(original, tmp_path, edit, expect):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    edit(raw)
    out = tmp_path / "imp"
    with pytest.raises(EroadInputError, match=None) as ei:
        import_logger(raw, write_map(tmp_path / "map.toml"), out)
    assert expect in str(ei.value) and str(raw) in str(ei.value)
    assert not out.exists()


def _set_cell(raw: Path, row: int, col: str, value: str, header_row: int = 1):
    lines = raw.read_text().splitlines()
    header = lines[header_row - 1].split(";")
    cells = lines[row - 1].split(";")
    cells[header.index(col)] = value
    lines[row - 1] = ";".join(cells)
    raw.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("value, expect", [
    ("abc", "not a number: 'abc'"), ("", "empty value"), ("nan", "NaN value ('nan')"),
    ("inf", "infinite value ('inf')"), ("0,25", "not a number: '0,25' (a decimal comma?"),
])
def test_bad_cell_named_by_file_column_row(original, tmp_path, value, expect):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    _set_cell(raw, 7, "aAchse_3_li", value)
    with pytest.raises(EroadInputError) as ei:
        import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp")
    assert str(ei.value).startswith(f"{raw}, column 'aAchse_3_li', row 7: {expect}")
    assert not (tmp_path / "imp").exists()


def test_bad_cell_in_unmapped_column_is_ignored(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    _set_cell(raw, 7, "Temperatur", "n/a")
    import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp")
    assert check_drive(tmp_path / "imp") == []


def test_time_not_increasing(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    _set_cell(raw, 9, "Zeit_ms", "460000")
    with pytest.raises(EroadInputError, match=r"column 'Zeit_ms', row 9: time not strictly "
                       r"increasing \(decreasing"):
        import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp")


@pytest.mark.parametrize("old, new, expect", [
    ('unit = "mm" }', 'unit = "furlong" }', "[channels] susp_disp_3L unit 'furlong' is unknown; "
     "for a length use one of m, cm, mm"),
    ('unit = "mm" }', 'unit = "km/h" }', "unit 'km/h' is a speed, but this column is a length"),
    ('unit = "ms"', 'unit = "mm"', "[time] unit 'mm' is a length, but this column is a time"),
    ("susp_disp_3L =", "susp_disp_3X =", "'susp_disp_3X' is not a contract channel name"),
    ('gravity = "g"', 'gravity = "yes"', 'must be "g" (subtract 9.80665 m/s^2), "mean"'),
    ('method = "cubic"', 'method = "sinc"', 'method = \'sinc\' must be "cubic" or "linear"'),
    ('vehicle = "dump_truck_8x4"', 'vehicle = "dump_truk"', "vehicle 'dump_truk': neither"),
])
def test_bad_map_refused(original, tmp_path, old, new, expect):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    mp.write_text(mp.read_text().replace(old, new, 1))
    with pytest.raises(EroadInputError) as ei:
        import_logger(raw, mp, tmp_path / "imp")
    assert expect in str(ei.value), str(ei.value)
    assert not (tmp_path / "imp").exists()


def test_gravity_forgotten_is_refused_with_the_fix(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    mp.write_text(mp.read_text().replace(', gravity = "g"', ""))
    with pytest.raises(EroadInputError, match=r"column 'aRahmen_3_li' \(body_acc_3L\): mean "
                       r"\+9\.\d+ m/s\^2 .*gravity left in; set gravity = \"g\""):
        import_logger(raw, mp, tmp_path / "imp")


def test_out_not_empty_is_refused_and_untouched(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    out = tmp_path / "imp"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    with pytest.raises(EroadInputError, match="exists and is not empty"):
        import_logger(raw, write_map(tmp_path / "map.toml"), out)
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_downsampling_refused(original, tmp_path):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    with pytest.raises(EroadInputError, match="alias"):
        import_logger(raw, write_map(tmp_path / "map.toml"), tmp_path / "imp", rate_hz=100.0)


# --------------------------------------------------------------------------- formats

@pytest.mark.parametrize("sep, decimal", [(",", "."), ("\t", "."), (";", ",")])
def test_delimiter_sniffed_and_decimal_comma(original, tmp_path, sep, decimal):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv", sep=sep, decimal=decimal)
    mp = write_map(tmp_path / "map.toml")
    text = mp.read_text().replace('delimiter = ";"', f'decimal = "{decimal}"')
    mp.write_text(text)
    s = import_logger(raw, mp, tmp_path / "imp")
    assert s["delimiter"] == sep
    assert max(rel_errors(original, read_drive(tmp_path / "imp")).values()) < 1e-6


def test_units_row_and_preamble(original, tmp_path):
    raw = tmp_path / "logger.csv"
    df = logger_frame(original)
    body = df.to_csv(sep=";", index=False).splitlines()
    units = ";".join(["ms"] + ["-"] * (df.shape[1] - 1))
    raw.write_text("\n".join(["Logger XY-200 export", "date;2026-01-01", body[0], units]
                             + body[1:]) + "\n")
    mp = write_map(tmp_path / "map.toml")
    mp.write_text(mp.read_text().replace('delimiter = ";"', 'delimiter = ";"\nheader_row = 3\n'
                                         'first_data_row = 5'))
    import_logger(raw, mp, tmp_path / "imp")
    assert max(rel_errors(original, read_drive(tmp_path / "imp")).values()) < 1e-6
    _set_cell(raw, 9, "aAchse_3_li", "x", header_row=3)
    with pytest.raises(EroadInputError, match="row 9: not a number"):
        import_logger(raw, mp, tmp_path / "imp2")


def test_constant_speed_and_vehicle_file(original, tmp_path):
    raw = write_logger(logger_frame(original).drop(columns="v_kmh"), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    mp.write_text(mp.read_text().replace('speed = { column = "v_kmh", unit = "km/h" }\n', ""))
    with pytest.raises(EroadInputError, match="no speed"):
        import_logger(raw, mp, tmp_path / "imp")
    from vehicles.params import PARAMS_DIR

    shutil.copy(PARAMS_DIR / "e_tractor.toml", tmp_path / "mine.toml")
    import_logger(raw, mp, tmp_path / "imp", speed_mps=9.5, vehicle=str(tmp_path / "mine.toml"))
    d = read_drive(tmp_path / "imp")
    assert d.speed_source == "meta" and d.meta["speed_mps"] == 9.5
    assert (tmp_path / "imp" / "vehicle.toml").read_bytes() == (tmp_path / "mine.toml").read_bytes()


def test_template_is_a_valid_map(tmp_path):
    (tmp_path / "t.toml").write_text(template_text())
    m = read_map(tmp_path / "t.toml")
    assert {c.name for c in m.channels} == {"susp_disp_3L", "axle_acc_3L", "body_acc_3L", "speed"}
    assert m.on_gap == "refuse" and m.method == "cubic" and m.max_step_factor == 1.5


# --------------------------------------------------------------------------- the command

def test_cli(original, tmp_path, capsys):
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    assert main(["data", "import", "--template"]) == 0
    assert "[channels]" in capsys.readouterr().out
    assert main(["data", "import", str(raw), "--map", str(mp), "--out", str(tmp_path / "a")]) == 0
    out = capsys.readouterr().out
    assert "wrote" in out and "susp_disp_3L" in out and "mm x 0.001" in out
    assert main(["data", "check", str(tmp_path / "a")]) == 0
    capsys.readouterr()
    # bad input: one line on stderr, exit 2
    assert main(["data", "import", str(raw), "--map", str(mp), "--out", str(tmp_path / "a")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "exists and is not empty" in err
    assert main(["data", "import", str(raw), "--out", str(tmp_path / "b")]) == 2
    assert "needs --map" in capsys.readouterr().err
    gappy = write_logger(_with_gap(original), tmp_path / "gappy.csv")
    assert main(["data", "import", str(gappy), "--map", str(mp), "--out", str(tmp_path / "c")]) == 2
    assert "gap in time" in capsys.readouterr().err and not (tmp_path / "c").exists()
    assert main(["data", "import", str(gappy), "--map", str(mp), "--out", str(tmp_path / "c"),
                 "--split-gaps", "--json"]) == 0
    assert '"datasets"' in capsys.readouterr().out


def test_wrong_unit_in_map_refused_by_the_contract_naming_the_map(original, tmp_path):
    """A map that says m where the logger wrote mm: the contract's range check refuses it,
    and the message names the map entry to fix."""
    raw = write_logger(logger_frame(original), tmp_path / "logger.csv")
    mp = write_map(tmp_path / "map.toml")
    mp.write_text(mp.read_text().replace('"Weg_HA3_li", unit = "mm"', '"Weg_HA3_li", unit = "m"'))
    with pytest.raises(EroadInputError) as ei:
        import_logger(raw, mp, tmp_path / "imp")
    msg = str(ei.value)
    assert msg.startswith("not written:") and "looks like millimetres" in msg
    assert "in the map map.toml: susp_disp_3L = column 'Weg_HA3_li' in 'm'" in msg
    assert not (tmp_path / "imp").exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
