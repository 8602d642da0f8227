"""Sweeps on dask.distributed with a resumable cache (studies.sweep).

The cache tests run serially (fast, in-process counters); the dask tests use
one 2-worker LocalCluster each with the small Exudyn reference case
(``mass_spring_case`` with 2000 steps, a few ms per case) and check that no
worker process is left behind.
"""
import hashlib
import json

import numpy as np
import psutil
import pytest

from eroad.errors import EroadInputError
from studies.sweep import (case_key, code_version_of, dask_client, mass_spring_case,
                           resolve_function, run_cases)

MSC = "studies.sweep:mass_spring_case"

# --- an in-process case function with a call counter and a fault switch -------
CALLS = []
FAIL_AT = set()


def counted_case(case):
    """Test case: counts calls, raises for case["i"] in FAIL_AT, returns an
    array result for even i (-> .npz) and scalars for odd i (-> .json)."""
    if case["i"] in FAIL_AT:
        raise RuntimeError(f"simulated failure at {case['i']}")
    CALLS.append(case["i"])
    out = {"square": case["i"] ** 2, "label": f"case-{case['i']}", "nan": float("nan"),
           "tuple": (1, 2)}
    if case["i"] % 2 == 0:
        out["series"] = np.arange(case["i"] + 1, dtype=float) / 3.0
    return out


@pytest.fixture(autouse=True)
def _reset():
    CALLS.clear()
    FAIL_AT.clear()
    yield
    CALLS.clear()
    FAIL_AT.clear()


def _workers():
    """Live worker processes of this test process (multiprocessing's
    resource tracker is a per-interpreter singleton that lives until exit and
    is not a worker)."""
    out = []
    for p in psutil.Process().children(recursive=True):
        try:
            if p.status() != psutil.STATUS_ZOMBIE and "spawn_main" in " ".join(p.cmdline()):
                out.append(p)
        except psutil.NoSuchProcess:
            pass
    return out


# --- keys ------------------------------------------------------------------
def test_case_key_follows_documented_recipe():
    """Key = sha256 of canonical JSON (sorted keys, compact) [:32]; independent
    of key order and numpy scalar types; 1 and 1.0 differ; function and code
    version are part of it."""
    case = {"b": 2.5, "a": [1, 2], "name": "x"}
    text = json.dumps({"case": {"a": [1, 2], "b": 2.5, "name": "x"}, "code": "v1",
                       "format": 1, "func": "m:f"}, sort_keys=True, separators=(",", ":"))
    assert case_key(case, "m:f", "v1") == hashlib.sha256(text.encode()).hexdigest()[:32]
    assert case_key({"name": "x", "a": (1, 2), "b": np.float64(2.5)}, "m:f", "v1") == \
        case_key(case, "m:f", "v1")
    assert case_key({"k": 1}, "m:f", "v1") != case_key({"k": 1.0}, "m:f", "v1")
    assert case_key(case, "m:g", "v1") != case_key(case, "m:f", "v1")
    assert case_key(case, "m:f", "v2") != case_key(case, "m:f", "v1")


def test_function_references():
    fn, name = resolve_function(MSC)
    assert fn is mass_spring_case and name == MSC
    assert resolve_function(counted_case)[1] == f"{__name__}:counted_case"
    assert code_version_of(MSC) == code_version_of(mass_spring_case)
    assert code_version_of(MSC).startswith("eroad-")
    with pytest.raises(TypeError):
        resolve_function(lambda c: c)
    for bad in ("nocolon", "studies.sweep:nope", "no_such_module_x:f"):
        with pytest.raises(EroadInputError):
            resolve_function(bad)


# --- serial: cache, resume, duplicates ---------------------------------------
def test_interrupted_sweep_resumes_without_recomputing(tmp_path):
    """A failure at case 5 stops the sweep (re-raised with the case named);
    cases 0-4 are cached; the rerun computes only 5-7; deleting two cache
    files recomputes exactly those two."""
    cases = [{"i": i} for i in range(8)]
    FAIL_AT.add(5)
    with pytest.raises(RuntimeError, match="simulated failure") as info:
        run_cases(counted_case, cases, tmp_path, n_workers=0, progress=False)
    assert any('"i":5' in note for note in info.value.__notes__)
    assert CALLS == [0, 1, 2, 3, 4]
    FAIL_AT.clear()
    CALLS.clear()
    res = run_cases(counted_case, cases, tmp_path, n_workers=1, progress=False)
    assert CALLS == [5, 6, 7] and res.computed == [5, 6, 7] and res.cached == [0, 1, 2, 3, 4]
    assert len(list(tmp_path.glob("*.npz"))) == 4 and len(list(tmp_path.glob("*.json"))) == 4

    for i in (2, 7):
        next(tmp_path.glob(f"{res.keys[i]}.*")).unlink()
    CALLS.clear()
    again = run_cases(counted_case, cases, tmp_path, n_workers=0, progress=False)
    assert CALLS == [2, 7] and again.n_computed == 2 and again.n_cached == 6
    # computed and cached results are the same objects (JSON-normalised)
    for a, b in zip(res.results, again.results):
        assert a.keys() == b.keys()
        for k in a:
            if isinstance(a[k], np.ndarray):
                assert np.array_equal(a[k], b[k]) and a[k].dtype == b[k].dtype
            elif k == "nan":
                assert np.isnan(a[k]) and np.isnan(b[k])
            else:
                assert a[k] == b[k]
    assert again[3]["tuple"] == [1, 2] and again[3]["square"] == 9
    df = again.to_dataframe()
    assert list(df["square"]) == [i * i for i in range(8)] and "series" not in df


