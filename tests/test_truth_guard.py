"""Nothing that estimates, fits or diagnoses reads a dataset's ``truth/``.

Synthetic datasets carry ``truth/`` (the road, the clean channels, the truth vehicle) for
scoring; ``eroad invert`` and ``eroad diagnose`` must never open it.  A copy-without-truth
comparison (tests/test_inverse_cli.py, tests/test_diagnosis_cli.py) only shows that the
answer does not depend on it; a read whose result is discarded, or that fails silently
when the folder is missing, passes that check.  Here every read of a path inside the
dataset's ``truth/`` raises during the run and is recorded (so a read inside a
``try/except`` is still seen):

* the Python-level openers are wrapped: ``builtins.open``/``io.open``, ``os.open``,
  ``pathlib.Path.open/read_text/read_bytes``, ``numpy.load/loadtxt/genfromtxt/fromfile``,
  ``pandas.read_csv``, ``tomllib.load``, ``json.load`` (a file object is judged by its
  ``name``);
* an audit hook (``sys.addaudithook``, PEP 578) catches every ``open`` event of the
  interpreter (``io.FileIO`` and C extensions opening through Python's io included) and
  the listing of ``truth/`` itself (``os.listdir``, ``os.scandir``).  Audit hooks cannot
  be removed, so the hook is installed once and does nothing while no guard is active.

A path is inside ``truth/`` when its real path (``os.path.realpath``: relative paths,
``..`` and symbolic links resolved) is ``DATASET/truth`` or below it.  Asking whether the
folder exists (``stat``) is not a read and is allowed.  Permissions are not used: the
tests may run as root, which reads anything.
"""
import builtins
import functools
import io
import json
import os
import pathlib
import sys
import time
import tomllib
from contextlib import contextmanager

import numpy as np
import pandas as pd
import pytest


class TruthRead(AssertionError):
    """A read of a dataset's truth/ inside a guarded block."""


#: active guards: (real path of DATASET/truth, list of recorded reads)
_GUARDS: list = []


def _name_of(obj):
    """The path an opener is given: str, bytes or PathLike, else a file object's ``name``."""
    if isinstance(obj, (str, bytes, os.PathLike)):
        return obj
    return getattr(obj, "name", None)


def _check(obj, what):
    if not _GUARDS:
        return
    p = _name_of(obj)
    if p is None or isinstance(p, int):          # file descriptors: opened elsewhere, checked there
        return
    try:
        p = os.fsdecode(os.fspath(p))
    except TypeError:
        return
    rp = os.path.realpath(p)
    for truth, hits in _GUARDS:
        if rp == truth or rp.startswith(truth + os.sep):
            hits.append((what, p))
            raise TruthRead(f"{what}({p!r}): truth/ must not be read by estimation code")


def _audit(event, args):
    if _GUARDS and event in ("open", "os.listdir", "os.scandir") and args:
        _check(args[0], event)


sys.addaudithook(_audit)


def _wrap(fn, what):
    @functools.wraps(fn)
    def guarded(*a, **k):
        target = a[0] if a else next(iter(k.values()), None)
        _check(target, what)
        return fn(*a, **k)
    return guarded


#: (owner, attribute) of the openers wrapped while a guard is active
OPENERS = [(builtins, "open"), (io, "open"), (os, "open"), (pathlib.Path, "open"),
           (pathlib.Path, "read_text"), (pathlib.Path, "read_bytes"), (np, "load"),
           (np, "loadtxt"), (np, "genfromtxt"), (np, "fromfile"), (pd, "read_csv"),
           (tomllib, "load"), (json, "load")]


@contextmanager
def truth_guard(dataset, monkeypatch):
    """Inside the block any read of ``dataset/truth`` raises :class:`TruthRead`; yields the
    list of the reads attempted (what, path)."""
    entry = (os.path.realpath(os.path.join(os.fspath(dataset), "truth")), [])
    with monkeypatch.context() as mp:
        for owner, name in OPENERS:
            mp.setattr(owner, name, _wrap(getattr(owner, name), f"{owner.__name__}.{name}"))
        _GUARDS.append(entry)
        try:
            yield entry[1]
        finally:
            _GUARDS.remove(entry)


@pytest.fixture
def toy_dataset(tmp_path):
    """A folder shaped like a dataset, with one file of each kind in truth/."""
    ds = tmp_path / "ds"
    (ds / "truth").mkdir(parents=True)
    (ds / "channels.csv").write_text("time,x\n0,1\n0.1,2\n")
    (ds / "meta.toml").write_text('[dataset]\nname = "d"\n')
    (ds / "truthful.txt").write_text("not the truth folder")     # a name, not a component
    t = ds / "truth"
    (t / "truth.json").write_text('{"w": 2.0}')
    (t / "scenario.toml").write_text("a = 1\n")
    (t / "channels_clean.csv").write_text("time,x\n0,1\n")
    np.save(t / "road.npy", np.arange(3.0))
    np.savez(t / "road.npz", z=np.arange(3.0))
    np.arange(3.0).tofile(t / "raw.bin")
    (tmp_path / "link.json").symlink_to(t / "truth.json")
    return ds


