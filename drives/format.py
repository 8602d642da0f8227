"""The measurement-dataset contract: reader, validator and writer.

What it is for: every command that reads measured data (field data or a virtual
test drive) goes through :func:`read_drive`; every command that makes data
writes it with :func:`write_drive`; :func:`check_drive` lists every way a
folder breaks the contract (``../shared/docs/measurement-format.md``, restated
with this project's optional extensions in ``docs/measurement.md``).

What it is not: it never reads ``truth/`` (see :mod:`drives.synth` for that),
and it depends on nothing of this project but :mod:`eroad.errors`, so that
``vehicles`` may use it to write datasets.

A dataset folder::

    my-drive/
      channels.csv   comma-separated, header row, first column ``time`` [s]
      meta.toml      [dataset] table: name, sample_rate_hz, vehicle, speed_mps, ...
      vehicle.toml   optional: the nominal vehicle
      truth/         optional, synthetic data only; never read here

Rows in messages are counted as lines of the file, the header being row 1, so
that the number is the one an editor or a spreadsheet shows.
"""
from __future__ import annotations

import dataclasses
import importlib.util
import math
import os
import re
import shutil
import tempfile
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterable

import numpy as np
import pandas as pd

from eroad.errors import EroadInputError

#: file names of the contract
CHANNELS_FILE = "channels.csv"
META_FILE = "meta.toml"
VEHICLE_FILE = "vehicle.toml"
TRUTH_DIR = "truth"

#: channels.csv larger than this is refused before reading [bytes] (2 GiB)
MAX_CSV_BYTES = 2 * 1024**3
#: rows per chunk when streaming channels.csv (peak memory ~ result + one chunk)
CHUNK_ROWS = 200_000
#: allowed relative deviation of each time step from the mean step [-]
TIME_JITTER_REL = 1e-6
#: allowed relative disagreement of meta sample_rate_hz with the time column [-]
RATE_REL_TOL = 1e-6
#: optional ``[dataset] susp_disp_zero``: where the suspension displacements read 0.
#: ``"nominal_static"``: the NOMINAL vehicle (the vehicle file's parameters, its rated
#: payload) at rest on level ground, so the mean displacement carries a static load difference
#: (``eroad synth`` writes it for both truth families; ``eroad diagnose`` then uses the mean as
#: evidence, docs/diagnosis.md "The static offset").  ``"unknown"`` (the default): sensors
#: zeroed on the vehicle as driven, or nobody knows; the mean is not used.
SUSP_DISP_ZERO = ("nominal_static", "unknown")
ZERO_NOMINAL_STATIC, ZERO_UNKNOWN = SUSP_DISP_ZERO

#: built-in vehicle ids, used when the ``vehicles`` package ships no parameter files
BUILTIN_VEHICLES_FALLBACK = ("dump_truck_8x4", "e_tractor")


@dataclass(frozen=True)
class Quantity:
    """What a channel prefix measures.

    Parameters
    ----------
    unit : str
        SI unit the contract requires.
    limit : float
        Largest plausible magnitude in ``unit``; above it the values are refused
        as being in the wrong unit.
    wrong_unit_hint : str
        What a value above ``limit`` most likely is.
    doc : str
        One-line meaning.
    """

    unit: str
    limit: float
    wrong_unit_hint: str
    doc: str


#: channel quantities: prefix -> Quantity (``speed`` is the optional speed column)
QUANTITIES: dict[str, Quantity] = {
    "susp_disp": Quantity("m", 0.5, "looks like millimetres; convert to metres",
                          "suspension displacement, axle relative to body, + compression"),
    "axle_acc": Quantity("m/s^2", 1000.0, "looks like millimetres (mm/s^2); convert to m/s^2",
                         "vertical acceleration at the axle end, + up, gravity removed"),
    "body_acc": Quantity("m/s^2", 200.0, "looks like millimetres (mm/s^2); convert to m/s^2",
                         "vertical body acceleration above the axle end, + up, gravity removed"),
    "dcdc_y": Quantity("m", 1.0, "looks like millimetres; convert to metres",
                       "lateral displacement of DCDC top point k from static (extension)"),
    "dcdc_z": Quantity("m", 1.0, "looks like millimetres; convert to metres",
                       "vertical displacement of DCDC top point k from static (extension)"),
    "speed": Quantity("m/s", 60.0, "looks like km/h; convert to m/s",
                      "vehicle speed"),
}

#: displacements [m] above their limit but below these are not millimetres (a record in
#: millimetres peaks at several units) but a physically impossible travel: a diverged
#: simulation or a faulty sensor
NOT_A_UNIT_BELOW = {"susp_disp": 2.0, "dcdc_y": 3.0, "dcdc_z": 3.0}


def implausible_hint(quantity: str, peak: float) -> str:
    """What a value ``peak`` above its quantity's limit most likely means."""
    q = QUANTITIES[quantity]
    if peak < NOT_A_UNIT_BELOW.get(quantity, 0.0):
        return (f"physically impossible for a truck ({q.doc}): a diverged simulation or a "
                "faulty sensor, not a unit")
    return q.wrong_unit_hint

