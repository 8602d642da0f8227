"""Blind benchmark of the road replica (issue 17) against synthetic truth.

For each family and seed: ``eroad synth --scenario FAMILY --seed S`` (cached), the
replica from the dataset's channels and speed only (``inverse.replica.reconstruct``
on the nominal linear model; truth/ is read here, for scoring, never by the method),
then:

* correlation of reconstructed and true track in the 0.5-20 m band, per track, over
  the stretch some tyre ran over during the record.  The true "track" of a side is
  the mean of the road under that side's tyre lines (front singles at |y| = 1.02 m,
  rear duals at 0.76 and 1.10 m): the vehicle's wheel track as the two-track model
  defines it.  The correlation with the single line under the front tyres is
  reported beside it (``corr_line``);
* IRI per 100 m (roadlib.iri) of reconstruction and truth, relative error;
* held out (``--holdout N`` drives): the replica from all channels but axle 2's,
  whose six channels are then predicted by the linear model on that replica:
  normalised RMSE = RMS(pred - meas) / RMS(meas).

Usage::

    nice python benchmarks/bench_replica.py --families null:10 second:5 random:3 \
        --holdout 3 --out results/replica/<date>-<what>

Writes ``cases.jsonl`` (one line per drive, appended as they finish), ``summary.json``
and ``summary.md`` in --out.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drives.format import read_drive  # noqa: E402
from inverse.replica import (axle_of, band_correlation, nrmse, reconstruct,  # noqa: E402
                             response_channels)

BAND = (0.5, 20.0)


def true_tracks(dataset, x, contacts) -> dict:
    """Scoring only: the truth road under each side's tyre lines at replica positions x.

    Returns {"L": mean over the side's tyre lines, "R": ..., "L_line": the first
    contact's line, "R_line": ...} on ``x`` (0 = first axle at the first sample).
    """
    from drives.synth import plan_drive, read_truth
    from roadlib.surface import RoadSurface

    tr = read_truth(dataset)
    cfg = tomllib.loads((Path(dataset) / "truth" / "scenario.toml").read_text())
    axle_x = tr["vehicle"]["axle_x_m"]
    plan = plan_drive(cfg, axle_x)
    ref = int(cfg["scenario"]["reference_axle"])
    x1 = plan["x_ref"][plan["n_runin"]] - axle_x[ref - 1]
    road = RoadSurface.load(tr["road_file"])
    ys = {}
    for c in contacts:
        ys.setdefault(c["side"], []).append(c["y"])
    out = {"line_at": lambda y: road.track(y, x1 + x)}
    for s, yy in ys.items():
        out[s] = np.mean([road.track(y, x1 + x) for y in yy], axis=0)
        out[s + "_line"] = road.track(yy[0], x1 + x)
    return out


def iri_100(x, z, start) -> list:
    from roadlib.iri import iri_segments
    return [s.iri for s in iri_segments(x, z, 100.0, start=start)]


def run_case(family: str, seed: int, cache: Path, holdout: bool, lines: str = "tyre", effects=None) -> dict:
    from drives.synth import synth_command
    from inverse.replica import replica_linear_model
    from vehicles.effects import parse_effects

    ds = cache / f"{family}-{seed}"
    if not (ds / "truth" / "summary.json").is_file():
        synth_command(scenario=family, seed=seed, out=ds, force=True)
    drive = read_drive(ds)
    names0 = response_channels(drive.channel_names)
    ch0 = {c: drive.channels[c].to_numpy(float) for c in names0}
    # the model eroad replica builds (leaf friction by statistical linearisation); the
    # hold-out replica below gets its own, without axle 2's data
    eff = parse_effects(effects) if effects else None
    lm, left_out, lin_notes = replica_linear_model(drive.vehicle, eff, ch0, drive.sample_rate_hz)
    names = response_channels(drive.channel_names)
    chans = {c: drive.channels[c].to_numpy(float) for c in names}
    t0 = time.perf_counter()
    rep = reconstruct(lm, drive.time, drive.speed, chans, lines=lines)
    wall = time.perf_counter() - t0
    cov = rep.covered
    x = rep.x[cov]
    dx = float(rep.x[1] - rep.x[0])
    truth = true_tracks(ds, rep.x, lm.contacts)
    case = {"family": family, "seed": seed, "wall_s": wall, "lines": lines, "effects": list(effects or []),
            "effects_left_out": left_out, "linearisation": lin_notes, "cg_iterations": rep.info["cg_iterations"],
            "gd0_em": rep.gd0, "covered_m": float(x[-1] - x[0]),
            "band_at_speed_m": rep.info["band_at_speed_m"], "speed_quantiles_mps": rep.info["speed_quantiles_mps"]}
    for s, est in (("L", rep.z_left), ("R", rep.z_right)):
        zt = truth[s][cov]
        ze = est[cov]
        case[f"corr_{s}"] = band_correlation(ze, zt, dx, BAND)
        # the front tyre line: its own estimate where the replica has tyre lines
        yf = next(c["y"] for c in lm.contacts if c["side"] == s)
        zf = next((z for sd, y, z in rep.lines if sd == s and abs(y - yf) < 0.01), est) if lines == "tyre" else est
        case[f"corr_line_{s}"] = band_correlation(zf[cov], truth[s + "_line"][cov], dx, BAND)
        start = float(x[0])
        ie, it = iri_100(x, ze, start), iri_100(x, zt, start)
        il = iri_100(x, truth[s + "_line"][cov], start)
        case[f"iri100_est_{s}"] = ie
        case[f"iri100_true_{s}"] = it
        case[f"iri100_line_{s}"] = il
        case[f"iri100_relerr_{s}"] = [float(a / b - 1) for a, b in zip(ie, it)]
    if holdout:
        keep = [c for c in names if axle_of(c) != 2]
        held = [c for c in names if axle_of(c) == 2]
        lm2 = lm if not lin_notes else replica_linear_model(
            drive.vehicle, eff, {c: chans[c] for c in keep}, drive.sample_rate_hz)[0]
        rep2 = reconstruct(lm2, drive.time, drive.speed, {c: chans[c] for c in keep}, lines=lines)
        pred = rep2.predict(held)
        case["holdout_nrmse"] = {c: nrmse(pred[c], chans[c]) for c in held}
        # what the model itself allows: the same linear model driven by the TRUE road under
        # every tyre line (no reconstruction), scored the same way
        from inverse.replica import ReplicaOperator
        op = ReplicaOperator(lm2, drive.time, drive.speed, held, lines="tyre")
        tl = true_tracks(ds, op.x, lm.contacts)
        U = np.zeros((op.n_blocks, op.n_grid))
        for b, blk in enumerate(op.blocks):
            if blk["kind"] == "line":
                U[b] = tl["line_at"](blk["y"])
        Yt = op.forward(U.ravel())
        case["holdout_true_road_nrmse"] = {c: nrmse(Yt[k], chans[c]) for k, c in enumerate(held)}
        c2 = rep2.covered
        case["holdout_corr_L"] = band_correlation(rep2.z_left[c2], truth["L"][c2], dx, BAND)
        case["holdout_corr_R"] = band_correlation(rep2.z_right[c2], truth["R"][c2], dx, BAND)
    return case


def summarise(cases: list) -> dict:
    out = {}
    for fam in sorted({c["family"] for c in cases}):
        cc = [c for c in cases if c["family"] == fam]
        corr = np.array([[c["corr_L"], c["corr_R"]] for c in cc])
        line = np.array([[c["corr_line_L"], c["corr_line_R"]] for c in cc])
        err = np.concatenate([np.abs(c["iri100_relerr_L"] + c["iri100_relerr_R"]) for c in cc])
        ho = [v for c in cc for v in c.get("holdout_nrmse", {}).values()]
        per_q = {}
        for q in ("susp_disp", "axle_acc", "body_acc"):
            v = [x for c in cc for k, x in c.get("holdout_nrmse", {}).items() if k.startswith(q)]
            f = [x for c in cc for k, x in c.get("holdout_true_road_nrmse", {}).items() if k.startswith(q)]
            if v:
                per_q[q] = {"median": float(np.median(v)), "max": float(max(v)),
                            "within_0.3": f"{int(np.sum(np.array(v) <= 0.3))}/{len(v)}",
                            "true_road_median": float(np.median(f)) if f else None,
                            "true_road_max": float(max(f)) if f else None}
        out[fam] = {"drives": len(cc), "corr_min": float(corr.min()), "corr_median": float(np.median(corr)),
                    "corr_line_min": float(line.min()), "corr_line_median": float(np.median(line)),
                    "iri100_abs_relerr_max": float(err.max()) if err.size else None,
                    "iri100_abs_relerr_median": float(np.median(err)) if err.size else None,
                    "iri100_within_10pct": f"{int(np.sum(err <= 0.10))}/{err.size}",
                    "holdout_channels": len(ho),
                    "holdout_nrmse_max": float(max(ho)) if ho else None,
                    "holdout_nrmse_median": float(np.median(ho)) if ho else None,
                    "holdout_within_0.3": f"{int(np.sum(np.array(ho) <= 0.3))}/{len(ho)}" if ho else None,
                    "holdout_by_quantity": per_q,
                    "wall_s_median": float(np.median([c["wall_s"] for c in cc]))}
    return out


def write_md(summary: dict, path: Path, command: str) -> None:
    lines = ["# Road replica benchmark", "", f"Command: `{command}`", "",
             "| family | drives | corr 0.5-20 m min / median | corr (front tyre line) min / median | "
             "IRI 100 m within 10 % | IRI rel. err. median / max | held-out nRMSE median / max (channels) | "
             "held-out <= 0.3 | wall s (median) |", "|---|---|---|---|---|---|---|---|---|"]
    for fam, s in summary.items():
        ho = (f"{s['holdout_nrmse_median']:.3f} / {s['holdout_nrmse_max']:.3f} ({s['holdout_channels']})"
              if s["holdout_channels"] else "-")
        lines.append(f"| {fam} | {s['drives']} | {s['corr_min']:.3f} / {s['corr_median']:.3f} | "
                     f"{s['corr_line_min']:.3f} / {s['corr_line_median']:.3f} | {s['iri100_within_10pct']} | "
                     f"{s['iri100_abs_relerr_median']:.3f} / {s['iri100_abs_relerr_max']:.3f} | {ho} | "
                     f"{s.get('holdout_within_0.3') or '-'} | {s['wall_s_median']:.0f} |")
    lines += ["", "Held-out nRMSE by quantity (axle 2 predicted from the replica of axles 1, 3, 4), and the "
              "same linear model driven by the TRUE road under every tyre line (what the vehicle model allows):",
              "", "| family | quantity | median | max | <= 0.3 | true road: median / max |", "|---|---|---|---|---|---|"]
    for fam, s in summary.items():
        for q, v in s.get("holdout_by_quantity", {}).items():
            tr = (f"{v['true_road_median']:.3f} / {v['true_road_max']:.3f}" if v.get("true_road_median") is not None
                  else "-")
            lines.append(f"| {fam} | {q} | {v['median']:.3f} | {v['max']:.3f} | {v['within_0.3']} | {tr} |")
    path.write_text("\n".join(lines) + "\n")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--families", nargs="+", default=["null:10", "second:5", "random:3"],
                    help="FAMILY:N (seeds 1..N)")
    ap.add_argument("--holdout", type=int, default=3, help="drives per family with the axle-2 hold-out")
    ap.add_argument("--cache", default="/tmp/eroad-replica-bench", help="where the synthetic drives go")
    ap.add_argument("--out", required=True, help="run folder, e.g. results/replica/<date>-<what>")
    ap.add_argument("--lines", choices=("tyre", "track"), default="tyre", help="replica unknowns per side")
    ap.add_argument("--effects", nargs="*", default=[], metavar="FAMILY:NAME=VALUE",
                    help="effects given to the replica's linear model for one family's drives "
                         "(e.g. random:frame_flex=1: what a diagnosis would name)")
    ap.add_argument("--diagnosis", nargs="*", default=[], metavar="FAMILY:PATTERN",
                    help="use the effects named by 'eroad diagnose' run folders, PATTERN with {seed} "
                         "(e.g. random:/tmp/diag/diag-{seed}); the closed-loop rule of eroad replica --effects auto")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    cache = Path(args.cache)
    cache.mkdir(parents=True, exist_ok=True)
    command = "nice python benchmarks/bench_replica.py " + " ".join(argv if argv is not None else sys.argv[1:])
    from eroad.archive import finish_run_info, run_info, write_run_json

    record = run_info("replica_benchmark", run_id=out.name, command=command, seed=None,
                      extra={"families": args.families, "holdout": args.holdout, "lines": args.lines,
                             "effects": args.effects, "diagnosis": args.diagnosis})
    write_run_json(out, record)
    t_start = time.perf_counter()
    cases = []
    jl = out / "cases.jsonl"
    jl.write_text("")
    for item in args.families:
        fam, _, n = item.partition(":")
        for seed in range(1, int(n or 1) + 1):
            eff = [e.split(":", 1)[1] for e in args.effects if e.split(":", 1)[0] == fam]
            verdict = None
            for d in args.diagnosis:
                dfam, pattern = d.split(":", 1)
                if dfam == fam:   # the effects a blind diagnosis of this drive named (the closed-loop rule)
                    from diagnosis.closed_loop import effects_from_diagnosis
                    dsum = json.loads((Path(pattern.format(seed=seed)) / "summary.json").read_text())
                    named, reason = effects_from_diagnosis(dsum)
                    eff += [f"{k}.{pn}={pv!r}" for k, pp in (named or {}).items() for pn, pv in pp.items()]
                    verdict = {"verdict": dsum.get("verdict"), "confidence": dsum.get("verdict_confidence"),
                               "reason": reason}
            case = run_case(fam, seed, cache, holdout=seed <= args.holdout, lines=args.lines, effects=eff)
            if verdict is not None:
                case["diagnosis"] = verdict
            cases.append(case)
            with jl.open("a") as f:
                f.write(json.dumps(case) + "\n")
            print(f"{fam} {seed}: corr L {case['corr_L']:.3f} R {case['corr_R']:.3f}, IRI err "
                  f"{[round(v, 3) for v in case['iri100_relerr_L'] + case['iri100_relerr_R']]}, "
                  f"holdout {case.get('holdout_nrmse')}, {case['wall_s']:.0f} s", flush=True)
            summary = summarise(cases)
            (out / "summary.json").write_text(json.dumps({"command": command, "families": summary}, indent=1))
            write_md(summary, out / "summary.md", command)
    write_run_json(out, finish_run_info(record, "complete", wall_s=time.perf_counter() - t_start))
    return 0


if __name__ == "__main__":
    sys.exit(main())
