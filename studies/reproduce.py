"""``eroad reproduce``: every paper figure and table from the embedded dataset.

What it is for: one command that runs the whole chain on the embedded ``luliang``
dataset (the virtual test drive of the paper's 460-490 s coal-road window) and
writes one folder with every paper item, the chassis-stiffness study, the gap
diagnosis and a manifest that maps each paper item to the file and the code that
made it.  What it is not: a place where science is done; each step calls the
package that owns it, and this module only wires the steps and keeps the record.

Steps (each in its own sub-folder of the run):

==========  ======================================  ==========================================
step        paper items                             code
==========  ======================================  ==========================================
dataset     (input)                                 drives.synth.default_dataset
fig4_5      Figures 4, 5                            drives.figures.plot_figures
invert      Figures 6, 8, 9; Tables 1, 2; road      diagnosis.closed_loop.invert_closed_loop
replica     Figure 8 on the reconstructed road      diagnosis.closed_loop.replica_closed_loop
figure11    Figure 11 and the findings table        studies.figure11.run_figure11
chassis     chassis-stiffness study                 studies.chassis_study.run_chassis_study
diagnose    sim-to-real gap of the dataset          (the invert step's diagnosis, copied)
==========  ======================================  ==========================================

The run folder is written under a temporary name beside ``--out`` and renamed into
place when complete, so an interrupted run never leaves a half-written ``--out``
and never overwrites another run (an existing non-empty ``--out`` is refused
unless ``--force``, which moves the old folder aside rather than deleting it).
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import time
from pathlib import Path

from eroad.errors import EroadInputError

#: paper item -> (step, file pattern relative to the run folder, code)
MANIFEST = [
    ("Figure 4", "fig4_5", "figure4_displacement.png", "drives.figures.plot_figures"),
    ("Figure 5", "fig4_5", "figure5_spectrum.png", "drives.figures.plot_figures"),
    ("Figure 6", "invert", "figures/figure6_segmentation.png", "inverse.run.run_inversion"),
    ("Table 1", "invert", "tables/table1.md", "inverse.run.run_inversion"),
    ("Figure 8", "invert", "figures/figure8_time_compare.png", "inverse.run.run_inversion"),
    ("Figure 8 on the road replica",
     "replica", "figures/replica_time.png", "inverse.replica.run_replica"),
    ("Road replica: wheel-track profiles, IRI, .crg", "replica", "tracks.csv", "inverse.replica.run_replica"),
    ("Road replica against the inversion, per segment", "replica", "figures/replica_vs_inversion.png",
     "inverse.replica.run_replica"),
    ("Figure 9", "invert", "figures/figure9_amplitude_distributions.png", "inverse.run.run_inversion"),
    ("Table 2", "invert", "tables/table2.md", "inverse.run.run_inversion"),
    ("Global road (section 2.5)", "invert", "road.*", "inverse.run.run_inversion"),
    ("Table 1, nominal vs corrected model", "invert", "tables/table1_nominal_vs_corrected.md",
     "diagnosis.closed_loop.invert_closed_loop"),
    ("Figure 11", "figure11", "figures/figure11.png", "studies.figure11.run_figure11"),
    ("Findings of section 5 (true/false)", "figure11", "data/findings.md",
     "studies.figure11.run_figure11"),
    ("Chassis-stiffness study", "chassis", "figures/*.png", "studies.chassis_study.run_chassis_study"),
    ("Sim-to-real gap diagnosis", "diagnose", "report.md", "diagnosis.pipeline.diagnose_dataset"),
]


def _step_dataset(run: Path, quick: bool, workers: int, log) -> dict:
    """Copy the embedded dataset (without ``truth/``) into the run: the 460-490 s window
    that the inversion and the diagnosis read, and its whole record (``dataset/record/``)
    that Figures 4 and 5 show it in."""
    from drives.synth import RECORD_DIR, default_dataset

    src = default_dataset()
    dst = run / "dataset"
    dst.mkdir()
    for sub in ("", RECORD_DIR):
        if sub and not (src / sub).is_dir():
            continue
        (dst / sub).mkdir(exist_ok=True)
        for name in ("channels.csv", "meta.toml", "vehicle.toml"):
            if (src / sub / name).is_file():
                shutil.copy2(src / sub / name, dst / sub / name)
    return {"source": str(src), "path": str(dst),
            "record": str(dst / RECORD_DIR) if (dst / RECORD_DIR).is_dir() else None,
            "regenerate": "eroad synth --scenario luliang --seed 0 --out DIR"}


def _step_fig4_5(run: Path, quick: bool, workers: int, log) -> dict:
    """Figures 4 and 5: the window in its whole record (the window alone when the dataset
    has no ``record/``)."""
    from drives.figures import plot_figures
    from drives.format import read_drive
    from drives.synth import RECORD_DIR

    out = run / "fig4_5"
    out.mkdir()
    win = read_drive(run / "dataset")
    rec = run / "dataset" / RECORD_DIR
    if rec.is_dir():
        summary = plot_figures(read_drive(rec), out,
                               window=(float(win.time[0]), float(win.time[-1]) + win.dt))
    else:
        summary = plot_figures(win, out)
    return _jsonable(summary)


def _step_invert(run: Path, quick: bool, workers: int, log) -> dict:
    """The loop closed: diagnose, invert nominal and, on a clear verdict, with the named
    effect (diagnosis.closed_loop); the chosen road goes on to Figure 11 and the chassis study."""
    from diagnosis.closed_loop import invert_closed_loop

    return _jsonable(invert_closed_loop(run / "dataset", run / "invert", quick=quick, workers=workers,
                                        seed=0, argv=sys.argv, progress=log))


def _step_replica(run: Path, quick: bool, workers: int, log) -> dict:
    """Figure 8 on the measured road's own time history: the road replica (inverse.replica)
    with the effect the invert step's diagnosis named (the same closed-loop rule)."""
    from diagnosis.closed_loop import replica_closed_loop

    made = run / "invert" / "diagnose"
    diag = made if (made / "summary.json").is_file() else None
    inv = run / "invert" if (run / "invert" / "summary.json").is_file() else None
    return _jsonable(replica_closed_loop(run / "dataset", run / "replica", diagnosis=diag, copy_diagnosis=False,
                                         inversion=inv, workers=workers, quick=quick, seed=0, argv=sys.argv,
                                         progress=log))


