"""The run archive: one folder per run that can be trusted later.

A base module: every layer (inverse, diagnosis, studies, the command line) may use
it, and it imports nothing of theirs.  It owns the one ``run.json`` schema every
command writes (:func:`run_info` / :func:`finish_run_info`), reads older run
folders into that schema (:func:`normalize_info`), finds every run folder under a
results root (:func:`list_runs`), and checks that a run's manifest lists only
files that exist (:func:`manifest_problems`).

Every study writes ``<root>/<study>/<run-id>/`` (``root`` is ``results`` by
default)::

    config.toml     resolved configuration of the run (TOML, written at start)
    run.json        command line, overrides, git commit and dirty flag, host,
                    package versions, seed, start/end time, wall time, status
    data/           numerical results (CSV, NPZ, ...)
    figures/        plots (PNG for looking, PDF for papers)
    summary.json    machine-readable key results (written by the study)
    error.txt       traceback, only when the run failed

The folder is built as a hidden temporary folder ``.tmp-<run-id>`` next to the
final one and renamed into place when the ``with`` block ends: with status
``"complete"`` on success, with status ``"failed"`` (and ``error.txt``) when the
block raised, so nothing is lost.  A run never overwrites another run: the
final name is reserved with an atomic ``mkdir`` and a fresh run-id is drawn if
it is taken.

This module is for writing and reading archives; it does not know what a study
computes.  Use it as::

    with RunArchive("chassis", config, seed=7) as run:
        np.savez(run.data_dir / "spectra.npz", ...)
        fig.savefig(run.figures_dir / "band_energy.png")
        run.write_summary({"n_cases": 12, ...})
    print(run.path)          # the final folder

Inside the block, :attr:`RunArchive.path` is the temporary folder; write files
relative to it (do not store its absolute path in results), it becomes the
final folder on exit.
"""
from __future__ import annotations

import datetime as _dt
import errno
import hashlib
import json
import math
import os
import platform
import shlex
import socket
import subprocess
import sys
import time
import traceback
from dataclasses import dataclass, field, fields, is_dataclass
from importlib import metadata
from pathlib import Path
from typing import Any, Iterator

import numpy as np
import tomli_w

from eroad.errors import EroadInputError

__all__ = [
    "RunArchive",
    "RunRecord",
    "list_runs",
    "load_run",
    "find_run",
    "write_json_atomic",
    "git_state",
    "package_versions",
    "new_run_id",
    "run_info",
    "finish_run_info",
    "write_run_json",
    "normalize_info",
    "manifest_rows",
    "manifest_problems",
    "RUN_SCHEMA",
]

#: distributions whose versions are recorded in run.json (absent ones -> null)
VERSIONED_PACKAGES = ("eroad", "exudyn", "casadi", "numpy", "scipy", "pandas",
                      "dask", "distributed")

#: file names inside a run folder
RUN_FILE = "run.json"
SUMMARY_FILE = "summary.json"
CONFIG_FILE = "config.toml"
ERROR_FILE = "error.txt"
TMP_PREFIX = ".tmp-"

#: version of the run.json schema written by :func:`run_info`
RUN_SCHEMA = 2

#: manifest file names a run folder may hold (listing files relative to the run)
MANIFEST_JSON = "manifest.json"
MANIFEST_MD = "manifest.md"

_REPO_DIR = Path(__file__).resolve().parents[1]


