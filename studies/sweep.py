"""Parameter sweeps and Monte-Carlo runs on dask.distributed, with a resumable cache.

:func:`run_cases` evaluates a case function on a list of parameter cases
(``dict`` each) and returns the results in case order.  It is built for Exudyn
models, which hold Python user functions and therefore cannot be pickled: the
*function reference* and the *case parameters* travel to the worker, the model
is built there.

- Execution: a ``LocalCluster`` (processes, one thread per worker) by default,
  an existing cluster with ``scheduler="tcp://host:8786"``, or serially in this
  process with ``n_workers`` 0 or 1 (identical results: same code path).
- Cache: every finished case is written to ``<cache_dir>/<key>.json`` (or
  ``.npz`` when the result holds arrays) as soon as it arrives, atomically.
  ``key`` is the SHA-256 of the canonical JSON of (case, function name, code
  version), see :func:`case_key`.  A rerun after an interruption loads the
  finished cases and computes only the missing ones.
- A tqdm progress bar counts finished cases (cached ones count as done).

This module does not know what a case computes; :func:`mass_spring_case` is a
small Exudyn reference case used by the tests and ``benchmarks/bench_sweep.py``.
"""
from __future__ import annotations

import argparse
import contextlib
import hashlib
import importlib
import io
import json
import logging
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from eroad.dask_client import dask_client  # re-exported: studies.sweep.dask_client
from eroad.dask_client import quiet_distributed as _quiet_distributed
from eroad.errors import EroadInputError

__all__ = [
    "SweepResult",
    "run_cases",
    "case_key",
    "code_version_of",
    "code_version_of_files",
    "resolve_function",
    "dask_client",
    "add_sweep_arguments",
    "sweep_kwargs",
    "mass_spring_case",
]

log = logging.getLogger(__name__)

#: name of the JSON record stored inside a cached ``.npz``
_RECORD = "__record__"
#: cache file format version, part of every key
CACHE_FORMAT = 1

CaseFunction = Callable[[dict], dict]


# ---------------------------------------------------------------------------
# function references and cache keys
# ---------------------------------------------------------------------------
def resolve_function(func: str | CaseFunction) -> tuple[CaseFunction, str]:
    """Resolve a case function and its stable name.

    Parameters
    ----------
    func : str or callable
        ``"package.module:function"`` or a top-level function object.

    Returns
    -------
    (callable, str)
        The function and its reference ``"module:qualname"``.

    Raises
    ------
    eroad.errors.EroadInputError
        If a string reference does not name an importable callable.
    TypeError
        If ``func`` is a lambda or a nested function (no stable name to
        cache under, and not importable in a worker).
    """
    if isinstance(func, str):
        module_name, sep, attr = func.partition(":")
        if not sep or not module_name or not attr:
            raise EroadInputError(f"case function {func!r}: expected 'module:function'")
        try:
            obj: Any = importlib.import_module(module_name)
            for part in attr.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError) as exc:
            raise EroadInputError(f"case function {func!r}: cannot import ({exc})") from None
        if not callable(obj):
            raise EroadInputError(f"case function {func!r} is not callable")
        return obj, func
    if not callable(func):
        raise TypeError(f"case function must be callable or 'module:function', not {func!r}")
    qualname = getattr(func, "__qualname__", "")
    module = getattr(func, "__module__", None)
    if not qualname or "<" in qualname or not module:
        raise TypeError(f"case function {func!r} must be a top-level function "
                        "(no lambda or nested function)")
    return func, f"{module}:{qualname}"


def code_version_of_files(patterns, root) -> str:
    """Code-version token over source files: ``"eroad-<version>+<sha>"``, ``sha`` the
    first 12 hex digits of the SHA-256 of each file's path relative to ``root`` and its
    bytes, for the files matching ``patterns`` (globs relative to ``root``, the source
    tree's top, each pattern's matches sorted).  For studies whose cases run code beyond
    the case module (vehicle models, roads): pass it to :func:`run_cases` as
    ``code_version``.
    """
    from eroad import __version__

    root = Path(root)
    h = hashlib.sha256()
    for pattern in patterns:
        for p in sorted(root.glob(pattern)):
            h.update(p.relative_to(root).as_posix().encode())
            h.update(p.read_bytes())
    return f"eroad-{__version__}+{h.hexdigest()[:12]}"