def _identified_road(run: Path) -> Path:
    road = run / "invert" / "road.npz"
    if not road.is_file():
        raise EroadInputError(f"{road}: missing; the inversion step did not write the global road")
    return road


def _archived(root: Path, study: str) -> Path:
    """Move the single archived run ``root/<study>/<run-id>`` up to ``root``."""
    runs = [p for p in (root / study).iterdir() if p.is_dir()]
    if len(runs) != 1:
        raise RuntimeError(f"expected one archived run in {root / study}, found {len(runs)}")
    for item in runs[0].iterdir():
        item.rename(root / item.name)
    runs[0].rmdir()
    (root / study).rmdir()
    return root


def _step_figure11(run: Path, quick: bool, workers: int, log) -> dict:
    from studies.figure11 import run_figure11

    out = run / "figure11"
    out.mkdir()
    summary = run_figure11(_identified_road(run), out, duration=15.0 if quick else 30.0,
                           command=sys.argv)
    _archived(out, "figure11")
    return _jsonable(summary)


def _step_chassis(run: Path, quick: bool, workers: int, log) -> dict:
    from studies.chassis_study import full_config, quick_config, run_chassis_study

    out = run / "chassis"
    out.mkdir()
    config = quick_config() if quick else full_config()
    summary = run_chassis_study(_identified_road(run), out, config, n_workers=workers,
                                cache_dir=run.parent / ".eroad-cache", progress=False,
                                command=sys.argv)
    _archived(out, "chassis_stiffness")
    return _jsonable(summary)


def rebase_diagnosis(dst: Path, src: Path, dataset: Path) -> None:
    """A diagnosis folder copied from ``src`` to ``dst``: its recorded dataset path
    (summary.json ``meta.dataset``, the report's dataset line) made relative to ``dst``."""
    old = os.path.relpath(Path(dataset).resolve(), Path(src).resolve())
    new = os.path.relpath(Path(dataset).resolve(), Path(dst).resolve())
    sf = dst / "summary.json"
    if sf.is_file():
        summ = json.loads(sf.read_text())
        if (summ.get("meta") or {}).get("dataset") == old:
            summ["meta"]["dataset"] = new
            sf.write_text(json.dumps(summ, indent=2))
    rf = dst / "report.md"
    if rf.is_file():
        rf.write_text(rf.read_text().replace(f"- dataset: `{old}`", f"- dataset: `{new}`", 1))