def test_duplicates_and_damaged_cache(tmp_path, caplog):
    cases = [{"i": 1}, {"i": 2}, {"i": 1}]
    res = run_cases(counted_case, cases, tmp_path, n_workers=0, progress=False)
    assert CALLS == [1, 2] and res.computed == [0, 1, 2] and res[2] == res[0]
    (tmp_path / f"{res.keys[1]}.npz").write_bytes(b"not an npz")
    CALLS.clear()
    res2 = run_cases(counted_case, cases, tmp_path, n_workers=0, progress=False)
    assert CALLS == [2] and res2.cached == [0, 2]
    assert "unreadable" in caplog.text
    assert np.array_equal(res2[1]["series"], np.arange(3) / 3.0)


def test_code_version_invalidates(tmp_path):
    run_cases(counted_case, [{"i": 1}], tmp_path, n_workers=0, progress=False,
              code_version="a")
    run_cases(counted_case, [{"i": 1}], tmp_path, n_workers=0, progress=False,
              code_version="a")
    run_cases(counted_case, [{"i": 1}], tmp_path, n_workers=0, progress=False,
              code_version="b")
    assert CALLS == [1, 1]


def test_bad_cases_and_results(tmp_path):
    with pytest.raises(EroadInputError, match="case 1"):
        run_cases(counted_case, [{"i": 1}, {"i": object()}], tmp_path, n_workers=0,
                  progress=False)
    with pytest.raises(EroadInputError, match="unknown parameter 'springs'"):
        run_cases(MSC, [{"springs": 2}], tmp_path, n_workers=0, progress=False)


# --- dask -----------------------------------------------------------------
def test_dask_matches_serial_and_resumes(tmp_path, capsys):
    """LocalCluster (2 processes) and serial fallback give bitwise identical
    results (same code, deterministic solver); a client reused for a second
    sweep computes only the deleted cases; connecting by scheduler address
    works; no worker process survives the context."""
    cases = [{"stiffness": 1e4 * (1 + i), "steps": 2000, "t_end": 0.5} for i in range(6)]
    serial = run_cases(MSC, cases, tmp_path / "serial", n_workers=0, progress=False)
    with dask_client(n_workers=2) as client:
        assert len(_workers()) == 2
        par = run_cases(MSC, cases, tmp_path / "dask", scheduler=client, progress=True)
        assert par.n_computed == 6
        for i in (1, 4):
            (tmp_path / "dask" / f"{par.keys[i]}.npz").unlink()
        again = run_cases(MSC, cases, tmp_path / "dask", scheduler=client, progress=False)
        assert again.computed == [1, 4] and again.n_cached == 4
        by_address = run_cases(MSC, cases[:2] + [{"steps": 100}], tmp_path / "dask",
                               scheduler=client.scheduler.address, progress=False)
        assert by_address.computed == [2]
        assert len(client.scheduler_info()["workers"]) == 2
    assert "6/6" in capsys.readouterr().err          # progress bar on stderr
    for a, b, c in zip(serial.results, par.results, again.results):
        assert np.array_equal(a["z"], b["z"]) and np.array_equal(a["z"], c["z"])
        assert a["z_final"] == b["z_final"] == c["z_final"]
    assert _workers() == []


def test_dask_default_cluster_and_error(tmp_path):
    """Default path (new LocalCluster per call); a failing case is re-raised in
    the client as its own type with the case named; finished cases stay cached
    and the cluster is closed."""
    cases = [{"steps": 500}, {"mass": -1.0}, {"steps": 600}]
    with pytest.raises(EroadInputError, match="must be positive") as info:
        run_cases(MSC, cases, tmp_path, n_workers=2, progress=False)
    assert any("sweep case 1" in note for note in info.value.__notes__)
    assert _workers() == []
    n_files = len(list(tmp_path.glob("*.npz")))      # cases that finished before the error
    ok = run_cases(MSC, [cases[0], cases[2]], tmp_path, n_workers=0, progress=False)
    assert ok.n_cached == n_files and ok.n_computed == 2 - n_files
    assert ok.results[0]["steps"] == 500


def test_unreachable_scheduler_is_one_line_error():
    with pytest.raises(EroadInputError, match="cannot connect"):
        with dask_client("tcp://127.0.0.1:9", connect_timeout=0.5):
            pass
