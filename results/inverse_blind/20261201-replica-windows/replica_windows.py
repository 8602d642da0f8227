"""Exploration (stop 72): how well does the road REPLICA's profile give each segment's G(1 cycle/m)
and class, against the inversion's own response-based fit, on blind drives?

    python replica_windows.py DATA ROOT OUT.jsonl SCENARIO SEED [SEED ...]

Per seed: ``eroad synth --scenario SCENARIO --seed S`` into DATA (kept), a copy without truth, the
default inversion of the copy (run_inversion, phases of the fit only, as benchmarks/bench_inverse.py)
into ROOT/run-S, the replica of the copy with the nominal linear model (inverse.replica.reconstruct,
all response channels).  Per true segment (scored as bench_inverse.score_case: the fit segment that
overlaps it most), the one-slope Whittle fit (roadlib.metrics.fit_iso_psd, one full-length Hann
periodogram per tyre line, averaged) of the REPLICA's tyre lines (not the side tracks: those are the mean
of a side's lines, whose short waves partly cancel) over
  * the fit segment's window, in the fit segment's own band [nmin, nmax]  ("replica_fit_band")
  * the fit segment's window, in the true band (as the bench's true-road oracle)  ("replica_true_band")
  * the true segment's window, in the true band  ("replica_true_window")
and the true road's fit on the fit window in the true band (bench_inverse.oracle_on_fit_windows).
Errors: ln G(1 cycle/m) against the true segment's ISO spectrum; class of Gq(n0)."""
import json
import math
import sys
from pathlib import Path

import numpy as np

from benchmarks.bench_inverse import (_most_overlapping, on_truth_axle, oracle_on_fit_windows, reference_axle_x,
                                      score_case)
from drives.format import read_drive
from drives.synth import copy_without_truth, read_truth, synth_command
from inverse.run import run_inversion
from inverse.replica import reconstruct, replica_linear_model, response_channels
from roadlib.metrics import fit_iso_psd, profile_psd
from roadlib.psd import class_of


def replica_fit(rep, x0, x1, band):
    sel = rep.covered & (rep.x >= x0) & (rep.x < x1)
    if sel.sum() < 64:
        return None
    z = np.vstack([zl[sel] for _, _, zl in rep.lines]).T     # every tyre line's own profile
    dx = float(rep.x[1] - rep.x[0])
    try:
        f = fit_iso_psd(profile_psd(z, dx, nperseg=int(sel.sum())), band=band)
    except Exception as exc:          # a band outside what the window resolves
        return {"error": str(exc)}
    return {"Gq": float(f.Gd_n0), "w": float(f.w)}


def err(fit, s):
    if not fit or "Gq" not in fit:
        return None
    g1 = fit["Gq"] * 10.0 ** -fit["w"]
    return {"lnG1": math.log(g1 / (s["Gq_n0"] * 10.0 ** -s["w"])), "class": class_of(fit["Gq"]),
            "lnGq": math.log(fit["Gq"] / s["Gq_n0"]), "w": fit["w"]}


def main(data, root, out, scen, seeds):
    data, root = Path(data), Path(root)
    for seed in seeds:
        ds = data / f"{scen}-{seed}"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=scen, seed=seed, out=ds, force=True)
        blind = data / f"{scen}-{seed}-blind"
        if not blind.exists():
            copy_without_truth(ds, blind)
        run = root / f"run-{seed}"
        if (run / "summary.json").is_file():
            summ = json.loads((run / "summary.json").read_text())
        else:
            summ = run_inversion(blind, run, workers=2, seed=0, candidates=0, max_iter=10, force=True)
        truth = read_truth(ds)
        summ = on_truth_axle(truth, summ)
        case = score_case(truth, summ)
        orc = oracle_on_fit_windows(ds, truth, summ)
        d = read_drive(blind)
        names = response_channels(d.channel_names)
        ch = {c: d.channels[c].to_numpy(float) for c in names}
        lm, _, _ = replica_linear_model(d.vehicle, None, ch, d.sample_rate_hz)
        rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
        x_a1 = float(reference_axle_x(truth, [float(d.time[0])], axle=1)[0])     # replica x = 0 there
        rows = []
        for s, r, o in zip(truth["segments"], case["segments"], orc):
            f = _most_overlapping(s, summ["segments"])
            xf = reference_axle_x(truth, [f["t_start"], f["t_end"]]) - x_a1
            xt = np.array([s["x_start"], s["x_end"]]) - x_a1
            tb = (s["nmin"], s["nmax"])
            rows.append({"seed": seed, "scenario": scen, "duration_s": r["duration_s"],
                         "class_true": r["class_true"], "fit": {"lnG1": r["lnG_1cpm_err"], "class": r["class_fit"]},
                         "oracle_fit_window": err(o, s),
                         "replica_fit_band": err(replica_fit(rep, *xf, (f["nmin"], f["nmax"])), s),
                         "replica_true_band": err(replica_fit(rep, *xf, tb), s),
                         "replica_true_window": err(replica_fit(rep, *xt, tb), s)})
        with open(out, "a") as fh:
            for r in rows:
                fh.write(json.dumps(r) + "\n")
        ok = [r for r in rows if r["duration_s"] >= 3.0]
        print(f"seed {seed}: {len(ok)} segments >= 3 s; fit |lnG1| "
              f"{[round(abs(r['fit']['lnG1']), 2) for r in ok]}; replica (fit band) "
              f"{[round(abs(r['replica_fit_band']['lnG1']), 2) if r['replica_fit_band'] else None for r in ok]}",
              flush=True)


def summarise(path):
    rows = [json.loads(x) for x in open(path)]
    rows = [r for r in rows if r["duration_s"] >= 3.0]
    out = [f"{len(rows)} true segments >= 3 s from {len({r['seed'] for r in rows})} drives"]
    for key in ("fit", "oracle_fit_window", "replica_fit_band", "replica_true_band", "replica_true_window"):
        v = [r[key] for r in rows if r.get(key)]
        e = np.array([x["lnG1"] for x in v])
        cl = np.mean([x["class"] == r["class_true"] for x, r in zip(v, [r for r in rows if r.get(key)])])
        out.append(f"{key:20s} n {len(v):3d}: G(1) within 20 % {100 * np.mean(np.abs(e) <= math.log(1.2)):5.1f} %, "
                   f"median abs ln {np.median(np.abs(e)):.3f}, mean ln {np.mean(e):+.3f}, sd {np.std(e):.3f}; "
                   f"class right {100 * cl:5.1f} %")
    return "\n".join(out)


if __name__ == "__main__":
    if sys.argv[1] == "--summary":
        print(summarise(sys.argv[2]))
    else:
        main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], [int(s) for s in sys.argv[5:]])