def test_guard_blocks_every_way_of_reading_truth(toy_dataset, monkeypatch):
    """Proof that the guard works: inside it, each of these reads of truth/ raises and is
    recorded (a read whose exception is swallowed too), by path, relative path with ``..``,
    symbolic link from outside, and through a file object opened before the block; the
    dataset's other files (and a file whose name merely starts with "truth") stay readable;
    after the block truth/ is readable again."""
    ds = toy_dataset
    t = ds / "truth"
    monkeypatch.chdir(ds)
    fp_toml = open(t / "scenario.toml", "rb")          # opened before the guard
    fp_json = open(t / "truth.json")
    reads = [
        lambda: open(t / "truth.json"),
        lambda: io.open(str(t / "truth.json"), "rb"),
        lambda: os.open(t / "truth.json", os.O_RDONLY),
        lambda: io.FileIO(str(t / "truth.json")),             # only the audit hook sees this
        lambda: (t / "truth.json").read_text(),
        lambda: (t / "truth.json").read_bytes(),
        lambda: (t / "truth.json").open(),
        lambda: np.load(t / "road.npy"),
        lambda: np.load(t / "road.npz")["z"],
        lambda: np.loadtxt(t / "channels_clean.csv", delimiter=",", skiprows=1),
        lambda: np.genfromtxt(t / "channels_clean.csv", delimiter=","),
        lambda: np.fromfile(t / "raw.bin"),
        lambda: pd.read_csv(t / "channels_clean.csv"),
        lambda: pd.read_csv(str(t / "channels_clean.csv"), engine="python"),
        lambda: tomllib.load(fp_toml),
        lambda: json.load(fp_json),
        lambda: open("truth/../truth/truth.json"),             # relative, with ..
        lambda: open(ds.parent / "link.json"),                 # a symbolic link into truth/
        lambda: os.listdir(t),
        lambda: list(os.scandir("truth")),
        lambda: list(t.iterdir()),
    ]
    with truth_guard(ds, monkeypatch) as hits:
        for i, read in enumerate(reads):
            with pytest.raises(TruthRead):
                read()
            assert len(hits) >= i + 1, i
        n = len(hits)
        try:                                                   # a read that hides its failure
            (t / "truth.json").read_text()
        except Exception:
            pass
        assert len(hits) == n + 1
        # what a reader may touch
        assert pd.read_csv(ds / "channels.csv").shape == (2, 2)
        assert tomllib.loads((ds / "meta.toml").read_text())["dataset"]["name"] == "d"
        with open(ds / "truthful.txt") as f:
            assert f.read() == "not the truth folder"
        assert (t / "truth.json").is_file()                    # stat is not a read
        assert len(hits) == n + 1
    fp_toml.close()
    fp_json.close()
    assert json.loads((t / "truth.json").read_text()) == {"w": 2.0}   # the guard is scoped


@pytest.fixture(scope="module")
def drive_with_truth(tmp_path_factory):
    """A 16 s synthetic drive (null scenario, seed 3, leaf friction 4 kN) with its truth/."""
    from drives.synth import synth_command

    out = tmp_path_factory.mktemp("guard") / "lf"
    synth_command(scenario="null", seed=3, effects=["leaf_friction=4000"], duration=16.0, out=out)
    return out


def test_invert_and_diagnose_never_read_truth(drive_with_truth, tmp_path, monkeypatch, capsys):
    """``eroad invert`` and ``eroad diagnose`` through the command line, in-process (one
    worker, so every read happens in this process), on a dataset whose truth/ holds the
    road, the clean channels and the truth vehicle: no read of truth/ is attempted (none
    raised, none recorded) and both runs complete.  The cheapest configurations that run
    the whole reading and fitting path: invert with K = 1, one fit iteration, the fit's own
    phases (``--candidates 0``); diagnose ``--quick`` with one candidate effect.  About
    8 s and 15 s here."""
    from eroad.cli import main

    ds = drive_with_truth
    assert len(list((ds / "truth").iterdir())) >= 3                  # there is a truth to read
    with truth_guard(ds, monkeypatch) as hits:
        t0 = time.perf_counter()
        rc_inv = main(["invert", str(ds), "--out", str(tmp_path / "inv"), "--segments", "1",
                       "--workers", "1", "--max-iter", "1", "--candidates", "0"])
        t1 = time.perf_counter()
        rc_diag = main(["diagnose", str(ds), "--out", str(tmp_path / "diag"), "--quick",
                        "--effects", "sensor", "--workers", "1"])
        t2 = time.perf_counter()
    print(f"invert {t1 - t0:.1f} s, diagnose {t2 - t1:.1f} s")
    assert hits == []
    assert rc_inv == 0 and rc_diag == 0
    assert json.loads((tmp_path / "inv" / "summary.json").read_text())["segments"]
    assert json.loads((tmp_path / "diag" / "summary.json").read_text())["verdict"]