_WHEEL_RE = re.compile(r"^(susp_disp|axle_acc|body_acc)_([1-9][0-9]*)([LR])$")
_DCDC_RE = re.compile(r"^(dcdc_[yz])_P([1-4])$")

#: accepted spellings of each SI unit in meta.toml [units]
_SI_SPELLINGS = {
    "s": {"s"},
    "m": {"m"},
    "m/s": {"m/s", "m s^-1", "m s-1", "m*s^-1"},
    "m/s^2": {"m/s^2", "m/s2", "m/s**2", "m s^-2", "m s-2", "m*s^-2"},
}
#: units that are understood but not SI: unit -> SI unit it should be converted to
_NON_SI = {"mm": "m", "cm": "m", "um": "m", "km": "m", "ms": "s", "min": "s", "h": "s",
           "mm/s^2": "m/s^2", "mm/s2": "m/s^2", "g": "m/s^2", "km/h": "m/s", "kmh": "m/s",
           "mph": "m/s", "mm/s": "m/s"}


def parse_channel(name: str) -> tuple[str, int | None, str | None] | None:
    """Parse a channel name.

    Parameters
    ----------
    name : str
        Column name, e.g. ``"susp_disp_3L"``, ``"dcdc_z_P2"`` or ``"speed"``.

    Returns
    -------
    tuple or None
        ``(quantity, axle_or_point, side)``: ``("susp_disp", 3, "L")``,
        ``("dcdc_z", 2, None)``, ``("speed", None, None)``; None if the name
        does not parse.
    """
    if name == "speed":
        return ("speed", None, None)
    m = _WHEEL_RE.match(name)
    if m:
        return (m.group(1), int(m.group(2)), m.group(3))
    m = _DCDC_RE.match(name)
    if m:
        return (m.group(1), int(m.group(2)), None)
    return None


def builtin_vehicles() -> tuple[str, ...]:
    """Built-in vehicle ids: the stems of ``vehicles/params/*.toml``.

    Found without importing :mod:`vehicles` (this module depends on nothing of
    the project but :mod:`eroad.errors`).  Falls back to
    :data:`BUILTIN_VEHICLES_FALLBACK` when that folder holds no files.

    Returns
    -------
    tuple of str
    """
    stems = [p.stem for d in _builtin_params_dirs() for p in d.glob("*.toml")]
    return tuple(sorted(set(stems))) or BUILTIN_VEHICLES_FALLBACK


def _builtin_params_dirs() -> list[Path]:
    """The folders of the built-in vehicle files (``vehicles/params``), found without
    importing :mod:`vehicles`."""
    try:
        spec = importlib.util.find_spec("vehicles")
    except (ImportError, ValueError):
        spec = None
    locs = (spec.submodule_search_locations or []) if spec is not None else []
    return [Path(loc, "params") for loc in locs]


