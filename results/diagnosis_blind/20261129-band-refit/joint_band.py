"""The road band as a joint parameter of the model, read off diagnoses already made: per drive,
the lowest held-out gap any ranked model reaches (the nominal model included) on the band the
diagnosis fitted and on a road cut at 2 cycles/m (twin_check.py --nmax=2, the measured profile's
band), and which band that joint choice would take.

Sources (no new simulation here):
  * fitted band of the 12 drives of ../20261129-fresh-40-share and of drive 241112 of
    ../20261128-veto-fresh-40: their committed case summaries (every ranked model's held-out gap);
  * fitted band of the 7 measured-profile friction drives and 4 full-band high-force friction
    drives: twin_check.py records ("as-is"; the ranking's first four, held-out gap =
    nominal x (1 - shrink), shrink rounded to 3 digits);
  * cut band: twin_check.py --nmax=2 records (same form).
A difference below 1 % is "same" (the two diagnoses ran the same band).

Usage: python joint_band.py [--fresh]   (one line per drive and the counts; --fresh: the 18 drives
of this folder's fresh set, first pass against records/fresh/, stated in decision.txt before it ran)
"""
import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
SETS = [HERE.parent / "20261129-fresh-40-share", HERE.parent / "20261128-veto-fresh-40"]
TWIN = HERE.parent / "20261129-twin-tracks" / "records"


def from_record(path):
    r = json.loads(Path(path).read_text())
    b = float(r["heldout_gap_before"])
    best = min(r["ranking"], key=lambda x: b * (1 - x[2]))
    return dict(truth=r["truth"], value=r["truth_value"], scenario=r["scenario"], nominal=b,
                best=best[0], best_gap=b * (1 - best[2]), verdict=r["verdict"])


def fitted_from_share():
    out = {}
    for root in SETS:
        for fam in ("nominal", "second"):
            for r in json.loads((root / fam / "blind.json").read_text())["results"]:
                s = json.loads((root / fam / f"case{r['case']:03d}-summary.json").read_text())
                best = min(s["ranking"], key=lambda e: e["heldout_gap_after"])
                out.setdefault(int(r["seed"]), dict(
                    truth=r["effect"], value=r["value"], scenario=r["scenario"],
                    nominal=float(s["nominal"]["heldout_gap"]), best=best["effect"],
                    best_gap=float(best["heldout_gap_after"]), verdict=s["verdict"]))
    return out


def fitted_from_fresh(folder):
    """The fresh set of this folder: the first pass (today's rules) of each drive; where the
    band refit made a second pass, the first pass's ranking kept in meta.band_refit."""
    out = {}
    for r in json.loads((folder / "blind.json").read_text())["results"]:
        s = json.loads((folder / f"case{r['case']:03d}-summary.json").read_text())
        first = (s["meta"].get("band_refit") or {}).get("first_pass")
        ranking = first["ranking"] if first else s["ranking"]
        verdict = first["verdict"] if first else s["verdict"]
        before = float(ranking[0]["heldout_gap_before"]) if ranking else float(s["nominal"]["heldout_gap"])
        best = min(ranking, key=lambda e: e["heldout_gap_after"])
        out[int(r["seed"])] = dict(truth=r["effect"], value=r["value"], scenario=r["scenario"],
                                   nominal=before, best=best["effect"],
                                   best_gap=float(best["heldout_gap_after"]), verdict=verdict)
    return out


def main(fresh=False):
    """``fresh``: the 18 drives of this folder's fresh set (records/fresh/), else the 23 before."""
    if fresh:
        share, cuts = fitted_from_fresh(HERE / "second"), sorted((HERE / "records" / "fresh").glob("*-nmax2.json"))
    else:
        share = fitted_from_share()
        cuts = sorted((HERE / "records").glob("*-nmax2.json")) + sorted(TWIN.glob("*-nmax2.json"))
    rows = []
    for cut in cuts:
        seed = int(cut.name.split("-")[0])
        c = from_record(cut)
        as_is = [p for p in (HERE / "records" / f"{seed}-as-is.json", TWIN / f"{seed}-as-is.json") if p.is_file()]
        f = from_record(as_is[0]) if as_is else share.get(seed)
        if f is None:
            continue
        gf, gc = min(f["nominal"], f["best_gap"]), min(c["nominal"], c["best_gap"])
        pick = "same" if abs(gc / gf - 1) < 0.01 else ("cut" if gc < gf else "fitted")
        rows.append((seed, c["scenario"], c["truth"], c["value"], f, c, gc / gf, pick))
    for seed, scen, truth, val, f, c, ratio, pick in rows:
        print(f"{seed} {scen:15s} {truth:15s} {'' if val is None else str(val)[:14]:14s} fitted band: "
              f"nominal {f['nominal']:.2f}, best {f['best']} {f['best_gap']:.2f} ({f['verdict']}) | "
              f"cut at 2: nominal {c['nominal']:.2f}, best {c['best']} {c['best_gap']:.2f} "
              f"({c['verdict']}) | cut/fitted {ratio:.2f} -> {pick}")
    for kind, sel in (("measured profile", lambda r: r[1] == "second_measured"),
                      ("full-band roads", lambda r: r[1] != "second_measured")):
        rs = [r for r in rows if sel(r)]
        print(f"{kind}: {len(rs)} drives, joint choice cut {sum(r[7] == 'cut' for r in rs)}, fitted "
              f"{sum(r[7] == 'fitted' for r in rs)}, same {sum(r[7] == 'same' for r in rs)}; "
              f"cut/fitted gap ratio {min(r[6] for r in rs):.2f}-{max(r[6] for r in rs):.2f}")


if __name__ == "__main__":
    import sys

    main(fresh="--fresh" in sys.argv[1:])
