"""Import a data-logger CSV into a measurement dataset (``eroad data import``).

What it is for: a real drive comes off a logger with the logger's own column names,
units (g, mm, ms, km/h), delimiter, a time column that is not exactly uniform, maybe
gaps, and accelerations with gravity in them. A column map (TOML, template:
``drives/import_template.toml``, printed by ``eroad data import --template``) says
which logger column is which contract channel and in which unit; this module converts,
resamples and writes the dataset with :func:`drives.format.write_drive`, so the result
passes ``eroad data check``. Every conversion is recorded in the output meta.toml's
``[import]`` table (source file and its sha256, map and its sha256, per column: logger
name, unit, factor, sign, gravity removed; the resampling rule and the time-step
statistics).

What it is not: a filter or a calibration tool. It applies exact unit factors, a sign
and gravity removal, nothing else; a record that then fails the contract's
plausibility checks (``drives.plausibility``) is refused like any other dataset.

The rules (also in ``docs/import.md``)
--------------------------------------
* **Units.** Exact factors: ``ms`` 1e-3, ``us`` 1e-6, ``min`` 60 (time); ``mm`` 1e-3,
  ``cm`` 1e-2, ``um`` 1e-6 (displacement); ``g`` 9.80665 (standard gravity, exact by
  definition), ``mm/s^2`` 1e-3 (acceleration); ``km/h`` 1/3.6, ``mph`` 0.44704 (speed);
  SI units as they are. Any other unit, or a unit of the wrong kind, is refused.
* **Order per column.** value x factor x sign, then gravity removal.
* **Gravity.** An accelerometer at rest with its axis up reads +1 g (it measures specific
  force). ``gravity = "g"`` subtracts 9.80665 m/s^2 (after unit and sign), right for a
  calibrated sensor on a vertical axis; ``gravity = "mean"`` subtracts the column's mean
  over the imported record (each output dataset its own), which also removes a sensor
  offset or the cos(tilt) part of gravity, but also the record's true mean (zero on a
  level road within the noise). Accelerations without a gravity entry are taken as
  gravity-free; any acceleration whose mean is still above g/2 after conversion is
  refused with the column named.
* **Gaps.** With the median time step h_med of the record (after the window), a step
  above ``max_step_factor`` x h_med (default 1.5: one dropped sample is a gap) is a gap.
  ``on_gap = "refuse"`` (default) refuses the file naming the row and time after the gap;
  ``on_gap = "split"`` (or ``--split-gaps``) writes one dataset per continuous piece,
  ``OUT/part01``, ``OUT/part02``, ..., each with its ``start_time_s``; pieces shorter
  than ``min_part_s`` (default 1 s) are left out and listed in every part's ``[import]``.
* **Resampling.** One uniform time grid for the whole file, t_k = t_0 + k / rate_hz with
  t_0 the file's first sample (so a window or a piece after a gap stays on the logger's
  time base); each continuous piece gets the grid points between its first and last
  sample, widened by 1 % of a step at both ends (a first or last sample that is slightly
  off its nominal time does not cost a grid point; those points are extrapolated by the
  end cubic, over at most 1 % of a step). ``rate_hz`` defaults to 1 / (mean time step of the
  continuous steps), rounded to 4 significant digits. ``method = "cubic"`` (default):
  a not-a-knot cubic spline (:class:`scipy.interpolate.CubicSpline`) through the logger
  samples at their recorded times; ``"linear"``: straight lines. A ``rate_hz`` below
  0.99 x the logger's rate is refused: there is no anti-alias filter here, so picking
  fewer points would fold the content above the new Nyquist frequency into the record.
* **Why cubic.** With jitter e_j (time offsets of the samples from the grid), the
  resampled value differs from the true signal at the grid point by about
  e_j (s'(t_j) - x'(t_j)), s being the interpolant: the interpolant's slope error,
  O(h^3 x'''') for a cubic spline, O(h x'') for straight lines. A sine of frequency f
  sampled at rate fs with jitter e = j / fs then carries a relative error of about
  j (2 pi f / fs)^4 / 24 (cubic) and j (2 pi f / fs)^2 / 2 (linear): for j = 1e-3 and
  f / fs = 0.05 (10 Hz at 200 Hz), 4e-7 and 5e-5. Linear interpolation cannot meet a
  1e-6 target on signals with content at a tenth of the sample rate; cubic can.
  (Measured in ``tests/test_data_import.py``: ``test_jitter_against_exact_signal``.)
* **Window.** ``[window] start_s / end_s`` (or ``--window``) keeps the grid points with
  start_s <= t <= end_s (the logger's time in seconds); the interpolation still uses up to
  20 samples beyond each end (``MARGIN_SAMPLES``), so the window's edges are as accurate
  as its middle. Only gaps that overlap the window count.
* **Refused, nothing written** (one line: file, column, row): an empty file, a header
  without rows, a mapped column missing from the header, a cell that is not a number
  (empty, text, NaN, infinite), a ragged row, a blank row inside the data, time not
  strictly increasing, an unknown unit, a map that is not valid, an output folder that
  exists and is not empty.
"""
from __future__ import annotations

import csv
import re
import math
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd

from eroad.archive import file_sha256
from drives.format import (MAX_CSV_BYTES, META_FILE, builtin_vehicles, parse_channel,
                           swap_into_place, temp_folder_beside, write_drive)
from eroad.errors import EroadInputError

