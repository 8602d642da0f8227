"""A quiet Dask client for eroad's parallel work (sweeps, many inversions).

What it is for: one place that starts a ``distributed.Client`` on a new
``LocalCluster`` (worker processes, one thread each, no dashboard, quiet logs) or
connects to an existing scheduler, for :mod:`studies.sweep` and :mod:`inverse.batch`
alike -- it sits at the bottom of the layers so both can use it.  What it is not: a
scheduler of its own or a place for case logic.
"""
from __future__ import annotations

import contextlib
import logging
import os
from typing import Any, Iterator

from distributed.diagnostics.plugin import WorkerPlugin

from eroad.errors import EroadInputError

__all__ = ["dask_client", "quiet_distributed"]


@contextlib.contextmanager
def quiet_distributed(level: int = logging.ERROR) -> Iterator[None]:
    """Raise the level of the ``distributed`` loggers (and their stream
    handlers) in this process for the duration of the block."""
    logger = logging.getLogger("distributed")
    old_level = logger.level
    handlers = [(h, h.level) for h in logger.handlers if isinstance(h, logging.StreamHandler)]
    logger.setLevel(level)
    for h, _ in handlers:
        h.setLevel(level)
    try:
        yield
    finally:
        logger.setLevel(old_level)
        for h, lv in handlers:
            h.setLevel(lv)


class _QuietWorkerLogs(WorkerPlugin):
    """Worker plugin: ``distributed.worker`` logs only CRITICAL messages (the
    "Compute Failed" report of a case that raised is re-raised by
    :func:`run_cases` in the client anyway).  Also applied to restarted
    workers."""

    def setup(self, worker) -> None:  # noqa: D102 - WorkerPlugin hook
        logging.getLogger("distributed.worker").setLevel(logging.CRITICAL)


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, n_workers: int = 2,
                connect_timeout: float = 20.0) -> Iterator[Any]:
    """A quiet ``distributed.Client``, closed (with its cluster) on exit.

    Parameters
    ----------
    scheduler : str, optional
        Address of an existing scheduler (``"tcp://host:8786"``).  Default: a
        new ``LocalCluster`` with ``n_workers`` worker processes, one thread
        each, no dashboard, scheduler and HTTP server on free ports, worker
        logs at ERROR level.
    n_workers : int, optional
        Number of local worker processes (default 2; ignored with
        ``scheduler``).
    connect_timeout : float, optional
        Seconds to wait for an existing scheduler (default 20 s).

    Yields
    ------
    distributed.Client
        Not set as the global default client.

    Raises
    ------
    eroad.errors.EroadInputError
        If the scheduler cannot be reached.

    Notes
    -----
    Reuse one client for several :func:`run_cases` calls (pass it as
    ``scheduler=client``) to pay the cluster start-up (about 1 s) once.
    Workers of an existing cluster must have eroad installed (they import the
    case function by name).
    """
    import dask
    from distributed import Client, LocalCluster

    # worker processes read this at import (environment is inherited)
    env = {"DASK_LOGGING__DISTRIBUTED": "error"}
    old_env = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        with contextlib.ExitStack() as stack:
            stack.enter_context(quiet_distributed())
            stack.enter_context(dask.config.set({"logging.distributed": "error"}))
            if scheduler is None:
                if n_workers < 1:
                    raise ValueError(f"n_workers must be >= 1, got {n_workers}")
                cluster = stack.enter_context(LocalCluster(
                    n_workers=n_workers, threads_per_worker=1, processes=True,
                    # HTTP server on a free port, no dashboard: a fixed :8787 would
                    # warn when another cluster on the host already holds it
                    dashboard_address=":0", scheduler_kwargs={"dashboard": False},
                    silence_logs=logging.ERROR))
                client = stack.enter_context(Client(cluster, set_as_default=False))
                # a failing case is re-raised by run_cases; the worker need not log it too
                client.register_plugin(_QuietWorkerLogs(), name="eroad-quiet-logs")
            else:
                try:
                    client = Client(scheduler, timeout=connect_timeout, set_as_default=False)
                except (OSError, TimeoutError, ValueError) as exc:
                    raise EroadInputError(f"--scheduler {scheduler}: cannot connect "
                                          f"({type(exc).__name__}: {exc})") from None
                stack.enter_context(client)
            yield client
    finally:
        for k, v in old_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
