"""Does the road's lateral structure confound the diagnosis on the measured-profile drives?

A counterfactual: the same blind drive diagnosed twice, with the diagnosis's simulations as they are (twin
tyres read the isotropic surface at their own lateral positions) and with every twin tyre of a side
reading ONE track (the wheel station's centre line: vehicles.simulate.road_under_tyres patched in this
process; the pool's workers fork after the patch).  The measured-profile road of the independent truck
puts a side's twin tyres on one profile (results/roads/20261129-measured-lateral/).

--w-range=LO,HI: the diagnosis's waviness range (pipeline.W_RANGE, 1.2-3.0) set to LO-HI, e.g. the
inversion's published 1.5-3.5.
--nmax=N: every segment's nmax fixed at N cycles/m instead of fitted (pipeline.fit_nmax replaced; the
measured profile holds nothing above 2: a truth-informed counterfactual).
--road-fit=inverse: the diagnosis's road is the inversion's fit of the whole record (``diagnose(road_fit=
"inverse")``, an existing option, not the default) instead of its own level-and-waviness fit.
--mixed-road: the diagnosis's road built as the measured-profile road is, from two unrelated ISO profiles
mixed linearly across the width (the whole lateral structure of that road, not only the twins).

Usage: python twin_check.py WORK SEED:SCENARIO:EFFECT[:PARAM=VALUE] ...   [--twins-one-track | --mixed-road]
Writes WORK/<seed>-<mode>.json (verdict, confidence, ranking summary, wall time).
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))


def _one_track_per_side(road_under_tyres):
    """``vehicles.simulate.road_under_tyres`` with each side's tyres of one axle on one track (their mean y):
    the original, handed the model with those tyres moved."""
    from dataclasses import replace
    from types import SimpleNamespace

    def wrapped(road, model, x_start, y_offset, s, v):
        ys = {}
        for ct in model.contacts:
            ys.setdefault((ct.axle, np.sign(ct.y)), []).append(ct.y)
        moved = [replace(ct, y=float(np.mean(ys[(ct.axle, np.sign(ct.y))]))) for ct in model.contacts]
        return road_under_tyres(road, SimpleNamespace(vp=model.vp, contacts=moved), x_start, y_offset, s, v)
    return wrapped


def _mixed_road_patch():
    """The diagnosis's road built as the measured-profile road is (drives.synth.build_profile_road), from
    two unrelated ISO profiles instead of one measured profile and its 40 m shift:
    z(x, y) = a(y) p1(x) + (1 - a(y)) p2(x), a = 0.5 + y / width; p1, p2 the centre tracks of the
    diagnosis's own surface for this seed and for another seed (same segments)."""
    from diagnosis import pipeline
    from roadlib.surface import RoadSurface

    orig = pipeline.TruckModel._road

    def _road(self, t0, t1, seed, gq):
        r1 = orig(self, t0, t1, seed, gq)
        r2 = orig(self, t0, t1, int(seed) + 7777, gq)
        width = float(r1.y[-1] - r1.y[0])
        a = 0.5 + r1.y / width
        p1, p2 = r1.track(0.0), r2.track(0.0)
        return RoadSurface(r1.x, r1.y, a[None, :] * p1[:, None] + (1 - a[None, :]) * p2[:, None], dict(r1.meta))
    pipeline.TruckModel._road = _road


def main(argv):
    twins = "--twins-one-track" in argv
    mixed = "--mixed-road" in argv
    wr = next((a for a in argv if a.startswith("--w-range=")), None)
    nx = next((a for a in argv if a.startswith("--nmax=")), None)
    rf = "inverse" if "--road-fit=inverse" in argv else "levels"
    argv = [a for a in argv if a not in ("--twins-one-track", "--mixed-road", "--road-fit=inverse", wr, nx)]
    if nx:   # every segment's nmax fixed (the truth's band, a counterfactual: the diagnosis cannot know it)
        import numpy as np_
        from diagnosis import pipeline as pl
        val = float(nx.split("=", 1)[1])

        def _fixed_nmax(model, sig, gq, seed=0, diag=None, mapper=map):
            out = np_.full(len(model.bounds) - 1, val)
            model.nmax = out
            model.high_band = {"cut": list(range(out.size)), "rolloff": [], "vetoed": False}
            return out
        pl.fit_nmax = _fixed_nmax
    if wr:   # the diagnosis's waviness range (diagnosis.pipeline.W_RANGE, 1.2-3.0) set to LO,HI
        from diagnosis import pipeline
        pipeline.W_RANGE = tuple(float(x) for x in wr.split("=", 1)[1].split(","))
    if twins:
        import vehicles.simulate as vs
        vs.road_under_tyres = _one_track_per_side(vs.road_under_tyres)
    if mixed:
        _mixed_road_patch()
    from diagnosis.blind import BLIND_SETTINGS
    from diagnosis.pipeline import diagnose
    from drives.synth import copy_without_truth, synth_command

    work = Path(argv[0])
    work.mkdir(parents=True, exist_ok=True)
    mode = "mixed-road" if mixed else "twins-one-track" if twins else "as-is"
    if wr:
        mode = "w" + wr.split("=", 1)[1].replace(",", "-") + ("" if mode == "as-is" else "-" + mode)
    if rf == "inverse":
        mode = "road-inverse" + ("" if mode == "as-is" else "-" + mode)
    if nx:
        mode = "nmax" + nx.split("=", 1)[1] + ("" if mode == "as-is" else "-" + mode)
    for spec in argv[1:]:
        parts = spec.split(":")
        seed, scen, eff = int(parts[0]), parts[1], parts[2]
        effects = [f"{eff}.{parts[3]}"] if len(parts) > 3 else []
        ds, blind = work / f"{seed}", work / f"{seed}-blind"
        if not (ds / "truth" / "summary.json").is_file():
            synth_command(scenario=scen, seed=seed, effects=effects, out=ds, force=True, duration=None)
        if not blind.exists():
            copy_without_truth(ds, blind)
        t = time.perf_counter()
        summ = diagnose(blind, work / f"{seed}-run-{mode}", workers=2, force=True, settings=dict(BLIND_SETTINGS),
                        road_fit=rf, progress=lambda m: None)
        wall = time.perf_counter() - t
        det = summ.get("verdict_detail") or {}
        rank = [(e["effect"], e.get("parameters"), round(float(e.get("shrink_fraction", 0)), 3))
                for e in summ.get("ranking", [])[:4]]
        out = {"seed": seed, "scenario": scen, "truth": eff, "truth_value": parts[3] if len(parts) > 3 else None,
               "mode": mode, "verdict": summ["verdict"], "confidence": summ.get("verdict_confidence"),
               "ranking_verdict": det.get("ranking_verdict"), "explained_share": det.get("explained_share"),
               "heldout_gap_before": summ["nominal"]["heldout_gap"], "null_sd": summ["nominal"]["null_gap_std"],
               "ranking": rank, "wall_s": round(wall, 1)}
        (work / f"{seed}-{mode}.json").write_text(json.dumps(out, indent=1))
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
