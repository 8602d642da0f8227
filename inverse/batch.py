"""Many drives inverted on Dask: ``eroad invert DIR1 DIR2 ... --out ROOT [--scheduler ADDRESS]``.

What it is for: one inversion per dataset, each an ordinary run folder ``ROOT/<dataset
folder name>/`` (what :func:`inverse.run.run_inversion` writes, with its archive record
``run.json``), the drives spread over the workers of a ``dask.distributed`` cluster:
a new ``LocalCluster`` of ``n_workers`` processes with one thread each by default, or
an existing cluster given by its scheduler address, or (``n_workers`` 0 or 1) one after the
other in this process without Dask -- the client of the sweeps
(:func:`eroad.dask_client.dask_client`, shared with ``studies.sweep``).  A drive that fails does not stop the others: its one-line error is
reported, its folder holds a ``run.json`` with status ``failed`` (unless the folder
already held something), and ``ROOT/batch.json`` lists every drive's outcome.

What it is not: parallel inside a drive -- each drive runs serially in its worker
(Dask's worker processes are daemonic and cannot start a process pool), the cluster
gives the parallelism across drives.  Nor the command line (``inverse.cli``).

The function run per drive is named by reference (``"module:function"``, default
``inverse.run:run_inversion``) so a caller above this layer can hand in its own (the
CLI's closed loop, ``diagnosis.closed_loop:invert_closed_loop``) without this module
importing it.  Workers of an existing cluster must have eroad installed.
"""
from __future__ import annotations

import importlib
import os
import time as _time
from pathlib import Path

from eroad.dask_client import dask_client
from eroad.errors import EroadInputError

__all__ = ["invert_many", "run_folder_names", "DEFAULT_RUNNER", "BATCH_FILE"]

#: the function run per drive
DEFAULT_RUNNER = "inverse.run:run_inversion"
#: the batch's record under ROOT
BATCH_FILE = "batch.json"


def run_folder_names(datasets) -> list:
    """Run folder names under ROOT: each dataset folder's name; duplicates refused (one line)."""
    names = [Path(os.path.abspath(d)).name for d in datasets]    # "." named, symlinks not followed
    seen = {}
    for d, n in zip(datasets, names):
        if n in seen:
            raise EroadInputError(f"{seen[n]} and {d}: two datasets with the folder name {n!r}; "
                                  "their run folders under --out would collide (rename one)")
        seen[n] = d
    return names


def silent(message: str) -> None:
    """A progress callback that says nothing (runners' progress lines stay in the worker)."""


def _resolve(ref: str):
    mod, _, name = ref.partition(":")
    return getattr(importlib.import_module(mod), name)


def one_line(exc: BaseException) -> str:
    """An exception as one line: the message of an EroadInputError, else ``Type: message``."""
    msg = " ".join(str(exc).split())
    if isinstance(exc, EroadInputError):
        return msg or type(exc).__name__
    return f"{type(exc).__name__}: {msg}" if msg else type(exc).__name__


def _invert_one(runner: str, dataset: str, out: str, kwargs: dict, argv: list) -> dict:
    """Run one drive (in a worker); never raises: a failure is returned with its one line."""
    from eroad.archive import finish_run_info, run_info, write_run_json

    t0 = _time.perf_counter()
    out_p = Path(out)
    existed = out_p.exists() and (not out_p.is_dir() or any(out_p.iterdir()))
    record = run_info("invert", run_id=out_p.name, command=argv, seed=kwargs.get("seed"))
    try:
        summary = _resolve(runner)(dataset, out, argv=argv, **kwargs)
    except Exception as exc:   # noqa: BLE001 - every failure is reported, the batch goes on
        line = one_line(exc)
        if not existed:       # an archived record of the failure; never over an existing folder
            try:
                out_p.mkdir(parents=True, exist_ok=True)
                write_run_json(out_p, finish_run_info(record, "failed", wall_s=_time.perf_counter() - t0,
                                                      error=exc))
            except OSError:
                pass
        return {"dataset": dataset, "run": out, "status": "failed", "error": line,
                "wall_s": _time.perf_counter() - t0}
    from inverse.report import class_label

    segs = summary.get("segments", [])
    e = summary.get("errors", {})
    return {"dataset": dataset, "run": out, "status": "complete", "error": None,
            "wall_s": _time.perf_counter() - t0, "classes": [class_label(s) for s in segs],
            "fit_quality": summary.get("fit_quality", {}).get("status"),
            "rms_err": {c: v.get("rms_err") for c, v in e.items() if c.startswith("axle_acc_")}}