#: standard gravity [m/s^2] (exact, CGPM 1901)
G = 9.80665
#: unit -> (kind, factor to SI); kinds: time, length, acceleration, speed
UNITS: dict[str, tuple[str, float]] = {
    "s": ("time", 1.0), "ms": ("time", 1e-3), "us": ("time", 1e-6), "µs": ("time", 1e-6),
    "min": ("time", 60.0),
    "m": ("length", 1.0), "cm": ("length", 1e-2), "mm": ("length", 1e-3),
    "um": ("length", 1e-6), "µm": ("length", 1e-6),
    "m/s^2": ("acceleration", 1.0), "m/s2": ("acceleration", 1.0), "m/s**2": ("acceleration", 1.0),
    "m s^-2": ("acceleration", 1.0), "g": ("acceleration", G),
    "mm/s^2": ("acceleration", 1e-3), "mm/s2": ("acceleration", 1e-3),
    "m/s": ("speed", 1.0), "km/h": ("speed", 1.0 / 3.6), "kmh": ("speed", 1.0 / 3.6),
    "kph": ("speed", 1.0 / 3.6), "mph": ("speed", 0.44704),
}
#: what each contract quantity is measured in
KIND_OF = {"susp_disp": "length", "axle_acc": "acceleration", "body_acc": "acceleration",
           "dcdc_y": "length", "dcdc_z": "length", "speed": "speed", "time": "time"}
#: delimiters tried when the map does not give one
SNIFF_DELIMITERS = (";", ",", "\t", "|")
#: default gap limit: a step above this multiple of the median step is a gap [-]
MAX_STEP_FACTOR = 1.5
#: default shortest piece kept when splitting at gaps [s]
MIN_PART_S = 1.0
#: grid points up to this fraction of a step past the last sample are kept [-]
END_SLACK_STEPS = 0.01
#: samples beyond a window's ends that the interpolation still uses (a cubic spline's
#: dependence on a sample decays by 2 - sqrt(3) = 0.27 per sample: 0.27^20 = 4e-12)
MARGIN_SAMPLES = 20
#: fewest samples of a piece (a not-a-knot cubic needs 4)
MIN_SAMPLES = 4
#: rows converted per chunk (bounds the memory of the text cells)
CHUNK_ROWS = 100_000

_MAP_TABLES = {"source", "time", "channels", "resample", "window", "dataset"}
_SOURCE_KEYS = {"delimiter", "decimal", "header_row", "first_data_row", "encoding"}
_CHANNEL_KEYS = {"column", "unit", "sign", "gravity"}
_RESAMPLE_KEYS = {"rate_hz", "method", "max_step_factor", "on_gap", "min_part_s"}
_WINDOW_KEYS = {"start_s", "end_s"}
_DATASET_KEYS = {"name", "vehicle", "speed_mps", "description"}


def template_text() -> str:
    """The commented template column map (``drives/import_template.toml``)."""
    return resources.files("drives").joinpath("import_template.toml").read_text(encoding="utf-8")


# --------------------------------------------------------------------------- the map

@dataclass
class ChannelMap:
    """One mapped column: contract name, logger column, unit factor, sign, gravity rule."""

    name: str
    column: str
    unit: str
    factor: float
    sign: float = 1.0
    gravity: str = "none"


@dataclass
class ImportMap:
    """A parsed column map (see the template for every key)."""

    path: Path
    time: ChannelMap
    channels: list[ChannelMap]
    delimiter: str | None = None
    decimal: str = "."
    header_row: int = 1
    first_data_row: int | None = None
    encoding: str = "utf-8-sig"
    rate_hz: float | None = None
    method: str = "cubic"
    max_step_factor: float = MAX_STEP_FACTOR
    on_gap: str = "refuse"
    min_part_s: float = MIN_PART_S
    window: tuple[float | None, float | None] = (None, None)
    dataset: dict = field(default_factory=dict)


