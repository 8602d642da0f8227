"""The replica's tyre lines against the truth on the same lines, on fresh drives (stop 74; decision.txt).

    python results/replica/20261201-shortfall/lines_blind.py --out CACHE [--families null:901-904 ...]

Per drive, side and tyre line: ln(replica PSD / truth PSD) of the line over the covered stretch in four
wavelength bands; the line counts as `single` when a single tyre (an axle side with one tyre) runs on it,
else `dual`.  The truth road under a line is read as benchmarks/bench_replica.py reads it (scoring only).
"""
import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.signal import welch

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from benchmarks.bench_replica import true_tracks  # noqa: E402
from drives.format import read_drive  # noqa: E402
from inverse.replica import reconstruct, replica_linear_model, response_channels  # noqa: E402

BANDS = ((20.0, 5.0), (5.0, 2.0), (2.0, 1.0), (1.0, 0.5))


def ln_bands(ze, zt, dx):
    f, pe = welch(ze - ze.mean(), fs=1 / dx, nperseg=1024)
    _, pt = welch(zt - zt.mean(), fs=1 / dx, nperseg=1024)
    return [float(np.log(pe[(f >= 1 / lo) & (f < 1 / sh)].mean() / pt[(f >= 1 / lo) & (f < 1 / sh)].mean()))
            for lo, sh in BANDS]


def single_lines(contacts) -> set:
    """(side, |y|) of the lines an axle side's only tyre runs on."""
    per = {}
    for c in contacts:
        per.setdefault((c["axle"], c["side"]), []).append(abs(c["y"]))
    return {(s, round(ys[0], 3)) for (a, s), ys in per.items() if len(ys) == 1}


def run(family, seed, cache):
    from drives.synth import synth_command

    ds = cache / f"{family}-{seed}"
    if not (ds / "truth" / "summary.json").is_file():
        synth_command(scenario=family, seed=seed, out=ds, force=True)
    d = read_drive(ds)
    ch = {c: d.channels[c].to_numpy(float) for c in response_channels(d.channel_names)}
    lm, _, _ = replica_linear_model(d.vehicle, None, ch, d.sample_rate_hz)
    rep = reconstruct(lm, d.time, d.speed, ch, lines="tyre")
    cov = rep.covered
    dx = float(rep.x[1] - rep.x[0])
    tt = true_tracks(ds, rep.x, lm.contacts)
    singles = single_lines(lm.contacts)
    rows = []
    for side, y, z in rep.lines:
        kind = "single" if (side, round(abs(y), 3)) in singles else "dual"
        rows.append((family, seed, side, y, kind, ln_bands(z[cov], tt["line_at"](y)[cov], dx)))
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--families", nargs="+", default=["null:901-904", "random:901-904", "second:901-904"])
    a = ap.parse_args(argv)
    cache = Path(a.out)
    cache.mkdir(parents=True, exist_ok=True)
    allrows = []
    print("| family | seed | side | line y [m] | kind | " + " | ".join(f"ln PSD {lo:g}-{sh:g} m" for lo, sh in BANDS) + " |")
    print("|---" * (5 + len(BANDS)) + "|", flush=True)
    for spec in a.families:
        fam, rng = spec.split(":")
        lo, hi = (int(v) for v in rng.split("-"))
        for seed in range(lo, hi + 1):
            for r in run(fam, seed, cache):
                allrows.append(r)
                print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:+.2f} | {r[4]} | " + " | ".join(f"{v:+.2f}" for v in r[5]) + " |",
                      flush=True)
    print("\nmedian over drives and sides (n lines):")
    fams = sorted({r[0] for r in allrows}, key=[r[0] for r in allrows].index)
    verdict = {}
    for fam in fams:
        med = {}
        for kind in ("single", "dual"):
            R = np.array([r[5] for r in allrows if r[0] == fam and r[4] == kind])
            if R.size:
                med[kind] = np.median(R, axis=0)
                print(f"  {fam:7s} {kind:6s} ({len(R):2d}) " + "  ".join(
                    f"{lo:g}-{sh:g} m: {v:+.2f}" for (lo, sh), v in zip(BANDS, med[kind])))
        a_ok = "single" in med and abs(med["single"][2]) <= 0.10 and abs(med["single"][3]) <= 0.10
        b_ok = "single" in med and "dual" in med and med["dual"][2] <= med["single"][2] - 0.10
        verdict[fam] = (a_ok, b_ok)
        print(f"  {fam}: bar A (single lines within +-0.10 at 1-2 m and 0.5-1 m) {'holds' if a_ok else 'FAILS'};"
              f" bar B (dual lines >= 0.10 lower at 1-2 m) {'holds' if b_ok else 'FAILS'}")
    ok = all(x and y for x, y in verdict.values())
    print(f"\ndecision.txt: {'every bar holds -> adopt' if ok else 'a bar fails -> no change to the comparison'}")


if __name__ == "__main__":
    main()