def invert_many(datasets, root, *, scheduler=None, n_workers: int = 2, runner: str = DEFAULT_RUNNER,
                argv=None, report=None, connect_timeout: float = 20.0, **kwargs) -> list:
    """Invert every dataset into ``root/<name>`` on a Dask cluster; one result per drive.

    Parameters
    ----------
    datasets : sequence of str or Path
        Dataset folders (their folder names must differ).
    root : str or Path
        Folder of the run folders (created; may exist).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``); default a new
        ``LocalCluster`` of ``n_workers`` processes.
    n_workers : int
        Local worker processes (ignored with ``scheduler``); 0 or 1: the drives one after
        the other in this process, no Dask (the sweeps' convention).
    runner : str
        ``"module:function"`` run per drive as ``function(dataset, out, argv=..., **kwargs)``,
        returning the run's summary dict.
    argv : list of str, optional
        Command line recorded in each run.json.
    report : callable, optional
        Called with each drive's result as it finishes (the CLI prints one line).
    connect_timeout : float
        Seconds to wait for an existing scheduler (the sweeps' 20 s).
    **kwargs
        Passed to the runner (``workers`` is set to 1: each drive runs serially).

    Returns
    -------
    list of dict
        Per dataset, in the given order: ``dataset``, ``run``, ``status``
        (``complete``/``failed``), ``error`` (one line or None), ``wall_s``, and for a
        complete run ``classes``, ``fit_quality``, ``rms_err`` (Table 2's medians).
        Also written to ``root/batch.json``.
    """
    datasets = [str(d) for d in datasets]
    if not datasets:
        raise EroadInputError("eroad invert: no dataset given")
    if not (isinstance(n_workers, int) and n_workers >= 0):
        raise EroadInputError(f"--workers must be an integer >= 0, got {n_workers!r}")
    root = Path(root)
    if root.exists() and not root.is_dir():
        raise EroadInputError(f"{root}: exists and is not a folder")
    names = run_folder_names(datasets)
    kwargs = {**kwargs, "workers": 1}
    argv = list(argv) if argv is not None else ["invert_many"]
    t0 = _time.perf_counter()
    results = [None] * len(datasets)
    if scheduler is None and n_workers <= 1:      # serial, no Dask: the same function per drive
        root.mkdir(parents=True, exist_ok=True)
        for i, (d, n) in enumerate(zip(datasets, names)):
            results[i] = _invert_one(runner, d, str(root / n), kwargs, argv)
            if report is not None:
                report(results[i])
        return _record(root, results, argv, "serial (no Dask)", t0)
    with dask_client(scheduler, n_workers=n_workers, connect_timeout=connect_timeout) as client:
        from distributed import as_completed

        root.mkdir(parents=True, exist_ok=True)

        futures = {client.submit(_invert_one, runner, d, str(root / n), kwargs, argv, pure=False): i
                   for i, (d, n) in enumerate(zip(datasets, names))}
        try:
            for fut in as_completed(list(futures), loop=client.loop):
                i = futures.pop(fut)
                try:
                    r = fut.result()
                except Exception as exc:   # noqa: BLE001 - a worker lost: that drive fails, not the batch
                    r = {"dataset": datasets[i], "run": str(root / names[i]), "status": "failed",
                         "error": one_line(exc), "wall_s": None}
                results[i] = r
                if report is not None:
                    report(r)
        finally:
            if futures:
                client.cancel(list(futures))
    return _record(root, results, argv, scheduler or f"LocalCluster({n_workers} workers)", t0)


def _record(root: Path, results: list, argv: list, where: str, t0: float) -> list:
    """Write ``root/batch.json`` (every drive's outcome) and return ``results``."""
    from eroad.archive import write_json_atomic

    record = {"command": argv, "scheduler": where, "wall_s": round(_time.perf_counter() - t0, 3),
              "n_complete": sum(r["status"] == "complete" for r in results),
              "n_failed": sum(r["status"] == "failed" for r in results),
              "runs": [{**r, "run": Path(r["run"]).name} for r in results]}
    write_json_atomic(root / BATCH_FILE, record)
    return results
