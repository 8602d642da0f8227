"""Benchmark: the linear-model fit against the simulation fit, same drives, same run.

Issue 14, item 6: ``eroad invert --fit linear`` (linear-model features, a few time
simulations for the offsets; docs/inverse.md section 12) against ``--fit simulation``
(every evaluation a time simulation).  Datasets: the embedded one (``eroad synth
--scenario luliang --seed 0``) and ``null`` drives (``synth_command(scenario="null",
seed=S)``: the truth vehicle is the nominal model).  Each is inverted from a copy
WITHOUT ``truth/`` by :func:`inverse.cli.run_inversion` (what ``eroad invert`` runs),
both fits one after the other on the same drive (so both see the same machine load),
and scored with ``drives.synth.read_truth`` per true segment against the fitted segment
overlapping it most (``benchmarks/bench_inverse.py`` ``score_case``):
|ln Gq(n0)| error, |w| error, |ln G(n_best)| error (the fitted PSD where the level is
best determined, against the true PSD there), class right.

Wall times: ``total`` = the whole ``run_inversion`` (segmentation, fit, realisation
selection, report), ``fit`` = segmentation and fit.  The luliang runs keep the command's
default 16 candidates (its total is the ``eroad invert`` time of the issue's target);
the null runs use ``--null-candidates`` (default 0: the selection does not change the
parameters).

Run:  nice python benchmarks/bench_inverse_speed.py [--null-seeds 1 2 3] [--workers 2] [--root DIR]
Per-run results are appended to ROOT/results.jsonl (a rerun skips runs already there);
the tables are printed at the end.  No pass/fail.
"""
from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_inverse import score_case  # noqa: E402

FITS = ("simulation", "linear")


def _med(rows, key):
    v = [r[key] for r in rows if key in r]
    return float(np.median(v)) if v else math.nan


