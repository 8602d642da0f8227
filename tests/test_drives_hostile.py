"""Hostile inputs to the dataset reader: each refused with its own one-line message
naming file, column and row, a non-zero exit, no traceback, and nothing written.

The list of cases and their messages is restated in docs/measurement.md.
"""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drives import format as fmt
from drives.format import check_drive, read_drive
from eroad.cli import main
from eroad.errors import EroadInputError

N = 40
FS = 200.0


def _csv_lines(n=N):
    t = np.arange(n) / FS
    lines = ["time,susp_disp_3L,axle_acc_3L,body_acc_3L,speed"]
    for k, tk in enumerate(t):
        lines.append(f"{float(tk)!r},{0.01 * np.sin(k / 3):.6f},{2 * np.cos(k / 5):.5f},"
                     f"{0.5 * np.sin(k / 7):.5f},{9.5 + 0.01 * k:.4f}")
    return lines


META = '[dataset]\nname = "h"\nsample_rate_hz = 200.0\nvehicle = "dump_truck_8x4"\n'


def make(tmp_path: Path, lines=None, meta=META, name="ds") -> Path:
    """A valid dataset (optionally with replaced channels.csv lines or meta.toml)."""
    d = tmp_path / name
    d.mkdir()
    if lines is not None:
        (d / "channels.csv").write_text("\n".join(lines) + ("\n" if lines else ""))
    if meta is not None:
        (d / "meta.toml").write_text(meta)
    return d


def snapshot(folder: Path):
    return sorted((str(p.relative_to(folder.parent)), p.stat().st_size, p.stat().st_mtime_ns)
                  for p in folder.parent.rglob("*"))


def edit(lines, row, col, value):
    """Replace field ``col`` (0-based) of file row ``row`` (1-based, header = 1)."""
    out = list(lines)
    f = out[row - 1].split(",")
    f[col] = value
    out[row - 1] = ",".join(f)
    return out


def _row(lines, row, text):
    out = list(lines)
    out[row - 1] = text
    return out


L = _csv_lines()