def code_version_of(func: str | CaseFunction) -> str:
    """Default code-version token of a case function.

    Parameters
    ----------
    func : str or callable
        The case function (see :func:`resolve_function`).

    Returns
    -------
    str
        ``"eroad-<version>+<sha>"`` where ``sha`` is the first 12 hex digits of
        the SHA-256 of the source file of the module defining ``func`` (of its
        bytecode when there is no file).  Editing that module invalidates its
        cached cases; edits elsewhere (e.g. in ``vehicles/``) do not: pass an
        explicit ``code_version`` to :func:`run_cases` for those.
    """
    from eroad import __version__

    fn, _ = resolve_function(func)
    module = sys.modules.get(fn.__module__)
    path = getattr(module, "__file__", None)
    try:
        payload = Path(path).read_bytes() if path else None
    except OSError:
        payload = None
    if payload is None:
        payload = getattr(getattr(fn, "__code__", None), "co_code", repr(fn).encode())
    return f"eroad-{__version__}+{hashlib.sha256(payload).hexdigest()[:12]}"


def _plain(obj: Any) -> Any:
    """Plain JSON types: numpy -> Python, tuple -> list, Path -> str;
    arrays become lists (used for case parameters and nested results)."""
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if not isinstance(k, str):
                raise TypeError(f"keys must be str, got {k!r}")
            out[k] = _plain(v)
        return out
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    if obj is None or isinstance(obj, (str, bool, int, float)):
        return obj
    raise TypeError(f"{type(obj).__name__} is not JSON-able: {obj!r:.80}")


def _canonical(obj: Any) -> str:
    return json.dumps(_plain(obj), sort_keys=True, separators=(",", ":"), allow_nan=True)


def case_key(case: dict, func_name: str, code_version: str) -> str:
    """Stable cache key of one case.

    Parameters
    ----------
    case : dict
        Case parameters (str keys; JSON-able values, NumPy scalars allowed).
    func_name : str
        Function reference ``"module:qualname"``.
    code_version : str
        Code-version token (see :func:`code_version_of`).

    Returns
    -------
    str
        32 hex digits: the first 128 bits of the SHA-256 of the canonical JSON
        (sorted keys, no spaces, shortest round-trip float repr) of
        ``{"case", "func", "code", "format"}``.  ``1`` and ``1.0`` give
        different keys; key order in ``case`` does not matter.
    """
    text = _canonical({"case": case, "func": func_name, "code": code_version,
                       "format": CACHE_FORMAT})
    return hashlib.sha256(text.encode()).hexdigest()[:32]


# ---------------------------------------------------------------------------
# executing one case (runs inside the worker) and normalising its result
# ---------------------------------------------------------------------------
def _split_result(result: Any) -> tuple[dict, dict[str, np.ndarray]]:
    """Split a case result into JSON-able scalars and top-level arrays."""
    if not isinstance(result, dict):
        raise TypeError(f"case function must return a dict, got {type(result).__name__}")
    plain: dict[str, Any] = {}
    arrays: dict[str, np.ndarray] = {}
    for k, v in result.items():
        if not isinstance(k, str) or k == _RECORD:
            raise TypeError(f"result key {k!r} is not allowed")
        if isinstance(v, np.ndarray):
            if v.dtype.hasobject:
                raise TypeError(f"result {k!r}: object arrays cannot be cached")
            arrays[k] = v
        else:
            plain[k] = _plain(v)
    # JSON round trip so computed and cached results are the same objects
    plain = json.loads(json.dumps(plain, allow_nan=True))
    return plain, arrays


def _run_case(ref: str | CaseFunction, case: dict) -> tuple[dict, float]:
    """Execute one case; runs in the worker (or in-process when serial).

    ``ref`` is resolved here, so the worker imports the function's module
    itself and builds its (unpicklable) Exudyn model from ``case``.
    """
    fn, _ = resolve_function(ref)
    t0 = time.perf_counter()
    result = fn(dict(case))
    return result, time.perf_counter() - t0


