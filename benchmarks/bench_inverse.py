"""Benchmark: accuracy of ``eroad invert`` against the truth on blind random drives.

For seeds 1, 2, ... until N valid cases (a seed whose dataset the format refuses,
e.g. an acceleration over the plausibility limit on a class E road, is skipped and
listed): ``eroad synth --scenario random --seed S`` (30 s, the truth vehicle
with leaf friction, flexible frame and sensor noise: a model gap the nominal rigid
truck does not have), a copy WITHOUT ``truth/``, the inversion of that copy
(:func:`inverse.cli.run_inversion`, phases of the fit only: the realisation
selection does not change the parameters), then scoring with
``drives.synth.read_truth``:

* per true segment: the fitted segment that overlaps it most;
  |ln(Gq_fit / Gq_true)|, |w_fit - w_true|, class right (ISO class of Gq);
* boundary error [s]: each interior true boundary to the nearest fitted one;
* rows for all segments, segments >= 3 s and >= 8 s; median and worst.

Run:  nice python benchmarks/bench_inverse.py --cases 20 [--workers 2] [--root DIR]
Per-case results are appended to ROOT/results.jsonl as they come (a rerun skips
cases already there); the table is printed at the end.  No pass/fail.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np


def oracle_fits(dataset: Path, truth: dict, track_y=(-0.9, 0.9)) -> list:
    """The statistical floor: each true segment's (Gq_n0, w) fitted to the TRUE road.

    The road under the wheels (both wheel tracks of ``truth/road.npz`` between the
    segment's x_start and x_end), one full-length Hann periodogram per track,
    Whittle fit (:func:`roadlib.metrics.fit_iso_psd`) over the segment's own true
    band [nmin, nmax].  No response-based method can know more about a segment's
    spectrum than the exact profile it drove over, so these errors bound what the
    inversion can reach on the same segments.
    """
    from roadlib.metrics import fit_iso_psd, profile_psd
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(Path(dataset) / "truth" / "road.npz")
    out = []
    for s in truth["segments"]:
        x = np.arange(s["x_start"], s["x_end"], road.dx)
        if x.size < 64:
            out.append(None)
            continue
        z = road.tracks(list(track_y), x).T
        est = profile_psd(z, road.dx, nperseg=x.size)
        fit = fit_iso_psd(est, band=(s["nmin"], s["nmax"]))
        out.append({"Gq": float(fit.Gd_n0), "w": float(fit.w),
                    "dlnGq": abs(math.log(fit.Gd_n0 / s["Gq_n0"])), "dw": abs(fit.w - s["w"])})
    return out


def score_case(truth: dict, summary: dict) -> dict:
    """Per-segment errors of one inversion against its truth."""
    from inverse.pipeline import segment_errors
    from roadlib.psd import class_of

    fit = summary["segments"]
    tf = np.array([fit[0]["t_start"]] + [s["t_end"] for s in fit])
    tsegs = truth["segments"]
    tt = np.array([tsegs[0]["t_start"]] + [s["t_end"] for s in tsegs])
    rows = []
    for s in tsegs:
        ov = [max(0.0, min(s["t_end"], f["t_end"]) - max(s["t_start"], f["t_start"])) for f in fit]
        f = fit[int(np.argmax(ov))]
        rows.append({"duration_s": s["t_end"] - s["t_start"], "Gq_true": s["Gq_n0"], "Gq_fit": f["Gq_n0"],
                     "w_true": s["w"], "w_fit": f["w"], "dlnGq": abs(math.log(f["Gq_n0"] / s["Gq_n0"])),
                     "dw": abs(f["w"] - s["w"]), "class_true": class_of(s["Gq_n0"]),
                     "class_fit": class_of(f["Gq_n0"]),
                     # the PSD at 1 cycle/m (~10 Hz at 10 m/s, where the truck responds)
                     "dlnG_1cpm": abs(math.log(f["Gq_n0"] / s["Gq_n0"]) - (f["w"] - s["w"]) * math.log(10.0)),
                     # signed errors and what the fit reported, for the interval calibration
                     "lnGq_err": math.log(f["Gq_n0"] / s["Gq_n0"]), "w_err": f["w"] - s["w"],
                     "sd_ln_Gq_n0": f["sd"]["ln_Gq_n0"], "sd_w": f["sd"]["w"],
                     "sd_laplace": f.get("sd_laplace", f["sd"]),
                     "sd_ln_G_n_best_laplace": f.get("sd_ln_G_n_best_laplace", f.get("sd_ln_G_n_best")),
                     "fit_quality": f.get("fit_quality"),
                     "objective": f.get("objective"), "n_features": f.get("n_features"),
                     "fit_duration_s": f["t_end"] - f["t_start"],
                     **({"interval": f["interval"]} if "interval" in f else {}),
                     **({"n_best": f["n_best"], "sd_ln_G_n_best": f["sd_ln_G_n_best"],
                         "lnG_n_best_err": math.log(f["G_n_best"] / (s["Gq_n0"] * (f["n_best"] / 0.1) ** -s["w"])),
                         "dlnG_n_best": abs(math.log(f["G_n_best"] / (s["Gq_n0"] * (f["n_best"] / 0.1) ** -s["w"])))}
                        if "n_best" in f else {})})
    berr = segment_errors(tt, tf)
    return {"segments": rows, "boundary_err_s": [float(b) for b in np.abs(berr)],
            "K_true": len(tsegs), "K_fit": len(fit)}


def table(cases: list) -> str:
    segs = [r for c in cases for r in c["segments"]]
    bnd = np.array([b for c in cases for b in c["boundary_err_s"]], float)
    lines = ["| segments | n | median abs ln(Gq) | worst | Gq within 20% | median abs w err | worst | "
             "w within 0.15 | class right | boundary err median / worst [s] |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, lo in (("all", 0.0), (">= 3 s", 3.0), (">= 8 s", 8.0)):
        rs = [r for r in segs if r["duration_s"] >= lo]
        if not rs:
            continue
        g = np.array([r["dlnGq"] for r in rs])
        w = np.array([r["dw"] for r in rs])
        cl = np.mean([r["class_true"] == r["class_fit"] for r in rs])
        b = f"{np.nanmedian(bnd):.2f} / {np.nanmax(bnd):.2f}" if name == "all" and bnd.size else ""
        lines.append(f"| {name} | {len(rs)} | {np.median(g):.3f} | {g.max():.3f} | "
                     f"{100 * np.mean(g <= math.log(1.2)):.0f}% | {np.median(w):.3f} | {w.max():.3f} | "
                     f"{100 * np.mean(w <= 0.15):.0f}% | {100 * cl:.0f}% | {b} |")
        orc = [r["oracle"] for r in rs if r.get("oracle")]
        if orc:
            from roadlib.psd import class_of
            go = np.array([o["dlnGq"] for o in orc])
            wo = np.array([o["dw"] for o in orc])
            clo = np.mean([class_of(o["Gq"]) == r["class_true"] for r, o in zip(rs, orc)])
            lines.append(f"| {name}, true-road oracle | {len(orc)} | {np.median(go):.3f} | {go.max():.3f} | "
                         f"{100 * np.mean(go <= math.log(1.2)):.0f}% | {np.median(wo):.3f} | {wo.max():.3f} | "
                         f"{100 * np.mean(wo <= 0.15):.0f}% | {100 * clo:.0f}% | |")
    lines.append("\nThe fitted PSD where the truck sees the road (segments >= 3 s):")
    rs = [r for r in segs if r["duration_s"] >= 3.0]
    g1 = np.array([r["dlnG_1cpm"] for r in rs if "dlnG_1cpm" in r])
    if g1.size:
        lines.append(f"* at 1 cycle/m: median abs ln error {np.median(g1):.3f}, within 20% in "
                     f"{100 * np.mean(g1 <= math.log(1.2)):.0f}% of {g1.size}")
    gb = [r for r in rs if "dlnG_n_best" in r]
    if gb:
        e = np.array([r["dlnG_n_best"] for r in gb])
        z = e / np.array([r["sd_ln_G_n_best"] for r in gb])
        nb = np.array([r["n_best"] for r in gb])
        lines.append(f"* at each segment's n_best (median {np.median(nb):.2f} cycles/m): median abs ln error "
                     f"{np.median(e):.3f}, within 20% in {100 * np.mean(e <= math.log(1.2)):.0f}%; "
                     f"error / reported sd: median {np.median(z):.2f} (0.67 if the sd is right)")
    kr = np.mean([c["K_true"] == c["K_fit"] for c in cases])
    lines.append(f"\n{len(cases)} cases, K right in {100 * kr:.0f}%, median wall "
                 f"{np.median([c['wall_s'] for c in cases]):.1f} s per inversion")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--first-seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--max-iter", type=int, default=10)
    ap.add_argument("--channels", default="axle3")
    ap.add_argument("--root", default="/tmp/eroad-bench-inverse")
    ap.add_argument("--data-root", default=None,
                    help="where the synthetic datasets are made or found (default: ROOT); share "
                         "it between runs that compare settings on the same drives")
    ap.add_argument("--no-polish", action="store_true", help="switch off the fit's polishing step")
    ap.add_argument("--known-noise", action="store_true",
                    help="give the inversion the sensor-noise levels (a data-sheet value a user "
                         "would know; read from truth/ noise, nothing else of the truth)")
    ap.add_argument("--scenario", default="random", choices=["random", "null"],
                    help="random: the truth has leaf friction and a flexible frame the nominal "
                         "model lacks; null: the truth vehicle IS the nominal model (the method's "
                         "accuracy alone, with the finer step, finer road grid and sensor noise)")
    ap.add_argument("--no-default-effects", action="store_true",
                    help="truth vehicle without the scenario's leaf friction (no model gap but the "
                         "flexible frame and the finer step): the method's accuracy alone")
    a = ap.parse_args(argv)
    from drives.synth import copy_without_truth, read_truth, synth_command
    from eroad.errors import EroadInputError
    from inverse.cli import run_inversion

    root = Path(a.root)
    root.mkdir(parents=True, exist_ok=True)
    data_root = Path(a.data_root) if a.data_root else root
    data_root.mkdir(parents=True, exist_ok=True)
    res_file = root / "results.jsonl"
    done = {}
    if res_file.is_file():
        for line in res_file.read_text().splitlines():
            d = json.loads(line)
            done[d["seed"]] = d
    seed = a.first_seed
    valid = [d for d in done.values() if "skipped" not in d]
    while len(valid) < a.cases:
        if seed in done:
            seed += 1
            continue
        ds = data_root / f"{a.scenario}-{seed}"
        try:
            if not (ds / "truth" / "summary.json").is_file():
                synth_command(scenario=a.scenario, seed=seed, out=ds, force=True,
                              default_effects=not a.no_default_effects)
        except EroadInputError as exc:   # e.g. a class E road overloads a sensor range
            case = {"seed": seed, "skipped": str(exc)}
            with res_file.open("a") as f:
                f.write(json.dumps(case) + "\n")
            done[seed] = case
            print(f"seed {seed}: skipped ({exc})", flush=True)
            seed += 1
            continue
        blind = data_root / f"blind-{a.scenario}-{seed}"
        if not blind.exists():
            copy_without_truth(ds, blind)
        noise = None
        if a.known_noise:
            nz = read_truth(ds)["noise"]
            noise = {q: nz[key] for q, key in (("susp_disp", "susp_disp_m"), ("axle_acc", "axle_acc_mps2"),
                                                ("body_acc", "body_acc_mps2"))}
        t0 = time.perf_counter()
        summ = run_inversion(blind, root / f"run-{seed}", workers=a.workers, seed=0, candidates=0,
                             max_iter=a.max_iter, channels=a.channels, force=True,
                             polish=not a.no_polish, noise_sd=noise)
        truth = read_truth(ds)
        case = score_case(truth, summ)
        for r, o in zip(case["segments"], oracle_fits(ds, truth)):
            r["oracle"] = o
        case.update(seed=seed, wall_s=time.perf_counter() - t0)
        with res_file.open("a") as f:
            f.write(json.dumps(case) + "\n")
        done[seed] = case
        valid.append(case)
        print(f"seed {seed}: K {case['K_fit']}/{case['K_true']}, "
              f"dlnGq {[round(r['dlnGq'], 2) for r in case['segments']]}, {case['wall_s']:.0f} s", flush=True)
        seed += 1
    cases = sorted(valid, key=lambda c: c["seed"])[:a.cases]
    skipped = [d["seed"] for d in done.values() if "skipped" in d]
    if skipped:
        print(f"skipped seeds (dataset refused by the format's plausibility checks): {sorted(skipped)}")
    print(table(cases))
    return 0


if __name__ == "__main__":
    sys.exit(main())
