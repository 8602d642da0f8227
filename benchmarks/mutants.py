"""Measure the test suite's power: apply each listed mutant to a copy of the repository and
check that the named default (not slow) tests fail on it.

Mutants are listed in ``tests/mutants/*.toml``::

    [[mutant]]
    name = "quarter FRF: sprung mass x1.5"
    file = "inverse/quarter.py"          # path relative to the repository root
    old = "exact text, found exactly once in the file"
    new = "its replacement"
    tests = ["tests/test_inverse_quarter.py::test_frf_against_independent_ode"]

For each mutant the script copies the tracked files (``git ls-files``) into a temporary
folder, replaces ``old`` by ``new`` (refusing a mutant whose ``old`` is not found exactly
once: a stale list must not pass silently), runs ``python -m pytest -q`` on its tests in
that copy (the copy comes first on ``sys.path``, ahead of the editable install) and
records CAUGHT when pytest exits non-zero because a test failed, MISSED when every test
passed. Before the mutants, the same tests run on an unmutated copy and must pass:
a test that fails anyway catches nothing.

Usage::

    python benchmarks/mutants.py              # every mutant, table on stdout
    python benchmarks/mutants.py -k quarter   # mutants whose name contains "quarter"

Exit status 0 when every mutant is caught, 1 otherwise. The table is the one quoted in
``tests/mutants.md``.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def load_mutants(folder: Path) -> list[dict]:
    out = []
    for f in sorted(folder.glob("*.toml")):
        for m in tomllib.loads(f.read_text()).get("mutant", []):
            missing = {"name", "file", "old", "new", "tests"} - set(m)
            if missing:
                raise SystemExit(f"mutants: {f.name}: mutant {m.get('name', '?')!r} lacks {sorted(missing)}")
            m["source"] = f.name
            out.append(m)
    return out


def copy_repo(dst: Path) -> None:
    files = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, check=True,
                           capture_output=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        src = ROOT / rel
        if not src.is_file():  # deleted in the work tree but still tracked
            continue
        target = dst / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, target)


def run_tests(copy: Path, tests: list[str]) -> tuple[int, float, str]:
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1")
    env["PYTHONPATH"] = str(copy) + os.pathsep + env.get("PYTHONPATH", "")
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *tests],
                       cwd=copy, env=env, capture_output=True, text=True)
    last = (p.stdout.strip().splitlines() or [""])[-1]
    return p.returncode, time.perf_counter() - t0, last


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-k", default="", help="only mutants whose name contains this text")
    args = ap.parse_args(argv)
    mutants = [m for m in load_mutants(ROOT / "tests" / "mutants") if args.k.lower() in m["name"].lower()]
    if not mutants:
        print("mutants: none selected")
        return 1
    rows, all_caught = [], True
    with tempfile.TemporaryDirectory(prefix="eroad-mutants-") as tmp:
        clean = Path(tmp) / "clean"
        copy_repo(clean)
        tests = sorted({t for m in mutants for t in m["tests"]})
        rc, dt, last = run_tests(clean, tests)
        if rc != 0:
            print(f"mutants: the tests fail on the unmutated copy ({last}); fix them first")
            return 1
        print(f"unmutated: {len(tests)} test ids pass ({dt:.0f} s)")
        for i, m in enumerate(mutants):
            work = Path(tmp) / f"m{i}"
            shutil.copytree(clean, work)
            path = work / m["file"]
            text = path.read_text()
            n = text.count(m["old"])
            if n != 1:
                rows.append((m["name"], m["file"], "STALE", f"old text found {n} times", 0.0))
                all_caught = False
                continue
            path.write_text(text.replace(m["old"], m["new"]))
            rc, dt, last = run_tests(work, m["tests"])
            status = "CAUGHT" if rc == 1 else ("MISSED" if rc == 0 else f"ERROR rc={rc}")
            all_caught &= status == "CAUGHT"
            rows.append((m["name"], m["file"], status, ", ".join(m["tests"]), dt))
            shutil.rmtree(work, ignore_errors=True)
            print(f"[{i + 1}/{len(mutants)}] {status:7s} {m['name']}  ({dt:.0f} s)", flush=True)
    print()
    print("| mutant | file | result | caught by | s |")
    print("|---|---|---|---|---|")
    for name, f, status, tests_, dt in rows:
        print(f"| {name} | `{f}` | {status} | {tests_} | {dt:.0f} |")
    caught = sum(r[2] == "CAUGHT" for r in rows)
    print(f"\n{caught} of {len(rows)} mutants caught")
    return 0 if all_caught else 1


if __name__ == "__main__":
    sys.exit(main())