@dataclass(frozen=True)
class Drive:
    """A measured drive read from a dataset folder.

    Parameters
    ----------
    path : Path
        The dataset folder.
    time : (N,) ndarray
        Time [s], strictly increasing, uniform.
    channels : DataFrame
        The measured channels (SI units), columns = channel names, default
        RangeIndex; neither ``time`` nor ``speed`` is among them.
    speed : (N,) ndarray
        Vehicle speed [m/s]: the ``speed`` column, else ``meta['speed_mps']``
        repeated.
    meta : dict
        The ``[dataset]`` table of meta.toml.
    vehicle : str or Path
        Built-in vehicle id (str) or the path of the vehicle file (Path).
    units : dict
        Channel name -> unit (always SI: ``m``, ``m/s^2``, ``m/s``).
    speed_source : str
        ``"column"`` or ``"meta"``.
    warnings : tuple of str
        Plausibility findings that do not refuse the data (``drives.plausibility``):
        one line each, naming the file and column.
    speed_check : dict or None
        The speed's distance scale measured by the axle-to-axle delay
        (``drives.plausibility.speed_delay_scale``: ``scale``, ``pairs``, ``agree``,
        ``signal``); None where it could not be measured.
    """

    path: Path
    time: np.ndarray
    channels: pd.DataFrame
    speed: np.ndarray
    meta: dict
    vehicle: str | Path
    units: dict = field(default_factory=dict)
    speed_source: str = "column"
    warnings: tuple = ()
    speed_check: dict | None = None

    @property
    def name(self) -> str:
        """Dataset name (meta ``name``, else the folder name)."""
        return str(self.meta.get("name", self.path.name))

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.time.size)

    @property
    def dt(self) -> float:
        """Sample step [s] (mean over the record)."""
        return float((self.time[-1] - self.time[0]) / (self.time.size - 1))

    @property
    def sample_rate_hz(self) -> float:
        """Sample rate [Hz] from meta.toml (agrees with the time column)."""
        return float(self.meta["sample_rate_hz"])

    @property
    def duration_s(self) -> float:
        """Record length N / sample_rate_hz [s] (one step more than last minus first time)."""
        return float(self.n_samples / self.sample_rate_hz)

    @property
    def susp_disp_zero(self) -> str:
        """Where the suspension displacements read 0 (``[dataset] susp_disp_zero``,
        :data:`SUSP_DISP_ZERO`; ``"unknown"`` where not declared)."""
        return str(self.meta.get("susp_disp_zero", ZERO_UNKNOWN))

    @property
    def channel_names(self) -> list[str]:
        """Names of the measured channels (without time and speed)."""
        return list(self.channels.columns)

    def has(self, *names: str) -> bool:
        """True if every named channel is present."""
        return all(n in self.channels.columns for n in names)

    def require(self, names: Iterable[str], purpose: str = "this command") -> None:
        """Refuse, with one line, a drive that lacks channels.

        Parameters
        ----------
        names : iterable of str
            Channels needed.
        purpose : str
            Who needs them, for the message.

        Raises
        ------
        EroadInputError
            Naming the missing channels and the file.
        """
        missing = [n for n in names if n not in self.channels.columns]
        if missing:
            raise EroadInputError(
                f"{self.path / CHANNELS_FILE}: {purpose} needs column(s) {', '.join(missing)}, "
                f"which are missing (present: {', '.join(self.channel_names) or 'none'})")

    def window(self, t0: float, t1: float) -> "Drive":
        """The part of the drive with ``t0 <= time < t1`` [s].

        Raises
        ------
        EroadInputError
            If the window holds fewer than 2 samples.
        """
        sel = (self.time >= t0) & (self.time < t1)
        if np.count_nonzero(sel) < 2:
            raise EroadInputError(
                f"{self.path / CHANNELS_FILE}: window [{t0}, {t1}) s holds fewer than 2 samples "
                f"(record spans {self.time[0]:g} to {self.time[-1]:g} s)")
        return dataclasses.replace(
            self, time=self.time[sel], speed=self.speed[sel],
            channels=self.channels.loc[sel].reset_index(drop=True))

    def to_dataframe(self) -> pd.DataFrame:
        """``time``, the channels and ``speed`` in one frame (the write_drive layout)."""
        df = pd.DataFrame({"time": self.time})
        df = pd.concat([df, self.channels], axis=1)
        if self.speed_source == "column":
            df["speed"] = self.speed
        return df

    def summary(self) -> dict:
        """A JSON-serialisable summary (independent of where the folder lies).

        Returns
        -------
        dict
            name, n_samples, duration_s, sample_rate_hz, t_start_s, t_end_s,
            channels, speed_min_mps, speed_max_mps, speed_source, vehicle, vehicle_is_file,
            warnings, speed_check, susp_disp_zero.
        """
        veh = self.vehicle.name if isinstance(self.vehicle, Path) else self.vehicle
        return {
            "name": self.name,
            "n_samples": self.n_samples,
            "duration_s": self.duration_s,
            "sample_rate_hz": self.sample_rate_hz,
            "t_start_s": float(self.time[0]),
            "t_end_s": float(self.time[-1]),
            "channels": self.channel_names,
            "speed_min_mps": float(np.min(self.speed)),
            "speed_max_mps": float(np.max(self.speed)),
            "speed_source": self.speed_source,
            "vehicle": veh,
            "vehicle_is_file": isinstance(self.vehicle, Path),
            "warnings": list(self.warnings),
            "speed_check": self.speed_check,
            "susp_disp_zero": self.susp_disp_zero,
        }


# --------------------------------------------------------------------------- reading

class _Problems:
    """Collects one-line problems, each prefixed with the file (and column, row)."""

    def __init__(self):
        self.items: list[str] = []

    def add(self, file: Path, msg: str, column: str | None = None, row: int | None = None):
        where = [str(file)]
        if column is not None:
            where.append(f"column '{column}'")
        if row is not None:
            where.append(f"row {row}")
        self.items.append(f"{', '.join(where)}: {msg}")