def _step_diagnose(run: Path, quick: bool, workers: int, log) -> dict:
    """The diagnosis the invert step already ran (its first stage), copied to diagnose/;
    run afresh only when the invert step was not run."""
    from diagnosis.pipeline import diagnose_dataset

    made = run / "invert" / "diagnose"
    if (made / "summary.json").is_file():
        dst = run / "diagnose"
        shutil.copytree(made, dst)
        rebase_diagnosis(dst, made, run / "dataset")
        return _jsonable(json.loads((dst / "summary.json").read_text()))
    return _jsonable(diagnose_dataset(run / "dataset", run / "diagnose", quick=quick,
                                      workers=workers))


STEPS = [("dataset", _step_dataset), ("fig4_5", _step_fig4_5), ("invert", _step_invert),
         ("replica", _step_replica), ("figure11", _step_figure11), ("chassis", _step_chassis), ("diagnose", _step_diagnose)]


def _jsonable(obj):
    """Round-trip through JSON with str() for anything unknown (paths, numpy scalars)."""
    def default(o):
        try:
            import numpy as np
            if isinstance(o, np.generic):
                return o.item()
            if isinstance(o, np.ndarray):
                return o.tolist()
        except ImportError:  # pragma: no cover
            pass
        return str(o)
    return json.loads(json.dumps(obj, default=default))


def _manifest(run: Path) -> list:
    """Manifest rows: each paper item with the files of it the run holds (relative to the run)."""
    from eroad.archive import manifest_rows

    return manifest_rows(run, [(item, f"{step}/{pattern}", code) for item, step, pattern, code in MANIFEST])


def _replica_warnings(run: Path) -> list:
    """The replica's warnings (:func:`inverse.replica.note_warnings` of its summary), for the manifest."""
    p = run / "replica" / "summary.json"
    if not p.is_file():
        return []
    from inverse.replica import note_warnings

    return note_warnings((json.loads(p.read_text()).get("linear_model") or {}).get("notes"))


def _manifest_md(rows: list, timings: dict, fit_quality: dict | None = None,
                 diagnosis_s: float | None = None, replica_warnings=()) -> str:
    lines = ["# eroad reproduce: manifest", "",
             "Each paper item, the file(s) that show it (relative to this folder) and the "
             "code that made them.", ""]
    if fit_quality and fit_quality.get("status") == "poor":
        lines += [f"**Inversion: POOR FIT.** {fit_quality['message']}. Tables 1-2 and the road are "
                  "shown, but they are not a clean result.", ""]
    elif fit_quality:
        lines += ["Inversion: every segment passes the fit-quality gate.", ""]
    for w in replica_warnings:
        lines += [f"**Road replica:** {w}", ""]
    lines += ["| paper item | file(s) | code |", "|---|---|---|"]
    for r in rows:
        files = "<br>".join(f"[{f}]({f})" for f in r["files"]) or "**missing**"
        lines.append(f"| {r['item']} | {files} | `{r['code']}` |")
    lines += ["", "## Timing", "", "| step | wall [s] |", "|---|---|"]
    lines += [f"| {k} | {v:.1f} |" for k, v in timings.items()]
    if diagnosis_s is not None:
        lines += ["", f"invert includes the diagnosis that closes the loop ({diagnosis_s:.0f} s, "
                      "diagnose/run.json); the diagnose step copies it."]
    return "\n".join(lines) + "\n"