# ---------------------------------------------------------------------------
# cache files
# ---------------------------------------------------------------------------
def _atomic_write_bytes(path: Path, data: bytes) -> None:
    tmp = path.parent / f".{path.name}.{os.getpid()}.{os.urandom(4).hex()}.tmp"
    try:
        with open(tmp, "xb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _write_cache(cache_dir: Path, key: str, record: dict, arrays: dict[str, np.ndarray]) -> Path:
    text = json.dumps(record, allow_nan=True, sort_keys=True)
    if arrays:
        buf = io.BytesIO()
        np.savez(buf, **arrays, **{_RECORD: np.array(text)})
        path = cache_dir / f"{key}.npz"
        _atomic_write_bytes(path, buf.getvalue())
    else:
        path = cache_dir / f"{key}.json"
        _atomic_write_bytes(path, (text + "\n").encode())
    return path


def _read_cache(cache_dir: Path, key: str, func_name: str) -> dict | None:
    """Cached result of ``key`` (plain values and arrays merged), or None if
    absent or unreadable (an unreadable file is recomputed and replaced)."""
    jpath, npath = cache_dir / f"{key}.json", cache_dir / f"{key}.npz"
    try:
        if jpath.is_file():
            record = json.loads(jpath.read_text(encoding="utf-8"))
            arrays: dict[str, np.ndarray] = {}
        elif npath.is_file():
            with np.load(npath, allow_pickle=False) as z:
                record = json.loads(str(z[_RECORD][()]))
                arrays = {k: z[k] for k in z.files if k != _RECORD}
        else:
            return None
        if record.get("key") != key or record.get("func") != func_name:
            raise ValueError("key or function in the file do not match its name")
        return {**record["result"], **arrays}
    except Exception as exc:  # noqa: BLE001 - any damage means: recompute
        log.warning("cache entry %s unreadable (%s); recomputing", key, exc)
        return None


# ---------------------------------------------------------------------------
# the sweep
# ---------------------------------------------------------------------------
@dataclass
class SweepResult:
    """Results of :func:`run_cases`, in case order.

    Attributes
    ----------
    cases : list of dict
        The input cases.
    results : list of dict
        One result per case: the case function's dict, with top-level NumPy
        arrays kept as arrays and everything else as plain JSON types.
    keys : list of str
        Cache key of each case.
    computed : list of int
        Indices of the cases computed by this call.
    cached : list of int
        Indices of the cases loaded from the cache.
    case_wall_s : list of float or None
        Compute time of each case in the worker [s]; None for cases loaded
        from the cache.
    wall_s : float
        Wall time of the call [s].
    func : str
        Function reference ``"module:qualname"``.
    code_version : str
        Code-version token used in the keys.
    """

    cases: list[dict]
    results: list[dict]
    keys: list[str]
    computed: list[int] = field(default_factory=list)
    cached: list[int] = field(default_factory=list)
    case_wall_s: list[float | None] = field(default_factory=list)
    wall_s: float = 0.0
    func: str = ""
    code_version: str = ""

    def __len__(self) -> int:
        return len(self.results)

    def __getitem__(self, i: int) -> dict:
        return self.results[i]

    def __iter__(self) -> Iterator[dict]:
        return iter(self.results)

    @property
    def n_computed(self) -> int:
        """Number of cases computed by this call."""
        return len(self.computed)

    @property
    def n_cached(self) -> int:
        """Number of cases loaded from the cache."""
        return len(self.cached)

    def to_dataframe(self):
        """Table of case parameters and scalar results (arrays left out).

        Returns
        -------
        pandas.DataFrame
            One row per case; parameter columns first, then results.  A result
            name equal to a parameter name gets the suffix ``_result``.
        """
        import pandas as pd

        rows = []
        for case, res in zip(self.cases, self.results):
            row = dict(case)
            for k, v in res.items():
                if isinstance(v, np.ndarray) or isinstance(v, (list, dict)):
                    continue
                row[f"{k}_result" if k in case else k] = v
            rows.append(row)
        return pd.DataFrame(rows)


def run_cases(func: str | CaseFunction, cases: list[dict], cache_dir: str | os.PathLike,
              scheduler: Any = None, n_workers: int = 2, progress: bool = True,
              code_version: str | None = None, desc: str | None = None) -> SweepResult:
    """Evaluate ``func(case)`` for every case, in parallel, with a resumable cache.

    Parameters
    ----------
    func : str or callable
        Case function, ``"module:function"`` or a top-level function, taking
        one ``dict`` of parameters and returning a ``dict``: top-level values
        may be NumPy arrays (cached in ``.npz``, numeric dtypes only), all other
        values must be JSON-able (NumPy scalars, tuples allowed; nested arrays
        become lists).  It must build its model itself from the case (Exudyn
        systems do not pickle) and be importable in the workers.
    cases : list of dict
        Parameter cases; str keys, JSON-able values.  Identical cases (same
        key) are computed once and share one result dict.
    cache_dir : str or os.PathLike
        Cache folder, created if missing.  Shared between sweeps is fine: keys
        include the function name and code version.
    scheduler : None, str or distributed.Client, optional
        ``None``: a new LocalCluster with ``n_workers`` processes (or serial,
        see ``n_workers``); a str: address of an existing scheduler; a Client:
        use it and leave it open (reuse across sweeps).
    n_workers : int, optional
        Local worker processes (default 2).  0 or 1 runs the cases serially
        in this process with the same code and the same cache (no dask).
    progress : bool, optional
        Show a tqdm progress bar on stderr (default True).
    code_version : str, optional
        Code-version token in the keys (default :func:`code_version_of`).
        Change it to invalidate the cache, e.g. pass the git commit when the
        case depends on code outside the function's module.
    desc : str, optional
        Label of the progress bar (default: the function name).

    Returns
    -------
    SweepResult
        Results in case order, with the indices computed and loaded.

    Raises
    ------
    Exception
        The first exception raised by a case, re-raised in this process with a
        note naming the case index and parameters; the remaining cases are
        cancelled, the finished ones stay cached.

    Notes
    -----
    Results are cached in this (the client) process as each case finishes,
    so workers need no shared file system and an interruption (Ctrl-C,
    crash) loses only the cases in flight.
    """
    t_start = time.perf_counter()
    fn, name = resolve_function(func)
    ref: str | CaseFunction = name if _importable(fn, name) else fn
    version = code_version if code_version is not None else code_version_of(fn)
    cases = [dict(c) for c in cases]
    for i, c in enumerate(cases):
        try:
            _plain(c)
        except TypeError as exc:
            raise EroadInputError(f"case {i}: {exc}") from None
    keys = [case_key(c, name, version) for c in cases]
    cache = Path(cache_dir)
    cache.mkdir(parents=True, exist_ok=True)

    results: list[dict | None] = [None] * len(cases)
    walls: list[float | None] = [None] * len(cases)
    cached: list[int] = []
    hits: dict[str, dict] = {}
    todo: dict[str, list[int]] = {}  # key -> indices of identical cases
    for i, key in enumerate(keys):
        if key in todo:
            todo[key].append(i)
            continue
        hit = hits.get(key) or _read_cache(cache, key, name)
        if hit is not None:
            hits[key] = results[i] = hit
            cached.append(i)
        else:
            todo[key] = [i]

    computed: list[int] = []

    def finish(key: str, result: Any, wall: float) -> None:
        idx = todo[key]
        try:
            plain, arrays = _split_result(result)
        except TypeError as exc:
            _annotate(exc, idx[0], cases[idx[0]])
            raise
        record = {"key": key, "func": name, "code_version": version,
                  "case": _plain(cases[idx[0]]), "wall_s": wall, "result": plain}
        _write_cache(cache, key, record, arrays)
        merged = {**plain, **arrays}
        for i in idx:
            results[i] = merged
            walls[i] = wall
        computed.extend(idx)

    from tqdm.auto import tqdm

    bar = tqdm(total=len(cases), initial=len(cached), desc=desc or name.split(":")[-1],
               unit="case", disable=not progress, file=sys.stderr, dynamic_ncols=True)
    try:
        if not todo:
            pass
        elif scheduler is None and n_workers <= 1:
            for key, idx in todo.items():
                try:
                    result, wall = _run_case(ref, cases[idx[0]])
                except Exception as exc:
                    _annotate(exc, idx[0], cases[idx[0]])
                    raise
                finish(key, result, wall)
                bar.update(len(idx))
        else:
            _run_distributed(ref, cases, todo, scheduler, n_workers, finish, bar)
    finally:
        bar.close()

    return SweepResult(cases=cases, results=results, keys=keys,  # type: ignore[arg-type]
                       computed=sorted(computed), cached=cached, case_wall_s=walls,
                       wall_s=time.perf_counter() - t_start, func=name, code_version=version)


def _importable(fn: CaseFunction, name: str) -> bool:
    """True if a worker can import ``fn`` by name (not defined in __main__)."""
    if fn.__module__ in ("__main__", "__mp_main__"):
        return False
    try:
        return resolve_function(name)[0] is fn
    except (EroadInputError, TypeError):
        return False


def _annotate(exc: BaseException, index: int, case: dict) -> None:
    exc.add_note(f"in sweep case {index}: {_canonical(case)[:300]}")


def _run_distributed(ref, cases, todo, scheduler, n_workers, finish, bar) -> None:
    from distributed import Client, as_completed

    with contextlib.ExitStack() as stack:
        if isinstance(scheduler, Client):
            client = scheduler
            stack.enter_context(_quiet_distributed())
        else:
            client = stack.enter_context(dask_client(scheduler, n_workers=n_workers))
        futures = {}
        for key, idx in todo.items():
            fut = client.submit(_run_case, ref, cases[idx[0]], pure=False)
            futures[fut] = key
        try:
            for fut in as_completed(list(futures), loop=client.loop):
                key = futures.pop(fut)
                try:
                    result, wall = fut.result()
                except Exception as exc:
                    idx = todo[key][0]
                    _annotate(exc, idx, cases[idx])
                    raise
                finish(key, result, wall)
                bar.update(len(todo[key]))
        finally:
            if futures:
                client.cancel(list(futures))


# ---------------------------------------------------------------------------
# command-line options for studies that sweep
# ---------------------------------------------------------------------------
def add_sweep_arguments(parser: argparse.ArgumentParser,
                        default_cache: str = ".eroad-cache") -> None:
    """Add ``--scheduler``, ``--workers``, ``--cache`` and ``--no-progress``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The study's parser.
    default_cache : str, optional
        Default cache folder (``.eroad-cache``, ignored by git).
    """
    g = parser.add_argument_group("parallel execution")
    g.add_argument("--scheduler", metavar="ADDRESS", default=None,
                   help="address of an existing dask scheduler (tcp://host:8786); "
                   "default: a local cluster")
    g.add_argument("--workers", type=int, default=2, metavar="N",
                   help="local worker processes (default 2; 0 or 1: serial, no dask)")
    g.add_argument("--cache", default=default_cache, metavar="DIR",
                   help=f"case cache folder (default {default_cache}); finished cases "
                   "are reused, so an interrupted sweep resumes")
    g.add_argument("--no-progress", action="store_true", help="no progress bar")


def sweep_kwargs(args: argparse.Namespace) -> dict[str, Any]:
    """Keyword arguments for :func:`run_cases` from :func:`add_sweep_arguments`.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed arguments.

    Returns
    -------
    dict
        ``scheduler``, ``n_workers``, ``cache_dir``, ``progress``.

    Raises
    ------
    eroad.errors.EroadInputError
        If ``--workers`` is negative.
    """
    if args.workers < 0:
        raise EroadInputError(f"--workers {args.workers}: must be >= 0")
    return {"scheduler": args.scheduler, "n_workers": args.workers,
            "cache_dir": args.cache, "progress": not args.no_progress}


# ---------------------------------------------------------------------------
# reference case: a small Exudyn model built inside the worker
# ---------------------------------------------------------------------------
def mass_spring_case(case: dict) -> dict:
    """Reference case: free vibration of a nonlinear mass-spring-damper in Exudyn.

    A mass point on a linear spring-damper (k, d) in x, y, z plus a 0.5 m
    spring below it with a Python force user function ``k u + k3 u^3 + d v``
    of its elongation u (so the model
    holds a Python user function, as the vehicle models do, and cannot be
    pickled), released from ``z0`` and integrated with the implicit
    generalized-alpha solver.  CPU time is about 1.7 us per step.

    Parameters
    ----------
    case : dict
        ``mass`` [kg] (default 10), ``stiffness`` k [N/m] (1e4),
        ``damping`` d [N s/m] (20), ``cubic`` k3 [N/m^3] (1e6),
        ``z0`` initial displacement [m] (0.01), ``t_end`` [s] (1.0),
        ``steps`` number of time steps [-] (1000).  Unknown keys raise.

    Returns
    -------
    dict
        ``z_final`` [m], ``z_max_abs`` [m], ``t`` (M,) [s] and ``z`` (M,) [m]
        sampled every 0.01 s, ``steps`` [-].

    Raises
    ------
    eroad.errors.EroadInputError
        For an unknown key or a non-positive mass, t_end or steps.
    """
    defaults = {"mass": 10.0, "stiffness": 1e4, "damping": 20.0, "cubic": 1e6,
                "z0": 0.01, "t_end": 1.0, "steps": 1000}
    unknown = sorted(set(case) - set(defaults))
    if unknown:
        raise EroadInputError(f"mass_spring_case: unknown parameter {unknown[0]!r}")
    p = {**defaults, **case}
    if not (p["mass"] > 0 and p["t_end"] > 0 and int(p["steps"]) > 0):
        raise EroadInputError("mass_spring_case: mass, t_end and steps must be positive")

    import exudyn as exu
    from exudyn.itemInterface import (CartesianSpringDamper, MarkerBodyPosition,
                                      MarkerNodePosition, MassPoint, NodePoint, ObjectGround,
                                      SensorNode, SpringDamper)

    k, d, k3 = float(p["stiffness"]), float(p["damping"]), float(p["cubic"])
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodePoint(referenceCoordinates=[0.0, 0.0, 0.0],
                                 initialCoordinates=[0.0, 0.0, float(p["z0"])]))
    mbs.AddObject(MassPoint(mass=float(p["mass"]), nodeNumber=node))
    ground = mbs.AddObject(ObjectGround())
    m_origin = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0]))
    m_below = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, -0.5]))
    m_mass = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
    # linear spring-damper in x, y, z between the origin and the mass
    mbs.AddObject(CartesianSpringDamper(markerNumbers=[m_origin, m_mass],
                                        stiffness=[k, k, k], damping=[d, d, d]))

    def spring_force(mbs_, t, item, u, v, k_, d_, f0):  # Python user function
        return k3 * u ** 3 + k_ * u + d_ * v

    # nonlinear spring 0.5 m long below the mass: u = its elongation ~ z
    mbs.AddObject(SpringDamper(markerNumbers=[m_below, m_mass], stiffness=k, damping=d,
                               referenceLength=0.5, springForceUserFunction=spring_force))
    sensor = mbs.AddSensor(SensorNode(nodeNumber=node, storeInternal=True,
                                      outputVariableType=exu.OutputVariableType.Displacement))
    mbs.Assemble()
    ss = exu.SimulationSettings()
    ss.timeIntegration.numberOfSteps = int(p["steps"])
    ss.timeIntegration.endTime = float(p["t_end"])
    ss.timeIntegration.verboseMode = 0
    ss.solution.sensors.writePeriod = 0.01
    ss.solution.file.write = False
    mbs.SolveDynamic(ss)
    data = mbs.GetSensorStoredData(sensor)
    z = np.ascontiguousarray(data[:, 3])
    return {"z_final": float(z[-1]), "z_max_abs": float(np.max(np.abs(z))),
            "t": np.ascontiguousarray(data[:, 0]), "z": z, "steps": int(p["steps"])}


if __name__ == "__main__":  # pragma: no cover
    print(mass_spring_case({}))
