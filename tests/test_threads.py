"""eroad.threads: the process pools' workers run with one BLAS thread."""
import os

from eroad.threads import process_pool


def _blas_threads():
    from threadpoolctl import threadpool_info

    return [d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas"]


def _mark():
    os.environ["EROAD_TEST_WORKER_INIT"] = "ran"


def _marked():
    return os.environ.get("EROAD_TEST_WORKER_INIT")


def test_workers_have_one_blas_thread_and_run_the_initializer():
    import numpy  # noqa: F401  (numpy's OpenBLAS loaded before the fork, as in eroad's runs)

    with process_pool(2, initializer=_mark) as pool:
        threads = pool.submit(_blas_threads).result()
        marked = pool.submit(_marked).result()
    assert threads, "no BLAS found in the worker"
    assert all(n == 1 for n in threads), threads
    assert marked == "ran"


def test_a_plain_pool_would_have_more_on_this_machine():
    """The check above can fail: without the limit a worker has one BLAS thread per core
    (skipped where this process has one already, e.g. on a 1-core machine)."""
    from concurrent.futures import ProcessPoolExecutor

    import pytest

    if max(_blas_threads(), default=1) < 2:
        pytest.skip("this process has one BLAS thread already (one core, or set from outside)")
    with ProcessPoolExecutor(1) as pool:
        threads = pool.submit(_blas_threads).result()
    assert max(threads) > 1, threads