def _sniff_header(csv: Path, probs: _Problems) -> list[str] | None:
    """Read and judge the header line; None if reading values makes no sense."""
    size = csv.stat().st_size
    if size == 0:
        probs.add(csv, "file is empty (0 bytes); expected a header row 'time,<channels>' "
                  "and data rows", row=1)
        return None
    if size > MAX_CSV_BYTES:
        probs.add(csv, f"file is {size / 1024**3:.2f} GiB, above the limit of "
                  f"{MAX_CSV_BYTES / 1024**3:.0f} GiB; split the drive into windows "
                  "(several datasets with start_time_s)")
        return None
    with open(csv, "rb") as fh:
        raw = fh.readline(1 << 20)
    try:
        line = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        probs.add(csv, "header is not UTF-8 text (binary file or another encoding?)", row=1)
        return None
    line = line.rstrip("\r\n")
    if not line.strip():
        probs.add(csv, "header row is blank; expected 'time,<channels>'", row=1)
        return None
    counts = {d: line.count(d) for d in (",", ";", "\t", "|")}
    if counts[","] == 0:
        names = {";": "semicolon", "\t": "tab", "|": "pipe"}
        found = [d for d in (";", "\t", "|") if counts[d] > 0]
        if found:
            probs.add(csv, f"{names[found[0]]}-delimited, expected comma "
                      f"(header {line[:60]!r})", row=1)
            return None
        if " " in line.strip():
            probs.add(csv, f"whitespace-delimited, expected comma (header '{line[:60]}')", row=1)
            return None
    cols = [c.strip().strip('"').strip("'").strip() for c in line.split(",")]
    ok = True
    if cols[0] != "time":
        if "time" in cols:
            probs.add(csv, f"'time' is column {cols.index('time') + 1}; it must be the first "
                      "column", column="time", row=1)
        else:
            probs.add(csv, f"missing; the first column must be 'time' [s] (header has: "
                      f"{', '.join(cols)[:120]})", column="time", row=1)
        ok = False
    seen = set()
    for i, c in enumerate(cols):
        if c in seen:
            probs.add(csv, f"duplicated column name (column {i + 1})", column=c, row=1)
            ok = False
        seen.add(c)
        if c == "time" or (i == 0 and "time" not in cols):
            continue  # a misnamed time column is reported once, above
        if c == "":
            probs.add(csv, f"column {i + 1} has an empty name", row=1)
            ok = False
        elif parse_channel(c) is None:
            m = re.match(r"^(.*?)\s*[\[(](.*)[\])]\s*$", c)
            if m and parse_channel(m.group(1).strip()) is not None:
                probs.add(csv, f"the header holds names only; put the unit '{m.group(2)}' in "
                          "meta.toml [units] or convert to SI (column "
                          f"{i + 1})", column=c, row=1)
            else:
                probs.add(csv, f"channel name does not parse (column {i + 1}); expected "
                          "susp_disp_<axle><L|R>, axle_acc_<axle><L|R>, body_acc_<axle><L|R>, "
                          "speed, dcdc_y_P<1-4> or dcdc_z_P<1-4>, e.g. susp_disp_3L",
                          column=c, row=1)
            ok = False
    if len(cols) == 1 and ok:
        probs.add(csv, "no channels: the header holds only 'time'", row=1)
        ok = False
    return cols if ok else None


def _column_to_float(series: pd.Series) -> tuple[np.ndarray, list[tuple[int, str]]]:
    """Float values of one chunk column and (position, reason) of the first bad entry."""
    if pd.api.types.is_float_dtype(series.dtype) or pd.api.types.is_integer_dtype(series.dtype):
        return series.to_numpy(dtype=float), []
    values = pd.to_numeric(series, errors="coerce").to_numpy(dtype=float)
    bad = []
    for pos in np.flatnonzero(np.isnan(values)):
        raw = series.iloc[pos]
        if raw is None or (isinstance(raw, float) and math.isnan(raw)) or str(raw).strip() == "":
            bad.append((int(pos), "empty value"))
        elif str(raw).strip().lower() in ("nan", "-nan", "+nan", "na", "n/a", "null", "none"):
            bad.append((int(pos), f"NaN value ('{str(raw).strip()}')"))
        else:
            bad.append((int(pos), f"not a number: '{str(raw).strip()[:30]}'"))
        break
    return values, bad