# ---------------------------------------------------------------------------
# small helpers: JSON / TOML conversion and atomic writes
# ---------------------------------------------------------------------------
def _jsonable(obj: Any) -> Any:
    """Convert ``obj`` to plain JSON types (numpy -> Python, Path -> str,
    dataclass -> dict, tuple/set -> list, non-finite float -> None)."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return _jsonable(obj.item())
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, (str, int, bool)) or obj is None:
        return obj
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, (_dt.datetime, _dt.date)):
        return obj.isoformat()
    if is_dataclass(obj) and not isinstance(obj, type):
        return _jsonable({f.name: getattr(obj, f.name) for f in fields(obj)})
    raise TypeError(f"cannot write {type(obj).__name__} to JSON: {obj!r:.80}")


def write_json_atomic(path: str | os.PathLike, obj: Any, *, indent: int = 2) -> Path:
    """Write ``obj`` as JSON to ``path`` atomically.

    The text goes to a temporary file in the same directory, is flushed and
    fsync'ed, and is renamed over ``path`` with :func:`os.replace`, so a reader
    sees either the old or the new file, never a partial one.

    Parameters
    ----------
    path : str or os.PathLike
        Destination file; its directory must exist.
    obj : Any
        JSON-able data.  NumPy scalars and arrays, ``Path``, tuples, dataclasses
        and datetimes are converted; non-finite floats (NaN, inf) are written as
        ``null`` so the file is standard JSON.
    indent : int, optional
        Indentation of the JSON text (default 2).

    Returns
    -------
    pathlib.Path
        The written path.
    """
    path = Path(path)
    text = json.dumps(_jsonable(obj), indent=indent, allow_nan=False) + "\n"
    # not tempfile.mkstemp: its 0600 mode would make shared results unreadable
    tmp = path.parent / f".{path.name}.{os.getpid()}.{os.urandom(4).hex()}.tmp"
    try:
        with open(tmp, "x", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 of a file's bytes (hex), read in 1 MiB blocks: the provenance of an input
    recorded beside what was made from it."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _tomlable(obj: Any) -> Any:
    """Convert a config to types tomli_w accepts; ``None`` entries are dropped
    (TOML has no null: an absent key means "default")."""
    if is_dataclass(obj) and not isinstance(obj, type):
        obj = {f.name: getattr(obj, f.name) for f in fields(obj)}
    if isinstance(obj, dict):
        return {str(k): _tomlable(v) for k, v in obj.items() if v is not None}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [_tomlable(v) for v in obj if v is not None]
    if isinstance(obj, np.ndarray):
        return _tomlable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    return obj


def _utc_now() -> _dt.datetime:
    return _dt.datetime.now(_dt.timezone.utc)


def _iso(t: _dt.datetime) -> str:
    return t.isoformat(timespec="milliseconds").replace("+00:00", "Z")


# ---------------------------------------------------------------------------
# provenance: run-id, git, versions
# ---------------------------------------------------------------------------
def new_run_id(when: _dt.datetime | None = None) -> str:
    """Return a new run-id ``YYYYmmddTHHMMSSZ-xxxxxxxx``.

    The first part is the UTC time (sortable), the second 8 hex digits of a
    SHA-256 hash of the time in ns, the process id and 8 random bytes, so two
    runs started in the same second get different ids.

    Parameters
    ----------
    when : datetime.datetime, optional
        UTC time to stamp (default: now).

    Returns
    -------
    str
        The run-id.
    """
    when = when or _utc_now()
    salt = f"{time.time_ns()}-{os.getpid()}-".encode() + os.urandom(8)
    return f"{when.strftime('%Y%m%dT%H%M%SZ')}-{hashlib.sha256(salt).hexdigest()[:8]}"


def git_state(repo: str | os.PathLike | None = None) -> dict[str, Any]:
    """Git commit and dirty flag of the repository holding this package.

    Parameters
    ----------
    repo : str or os.PathLike, optional
        Folder to inspect (default: the folder containing the ``eroad``
        package, i.e. the eroad source tree of an editable install).

    Returns
    -------
    dict
        ``{"commit": str | None, "dirty": bool | None}``.  ``dirty`` is true when
        tracked files differ from the commit (untracked files such as new
        results are not counted).  Both are ``None`` when git is not installed,
        the folder is not the top of a git work tree (e.g. an installed wheel),
        or git fails.
    """
    repo = Path(repo) if repo is not None else _REPO_DIR
    out: dict[str, Any] = {"commit": None, "dirty": None}

    def git(*args: str) -> str:
        return subprocess.run(["git", "-C", str(repo), *args], capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
    try:
        top = Path(git("rev-parse", "--show-toplevel")).resolve()
        if top != repo.resolve():
            return out
        out["commit"] = git("rev-parse", "HEAD")
        out["dirty"] = bool(git("status", "--porcelain", "--untracked-files=no"))
    except (OSError, subprocess.SubprocessError):
        pass
    return out


def package_versions(names: tuple[str, ...] = VERSIONED_PACKAGES) -> dict[str, str | None]:
    """Installed versions of ``names`` plus Python, read from package metadata
    (nothing is imported, so this is fast).

    Parameters
    ----------
    names : tuple of str
        Distribution names.

    Returns
    -------
    dict
        ``{"python": "3.11.7", "exudyn": "1.13.6", ...}``; ``None`` for a
        distribution that is not installed.
    """
    versions: dict[str, str | None] = {"python": platform.python_version()}
    for name in names:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return versions


def host_info() -> dict[str, Any]:
    """``{"hostname", "platform", "machine", "cpu_count"}`` of this machine."""
    return {"hostname": socket.gethostname(), "platform": platform.platform(),
            "machine": platform.machine(), "cpu_count": os.cpu_count()}


def run_info(study: str, *, run_id: str = "", command: list[str] | str | None = None,
             seed: int | None = None, overrides: list[str] | dict | None = None,
             extra: dict | None = None, start: _dt.datetime | None = None) -> dict[str, Any]:
    """The ``run.json`` record of a run that starts now (status ``"running"``).

    Every command that writes a run folder (``invert``, ``diagnose``,
    ``reproduce``, the studies) writes this one schema; finish it with
    :func:`finish_run_info` and write it with :func:`write_run_json`.

    Parameters
    ----------
    study : str
        What made the run (``"invert"``, ``"diagnose"``, ``"reproduce"``, a study name).
    run_id : str, optional
        The run's id (default: filled in from the folder name when written).
    command : list of str or str, optional
        Command line (default ``sys.argv``).
    seed : int, optional
        Root seed of the run (``None``: the run draws nothing random).
    overrides : list or dict, optional
        Configuration overrides given by the user.
    extra : dict, optional
        Command-specific fields (e.g. ``{"quick": False, "workers": 2}``), kept
        under ``"extra"`` so the shared fields keep one meaning.
    start : datetime.datetime, optional
        Start time (default now, UTC).

    Returns
    -------
    dict
        The record: ``schema, study, run_id, status, command, argv, overrides, cwd,
        git, host, versions, seed, start_utc, end_utc, wall_s, error, extra``.
    """
    if command is None:
        command = list(sys.argv)
    start = start or _utc_now()
    return {
        "schema": RUN_SCHEMA,
        "study": study,
        "run_id": run_id,
        "status": "running",
        "command": command if isinstance(command, str) else shlex.join(map(str, command)),
        "argv": None if isinstance(command, str) else [str(c) for c in command],
        "overrides": overrides,
        "cwd": os.getcwd(),
        "git": git_state(),
        "host": host_info(),
        "versions": package_versions(),
        "seed": seed,
        "start_utc": _iso(start),
        "end_utc": None,
        "wall_s": None,
        "error": None,
        "extra": dict(extra or {}),
    }


def finish_run_info(info: dict, status: str = "complete", *, wall_s: float | None = None,
                    error: BaseException | None = None) -> dict:
    """Set status, end time, wall time [s] and error of a :func:`run_info` record
    (in place; also returned)."""
    end = _utc_now()
    info["status"] = status
    info["end_utc"] = _iso(end)
    if wall_s is None:
        try:
            t0 = _dt.datetime.fromisoformat(str(info["start_utc"]).replace("Z", "+00:00"))
            wall_s = (end - t0).total_seconds()
        except (KeyError, ValueError):
            wall_s = None
    info["wall_s"] = None if wall_s is None else round(float(wall_s), 3)
    if error is not None:
        info["error"] = {"type": type(error).__name__, "message": str(error)}
    return info


def write_run_json(folder: str | os.PathLike, info: dict) -> Path:
    """Write ``info`` to ``<folder>/run.json`` (atomically); an empty ``run_id``
    becomes the folder name."""
    folder = Path(folder)
    if not info.get("run_id"):
        info = {**info, "run_id": folder.name}
    return write_json_atomic(folder / RUN_FILE, info)


# ---------------------------------------------------------------------------
# the archive
# ---------------------------------------------------------------------------
class RunArchive:
    """Context manager writing one archived run ``<root>/<study>/<run-id>/``.

    Parameters
    ----------
    study : str
        Study name, used as folder name (letters, digits, ``-``, ``_``, ``.``).
    config : dict
        Resolved configuration of the run (all parameters after defaults and
        overrides are applied); written to ``config.toml``.  NumPy values,
        tuples, ``Path`` and dataclasses are converted; ``None`` values are
        omitted because TOML has no null.
    root : str or os.PathLike, optional
        Results root (default ``"results"``, relative to the working folder).
    seed : int, optional
        Root seed of the run, recorded in ``run.json``.
    command : list of str or str, optional
        Command line to record (default ``sys.argv``).
    overrides : list of str or dict, optional
        Configuration overrides given by the user (e.g. ``["frame.k=2.0"]``),
        recorded in ``run.json``.

    Attributes
    ----------
    run_id : str
        The run-id (final once the block has ended).
    path : pathlib.Path
        The run folder: the temporary folder inside the block, the final
        folder afterwards.
    status : str
        ``"running"``, ``"complete"`` or ``"failed"``.
    info : dict
        The content of ``run.json``.

    Notes
    -----
    The archive never suppresses an exception: the block's exception
    propagates after the folder has been renamed with status ``"failed"`` and
    the traceback written to ``error.txt``.  If the process is killed hard
    (SIGKILL, power loss), the hidden ``.tmp-<run-id>`` folder stays behind with
    status ``"running"``; :func:`list_runs` ignores it.
    """

    def __init__(self, study: str, config: dict, root: str | os.PathLike = "results",
                 seed: int | None = None, command: list[str] | str | None = None,
                 overrides: list[str] | dict | None = None) -> None:
        if not study or not all(c.isalnum() or c in "-_." for c in study) or study[0] == ".":
            raise EroadInputError(f"study name {study!r} must be letters, digits, '-', '_' "
                                  "or '.', not starting with '.'")
        self.study = study
        self.config = dict(config)
        self.root = Path(root)
        self.seed = seed
        if command is None:
            command = list(sys.argv)
        self.command = command
        self.overrides = overrides
        self.run_id = ""
        self.path = Path()
        self.status = "new"
        self.info: dict[str, Any] = {}
        self._t0 = 0.0

    # -- folders ------------------------------------------------------------
    @property
    def study_dir(self) -> Path:
        """Folder holding all runs of this study, ``<root>/<study>``."""
        return self.root / self.study

    @property
    def data_dir(self) -> Path:
        """``<run>/data``: numerical results."""
        return self.path / "data"

    @property
    def figures_dir(self) -> Path:
        """``<run>/figures``: plots."""
        return self.path / "figures"

    # -- writing --------------------------------------------------------------
    def write_summary(self, summary: dict) -> Path:
        """Write ``summary.json`` (atomically; may be called repeatedly).

        Parameters
        ----------
        summary : dict
            Machine-readable key results with units in the key names or values.

        Returns
        -------
        pathlib.Path
            Path of ``summary.json`` (inside the temporary folder while the
            block runs).
        """
        self._require_open()
        return write_json_atomic(self.path / SUMMARY_FILE, summary)

    def write_json(self, name: str, obj: Any) -> Path:
        """Write ``obj`` atomically to ``data/<name>`` as JSON.

        Parameters
        ----------
        name : str
            File name inside ``data/`` (e.g. ``"bands.json"``).
        obj : Any
            JSON-able data (see :func:`write_json_atomic`).

        Returns
        -------
        pathlib.Path
            Path of the written file.
        """
        self._require_open()
        return write_json_atomic(self.data_dir / name, obj)

    def _require_open(self) -> None:
        if self.status != "running":
            raise RuntimeError(f"run archive is {self.status}; write inside the with block")

    # -- context manager --------------------------------------------------------
    def __enter__(self) -> "RunArchive":
        if self.status != "new":
            raise RuntimeError("a RunArchive can be entered only once")
        self.study_dir.mkdir(parents=True, exist_ok=True)
        start = _utc_now()
        self._t0 = time.perf_counter()
        for _ in range(100):
            self.run_id = new_run_id(start)
            tmp = self.study_dir / f"{TMP_PREFIX}{self.run_id}"
            try:
                tmp.mkdir()
                break
            except FileExistsError:
                continue
        else:  # pragma: no cover - 100 hash collisions
            raise RuntimeError(f"cannot create a temporary run folder in {self.study_dir}")
        self.path = tmp
        self.data_dir.mkdir()
        self.figures_dir.mkdir()
        self.status = "running"
        self.info = run_info(self.study, run_id=self.run_id, command=self.command,
                             seed=self.seed, overrides=self.overrides, start=start)
        try:
            (self.path / CONFIG_FILE).write_bytes(tomli_w.dumps(_tomlable(self.config)).encode())
        except TypeError as exc:
            raise TypeError(f"config of study {self.study!r} cannot be written as TOML: {exc}") \
                from exc
        write_json_atomic(self.path / RUN_FILE, self.info)
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if self.status != "running":
            return False
        self.status = "complete" if exc_type is None else "failed"
        finish_run_info(self.info, self.status, wall_s=time.perf_counter() - self._t0,
                        error=exc if exc_type is not None else None)
        if exc_type is not None:
            (self.path / ERROR_FILE).write_text(
                "".join(traceback.format_exception(exc_type, exc, tb)), encoding="utf-8")
        self._move_into_place()
        return False  # never swallow the exception

    def _move_into_place(self) -> None:
        """Rename the temporary folder to ``<study>/<run-id>``, never over
        another run: the final name is reserved with an atomic ``mkdir`` (which
        fails if the name exists) and the temporary folder is renamed over that
        empty reserved folder (allowed by POSIX ``rename``)."""
        tmp = self.path
        for attempt in range(100):
            if attempt:
                self.run_id = new_run_id()
            final = self.study_dir / self.run_id
            try:
                final.mkdir()
            except FileExistsError:
                continue
            self.info["run_id"] = self.run_id
            write_json_atomic(tmp / RUN_FILE, self.info)
            try:
                os.rename(tmp, final)
            except OSError as exc:  # pragma: no cover - platforms without rename-over-dir
                final.rmdir()
                if exc.errno in (errno.EEXIST, errno.ENOTEMPTY):
                    continue
                raise
            self.path = final
            return
        raise RuntimeError(f"no free run-id in {self.study_dir}")  # pragma: no cover


# ---------------------------------------------------------------------------
# reading archives
# ---------------------------------------------------------------------------
#: what :func:`normalize_info` records for a field an older run did not record
NOT_RECORDED = "not recorded"


def _iso_any(value: Any) -> str | None:
    """An ISO 8601 time in any of the forms older runs wrote -> ``...Z`` (or None)."""
    if not value:
        return None
    text = str(value)
    if len(text) == 10:         # a date only (a run that recorded no time of day)
        return text
    try:
        t = _dt.datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        return text
    if t.tzinfo is None:
        t = t.replace(tzinfo=_dt.timezone.utc)
    return _iso(t.astimezone(_dt.timezone.utc))


def normalize_info(info: dict, path: str | os.PathLike | None = None) -> dict:
    """A ``run.json`` of any age in the current schema (:func:`run_info`).

    Older runs wrote other names: ``eroad invert`` ``started``/``finished`` and a
    host string, ``eroad reproduce`` ``start`` and its options at the top level,
    and a command as a list.  They are mapped onto ``start_utc``/``end_utc``,
    ``host.hostname``, ``extra`` and ``command``/``argv``; nothing is dropped
    (unknown top-level keys go to ``extra``).  The file is not changed.

    Parameters
    ----------
    info : dict
        Content of a ``run.json``.
    path : path, optional
        The run folder (fills ``study`` and ``run_id`` when absent).

    Returns
    -------
    dict
        A new dict with every key of the schema.
    """
    info = dict(info)
    out: dict[str, Any] = {"schema": info.pop("schema", 1)}
    p = Path(path) if path is not None else None
    out["study"] = info.pop("study", None) or (p.parent.name if p is not None else None)
    out["run_id"] = info.pop("run_id", None) or (p.name if p is not None else None)
    out["status"] = info.pop("status", None) or "unknown"
    command = info.pop("command", None)
    argv = info.pop("argv", None)
    if isinstance(command, list):
        argv = argv or [str(c) for c in command]
        command = shlex.join(argv)
    out["command"] = command
    out["argv"] = argv
    out["overrides"] = info.pop("overrides", None)
    out["cwd"] = info.pop("cwd", None)
    out["git"] = info.pop("git", None) or {"commit": None, "dirty": None}
    host = info.pop("host", None)
    out["host"] = {"hostname": host} if isinstance(host, str) else (host or {})
    out["versions"] = info.pop("versions", None) or {}
    out["seed"] = info.pop("seed", None)
    start_utc, start, started = info.pop("start_utc", None), info.pop("start", None), \
        info.pop("started", None)
    end_utc, finished = info.pop("end_utc", None), info.pop("finished", None)
    out["start_utc"] = _iso_any(start_utc or start or started)
    out["end_utc"] = _iso_any(end_utc or finished)
    out["wall_s"] = info.pop("wall_s", None)
    err = info.pop("error", None)
    out["error"] = {"type": "", "message": err} if isinstance(err, str) else err
    extra = dict(info.pop("extra", None) or {})
    extra.update(info)          # whatever else an older run recorded
    out["extra"] = extra
    return out


@dataclass(frozen=True)
class RunRecord:
    """One archived run as read from disk.

    Attributes
    ----------
    path : pathlib.Path
        The run folder.
    info : dict
        Content of ``run.json`` in the current schema (:func:`normalize_info`).
    summary : dict or None
        Content of ``summary.json`` (``None`` if absent).
    """

    path: Path
    info: dict = field(repr=False)
    summary: dict | None = field(default=None, repr=False)

    @property
    def study(self) -> str:
        """Study name (the command or study that made the run)."""
        return str(self.info.get("study") or self.path.parent.name)

    @property
    def run_id(self) -> str:
        """Run-id (the folder name)."""
        return self.path.name

    @property
    def status(self) -> str:
        """``"complete"``, ``"failed"``, ``"running"``, ``"partial"``, ..."""
        return str(self.info.get("status", "unknown"))

    @property
    def start(self) -> str:
        """Start time, ISO 8601 UTC (``""`` if not recorded)."""
        return str(self.info.get("start_utc") or "")

    @property
    def wall_s(self) -> float | None:
        """Wall-clock duration [s] (``None`` if the run did not finish)."""
        w = self.info.get("wall_s")
        return None if w is None else float(w)


def _read_json_object(p: Path) -> dict:
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise EroadInputError(f"{p}: cannot read JSON: {exc}") from None
    if not isinstance(data, dict):
        raise EroadInputError(f"{p}: expected a JSON object")
    return data


def load_run(path: str | os.PathLike) -> RunRecord:
    """Read a run folder.

    Parameters
    ----------
    path : str or os.PathLike
        A run folder.  Without ``run.json`` (a folder written before runs had
        one) the record holds only what the folder says: study and run-id from
        its place, every other field ``"not recorded"``.

    Returns
    -------
    RunRecord
        The run, its ``info`` in the current schema.

    Raises
    ------
    eroad.errors.EroadInputError
        If the folder does not exist or is empty, or a JSON file is not a valid
        JSON object.
    """
    path = Path(path)
    if not path.is_dir():
        raise EroadInputError(f"{path}: no such run folder")
    run_file = path / RUN_FILE
    if not run_file.is_file() and not any(path.iterdir()):
        raise EroadInputError(f"{path}: not a run folder (empty)")
    if run_file.is_file():
        info = normalize_info(_read_json_object(run_file), path)
    else:
        info = normalize_info({"status": NOT_RECORDED, "command": NOT_RECORDED,
                               "extra": {"note": f"no {RUN_FILE} in this folder"}}, path)
    summary_file = path / SUMMARY_FILE
    summary = _read_json_object(summary_file) if summary_file.is_file() else None
    return RunRecord(path=path, info=info, summary=summary)


def _is_hidden(p: Path) -> bool:
    return p.name.startswith(".") or p.name == "__pycache__"


def _iter_run_dirs(root: Path) -> Iterator[Path]:
    """Every run folder under ``root``: ``<root>/<study>/<run>/``, or ``<root>/<study>/``
    itself when it holds ``run.json`` or no sub-folders (a study of one run).

    Hidden folders (temporary ``.tmp-*`` runs) and empty folders are skipped.  Runs nested inside a
    run (the steps of ``eroad reproduce``) belong to their parent and are not
    listed separately.
    """
    if not root.is_dir():
        return
    for study in sorted(root.iterdir()):
        if not study.is_dir() or _is_hidden(study):
            continue
        subdirs = [d for d in sorted(study.iterdir()) if d.is_dir() and not _is_hidden(d)]
        if (study / RUN_FILE).is_file() or not subdirs:
            if any(study.iterdir()):
                yield study
            continue
        yield from (d for d in subdirs if any(d.iterdir()))   # an empty folder holds no run


def list_runs(root: str | os.PathLike = "results", study: str | None = None) -> list[RunRecord]:
    """All run folders under ``root``, oldest first.

    Parameters
    ----------
    root : str or os.PathLike, optional
        Results root (default ``"results"``).  A missing root gives ``[]``.
    study : str, optional
        Only runs of this study (the folder name under ``root``).

    Returns
    -------
    list of RunRecord
        Sorted by start time, then study and run-id.  Hidden folders (temporary
        ``.tmp-*`` runs) are skipped; a folder without ``run.json`` is listed with
        status ``"not recorded"``; a run whose JSON is unreadable with status
        ``"unreadable"``.
    """
    records = []
    root = Path(root)
    for run_dir in _iter_run_dirs(root):
        group = run_dir.name if run_dir.parent == root else run_dir.parent.name
        if study is not None and group != study:
            continue
        try:
            rec = load_run(run_dir)
            if group == run_dir.name and not (run_dir / RUN_FILE).is_file():   # a study of one run
                rec = RunRecord(path=rec.path, info={**rec.info, "study": group}, summary=rec.summary)
            records.append(rec)
        except EroadInputError as exc:
            records.append(RunRecord(path=run_dir, info=normalize_info(
                {"status": "unreadable", "error": {"type": "", "message": str(exc)}}, run_dir)))
    return sorted(records, key=lambda r: (r.start, r.study, r.run_id))


def find_run(run: str | os.PathLike, root: str | os.PathLike = "results") -> RunRecord:
    """Find a run by folder path, run-id or unique run-id prefix.

    Parameters
    ----------
    run : str or os.PathLike
        A run folder, ``<study>/<run-id>`` relative to ``root``, a run-id, or
        a prefix of a run-id that matches exactly one run.
    root : str or os.PathLike, optional
        Results root searched for run-ids (default ``"results"``).

    Returns
    -------
    RunRecord
        The run.

    Raises
    ------
    eroad.errors.EroadInputError
        If nothing or more than one run matches.
    """
    p = Path(run)
    dirs = list(_iter_run_dirs(Path(root)))
    known = {d.resolve() for d in dirs}
    for candidate in (p, Path(root) / p):
        if candidate.is_dir() and ((candidate / RUN_FILE).is_file() or candidate.resolve() in known):
            return load_run(candidate)
    name = str(run)
    matches = [d for d in dirs if d.name == name]
    if not matches:
        matches = [d for d in dirs if d.name.startswith(name)]
    if not matches:
        raise EroadInputError(f"run {name!r}: no run folder or run-id under {root} "
                              "(see `eroad runs list`)")
    if len(matches) > 1:
        shown = ", ".join(f"{d.parent.name}/{d.name}" for d in matches[:3])
        raise EroadInputError(f"run {name!r} is ambiguous under {root}: {len(matches)} runs "
                              f"match ({shown}{', ...' if len(matches) > 3 else ''})")
    return load_run(matches[0])


# ---------------------------------------------------------------------------
# manifests: paper item -> files relative to the run
# ---------------------------------------------------------------------------
def manifest_rows(run: str | os.PathLike, items) -> list[dict]:
    """Manifest rows of the files that exist in ``run``.

    Parameters
    ----------
    run : path
        The run folder.
    items : iterable of (item, pattern, code)
        Paper item, glob pattern relative to the run (``"invert/road.*"``) and the
        code that makes it.

    Returns
    -------
    list of dict
        ``{"item", "files", "code", "present"}`` with ``files`` the existing
        matches, sorted, relative to the run (``/``-separated).
    """
    run = Path(run)
    rows = []
    for item, pattern, code in items:
        files = sorted(p.relative_to(run).as_posix() for p in run.glob(pattern) if p.is_file())
        rows.append({"item": item, "files": files, "code": code, "present": bool(files)})
    return rows


def _md_links(text: str) -> list[str]:
    import re
    return [m for m in re.findall(r"\]\(([^)\s]+)\)", text) if "://" not in m and not m.startswith("#")]


def manifest_problems(run: str | os.PathLike) -> list[str]:
    """What a run's manifest claims that its folder does not hold.

    Checks ``manifest.json`` (every listed file exists, is relative to the run and
    inside it; ``present`` says whether files are listed) and ``manifest.md``
    (every relative link points at an existing file).

    Parameters
    ----------
    run : path
        The run folder.

    Returns
    -------
    list of str
        One line per problem; empty when the manifests agree with the folder (or
        the run has none).
    """
    run = Path(run)
    problems = []
    mj = run / MANIFEST_JSON
    if mj.is_file():
        try:
            rows = json.loads(mj.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            return [f"{mj}: cannot read JSON: {exc}"]
        for row in rows if isinstance(rows, list) else []:
            files = row.get("files") or []
            for f in files:
                if Path(f).is_absolute() or ".." in Path(f).parts:
                    problems.append(f"{mj}: {row.get('item')}: {f} is not a path inside the run")
                elif not (run / f).is_file():
                    problems.append(f"{mj}: {row.get('item')}: {f} is listed but missing")
            if "present" in row and bool(row["present"]) != bool(files):
                problems.append(f"{mj}: {row.get('item')}: present={row['present']} "
                                f"with {len(files)} file(s) listed")
    md = run / MANIFEST_MD
    if md.is_file():
        for link in _md_links(md.read_text(encoding="utf-8")):
            if Path(link).is_absolute() or not (run / link).exists():
                problems.append(f"{md}: link {link} points at no file of the run")
    return problems
