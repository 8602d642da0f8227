"""How much of the inversion's measured-profile bias the measured road's lateral structure explains.

The measured-profile road (drives.synth.build_profile_road) is z(x, y) = a(y) p(x) + (1 - a(y)) p(x + 40 m),
a(y) = 0.5 + y / W.  p(x) and p(x + 40 m) are unrelated at the wavelengths the truck responds to, so the
cross spectrum of the heights under tyres i and j is

    S_ij(n) = G_p(n) [a_i a_j + (1 - a_i)(1 - a_j)]          (exact up to the 40 m cross term)

and the scoring truth is the PSD of the tracks at y = +-0.93 m, G_t = (a^2 + (1 - a)^2) G_p.  The inversion
assumes instead an isotropic surface: S_ij = G_t gamma_iso(n, |y_i - y_j|).  For each segment an inversion
fitted, this script gives the linear truck's band power of each fitted channel under both structures, at the
fitted spectrum and the segment's mean speed, and the level shift that the inversion would make by reading the
measured road's responses with the isotropic model: dln G = mean over channels of ln(P_measured / P_iso).
That is the predicted bias, compared with the bias the inversion showed (fit against the profile under the
segment, bench_inverse.profile_scores).

Usage: python coherence_check.py ROOT [ROOT ...]   (ROOT: a bench_inverse.py --scenario second_measured root)
"""
import json
import sys
from pathlib import Path

import numpy as np


def measured_structure(lm, width):
    """Cross-spectrum weights a_i a_j + (1 - a_i)(1 - a_j) of the contacts, relative to the truth track."""
    from benchmarks.bench_inverse import REF_TRACK_Y
    from drives.synth import profile_mix_weight
    ys = np.array([c["y"] for c in lm.contacts])
    a = profile_mix_weight(ys, width)
    W = a[:, None] * a[None, :] + (1 - a[:, None]) * (1 - a[None, :])
    at = profile_mix_weight(REF_TRACK_Y[1], width)
    return W / (at ** 2 + (1 - at) ** 2)


def cross_spectra(lm, road, v, f, Wm):
    """Road cross spectra under the tyres: isotropic (assumed), measured-road structure, and the measured
    structure on one part only (same side: the dual tyres of a side; cross side: left against right)."""
    iso = lm.road_cross_spectrum(road, v, f, "surface")
    meas = lm.road_cross_spectrum(road, v, f, "correlated") * Wm[None]
    ys = np.array([c["y"] for c in lm.contacts])
    same = (np.sign(ys)[:, None] == np.sign(ys)[None, :])[None]
    return {"measured": meas, "same side only": np.where(same, meas, iso),
            "cross side only": np.where(same, iso, meas)}, iso


def band_log_ratios(lm, road, v, chans, band, Wm, n_freq=600):
    """Mean over the channels of ln(band power under a structure / under the isotropic surface)."""
    f = np.geomspace(band[0], band[1], n_freq)
    alts, iso = cross_spectra(lm, road, v, f, Wm)
    H = lm.frf(f, chans)

    def power(S):
        P = np.einsum("foi,fij,foj->fo", H, S, H.conj()).real
        return np.trapezoid(P, f, axis=0)
    p0 = power(iso)
    return {k: float(np.mean(np.log(power(S) / p0))) for k, S in alts.items()}


AT_1CPM = False


def main(roots):
    from vehicles.linear import linear_model
    rows = []
    for root in map(Path, roots):
        for line in (root / "results.jsonl").read_text().splitlines():
            case = json.loads(line)
            if case.get("scenario") != "second_measured" or "profile" not in case:
                continue
            summ = json.loads((root / f"run-{case['seed']}" / "summary.json").read_text())
            width = 3.0                      # [road] width_m of the second_measured scenario
            lm = linear_model(summ["dataset"]["vehicle"], "rigid")
            Wm = measured_structure(lm, width)
            chans = [c for c in summ["fit"]["channels"] if c in lm.channel_names]
            speeds = [r["speed_mps"] for r in summ["lateral"]["segments"]]
            for s, pr, v in zip(summ["segments"], case["profile"], speeds):
                if pr["duration_s"] < 3 or "lnG_1cpm_err" not in pr:
                    continue
                road = {k: float(s[k]) for k in ("Gq_n0", "w", "nmin", "nmax")}
                band = (max(0.5, road["nmin"] * v), min(40.0, road["nmax"] * v))
                if AT_1CPM:   # the third octave around 1 cycle/m (f = v), where the error is scored
                    band = (v / 2 ** (1 / 6), v * 2 ** (1 / 6))
                lr = band_log_ratios(lm, road, v, chans, band, Wm)
                d = lr["measured"]
                rows.append((case["seed"], s["t_start"], s["t_end"], v, d, pr["lnG_1cpm_err"],
                             lr["same side only"], lr["cross side only"]))
                print(f"seed {case['seed']} {s['t_start']:6.1f}-{s['t_end']:6.1f} s  v {v:5.2f} m/s  "
                      f"predicted bias dln G {d:+.3f} (duals only {lr['same side only']:+.3f}, left/right only "
                      f"{lr['cross side only']:+.3f})   observed ln G(1) error vs profile {pr['lnG_1cpm_err']:+.3f}",
                      flush=True)
    r = np.array([x[4:8] for x in rows])
    print(f"\n{len(r)} segments >= 3 s: predicted mean {r[:, 0].mean():+.3f}, observed mean {r[:, 1].mean():+.3f} "
          f"(median {np.median(r[:, 1]):+.3f}); observed minus predicted mean {np.mean(r[:, 1] - r[:, 0]):+.3f} "
          f"sd {np.std(r[:, 1] - r[:, 0]):.3f}; "
          f"predicted from the dual tyres' structure alone {r[:, 2].mean():+.3f}, from left/right alone "
          f"{r[:, 3].mean():+.3f}; correlation predicted/observed over segments {np.corrcoef(r[:, 0], r[:, 1])[0, 1]:+.2f}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
    args = sys.argv[1:]
    if args and args[0] == "--at-1cpm":
        AT_1CPM = True
        args = args[1:]
    main(args)