def _read_values(csv: Path, cols: list[str], probs: _Problems):
    """Stream channels.csv in chunks.

    Returns ``(values, ok, time_ok)``: column arrays, whether every value is
    acceptable, and whether the time column is finite; or None when the file
    cannot be read as a table.
    """
    parts: dict[str, list[np.ndarray]] = {c: [] for c in cols}
    first_bad: dict[str, tuple[int, str, int]] = {}  # column -> (row, reason, count)
    peak: dict[str, tuple[float, int]] = {}          # column -> (max |value|, row)
    neg_speed: tuple[float, int] | None = None
    blank_rows: list[int] = []
    n_rows = 0
    try:
        reader = pd.read_csv(csv, chunksize=CHUNK_ROWS, skip_blank_lines=False,
                             keep_default_na=False, na_values=[], skipinitialspace=True,
                             encoding="utf-8-sig", header=0, names=cols, dtype=None,
                             engine="c")
        for chunk in reader:
            if chunk.shape[1] != len(cols):
                probs.add(csv, f"{chunk.shape[1]} columns where the header has {len(cols)}",
                          row=2 + n_rows)
                return None
            row0 = 2 + n_rows  # file line of the first row of this chunk
            arrays = {}
            for c in cols:
                vals, bad = _column_to_float(chunk[c])
                arrays[c] = vals
                if bad and c not in first_bad:
                    first_bad[c] = (row0 + bad[0][0], bad[0][1], 0)
            # blank rows: every field empty
            allnan = np.all(np.isnan(np.column_stack([arrays[c] for c in cols])), axis=1)
            if allnan.any():
                blank = np.flatnonzero(allnan & np.all(
                    chunk.astype(str).apply(lambda s: s.str.strip().isin(["", "<NA>", "nan"]))
                    .to_numpy(), axis=1))
                blank_rows += [row0 + int(b) for b in blank]
            for c in cols:
                v = arrays[c]
                nonfinite = ~np.isfinite(v)
                k = int(np.count_nonzero(nonfinite))
                if k:
                    r, why, cnt = first_bad.get(c, (None, None, 0))
                    if r is None:
                        pos = int(np.flatnonzero(nonfinite)[0])
                        why = "NaN value" if np.isnan(v[pos]) else "infinite value"
                        r = row0 + pos
                    first_bad[c] = (r, why, cnt + k)
                fin = np.where(nonfinite, 0.0, np.abs(v))
                if v.size:
                    i = int(np.argmax(fin))
                    if c not in peak or fin[i] > peak[c][0]:
                        peak[c] = (float(fin[i]), row0 + i)
                if c == "speed" and v.size:
                    vv = np.where(nonfinite, 0.0, v)
                    i = int(np.argmin(vv))
                    if vv[i] < 0 and neg_speed is None:
                        neg_speed = (float(vv[i]), row0 + i)
                parts[c].append(v)
            n_rows += len(chunk)
    except pd.errors.EmptyDataError:
        probs.add(csv, "file holds no header row", row=1)
        return None
    except pd.errors.ParserError as exc:
        m = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", str(exc))
        if m:
            probs.add(csv, f"{m.group(3)} fields where the header has {m.group(1)} "
                      "(a delimiter inside a value, or a misaligned row?)", row=int(m.group(2)))
        else:
            probs.add(csv, f"cannot be parsed as CSV: {str(exc).splitlines()[0]}")
        return None
    except UnicodeDecodeError as exc:
        probs.add(csv, f"not UTF-8 text (byte {exc.start})")
        return None
    # trailing blank rows are harmless (an extra newline at the end): drop them
    n_trailing = 0
    while blank_rows and blank_rows[-1] == 1 + n_rows - n_trailing:
        blank_rows.pop()
        n_trailing += 1
    n_rows -= n_trailing
    for c in list(first_bad):
        r, why, cnt = first_bad[c]
        if r > 1 + n_rows:
            del first_bad[c]
        else:
            first_bad[c] = (r, why, cnt - n_trailing)
    if n_rows == 0:
        probs.add(csv, "header but no data rows", row=2)
        return None
    if blank_rows:
        probs.add(csv, f"blank row (blank rows in the file: {len(blank_rows)})", row=blank_rows[0])
        return None
    ok = True
    for c in cols:
        if c in first_bad:
            r, why, cnt = first_bad[c]
            extra = f" ({cnt} non-finite or missing values in this column)" if cnt > 1 else ""
            probs.add(csv, f"{why}; NaN, infinite and empty values are not allowed{extra}",
                      column=c, row=r)
            ok = False
    values = {c: np.concatenate(parts[c])[:n_rows] for c in cols}
    # magnitudes: wrong units
    for c in cols:
        if c == "time":
            continue
        q = QUANTITIES[parse_channel(c)[0]]
        if c in peak and peak[c][0] > q.limit:
            hint = (_mapping_hint(c, values, first_bad, peak[c][0])
                    or implausible_hint(parse_channel(c)[0], peak[c][0]))
            probs.add(csv, f"|value| up to {peak[c][0]:.4g} is implausible in {q.unit} "
                      f"(limit {q.limit:g} {q.unit}): {hint}", column=c, row=peak[c][1])
            ok = False
    if neg_speed is not None:
        probs.add(csv, f"negative speed {neg_speed[0]:.4g} m/s; speed must be >= 0 m/s "
                  "(the vehicle drives forward)", column="speed", row=neg_speed[1])
        ok = False
    return values, ok, "time" not in first_bad


def _mapping_hint(column: str, values: dict, first_bad: dict, peak: float) -> str | None:
    """A suspension displacement over its range that physics says is not millimetres (a copy
    of another column, swapped with an acceleration: ``drives.plausibility.
    large_displacement_cause``); None where the unit hint stands.  Needs every column finite
    and a usable time column."""
    if not column.startswith("susp_disp_") or first_bad or "time" not in values:
        return None
    t = values["time"]
    d = np.diff(t)
    if t.size < 3 or not np.all(d > 0):
        return None
    from drives.plausibility import large_displacement_cause

    return large_displacement_cause(column, values, 1.0 / float(np.median(d)),
                                    named_only=peak < NOT_A_UNIT_BELOW.get("susp_disp", 0.0))


def _check_time(csv: Path, t: np.ndarray, probs: _Problems) -> float | None:
    """Strictly increasing, uniform time; returns the mean step [s] or None."""
    if t.size < 2:
        probs.add(csv, f"only {t.size} data row; need at least 2 to define the sample rate",
                  column="time", row=2)
        return None
    d = np.diff(t)
    nonpos = np.flatnonzero(d <= 0)
    if nonpos.size:
        i = int(nonpos[0])
        kind = "duplicated" if d[i] == 0 else "decreasing"
        probs.add(csv, f"time not strictly increasing: {kind} value {float(t[i + 1])!r} "
                  f"after {float(t[i])!r} (steps <= 0: {nonpos.size})", column="time", row=i + 3)
        return None
    step = float((t[-1] - t[0]) / (t.size - 1))
    jitter = np.abs(d - step) / step
    bad = np.flatnonzero(jitter > TIME_JITTER_REL)
    if bad.size:
        i = int(bad[0])
        probs.add(csv, f"non-uniform sampling: step {d[i]:.9g} s against the mean step "
                  f"{step:.9g} s (relative jitter {jitter[i]:.2g} > {TIME_JITTER_REL:g}; "
                  f"non-uniform steps: {bad.size})", column="time", row=i + 3)
        return None
    return step