def table(results: list) -> str:
    by = {}
    for r in results:
        by.setdefault(r["dataset"], {})[r["fit"]] = r
    lines = ["| dataset | fit | total wall [s] | fit wall [s] | time sims (fit) | median abs ln Gq(n0) | "
             "median abs w | median abs ln G(n_best) | class right |",
             "|---|---|---|---|---|---|---|---|---|"]
    for ds, fits in by.items():
        for f in FITS:
            if f not in fits:
                continue
            r = fits[f]
            segs = r["segments"]
            cls = np.mean([s["class_true"] == s["class_fit"] for s in segs])
            lines.append(f"| {ds} | {f} | {r['total_s']:.1f} | {r['fit_s']:.1f} | {r['n_sims_fit']} | "
                         f"{_med(segs, 'dlnGq'):.3f} | {_med(segs, 'dw'):.3f} | {_med(segs, 'dlnG_n_best'):.3f} | "
                         f"{100 * cls:.0f}% |")
    lines.append("")
    lines.append("| dataset | total wall ratio sim/linear | fit wall ratio sim/linear | time sims ratio |")
    lines.append("|---|---|---|---|")
    for ds, fits in by.items():
        if all(f in fits for f in FITS):
            s, l_ = fits["simulation"], fits["linear"]
            lines.append(f"| {ds} | {s['total_s'] / l_['total_s']:.2f} | {s['fit_s'] / l_['fit_s']:.2f} | "
                         f"{s['n_sims_fit'] / max(l_['n_sims_fit'], 1):.1f} |")
    lines.append("")
    lines.append("Per true segment (simulation | linear):")
    lines.append("| dataset | seg | dur [s] | class true | class sim / lin | abs ln Gq sim / lin | abs w sim / lin | "
                 "abs ln G(n_best) sim / lin |")
    lines.append("|---|---|---|---|---|---|---|---|")
    for ds, fits in by.items():
        if not all(f in fits for f in FITS):
            continue
        for i, (a, b) in enumerate(zip(fits["simulation"]["segments"], fits["linear"]["segments"])):
            lines.append(f"| {ds} | {i + 1} | {a['duration_s']:.1f} | {a['class_true']} | {a['class_fit']} / "
                         f"{b['class_fit']} | {a['dlnGq']:.3f} / {b['dlnGq']:.3f} | {a['dw']:.3f} / {b['dw']:.3f} | "
                         f"{a.get('dlnG_n_best', math.nan):.3f} / {b.get('dlnG_n_best', math.nan):.3f} |")
    allseg = {f: [s for fits in by.values() if f in fits for s in fits[f]["segments"]] for f in FITS}
    lines.append("")
    pairs = [(a, b) for fits in by.values() if all(f in fits for f in FITS)
             for a, b in zip(fits["simulation"]["segments"], fits["linear"]["segments"])]
    if pairs:
        # paired per true segment: the two fits share the data, so the difference is the fits'
        for key, lab in (("dlnGq", "abs ln Gq(n0)"), ("dw", "abs w"), ("dlnG_n_best", "abs ln G(n_best)")):
            d = np.array([b[key] - a[key] for a, b in pairs if key in a and key in b])
            if d.size:
                lines.append(f"* paired, linear minus simulation, {lab}: mean {d.mean():+.3f} "
                             f"(standard error {d.std(ddof=1) / math.sqrt(d.size) if d.size > 1 else math.nan:.3f}), "
                             f"median {np.median(d):+.3f}; linear better in {int(np.sum(d < -0.005))}, worse in "
                             f"{int(np.sum(d > 0.005))} of {d.size} segments (|difference| > 0.005)")
    for f in FITS:
        if allseg[f]:
            cls = np.mean([s["class_true"] == s["class_fit"] for s in allseg[f]])
            lines.append(f"* all segments, {f}: n {len(allseg[f])}, median abs ln Gq {_med(allseg[f], 'dlnGq'):.3f}, "
                         f"median abs w {_med(allseg[f], 'dw'):.3f}, median abs ln G(n_best) "
                         f"{_med(allseg[f], 'dlnG_n_best'):.3f}, class right {100 * cls:.0f}%")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default="/tmp/eroad-bench-inverse-speed")
    ap.add_argument("--null-seeds", type=int, nargs="*", default=[1, 2])
    ap.add_argument("--no-luliang", action="store_true")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--candidates", type=int, default=None, help="luliang selection size (default: the command's 16)")
    ap.add_argument("--null-candidates", type=int, default=0)
    ap.add_argument("--max-iter", type=int, default=None)
    a = ap.parse_args(argv)
    from drives.synth import copy_without_truth, default_dataset, read_truth, synth_command
    from inverse.cli import run_inversion

    root = Path(a.root)
    root.mkdir(parents=True, exist_ok=True)
    res_file = root / "results.jsonl"
    done = {}
    if res_file.is_file():
        for line in res_file.read_text().splitlines():
            d = json.loads(line)
            done[(d["dataset"], d["fit"])] = d
    cases = ([] if a.no_luliang else [("luliang-0", "luliang", 0, a.candidates)]) + \
        [(f"null-{s}", "null", s, a.null_candidates) for s in a.null_seeds]
    for name, scen, seed, n_cand in cases:
        ds = root / name
        if not (ds / "truth" / "summary.json").is_file():
            if scen == "luliang":   # the embedded dataset (made on first use by eroad synth, cached)
                shutil.copytree(default_dataset(), ds, dirs_exist_ok=True)
            else:
                synth_command(scenario=scen, seed=seed, out=ds, force=True)
        blind = root / f"blind-{name}"
        if not blind.exists():
            copy_without_truth(ds, blind)
        truth = read_truth(ds)
        for fit in FITS:
            if (name, fit) in done:
                continue
            t0 = time.perf_counter()
            summ = run_inversion(blind, root / f"run-{name}-{fit}", workers=a.workers, seed=0, candidates=n_cand,
                                 max_iter=a.max_iter, force=True, fit_model=fit)
            wall = time.perf_counter() - t0
            case = score_case(truth, summ)
            r = {"dataset": name, "fit": fit, "total_s": summ["timing"]["total_s"], "fit_s": summ["timing"]["fit_s"],
                 "wall_s": wall, "n_sims_fit": summ["fit"]["n_sims"], "n_sims": summ["timing"]["n_sims"],
                 "fit_model": summ["fit"].get("model"), "candidates": n_cand, **case}
            with res_file.open("a") as f:
                f.write(json.dumps(r) + "\n")
            done[(name, fit)] = r
            print(f"{name} {fit}: total {r['total_s']:.1f} s, fit {r['fit_s']:.1f} s, {r['n_sims_fit']} sims, "
                  f"dlnGq {[round(s['dlnGq'], 2) for s in case['segments']]}", flush=True)
    print(table([done[k] for k in done if any(k[0] == c[0] for c in cases)]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