def _number(v, where: str, mapf: Path, *, positive=False, integer=False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise EroadInputError(f"{mapf}: {where} = {v!r} is not a finite number")
    if integer and not float(v).is_integer():
        raise EroadInputError(f"{mapf}: {where} = {v!r} must be a whole number")
    if positive and not v > 0:
        raise EroadInputError(f"{mapf}: {where} = {v!r} must be > 0")
    return float(v)


def _table(doc: dict, key: str, allowed: set, mapf: Path) -> dict:
    t = doc.get(key, {})
    if not isinstance(t, dict):
        raise EroadInputError(f"{mapf}: [{key}] must be a table")
    for k in t:
        if k not in allowed:
            raise EroadInputError(f"{mapf}: [{key}] unknown key '{k}' (known: "
                                  f"{', '.join(sorted(allowed))})")
    return t


def _unit(unit, kind: str, where: str, mapf: Path) -> float:
    if not isinstance(unit, str):
        raise EroadInputError(f"{mapf}: {where} unit = {unit!r} must be a string such as 'mm'")
    u = unit.strip()
    known = UNITS.get(u) or UNITS.get(u.lower())
    choices = ", ".join(k for k, (kd, _) in UNITS.items() if kd == kind)
    if known is None:
        raise EroadInputError(f"{mapf}: {where} unit '{u}' is unknown; for a {kind} use one "
                              f"of {choices}")
    if known[0] != kind:
        raise EroadInputError(f"{mapf}: {where} unit '{u}' is a {known[0]}, but this column "
                              f"is a {kind}; use one of {choices}")
    return known[1]


def _channel_entry(name: str, entry, mapf: Path, where: str) -> ChannelMap:
    if isinstance(entry, str):
        raise EroadInputError(f"{mapf}: {where} must be a table such as "
                              f"{{ column = \"{entry}\", unit = \"...\" }} (the unit is required)")
    if not isinstance(entry, dict):
        raise EroadInputError(f"{mapf}: {where} must be a table {{ column = ..., unit = ... }}")
    for k in entry:
        if k not in _CHANNEL_KEYS:
            raise EroadInputError(f"{mapf}: {where} unknown key '{k}' (known: "
                                  f"{', '.join(sorted(_CHANNEL_KEYS))})")
    for k in ("column", "unit"):
        if k not in entry:
            raise EroadInputError(f"{mapf}: {where} needs '{k}'")
    col = entry["column"]
    if not isinstance(col, str) or not col.strip():
        raise EroadInputError(f"{mapf}: {where} column = {col!r} must be the logger's column name")
    kind = KIND_OF[name] if name in KIND_OF else KIND_OF[parse_channel(name)[0]]
    factor = _unit(entry["unit"], kind, where, mapf)
    sign = entry.get("sign", 1)
    if isinstance(sign, bool) or sign not in (1, -1):
        raise EroadInputError(f"{mapf}: {where} sign = {sign!r} must be 1 or -1")
    grav = entry.get("gravity", "none")
    if grav not in ("none", "g", "mean"):
        raise EroadInputError(f"{mapf}: {where} gravity = {grav!r} must be \"g\" (subtract "
                              "9.80665 m/s^2), \"mean\" (subtract the record mean) or \"none\"")
    if grav != "none" and kind != "acceleration":
        raise EroadInputError(f"{mapf}: {where} gravity applies to accelerations only")
    return ChannelMap(name=name, column=col.strip(), unit=str(entry["unit"]).strip(),
                      factor=factor, sign=float(sign), gravity=grav)


def read_map(path) -> ImportMap:
    """Read and validate a column map.

    Parameters
    ----------
    path : str or Path
        The TOML map (template: :func:`template_text`).

    Returns
    -------
    ImportMap

    Raises
    ------
    EroadInputError
        One line naming the map, the table and the key.
    """
    mapf = Path(path)
    if not mapf.is_file():
        raise EroadInputError(f"{mapf}: no such map file (make one with "
                              "'eroad data import --template > map.toml')")
    try:
        doc = tomllib.loads(mapf.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise EroadInputError(f"{mapf}: not UTF-8 text") from None
    except tomllib.TOMLDecodeError as exc:
        raise EroadInputError(f"{mapf}: not valid TOML: {exc}") from None
    for k in doc:
        if k not in _MAP_TABLES:
            raise EroadInputError(f"{mapf}: unknown table [{k}] (known: "
                                  f"{', '.join(sorted(_MAP_TABLES))})")
    src = _table(doc, "source", _SOURCE_KEYS, mapf)
    res = _table(doc, "resample", _RESAMPLE_KEYS, mapf)
    win = _table(doc, "window", _WINDOW_KEYS, mapf)
    ds = _table(doc, "dataset", _DATASET_KEYS, mapf)
    if "time" not in doc:
        raise EroadInputError(f"{mapf}: no [time] table; it names the logger's time column "
                              "and its unit, e.g. [time] column = \"t\", unit = \"ms\"")
    time = _channel_entry("time", doc["time"], mapf, "[time]")
    chans = doc.get("channels")
    if not isinstance(chans, dict) or not chans:
        raise EroadInputError(f"{mapf}: no [channels] table; it maps contract names to logger "
                              "columns, e.g. susp_disp_3L = { column = \"W3L\", unit = \"mm\" }")
    channels = []
    seen_cols: dict[str, str] = {time.column: "time"}
    for name, entry in chans.items():
        if parse_channel(name) is None:
            raise EroadInputError(
                f"{mapf}: [channels] '{name}' is not a contract channel name; expected "
                "susp_disp_<axle><L|R>, axle_acc_<axle><L|R>, body_acc_<axle><L|R>, speed, "
                "dcdc_y_P<1-4> or dcdc_z_P<1-4>, e.g. susp_disp_3L (docs/measurement.md)")
        cm = _channel_entry(name, entry, mapf, f"[channels] {name}")
        if cm.column in seen_cols:
            raise EroadInputError(f"{mapf}: [channels] {name}: logger column '{cm.column}' is "
                                  f"already mapped to {seen_cols[cm.column]}")
        seen_cols[cm.column] = name
        channels.append(cm)
    m = ImportMap(path=mapf, time=time, channels=channels)
    if "delimiter" in src:
        d = src["delimiter"]
        d = "\t" if d in ("tab", "\\t") else d
        if not isinstance(d, str) or len(d) != 1 or d in "\r\n\"":
            raise EroadInputError(f"{mapf}: [source] delimiter = {src['delimiter']!r} must be "
                                  "one character (or \"tab\")")
        m.delimiter = d
    if "decimal" in src:
        if src["decimal"] not in (".", ","):
            raise EroadInputError(f"{mapf}: [source] decimal = {src['decimal']!r} must be "
                                  "\".\" or \",\"")
        m.decimal = src["decimal"]
    if m.decimal == "," and m.delimiter == ",":
        raise EroadInputError(f"{mapf}: [source] decimal and delimiter are both ','")
    if "header_row" in src:
        m.header_row = int(_number(src["header_row"], "[source] header_row", mapf,
                                   positive=True, integer=True))
    if "first_data_row" in src:
        m.first_data_row = int(_number(src["first_data_row"], "[source] first_data_row", mapf,
                                       positive=True, integer=True))
        if m.first_data_row <= m.header_row:
            raise EroadInputError(f"{mapf}: [source] first_data_row = {m.first_data_row} must "
                                  f"be after header_row = {m.header_row}")
    if "encoding" in src:
        enc = src["encoding"]
        try:
            "".encode(enc)
        except (LookupError, TypeError):
            raise EroadInputError(f"{mapf}: [source] encoding = {enc!r} is not a known "
                                  "text encoding (e.g. \"utf-8\", \"latin-1\")") from None
        m.encoding = enc
    if "rate_hz" in res:
        m.rate_hz = _number(res["rate_hz"], "[resample] rate_hz", mapf, positive=True)
    if "method" in res:
        if res["method"] not in ("cubic", "linear"):
            raise EroadInputError(f"{mapf}: [resample] method = {res['method']!r} must be "
                                  "\"cubic\" or \"linear\"")
        m.method = res["method"]
    if "max_step_factor" in res:
        m.max_step_factor = _number(res["max_step_factor"], "[resample] max_step_factor", mapf)
        if not m.max_step_factor > 1.0:
            raise EroadInputError(f"{mapf}: [resample] max_step_factor = {m.max_step_factor:g} "
                                  "must be > 1 (a multiple of the median time step)")
    if "on_gap" in res:
        if res["on_gap"] not in ("refuse", "split"):
            raise EroadInputError(f"{mapf}: [resample] on_gap = {res['on_gap']!r} must be "
                                  "\"refuse\" or \"split\"")
        m.on_gap = res["on_gap"]
    if "min_part_s" in res:
        m.min_part_s = _number(res["min_part_s"], "[resample] min_part_s", mapf)
    m.window = tuple(_number(win[k], f"[window] {k}", mapf) if k in win else None
                     for k in ("start_s", "end_s"))
    for k in ("name", "vehicle", "description"):
        if k in ds and not isinstance(ds[k], str):
            raise EroadInputError(f"{mapf}: [dataset] {k} = {ds[k]!r} must be a string")
    if "speed_mps" in ds:
        _number(ds["speed_mps"], "[dataset] speed_mps", mapf)
    m.dataset = dict(ds)
    return m


# --------------------------------------------------------------------------- the logger file

def _sniff(lines: list[str], raw: Path, header_row: int) -> str:
    """The delimiter that splits the header and the next lines into one equal count >= 2."""
    best = None
    for d in SNIFF_DELIMITERS:
        counts = {len(next(csv.reader([ln], delimiter=d))) for ln in lines if ln.strip()}
        if len(counts) == 1 and (n := counts.pop()) >= 2 and (best is None or n > best[1]):
            best = (d, n)
    if best is None:
        raise EroadInputError(
            f"{raw}, row {header_row}: cannot tell the delimiter (tried ; , tab |: none splits "
            "the header and the first rows into the same number of fields); set [source] "
            "delimiter in the map")
    return best[0]


def _to_float(cells: list[str], decimal: str) -> np.ndarray | int:
    """Float array of text cells, or the index of the first cell that is not a finite number."""
    if decimal == ",":
        cells = [c.replace(",", ".") for c in cells]
    try:
        a = np.asarray(cells, dtype=float)
    except ValueError:
        a = None
    if a is not None:
        bad = np.flatnonzero(~np.isfinite(a))
        return a if bad.size == 0 else int(bad[0])
    for i, c in enumerate(cells):
        try:
            if not math.isfinite(float(c)):
                return i
        except ValueError:
            return i
    return 0  # pragma: no cover - np.asarray failed, so one cell does


def _cell_problem(text: str, decimal: str) -> str:
    s = text.strip()
    if s == "":
        return "empty value"
    low = s.lower()
    if low.lstrip("+-") in ("nan", "na", "n/a", "null", "none"):
        return f"NaN value ('{s}')"
    if low.lstrip("+-") in ("inf", "infinity"):
        return f"infinite value ('{s}')"
    hint = ""
    if decimal == "." and "," in s and s.replace(",", ".", 1).replace(".", "", 1).lstrip("+-").isdigit():
        hint = " (a decimal comma? set [source] decimal = \",\" in the map)"
    return f"not a number: '{s[:30]}'{hint}"


@dataclass
class RawTable:
    """The mapped columns of a logger file, in SI units, one float array each."""

    time: np.ndarray
    rows: np.ndarray          # the file's line number of each sample
    values: dict              # contract name -> array (SI, sign applied, gravity not yet removed)
    delimiter: str
    sniffed: bool
    header: list[str]


def read_raw(raw, m: ImportMap) -> RawTable:
    """Read the mapped columns of a logger CSV and convert them to SI units.

    Parameters
    ----------
    raw : str or Path
        The logger file.
    m : ImportMap

    Returns
    -------
    RawTable

    Raises
    ------
    EroadInputError
        One line naming the file, the column and the row.
    """
    raw = Path(raw)
    if not raw.is_file():
        raise EroadInputError(f"{raw}: no such file")
    size = raw.stat().st_size
    if size == 0:
        raise EroadInputError(f"{raw}, row 1: file is empty (0 bytes)")
    if size > MAX_CSV_BYTES:
        raise EroadInputError(f"{raw}: file is {size / 1024**3:.2f} GiB, above the limit of "
                              f"{MAX_CSV_BYTES / 1024**3:.0f} GiB; cut it into parts")
    try:
        fh = open(raw, encoding=m.encoding, newline="")
        fh.read(1 << 16)
        fh.seek(0)
    except UnicodeDecodeError:
        raise EroadInputError(f"{raw}: not {m.encoding} text; set [source] encoding in the map "
                              "(e.g. \"latin-1\")") from None
    with fh:
        try:
            return _read_open(raw, fh, m)
        except UnicodeDecodeError:
            raise EroadInputError(f"{raw}: not {m.encoding} text further down the file; set "
                                  "[source] encoding in the map (e.g. \"latin-1\")") from None


def _read_open(raw: Path, fh, m: ImportMap) -> RawTable:
    hdr_row = m.header_row
    first = m.first_data_row or hdr_row + 1
    lines = []
    for _ in range(hdr_row - 1):
        if not fh.readline():
            raise EroadInputError(f"{raw}, row {hdr_row}: the file ends before the header row "
                                  f"([source] header_row = {hdr_row})")
    header_line = fh.readline()
    if not header_line.strip():
        raise EroadInputError(f"{raw}, row {hdr_row}: header row is blank" +
                              (" (the file holds no text)" if not header_line else ""))
    lines.append(header_line.rstrip("\r\n"))
    skipped = [fh.readline() for _ in range(first - hdr_row - 1)]
    body_start = fh.tell()
    for _ in range(20):
        ln = fh.readline()
        if not ln:
            break
        lines.append(ln.rstrip("\r\n"))
    sniffed = m.delimiter is None
    delim = _sniff(lines, raw, hdr_row) if sniffed else m.delimiter
    header = [c.strip().strip('"').strip() for c in next(csv.reader([lines[0]], delimiter=delim))]
    idx = {}
    for cm in [m.time] + m.channels:
        if cm.column not in header:
            raise EroadInputError(
                f"{raw}, column '{cm.column}', row {hdr_row}: missing; the map {m.path.name} maps "
                f"it to {cm.name} (header has: {', '.join(header)[:200]})")
        if header.count(cm.column) > 1:
            raise EroadInputError(f"{raw}, column '{cm.column}', row {hdr_row}: appears "
                                  f"{header.count(cm.column)} times in the header")
        idx[cm.name] = header.index(cm.column)
    del skipped
    fh.seek(body_start)
    reader = csv.reader(fh, delimiter=delim)
    names = list(idx)
    cols = [idx[n] for n in names]
    chunks = {n: [] for n in names}
    rows_all: list[np.ndarray] = []
    buf = [[] for _ in names]
    rows: list[int] = []
    blank_at = None
    nfields = len(header)

    def flush():
        r = np.asarray(rows, dtype=np.int64)
        for j, n in enumerate(names):
            got = _to_float(buf[j], m.decimal)
            if isinstance(got, int):
                cm = m.time if n == "time" else next(c for c in m.channels if c.name == n)
                raise EroadInputError(f"{raw}, column '{cm.column}', row {int(r[got])}: "
                                      f"{_cell_problem(buf[j][got], m.decimal)}")
            chunks[n].append(got)
            buf[j].clear()
        rows_all.append(r)
        rows.clear()

    line_no = first - 1
    for rec in reader:
        line_no = first - 1 + reader.line_num
        if not rec or all(not c.strip() for c in rec):
            if blank_at is None:
                blank_at = line_no
            continue
        if blank_at is not None:
            raise EroadInputError(f"{raw}, row {blank_at}: blank row inside the data")
        if len(rec) != nfields:
            raise EroadInputError(f"{raw}, row {line_no}: {len(rec)} fields where the header "
                                  f"has {nfields} (delimiter {delim!r}; a delimiter inside a "
                                  "value, or a misaligned row?)")
        for j, c in enumerate(cols):
            buf[j].append(rec[c])
        rows.append(line_no)
        if len(rows) >= CHUNK_ROWS:
            flush()
    if rows:
        flush()
    if not rows_all:
        raise EroadInputError(f"{raw}, row {first}: header but no data rows")
    values = {n: np.concatenate(chunks[n]) for n in names}
    row_nums = np.concatenate(rows_all)
    t = values.pop("time") * m.time.factor
    d = np.diff(t)
    nonpos = np.flatnonzero(d <= 0)
    if nonpos.size:
        i = int(nonpos[0])
        raise EroadInputError(
            f"{raw}, column '{m.time.column}', row {int(row_nums[i + 1])}: time not strictly "
            f"increasing ({'repeated' if d[i] == 0 else 'decreasing'} value at "
            f"t = {t[i + 1]:.9g} s after {t[i]:.9g} s; {nonpos.size} such step(s))")
    out = {}
    for cm in m.channels:
        out[cm.name] = values[cm.name] * (cm.factor * cm.sign)
    return RawTable(time=t, rows=row_nums, values=out, delimiter=delim, sniffed=sniffed,
                    header=header)


# --------------------------------------------------------------------------- resampling

def find_gaps(t: np.ndarray, max_step_factor: float) -> tuple[np.ndarray, float]:
    """Indices i where the step t[i+1] - t[i] is a gap, and the median step.

    A gap is a step above ``max_step_factor`` times the median step.
    """
    d = np.diff(t)
    med = float(np.median(d))
    return np.flatnonzero(d > max_step_factor * med), med


def default_rate(t: np.ndarray, gaps: np.ndarray) -> float:
    """1 / mean step over the continuous steps, rounded to 4 significant digits [Hz]."""
    d = np.diff(t)
    keep = np.ones(d.size, bool)
    keep[gaps] = False
    r = 1.0 / float(np.mean(d[keep]))
    return float(f"{r:.4g}")


def resample(t: np.ndarray, x: np.ndarray, grid: np.ndarray, method: str) -> np.ndarray:
    """Values of the samples (t, x) on ``grid`` by a not-a-knot cubic spline or linearly."""
    if method == "linear":
        return np.interp(grid, t, x)
    from scipy.interpolate import CubicSpline

    return CubicSpline(t, x, bc_type="not-a-knot", extrapolate=True)(grid)


def uniform_grid(t_ref: float, t0: float, t1: float, rate: float) -> np.ndarray:
    """The points t_ref + k / rate within [t0, t1], widened by ``END_SLACK_STEPS`` steps."""
    k0 = int(math.ceil((t0 - t_ref) * rate - END_SLACK_STEPS))
    k1 = int(math.floor((t1 - t_ref) * rate + END_SLACK_STEPS))
    return t_ref + np.arange(k0, k1 + 1) / rate


# --------------------------------------------------------------------------- the command

def _resolve_vehicle(vehicle: str, base: Path) -> tuple[str, Path | None]:
    """(meta value, file to copy or None) for a built-in id or a vehicle .toml file."""
    if vehicle in builtin_vehicles():
        return vehicle, None
    p = Path(vehicle)
    if not p.is_absolute() and not p.is_file():
        p = base / p
    if p.is_file():
        return "vehicle.toml", p
    raise EroadInputError(f"vehicle '{vehicle}': neither a built-in id "
                          f"({', '.join(builtin_vehicles())}) nor a vehicle .toml file")


def import_logger(raw, map_path, out, *, window=None, vehicle=None, speed_mps=None,
                  rate_hz=None, split_gaps=False, name=None) -> dict:
    """Convert a logger CSV with a column map into a dataset folder (or one per piece).

    Parameters
    ----------
    raw : str or Path
        Logger CSV.
    map_path : str or Path
        Column map (TOML).
    out : str or Path
        Dataset folder to create (must not exist or be empty). With gaps split, the
        folder holding ``part01``, ``part02``, ...
    window : (float, float), optional
        [start_s, end_s] in the logger's time [s]; overrides the map's [window].
    vehicle : str, optional
        Built-in id or vehicle .toml (relative to the working directory); overrides
        the map's [dataset] vehicle (there relative to the map's folder).
    speed_mps : float, optional
        Constant speed [m/s] when no speed column is mapped; overrides the map.
    rate_hz : float, optional
        Output sample rate [Hz]; overrides the map.
    split_gaps : bool
        Split at gaps instead of refusing (overrides the map's on_gap).
    name : str, optional
        Dataset name; overrides the map.

    Returns
    -------
    dict
        JSON-serialisable summary: out, datasets (path, samples, rate, span, channels),
        source, sha256, gaps, skipped pieces.

    Raises
    ------
    EroadInputError
        One line (file, column, row); nothing is written.
    """
    raw, out = Path(raw), Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        raise EroadInputError(f"{out}: exists and is not empty; choose a new folder "
                              "(nothing was written)")
    m = read_map(map_path)
    if rate_hz is not None:
        if not (math.isfinite(rate_hz) and rate_hz > 0):
            raise EroadInputError(f"--rate must be a positive number of Hz, got {rate_hz:g}")
        m.rate_hz = float(rate_hz)
    if split_gaps:
        m.on_gap = "split"
    if window is not None:
        m.window = (float(window[0]), float(window[1]))
    if m.window[0] is not None and m.window[1] is not None and not m.window[1] > m.window[0]:
        raise EroadInputError(f"window [{m.window[0]:g}, {m.window[1]:g}] s: the end must be "
                              "after the start")
    ds = dict(m.dataset)
    if name is not None:
        ds["name"] = name
    if speed_mps is not None:
        ds["speed_mps"] = float(speed_mps)
    has_speed = any(c.name == "speed" for c in m.channels)
    if not has_speed and "speed_mps" not in ds:
        raise EroadInputError(f"{m.path}: no speed: map a 'speed' column in [channels] or give "
                              "a constant [dataset] speed_mps (or --speed)")
    if "speed_mps" in ds and not ds["speed_mps"] >= 0:
        raise EroadInputError(f"speed_mps = {ds['speed_mps']:g} must be >= 0 (the vehicle drives "
                              "forward)")
    if vehicle is not None:
        veh_meta, veh_file = _resolve_vehicle(vehicle, Path.cwd())
    elif "vehicle" in ds:
        veh_meta, veh_file = _resolve_vehicle(ds["vehicle"], m.path.parent)
    else:
        raise EroadInputError(f"{m.path}: [dataset] vehicle is missing; name a built-in vehicle "
                              f"({', '.join(builtin_vehicles())}) or a vehicle .toml file, in "
                              "the map or with --vehicle")
    ds["vehicle"] = veh_meta

    tab = read_raw(raw, m)
    t, rows, vals = tab.time, tab.rows, tab.values
    t_ref = float(t[0])   # one time grid for the whole file: windows and pieces stay on it
    ws = -math.inf if m.window[0] is None else m.window[0]
    we = math.inf if m.window[1] is None else m.window[1]
    gaps, med = find_gaps(t, m.max_step_factor)
    data_rate = default_rate(t, gaps)
    rate = m.rate_hz or data_rate
    if rate < 0.99 * data_rate:
        raise EroadInputError(
            f"{raw}, column '{m.time.column}': rate_hz = {rate:g} is below the logger's rate "
            f"({data_rate:g} Hz); resampling down without a low-pass filter would alias the "
            f"content between {rate / 2:g} and {data_rate / 2:g} Hz into the record; import at the "
            "logger's rate (leave rate_hz out)")
    # gaps that matter: those overlapping the window
    gaps_in = np.array([i for i in gaps if t[i + 1] > ws and t[i] < we], dtype=int)
    if gaps_in.size and m.on_gap == "refuse":
        i = int(gaps_in[0])
        step = t[i + 1] - t[i]
        raise EroadInputError(
            f"{raw}, column '{m.time.column}', row {int(rows[i + 1])}: gap in time: step "
            f"{step:.6g} s from t = {t[i]:.9g} s to {t[i + 1]:.9g} s is {step / med:.3g} median "
            f"steps ({med:.6g} s), above the limit of {m.max_step_factor:g} ({gaps_in.size} "
            "gap(s)); set [resample] on_gap = \"split\" in the map (or --split-gaps) to write "
            "one dataset per continuous piece, or leave it out with --window")
    bounds = np.concatenate([[0], gaps + 1, [t.size]])
    tol = 1e-9 / rate
    pieces, skipped = [], []
    for a, b in zip(bounds[:-1], bounds[1:]):
        grid = uniform_grid(t_ref, float(t[a]), float(t[b - 1]), rate)
        grid = grid[(grid >= ws - tol) & (grid <= we + tol)]
        if grid.size == 0:
            continue                      # the piece lies outside the window
        span = grid[-1] - grid[0]
        if min(b - a, grid.size) < MIN_SAMPLES or (m.on_gap == "split" and span < m.min_part_s):
            skipped.append({"rows": [int(rows[a]), int(rows[b - 1])],
                            "t_s": [float(grid[0]), float(grid[-1])], "samples": int(grid.size)})
            continue
        # the samples the interpolation uses: the piece within the window +- MARGIN samples
        lo = max(a, int(np.searchsorted(t, grid[0], "left")) - MARGIN_SAMPLES)
        hi = min(b, int(np.searchsorted(t, grid[-1], "right")) + MARGIN_SAMPLES)
        pieces.append((lo, hi, grid))
    if not pieces:
        w = [("start" if v is None else f"{v:g}") for v in m.window]
        raise EroadInputError(
            f"{raw}, column '{m.time.column}': no continuous piece of at least "
            f"{MIN_SAMPLES} samples{f' and {m.min_part_s:g} s' if m.on_gap == 'split' else ''} "
            f"in the window [{w[0]}, {w[1]}] s (the file spans {t[0]:.9g} to {t[-1]:.9g} s, "
            f"{gaps.size} gap(s))")

    d = np.diff(t)
    cont = np.delete(d, gaps)
    stats = {"median_step_s": med, "mean_step_s": float(np.mean(cont)),
             "min_step_s": float(d.min()), "max_step_s": float(d.max()),
             "max_rel_jitter": float(np.max(np.abs(cont - med)) / med) if cont.size else 0.0}
    record = {
        "tool": "eroad data import",
        "source": str(raw), "source_sha256": file_sha256(raw),
        "map": str(m.path), "map_sha256": file_sha256(m.path),
        "delimiter": tab.delimiter, "delimiter_sniffed": tab.sniffed, "decimal": m.decimal,
        "rows_read": int(tab.time.size),
        "ignored_columns": [c for c in tab.header
                            if c not in {m.time.column, *(cm.column for cm in m.channels)}],
        "time": {"column": m.time.column, "unit": m.time.unit, "factor": m.time.factor},
        **({"window_s": {k: v for k, v in zip(("start", "end"), m.window) if v is not None}}
           if any(v is not None for v in m.window) else {}),
        "resampling": {
            "method": m.method,
            "rule": ("not-a-knot cubic spline through the logger samples at their recorded times"
                     if m.method == "cubic" else "linear interpolation between the logger samples")
                    + ", evaluated on t_0 + k / rate_hz (t_0 the file's first sample) between "
                    f"each continuous piece's first and last sample +- {END_SLACK_STEPS:g} step, "
                    f"within the window; the samples used reach {MARGIN_SAMPLES} beyond the "
                    "window where the piece has them",
            "t0_s": t_ref,
            "rate_hz": rate, "rate_from": "map or command line" if m.rate_hz else
            "1 / mean continuous step, 4 significant digits",
            "gap_rule": f"a step above {m.max_step_factor:g} x the median step is a gap",
            "max_step_factor": m.max_step_factor, "on_gap": m.on_gap,
            "gaps": [{"row": int(rows[i + 1]), "from_s": float(t[i]), "to_s": float(t[i + 1])}
                     for i in gaps_in],
            "gaps_outside_window": int(gaps.size - gaps_in.size),
            "skipped_pieces": skipped, **stats,
        },
    }
    outputs = []
    for k, (a, b, grid) in enumerate(pieces):
        tp = t[a:b]
        frame = {"time": grid}
        conv = {}
        for cm in m.channels:
            x = vals[cm.name][a:b]
            y = resample(tp, x, grid, m.method)
            removed = 0.0
            if cm.gravity == "g":
                removed = G
            elif cm.gravity == "mean":
                removed = float(np.mean(y))
            y = y - removed
            q = parse_channel(cm.name)[0]
            if q in ("axle_acc", "body_acc") and abs(float(np.mean(y))) > 0.5 * G:
                mean = float(np.mean(y))
                hint = ("set gravity = \"g\" (subtract 9.80665 m/s^2) or \"mean\" for this column "
                        "in the map" if cm.gravity == "none" else
                        "the sensor reads -1 g at rest: mounted upside down? set sign = -1"
                        if cm.gravity == "g" and mean < 0 else "is the unit right?")
                raise EroadInputError(
                    f"{raw}, column '{cm.column}' ({cm.name}): mean {mean:+.4g} m/s^2 over the "
                    f"record after conversion: gravity left in; {hint}")
            frame[cm.name] = y
            conv[cm.name] = {"column": cm.column, "unit": cm.unit, "factor": cm.factor,
                             "sign": int(cm.sign), "gravity": cm.gravity,
                             "gravity_removed_mps2": removed}
        order = ["time"] + [c for c in frame if c not in ("time", "speed")] + (
            ["speed"] if "speed" in frame else [])
        df = pd.DataFrame({c: frame[c] for c in order})
        meta = {k2: v for k2, v in ds.items() if not (k2 == "speed_mps" and has_speed)}
        meta["sample_rate_hz"] = rate
        meta["start_time_s"] = float(grid[0])
        base_name = ds.get("name", out.name)
        meta["name"] = base_name if len(pieces) == 1 and m.on_gap != "split" else \
            f"{base_name}-part{k + 1:02d}"
        meta.setdefault("description", f"imported from {raw.name} by eroad data import")
        rec = dict(record, columns=conv,
                   piece={"part": k + 1, "parts": len(pieces),
                          "source_rows_used": [int(rows[a]), int(rows[b - 1])],
                          "source_t_s_used": [float(tp[0]), float(tp[-1])],
                          "samples_in": int(b - a),
                          "samples_out": int(grid.size)})
        outputs.append((df, meta, rec))

    def write(folder: Path, df, meta, rec):
        def add(tmp: Path) -> None:
            import tomli_w

            doc = tomllib.loads((tmp / META_FILE).read_text(encoding="utf-8"))
            doc["import"] = rec
            (tmp / META_FILE).write_text(tomli_w.dumps(doc), encoding="utf-8")

        try:
            write_drive(folder, df, meta, vehicle_file=veh_file, add_files=add)
        except EroadInputError as exc:
            # the contract check speaks of the dataset's columns; name the map's entries too
            msg = str(exc)
            st = re.search(r"at station (\d+)", msg)
            if st:   # the kinematic unit check: every channel of that axle is concerned
                named = [cm for cm in m.channels if cm.name != "speed"
                         and str(parse_channel(cm.name)[1]) == st.group(1)]
            else:
                col = re.search(r"column '([^']+)'", msg)
                named = [cm for cm in m.channels if col and cm.name == col.group(1)]
            if named:
                msg += "; in the map " + m.path.name + ": " + ", ".join(
                    f"{cm.name} = column '{cm.column}' in '{cm.unit}'" for cm in named) + \
                    " (the values are written as unit x factor; is the unit right?)"
            raise EroadInputError(msg) from None

    written = []
    if m.on_gap == "split":
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = temp_folder_beside(out)
        try:
            for k, (df, meta, rec) in enumerate(outputs):
                try:
                    write(tmp / f"part{k + 1:02d}", df, meta, rec)
                except EroadInputError as exc:
                    raise EroadInputError(str(exc).replace(str(tmp), str(out))) from None
                written.append(out / f"part{k + 1:02d}")
            swap_into_place(tmp, out)
        finally:
            if tmp.exists():
                import shutil

                shutil.rmtree(tmp, ignore_errors=True)
    else:
        df, meta, rec = outputs[0]
        write(out, df, meta, rec)
        written.append(out)
    return {
        "out": str(out), "source": str(raw), "source_sha256": record["source_sha256"],
        "map": str(m.path), "delimiter": tab.delimiter, "rows_read": record["rows_read"],
        "rate_hz": rate, "method": m.method, "on_gap": m.on_gap,
        "gaps": record["resampling"]["gaps"], "skipped_pieces": skipped,
        "datasets": [{"path": str(p), "samples": int(df.shape[0]),
                      "t_start_s": float(df["time"].iloc[0]), "t_end_s": float(df["time"].iloc[-1]),
                      "channels": [c for c in df.columns if c != "time"],
                      "conversions": {c: f"{v['unit']} x {v['factor']:.10g}"
                                      + (" x -1" if v["sign"] < 0 else "")
                                      + (f" - {v['gravity_removed_mps2']:.6g} m/s^2 (gravity, "
                                         f"{v['gravity']})" if v["gravity"] != "none" else "")
                                      for c, v in rec["columns"].items()}}
                     for p, (df, meta, rec) in zip(written, outputs)],
    }