def _read_meta(folder: Path, probs: _Problems) -> dict | None:
    metaf = folder / META_FILE
    if not metaf.is_file():
        probs.add(metaf, "missing; a dataset needs meta.toml with a [dataset] table "
                  "(sample_rate_hz, vehicle, speed_mps)")
        return None
    try:
        doc = tomllib.loads(metaf.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        probs.add(metaf, "not UTF-8 text")
        return None
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        where = f"row {m.group(1)}, column {m.group(2)}" if m else ""
        msg = str(exc).split(" (at")[0]
        probs.add(metaf, f"not valid TOML: {msg}" + (f" at {where}" if where else ""))
        return None
    if not isinstance(doc.get("dataset"), dict):
        probs.add(metaf, "no [dataset] table")
        return None
    return doc


def _number(metaf, ds, key, probs, *, required, positive=False, nonneg=False):
    if key not in ds:
        if required:
            probs.add(metaf, f"[dataset] {key} is missing")
        return None
    v = ds[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        probs.add(metaf, f"[dataset] {key} = {v!r} is not a finite number")
        return None
    if positive and v <= 0:
        probs.add(metaf, f"[dataset] {key} = {v!r} must be > 0")
        return None
    if nonneg and v < 0:
        probs.add(metaf, f"[dataset] {key} = {v!r} must be >= 0" +
                  (" (the vehicle drives forward)" if key == "speed_mps" else ""))
        return None
    return float(v)


def _resolve_vehicle(folder: Path, ds: dict, probs: _Problems) -> str | Path | None:
    metaf = folder / META_FILE
    v = ds.get("vehicle")
    if v is None:
        if (folder / VEHICLE_FILE).is_file():
            return (folder / VEHICLE_FILE).resolve()
        probs.add(metaf, "[dataset] vehicle is missing and there is no vehicle.toml; name a "
                  f"built-in vehicle ({', '.join(builtin_vehicles())}) or a file in the dataset")
        return None
    if not isinstance(v, str) or not v.strip():
        probs.add(metaf, f"[dataset] vehicle = {v!r} is not a file name or vehicle id")
        return None
    looks_like_file = v.endswith(".toml") or "/" in v or os.sep in v
    path = folder / v
    if path.is_file():
        return path.resolve()
    if looks_like_file:
        probs.add(path, f"missing: meta.toml [dataset] vehicle = '{v}' names this file, which "
                  f"is not there (or use a built-in id: {', '.join(builtin_vehicles())})")
        return None
    ids = builtin_vehicles()
    if v not in ids:
        probs.add(metaf, f"[dataset] vehicle = '{v}' is neither a file in the dataset nor a "
                  f"built-in vehicle id ({', '.join(ids)})")
        return None
    return v


def axle_positions(vehicle) -> dict[int, float] | None:
    """Axle number (1 = front) -> position along x [m] of a resolved vehicle (a file path or
    a built-in id), read from its TOML's ``[[axle]]`` tables without importing
    :mod:`vehicles`; None when the file cannot be read (the vehicle's own loader reports
    that where the vehicle is used)."""
    path = Path(vehicle) if isinstance(vehicle, Path) else None
    if path is None:
        path = next((d / f"{vehicle}.toml" for d in _builtin_params_dirs()
                     if (d / f"{vehicle}.toml").is_file()), None)
    try:
        axles = tomllib.loads(path.read_text())["axle"]
        return {i + 1: float(a["x"]) for i, a in enumerate(axles)}
    except (AttributeError, OSError, KeyError, TypeError, ValueError, tomllib.TOMLDecodeError):
        return None


def _check_units(folder: Path, doc: dict, cols: list[str] | None, probs: _Problems) -> dict:
    """Optional [units] table: each entry must be the SI unit of its column."""
    metaf = folder / META_FILE
    units = doc.get("units", {})
    out = {}
    if not isinstance(units, dict):
        probs.add(metaf, "[units] must be a table of column = \"unit\"")
        return out
    for col, u in units.items():
        if cols is not None and col not in cols:
            probs.add(metaf, f"[units] names column '{col}', which channels.csv does not have")
            continue
        if col == "time":
            si = "s"
        else:
            p = parse_channel(col)
            if p is None:
                probs.add(metaf, f"[units] names '{col}', which is not a channel name")
                continue
            si = QUANTITIES[p[0]].unit
        us = str(u).strip()
        if us in _SI_SPELLINGS[si]:
            out[col] = si
        elif us in _NON_SI or us.lower() in _NON_SI:
            probs.add(metaf, f"[units] {col} = '{us}': values must be SI; convert to {si}")
        else:
            probs.add(metaf, f"[units] {col} = '{us}': unknown unit, expected '{si}'")
    return out


def inspect_drive(folder) -> tuple[list[str], Drive | None]:
    """All problems of a dataset folder and, when there are none, the Drive.

    Parameters
    ----------
    folder : str or Path
        Dataset folder.

    Returns
    -------
    problems : list of str
        One line each (file, column, row); empty if valid.
    drive : Drive or None
        The drive when ``problems`` is empty.
    """
    folder = Path(folder)
    probs = _Problems()
    if not folder.exists():
        probs.add(folder, "no such dataset folder")
        return probs.items, None
    if not folder.is_dir():
        probs.add(folder, "not a folder; a dataset is a folder with channels.csv and meta.toml")
        return probs.items, None
    doc = _read_meta(folder, probs)
    csv = folder / CHANNELS_FILE
    cols = values = None
    step = None
    if not csv.is_file():
        probs.add(csv, "missing; a dataset needs channels.csv (time and channels)")
    else:
        cols = _sniff_header(csv, probs)
        if cols is not None:
            read = _read_values(csv, cols, probs)
            if read is not None:
                values, _, time_ok = read
                if time_ok:
                    step = _check_time(csv, values["time"], probs)
    ds = doc["dataset"] if doc else None
    units = {}
    vehicle = None
    rate = speed_mps = None
    if ds is not None:
        metaf = folder / META_FILE
        rate = _number(metaf, ds, "sample_rate_hz", probs, required=True, positive=True)
        has_speed_col = cols is not None and "speed" in cols
        speed_mps = _number(metaf, ds, "speed_mps", probs, required=(cols is not None
                            and not has_speed_col), nonneg=True)
        if "speed_mps" not in ds and cols is not None and not has_speed_col:
            probs.items[-1] += " (channels.csv has no speed column, so meta must give it)"
        _number(metaf, ds, "start_time_s", probs, required=False)
        zero = ds.get("susp_disp_zero", ZERO_UNKNOWN)
        if zero not in SUSP_DISP_ZERO:
            probs.add(metaf, f"[dataset] susp_disp_zero = {zero!r} is not one of "
                      + ", ".join(f'"{z}"' for z in SUSP_DISP_ZERO))
        vehicle = _resolve_vehicle(folder, ds, probs)
        units = _check_units(folder, doc, cols, probs)
        if rate is not None and step is not None:
            data_rate = 1.0 / step
            if abs(data_rate - rate) > RATE_REL_TOL * rate:
                hint = ""
                if abs(step * rate - 1000.0) < 1e-3 * 1000:
                    hint = "; time looks like milliseconds, expected seconds"
                probs.add(metaf, f"[dataset] sample_rate_hz = {rate:g} disagrees with the time "
                          f"column of channels.csv ({data_rate:.9g} Hz, step {step:.9g} s){hint}")
    if probs.items:
        return probs.items, None
    t = values.pop("time")
    speed_col = values.pop("speed", None)
    chans = pd.DataFrame(values)
    if speed_col is not None:
        speed, source = speed_col, "column"
    else:
        speed, source = np.full(t.size, speed_mps), "meta"
    for c in chans.columns:
        units.setdefault(c, QUANTITIES[parse_channel(c)[0]].unit)
    from drives.plausibility import check_signals, check_speed, check_units as _physics, speed_delay_scale

    warnings = []
    arrays = {c: chans[c].to_numpy(float) for c in chans.columns}
    findings = _physics(arrays, 1.0 / step)
    findings += check_signals(arrays)
    axle_x = axle_positions(vehicle)
    delay = speed_delay_scale(arrays, speed, 1.0 / step, axle_x)
    speed_findings = check_speed(arrays, speed, 1.0 / step, axle_x, estimate=delay)
    if source == "meta":   # the constant speed of meta.toml, not a column
        for f in speed_findings:
            msg = f"[dataset] speed_mps = {speed_mps:g}: {f.message}"
            if f.fatal:
                probs.add(folder / META_FILE, msg)
            else:
                warnings.append(f"{META_FILE}: {msg}")
        speed_findings = []
    for f in findings + speed_findings:
        if f.fatal:
            probs.add(csv, f.message, column=f.column)
        else:
            warnings.append(f"{CHANNELS_FILE}, column '{f.column}': {f.message}")
    if probs.items:
        return probs.items, None
    meta = dict(ds)
    meta.setdefault("name", folder.name)
    return [], Drive(path=folder, time=t, channels=chans, speed=speed, meta=meta,
                     vehicle=vehicle, units=units, speed_source=source, warnings=tuple(warnings),
                     speed_check=delay)


def check_drive(path) -> list[str]:
    """Every way a dataset folder breaks the contract.

    Parameters
    ----------
    path : str or Path
        Dataset folder.

    Returns
    -------
    list of str
        One line per problem, each naming the file (and column and row where
        they apply); empty if the dataset is valid.  Nothing is written.
    """
    return inspect_drive(path)[0]


def read_drive(path) -> Drive:
    """Read and validate a dataset folder.

    Parameters
    ----------
    path : str or Path
        Dataset folder holding channels.csv and meta.toml.

    Returns
    -------
    Drive

    Raises
    ------
    EroadInputError
        One line: the first problem (file, column, row), and how many more
        ``eroad data check`` would list.
    """
    problems, drive = inspect_drive(path)
    if problems:
        more = (f" (+{len(problems) - 1} more; run 'eroad data check {path}')"
                if len(problems) > 1 else "")
        raise EroadInputError(problems[0] + more)
    return drive


# --------------------------------------------------------------------------- writing

def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def swap_into_place(tmp: Path, target: Path) -> None:
    """Rename the complete folder ``tmp`` to ``target``.

    An empty ``target`` is removed first; a non-empty one (the caller has checked that
    overwriting is wanted) is first moved aside under a hidden name in the same
    directory and removed only after ``tmp`` is in place, so a failure in between
    never loses both.
    """
    tmp, target = Path(tmp), Path(target)
    if target.exists():
        if target.is_dir() and not any(target.iterdir()):
            target.rmdir()
            os.replace(tmp, target)
        else:
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            os.replace(target, old / "d")
            os.replace(tmp, target)
            shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(tmp, target)


def temp_folder_beside(target) -> Path:
    """A new temporary folder in the parent of ``target`` (for write-then-rename).

    Unlike :func:`tempfile.mkdtemp` (mode 0700) it gets the ordinary permissions
    of a new folder (0777 less the umask), which it keeps after the rename.

    Parameters
    ----------
    target : str or Path
        The folder that will be replaced by the temporary one.

    Returns
    -------
    Path
    """
    target = Path(target)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.tmp-", dir=target.parent))
    os.chmod(tmp, 0o777 & ~_umask())
    return tmp


def _toml_dumps(doc: dict) -> str:
    import tomli_w

    return tomli_w.dumps(doc)


def write_drive(folder, frame: pd.DataFrame, meta: dict, *, vehicle_file=None,
                overwrite: bool = False, units: dict | None = None,
                add_files: Callable[[Path], None] | None = None) -> Path:
    """Write a dataset folder atomically.

    The dataset is written into a temporary folder beside ``folder``, validated
    with :func:`check_drive`, and renamed into place; on any problem the
    temporary folder is removed and nothing the user had is touched.

    Parameters
    ----------
    folder : str or Path
        Target dataset folder.  Must not exist or be empty unless ``overwrite``.
    frame : DataFrame
        First column ``time`` [s], then channels (SI) and optionally ``speed`` [m/s].
    meta : dict
        The ``[dataset]`` table (name, sample_rate_hz, vehicle, speed_mps, ...).
        ``sample_rate_hz`` defaults to the time column's rate; ``name`` to the
        folder name.
    vehicle_file : str or Path, optional
        Copied to ``folder/vehicle.toml``; ``meta['vehicle']`` then defaults to
        ``"vehicle.toml"``.
    overwrite : bool
        Replace an existing non-empty ``folder``.
    units : dict, optional
        Written as the optional ``[units]`` table (must be SI).
    add_files : callable, optional
        Called with the temporary folder before validation and renaming, to add
        files such as ``truth/`` inside the same atomic step.

    Returns
    -------
    Path
        The written folder.

    Raises
    ------
    EroadInputError
        Existing non-empty target, a frame without leading ``time``, or any
        contract violation of the result (one line, the first problem).
    """
    folder = Path(folder)
    if not isinstance(frame, pd.DataFrame) or frame.shape[1] == 0 or frame.columns[0] != "time":
        raise EroadInputError(f"{folder}: write_drive needs a DataFrame whose first column is "
                              "'time' [s]")
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())) and not overwrite:
        raise EroadInputError(f"{folder}: exists and is not empty; choose another folder or "
                              "use --force")
    parent = folder.parent
    parent.mkdir(parents=True, exist_ok=True)
    meta = dict(meta)
    meta.setdefault("name", folder.name)
    t = frame["time"].to_numpy(dtype=float)
    if "sample_rate_hz" not in meta and t.size >= 2:
        meta["sample_rate_hz"] = float((t.size - 1) / (t[-1] - t[0]))
    if vehicle_file is not None:
        meta.setdefault("vehicle", VEHICLE_FILE)
    tmp = temp_folder_beside(folder)
    try:
        frame.to_csv(tmp / CHANNELS_FILE, index=False, lineterminator="\n", na_rep="nan")
        doc = {"dataset": meta}
        if units:
            doc["units"] = dict(units)
        (tmp / META_FILE).write_text(_toml_dumps(doc), encoding="utf-8")
        if vehicle_file is not None:
            vf = Path(vehicle_file)
            if not vf.is_file():
                raise EroadInputError(f"{vf}: vehicle file not found")
            shutil.copyfile(vf, tmp / VEHICLE_FILE)
        if add_files is not None:
            add_files(tmp)
        problems = check_drive(tmp)
        if problems:
            first = problems[0].replace(str(tmp), str(folder))
            raise EroadInputError(f"not written: {first}")
        swap_into_place(tmp, folder)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)
    return folder