# (id, lines, meta, expected fragments of the single problem line)
CASES = [
    ("nan", edit(L, 7, 1, "nan"), META,
     ["channels.csv, column 'susp_disp_3L', row 7", "NaN value"]),
    ("nan_float_column", edit(L, 9, 2, "NaN"), META,
     ["column 'axle_acc_3L', row 9", "NaN value"]),
    ("inf", edit(L, 12, 3, "inf"), META,
     ["column 'body_acc_3L', row 12", "infinite value"]),
    ("empty_value", edit(L, 5, 1, ""), META,
     ["column 'susp_disp_3L', row 5", "empty value"]),
    ("not_a_number", edit(L, 6, 2, "abc"), META,
     ["column 'axle_acc_3L', row 6", "not a number: 'abc'"]),
    ("missing_time", _row(L, 1, "t,susp_disp_3L,axle_acc_3L,body_acc_3L,speed"), META,
     ["column 'time', row 1", "missing; the first column must be 'time'"]),
    ("time_not_first", _row(L, 1, "susp_disp_3L,time,axle_acc_3L,body_acc_3L,speed"), META,
     ["column 'time', row 1", "'time' is column 2"]),
    ("duplicated_time", edit(L, 11, 0, repr(8 / FS)), META,
     ["column 'time', row 11", "duplicated value"]),
    ("decreasing_time", edit(L, 11, 0, repr(3 / FS)), META,
     ["column 'time', row 11", "decreasing value"]),
    ("non_uniform", edit(L, 11, 0, repr(9 / FS + 1e-6)), META,
     ["column 'time', row 11", "non-uniform sampling"]),
    ("rate_mismatch", L, META.replace("200.0", "100.0"),
     ["meta.toml: [dataset] sample_rate_hz = 100 disagrees with the time column"]),
    ("time_in_ms", ["time" + ln[ln.index(","):] if i == 0 else
                    f"{(i - 1) * 5.0!r}" + ln[ln.index(","):] for i, ln in enumerate(L)], META,
     ["disagrees with the time column", "time looks like milliseconds"]),
    ("empty_file", [], META, ["channels.csv, row 1: file is empty (0 bytes)"]),
    ("header_only", L[:1], META, ["channels.csv, row 2: header but no data rows"]),
    ("one_row", L[:2], META, ["column 'time', row 2", "only 1 data row"]),
    ("semicolon", [ln.replace(",", ";") for ln in L], META,
     ["row 1: semicolon-delimited, expected comma"]),
    ("tab", [ln.replace(",", "\t") for ln in L], META, ["row 1: tab-delimited, expected comma"]),
    ("bad_channel_name", _row(L, 1, "time,susp_disp_3X,axle_acc_3L,body_acc_3L,speed"), META,
     ["column 'susp_disp_3X', row 1", "channel name does not parse (column 2)"]),
    ("unit_in_header", _row(L, 1, "time,susp_disp_3L [mm],axle_acc_3L,body_acc_3L,speed"), META,
     ["column 'susp_disp_3L [mm]', row 1", "the header holds names only"]),
    ("duplicated_column", _row(L, 1, "time,susp_disp_3L,susp_disp_3L,body_acc_3L,speed"), META,
     ["column 'susp_disp_3L', row 1", "duplicated column name (column 3)"]),
    ("millimetres_disp", edit(L, 20, 1, "12.5"), META,
     ["column 'susp_disp_3L', row 20", "implausible in m", "looks like millimetres"]),
    ("millimetres_acc", edit(L, 21, 2, "2500.0"), META,
     ["column 'axle_acc_3L', row 21", "implausible in m/s^2", "looks like millimetres"]),
    ("speed_kmh", edit(L, 22, 4, "80.0"), META,
     ["column 'speed', row 22", "looks like km/h"]),
    ("speed_negative", edit(L, 23, 4, "-0.5"), META,
     ["column 'speed', row 23", "negative speed -0.5 m/s"]),
    ("ragged_row", _row(L, 15, L[14] + ",1.0"), META,
     ["channels.csv, row 15: 6 fields where the header has 5"]),
    ("blank_row", _row(L, 15, ""), META, ["channels.csv, row 15: blank row"]),
    ("missing_vehicle_file", L, META.replace('"dump_truck_8x4"', '"truck.toml"'),
     ["truck.toml: missing: meta.toml [dataset] vehicle = 'truck.toml' names this file"]),
    ("unknown_vehicle_id", L, META.replace('"dump_truck_8x4"', '"dump_truk"'),
     ["meta.toml: [dataset] vehicle = 'dump_truk' is neither a file in the dataset nor a "
      "built-in vehicle id"]),
    ("no_vehicle", L, META.replace('vehicle = "dump_truck_8x4"\n', ""),
     ["meta.toml: [dataset] vehicle is missing and there is no vehicle.toml"]),
    ("missing_meta", L, None, ["meta.toml: missing"]),
    ("missing_channels", None, META, ["channels.csv: missing"]),
    ("bad_toml", L, META + "x = = 1\n", ["meta.toml: not valid TOML", "row 5, column 5"]),
    ("no_dataset_table", L, 'name = "x"\n', ["meta.toml: no [dataset] table"]),
    ("no_rate", L, META.replace("sample_rate_hz = 200.0\n", ""),
     ["meta.toml: [dataset] sample_rate_hz is missing"]),
    ("rate_not_number", L, META.replace("200.0", '"fast"'),
     ["meta.toml: [dataset] sample_rate_hz = 'fast' is not a finite number"]),
    ("unknown_unit", L, META + '[units]\nsusp_disp_3L = "furlong"\n',
     ["meta.toml: [units] susp_disp_3L = 'furlong': unknown unit, expected 'm'"]),
    ("non_si_unit", L, META + '[units]\naxle_acc_3L = "g"\n',
     ["meta.toml: [units] axle_acc_3L = 'g': values must be SI; convert to m/s^2"]),
    ("units_unknown_column", L, META + '[units]\nbody_acc_1R = "m/s^2"\n',
     ["meta.toml: [units] names column 'body_acc_1R', which channels.csv does not have"]),
    ("speed_mps_negative", [ln.rsplit(",", 1)[0] for ln in L], META + "speed_mps = -3.0\n",
     ["meta.toml: [dataset] speed_mps = -3.0 must be >= 0"]),
    ("speed_mps_missing", [ln.rsplit(",", 1)[0] for ln in L], META,
     ["meta.toml: [dataset] speed_mps is missing (channels.csv has no speed column"]),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_hostile_case_refused_with_its_message(tmp_path, case):
    """Each case gives exactly one problem line containing its own fragments, read_drive
    raises that line, `eroad data check` exits 2, and no file is written or touched."""
    _, lines, meta, fragments = case
    d = make(tmp_path, lines, meta)
    before = snapshot(d)
    problems = check_drive(d)
    assert len(problems) == 1, problems
    for frag in fragments:
        assert frag in problems[0], (frag, problems[0])
    assert "\n" not in problems[0]
    with pytest.raises(EroadInputError) as exc:
        read_drive(d)
    assert str(exc.value) == problems[0]
    assert main(["data", "check", str(d)]) == 2
    assert snapshot(d) == before


def test_hostile_messages_are_distinct(tmp_path):
    """'Each its own message': no two cases give the same text (after the folder prefix)."""
    msgs = []
    for i, (_, lines, meta, _) in enumerate(CASES):
        d = make(tmp_path, lines, meta, name=f"d{i}")
        msgs.append(check_drive(d)[0].replace(str(d), ""))
    assert len(set(msgs)) == len(msgs)


def test_valid_fixture_passes_and_trailing_blank_line_is_fine(tmp_path):
    d = make(tmp_path, L + [""])
    assert check_drive(d) == []
    drive = read_drive(d)
    assert drive.n_samples == N
    assert drive.channel_names == ["susp_disp_3L", "axle_acc_3L", "body_acc_3L"]


def test_all_problems_listed_and_cli_prints_each_line_without_traceback(tmp_path):
    lines = edit(edit(L, 7, 1, "nan"), 9, 2, "9999")
    d = make(tmp_path, lines, META.replace('"dump_truck_8x4"', '"truck.toml"'))
    problems = check_drive(d)
    assert len(problems) == 3
    proc = subprocess.run([sys.executable, "-m", "eroad.cli", "data", "check", str(d)],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    for p in problems:
        assert f"eroad: error: {p}" in proc.stderr.splitlines()


def test_very_large_file_refused_before_reading(tmp_path):
    """A sparse channels.csv just above MAX_CSV_BYTES (2 GiB) is refused from its size,
    without reading it (the test takes milliseconds and no disk)."""
    d = make(tmp_path, L)
    with open(d / "channels.csv", "r+b") as fh:
        fh.truncate(fmt.MAX_CSV_BYTES + 1)
    problems = check_drive(d)
    assert len(problems) == 1
    assert "above the limit of 2 GiB" in problems[0]


def test_streamed_reading_in_chunks_is_exact_and_counts_rows(tmp_path, monkeypatch):
    """Reading in 7-row chunks gives the same arrays as one chunk, and a bad value in a
    later chunk is reported at its file row."""
    d = make(tmp_path, L)
    whole = read_drive(d)
    monkeypatch.setattr(fmt, "CHUNK_ROWS", 7)
    chunked = read_drive(d)
    np.testing.assert_array_equal(whole.time, chunked.time)
    pd.testing.assert_frame_equal(whole.channels, chunked.channels)
    np.testing.assert_array_equal(whole.speed, chunked.speed)
    d2 = make(tmp_path, edit(L, 33, 3, "inf"), name="d2")
    (p,) = check_drive(d2)
    assert "column 'body_acc_3L', row 33: infinite value" in p
    d3 = make(tmp_path, edit(L, 30, 0, repr(27 / FS)), name="d3")
    (p,) = check_drive(d3)
    assert "column 'time', row 30" in p and "duplicated" in p


def test_vehicle_file_in_dataset_resolves(tmp_path):
    d = make(tmp_path, L, META.replace('"dump_truck_8x4"', '"vehicle.toml"'))
    (d / "vehicle.toml").write_text("# nominal vehicle\n")
    drive = read_drive(d)
    assert isinstance(drive.vehicle, Path) and drive.vehicle.name == "vehicle.toml"


def test_builtin_ids_known():
    ids = fmt.builtin_vehicles()
    assert "dump_truck_8x4" in ids and "e_tractor" in ids


def test_missing_folder_and_file_instead_of_folder(tmp_path):
    assert "no such dataset folder" in check_drive(tmp_path / "nope")[0]
    f = tmp_path / "f.csv"
    f.write_text("time\n")
    assert "not a folder" in check_drive(f)[0]
    assert not os.path.exists(tmp_path / "nope")


def test_crlf_bom_and_spaces_are_accepted(tmp_path):
    """Files from Windows tools (BOM, CRLF) and 'time, susp_disp_3L' spacing read the same."""
    ref = read_drive(make(tmp_path, L, name="ref"))
    d = tmp_path / "win"
    d.mkdir()
    text = "\r\n".join(ln.replace(",", ", ") for ln in L) + "\r\n"
    (d / "channels.csv").write_bytes(b"\xef\xbb\xbf" + text.encode())
    (d / "meta.toml").write_text(META)
    win = read_drive(d)
    np.testing.assert_array_equal(win.time, ref.time)
    pd.testing.assert_frame_equal(win.channels, ref.channels)
