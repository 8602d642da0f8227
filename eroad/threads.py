"""Process pools with one BLAS thread per worker.

numpy and scipy each load an OpenBLAS that starts one thread per core.  eroad runs its
parallel work in processes (Exudyn holds the GIL), so on a 2-core machine two workers
each with two BLAS threads put four busy threads on two cores: after every matrix
product the idle BLAS threads spin for a while and take the core from the other worker.
Measured on the embedded drive (``eroad invert``, luliang, 2 workers, 3 runs each, same
machine and session): 8.3-8.5 s with the default threads, 6.4-6.7 s with one BLAS
thread per worker; with one also in the main process no further gain (6.4-6.7 s).
Dask's worker processes already get one (its nanny sets ``OPENBLAS_NUM_THREADS=1``);
this module does the same for the ``concurrent.futures`` pools.

``threadpoolctl`` sets the limit at run time in the worker, which an environment
variable cannot (the workers are forked from a process that has loaded OpenBLAS).
"""
from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor


def limit_blas_threads(n: int = 1) -> None:
    """Limit every BLAS loaded in this process (numpy's and scipy's OpenBLAS) to ``n``
    threads, for the rest of the process's life."""
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=int(n), user_api="blas")


def _init_worker(then) -> None:
    limit_blas_threads(1)
    if then is not None:
        then()


def process_pool(workers: int, initializer=None) -> ProcessPoolExecutor:
    """A ``ProcessPoolExecutor`` of ``workers`` processes whose workers run with one BLAS
    thread; ``initializer`` (picklable, no arguments) runs after that in each worker."""
    return ProcessPoolExecutor(int(workers), initializer=_init_worker, initargs=(initializer,))
