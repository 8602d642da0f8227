"""Blind check of the reader's unit and plausibility checks on drives of three truth families.

For each family and seed a 20 s drive is made (``eroad synth --scenario FAMILY --seed S
--duration 20``, cached): ``null`` and ``random`` by our own Exudyn truck (random: leaf
friction and a flexible frame), ``second`` by the independently written truck
(``drives/independent_truck.py``: its own equations and integrator, anti-roll bars, cab
mounts, tyre lift-off), ``second_measured`` by the same truck on the measured road profile
(``../shared/data/iri/profile_1.txt``, shipped as drives/data/profile_1.txt). Each drive is then
written again in every unit error a logger or a user makes (the variants below, applied to
channels.csv or meta.toml of a copy) and read with ``drives.format.inspect_drive``, the
reader every command uses. The outcome per variant: ``refused`` (a fatal problem: one line,
non-zero exit), ``flagged`` (read, with a warning) or ``clean``.

What must hold: every unaltered drive ``clean`` (no false refusal, no warning), every
wrong-unit variant ``refused`` or at least ``flagged``; none ``clean``.

Usage::

    nice python benchmarks/bench_units.py --families null:6 random:6 second:10 second_measured:4 \
        --out results/units_blind/<date>-<what>

Writes ``cases.jsonl`` (one line per drive and variant) and ``summary.md`` in --out.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

G = 9.80665


def _acc(df, prefix, f):
    for c in df.columns:
        if c.startswith(prefix):
            df[c] = f(df[c])


def _scale_disp(k):
    def edit(df, meta):
        _acc(df, "susp_disp_", lambda x: x * k)
    return edit


def _speed(k):
    def edit(df, meta):
        df["speed"] = df["speed"] * k
    return edit


def _axle3_only_kmh(df, meta):
    for c in list(df.columns):
        if c not in ("time", "speed") and c[-2] != "3":
            del df[c]
    df["speed"] = df["speed"] * 3.6


def _meta_speed_kmh(df, meta):
    v = float(df["speed"].mean())
    del df["speed"]
    meta["speed_mps"] = v * 3.6


#: variant -> (edit of (channels frame, [dataset] table), is it a wrong-unit variant)
VARIANTS = {
    "unaltered": (lambda df, meta: None, False),
    "all accelerations in g": (lambda df, meta: _acc(df, ("axle_acc_", "body_acc_"), lambda x: x / G), True),
    "axle accelerations in g": (lambda df, meta: _acc(df, "axle_acc_", lambda x: x / G), True),
    "body accelerations in g": (lambda df, meta: _acc(df, "body_acc_", lambda x: x / G), True),
    "gravity left in (body)": (lambda df, meta: _acc(df, "body_acc_", lambda x: x + G), True),
    "gravity left in (axle, upside down)": (lambda df, meta: _acc(df, "axle_acc_", lambda x: x - G), True),
    "displacement in mm": (_scale_disp(1000.0), True),
    "displacement in cm": (_scale_disp(100.0), True),
    "accelerations in mm/s^2": (lambda df, meta: _acc(df, ("axle_acc_", "body_acc_"), lambda x: x * 1000.0), True),
    "speed in km/h": (_speed(3.6), True),
    "speed in mph": (_speed(1.0 / 0.44704), True),
    "speed 25 % high (wheel radius)": (_speed(1.25), True),
    "meta speed_mps in km/h": (_meta_speed_kmh, True),
    "axle 3 only, speed in km/h": (_axle3_only_kmh, True),
}


def make_variant(src: Path, dst: Path, edit) -> None:
    import tomllib

    from drives.format import _toml_dumps
    if dst.exists():
        shutil.rmtree(dst)
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("truth", "record"))
    df = pd.read_csv(dst / "channels.csv")
    doc = tomllib.loads((dst / "meta.toml").read_text())
    edit(df, doc["dataset"])
    df.to_csv(dst / "channels.csv", index=False, float_format="%.10g")
    (dst / "meta.toml").write_text(_toml_dumps(doc))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--families", nargs="+", default=["null:6", "random:6", "second:10", "second_measured:4"], help="FAMILY:N (seeds 1..N)")
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--duration", type=float, default=20.0, help="drive length [s]")
    ap.add_argument("--cache", default="/tmp/eroad-units-bench", help="where the synthetic drives go")
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    from drives.format import inspect_drive
    from drives.synth import synth_command
    from eroad.archive import finish_run_info, run_info, write_run_json

    out, cache = Path(args.out), Path(args.cache)
    out.mkdir(parents=True, exist_ok=True)
    cache.mkdir(parents=True, exist_ok=True)
    command = "nice python benchmarks/bench_units.py " + " ".join(argv if argv is not None else sys.argv[1:])
    record = run_info("units_benchmark", run_id=out.name, command=command, seed=None,
                      extra={"families": args.families, "duration_s": args.duration})
    write_run_json(out, record)
    t0 = time.perf_counter()
    rows = []
    jl = out / "cases.jsonl"
    jl.write_text("")
    for item in args.families:
        fam, _, n = item.partition(":")
        for seed in range(args.first_seed, args.first_seed + int(n or 1)):
            src = cache / f"{fam}-{seed}-{args.duration:g}s"
            if not (src / "channels.csv").is_file():
                synth_command(scenario=fam, seed=seed, duration=args.duration, out=src, force=True)
            road = "measured profile" if fam.endswith("_measured") else "synthetic"
            for name, (edit, wrong) in VARIANTS.items():
                dst = cache / "variants" / f"{fam}-{seed}" / name.replace(" ", "_").replace("/", "")
                make_variant(src, dst, edit)
                problems, drive = inspect_drive(dst)
                outcome = "refused" if problems else ("flagged" if drive.warnings else "clean")
                row = {"family": fam, "seed": seed, "road": road, "variant": name, "wrong_unit": wrong,
                       "outcome": outcome, "lines": problems or list(drive.warnings)}
                rows.append(row)
                with jl.open("a") as f:
                    f.write(json.dumps(row) + "\n")
            print(f"{fam} {seed}: " + ", ".join(f"{r['variant']}={r['outcome']}" for r in rows if r["family"] == fam
                                                and r["seed"] == seed), flush=True)
    write_md(rows, out / "summary.md", command)
    write_run_json(out, finish_run_info(record, "complete", wall_s=time.perf_counter() - t0))
    return 0


def write_md(rows: list, path: Path, command: str) -> None:
    fams = sorted({r["family"] for r in rows})
    lines = ["# Unit and plausibility checks on blind drives", "", f"Command: `{command}`", "",
             "Per variant and truth family: refused / flagged (read with a warning) / clean, out of the "
             "family's drives. Unaltered drives must be clean; every other variant must not.", "",
             "| variant | " + " | ".join(fams) + " |", "|---|" + "---|" * len(fams)]
    bad = []
    for v, (_, wrong) in VARIANTS.items():
        cells = []
        for fam in fams:
            rs = [r for r in rows if r["family"] == fam and r["variant"] == v]
            c = {k: sum(r["outcome"] == k for r in rs) for k in ("refused", "flagged", "clean")}
            cells.append(f"{c['refused']} / {c['flagged']} / {c['clean']}")
            bad += [r for r in rs if (r["outcome"] == "clean") == wrong]
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    lines += ["", f"Misses (a wrong-unit variant read clean, or an unaltered drive not clean): {len(bad)}", ""]
    for r in bad:
        lines.append(f"- {r['family']} {r['seed']} ({r['road']}), {r['variant']}: {r['outcome']}; "
                     + "; ".join(x[:300] for x in r["lines"]))
    path.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    sys.exit(main())