def reproduce(out, *, quick: bool = False, workers: int = 2, force: bool = False,
              steps=None, log=print) -> dict:
    """Run every step into ``out`` and write the manifest.

    Parameters
    ----------
    out : str or Path
        Run folder to create; refused when it exists and is not empty, unless
        ``force`` (the old folder is renamed to ``<out>.old-<timestamp>``, not deleted).
    quick : bool
        Smoke-test settings (shorter fits, fewer study cases; <= 2 minutes).
    workers : int
        Worker processes for the parallel steps.
    steps : list of str, optional
        Subset of step names (default all; later steps need the earlier ones).
    log : callable
        Progress lines.

    Returns
    -------
    dict
        The summary (also ``summary.json``): per-step summaries, timings, manifest.
    """
    from eroad.archive import finish_run_info, run_info, write_json_atomic, write_run_json

    out = Path(out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        if not force:
            raise EroadInputError(f"{out}: exists and is not empty; choose another --out or use --force")
        aside = out.with_name(f"{out.name}.old-{time.strftime('%Y%m%dT%H%M%S')}")
        out.rename(aside)
        log(f"moved the old {out} aside to {aside}")
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir()
    wanted = [name for name, _ in STEPS] if steps is None else list(steps)
    start = time.time()
    record = run_info("reproduce", run_id=out.name, seed=0,   # every step runs with seed 0
                      extra={"quick": quick, "workers": workers})
    timings, results = {}, {}
    try:
        for name, func in STEPS:
            if name not in wanted:
                continue
            log(f"[{name}] ...")
            t0 = time.perf_counter()
            results[name] = func(tmp, quick, workers, log)
            timings[name] = time.perf_counter() - t0
            log(f"[{name}] done in {timings[name]:.1f} s")
        finish_run_info(record, "complete", wall_s=time.time() - start)
    except BaseException as exc:
        finish_run_info(record, "failed", wall_s=time.time() - start, error=exc)
        raise
    finally:
        record["extra"]["timings_s"] = timings
        rows = _manifest(tmp)
        write_run_json(tmp, record)
        summary = {"status": record["status"], "quick": quick, "timings_s": timings,
                   "wall_s": record["wall_s"], "manifest": rows, "steps": results}
        write_json_atomic(tmp / "summary.json", _jsonable(summary))
        write_json_atomic(tmp / "manifest.json", rows)
        fq = results.get("invert", {}).get("fit_quality") if isinstance(results.get("invert"), dict) else None
        dg = tmp / "invert" / "diagnose" / "run.json"
        dg_s = json.loads(dg.read_text()).get("wall_s") if dg.is_file() else None
        (tmp / "manifest.md").write_text(_manifest_md(rows, timings, fq, dg_s, _replica_warnings(tmp)))
        target = out if record["status"] == "complete" else out.with_name(f"{out.name}.failed-{os.getpid()}")
        if target.exists():
            target.rmdir()  # empty (checked above)
        tmp.rename(target)
        _repoint(target, tmp, target)
    return summary


def _repoint(folder: Path, old: Path, new: Path, max_bytes: int = 20_000_000) -> int:
    """Replace the temporary run path in the run's text records by a relative path.

    Steps record the paths they were given (the dataset, their output); those pointed
    into the temporary folder, which no longer exists once it is renamed into place.
    Each becomes relative to the run folder the file belongs to (the nearest folder
    above it holding a ``run.json``), so the records stay right when the run is moved
    or committed.

    Returns
    -------
    int
        Number of files rewritten.
    """
    old_s = str(old.resolve())
    new = new.resolve()
    n = 0
    for path in folder.rglob("*"):
        if path.suffix not in (".json", ".md", ".toml", ".txt") or not path.is_file() \
                or path.stat().st_size > max_bytes:
            continue
        text = path.read_text(encoding="utf-8")
        if old_s not in text:
            continue
        run_dir = path.parent
        while run_dir != folder and not (run_dir / "run.json").is_file():
            run_dir = run_dir.parent
        rel = Path(os.path.relpath(new, run_dir.resolve())).as_posix()
        tmp_file = path.with_name(path.name + ".repoint")
        tmp_file.write_text(text.replace(old_s + "/", rel + "/").replace(old_s, rel), encoding="utf-8")
        tmp_file.replace(path)
        n += 1
    return n


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "reproduce", help="every paper figure and table from the embedded dataset",
        description="Run the whole chain on the embedded luliang dataset: Figures 4, 5, 6, 8, "
        "9, 11, Tables 1, 2, the chassis-stiffness study and the gap diagnosis, with a "
        "manifest mapping each paper item to its file and code.")
    p.add_argument("--out", default="out/reproduce", help="run folder to create (default out/reproduce)")
    p.add_argument("--quick", action="store_true", help="smoke-test settings (<= 2 minutes)")
    p.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    p.add_argument("--force", action="store_true",
                   help="if --out exists, move it aside (never deleted) and write a new run")
    p.add_argument("--steps", default=None,
                   help="comma-separated subset of steps: " + ",".join(n for n, _ in STEPS))
    p.add_argument("--json", action="store_true", help="print summary.json")
    p.set_defaults(func=_cmd)


def _cmd(args) -> int:
    steps = None if args.steps is None else [s.strip() for s in args.steps.split(",") if s.strip()]
    if steps is not None:
        unknown = sorted(set(steps) - {n for n, _ in STEPS})
        if unknown:
            raise EroadInputError(f"--steps: unknown step(s) {', '.join(unknown)}; "
                                  f"choose from {', '.join(n for n, _ in STEPS)}")
    summary = reproduce(args.out, quick=args.quick, workers=args.workers, force=args.force,
                        steps=steps, log=(lambda *a: None) if args.json else
                        (lambda msg: print(msg, flush=True)))
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        missing = [r["item"] for r in summary["manifest"] if not r["present"]]
        print(f"wrote {args.out} in {summary['wall_s']:.0f} s; manifest: {args.out}/manifest.md")
        if missing:
            print("not produced: " + ", ".join(missing))
    return 0
