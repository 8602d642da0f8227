"""What the axle accelerations hold about a segment's road spectrum: a bin-level (Whittle) fit
of the linear model's expected periodogram, on the TRUE segments of `null` drives (issue 14,
stop 54).  An experiment, not the inversion: it is given the true boundaries, the truth's band
([0.1, 5] cycles/m: the analysis band is kept inside it) and the true sensor-noise level, so it
measures the estimator's efficiency about a segment, not the segmentation or the band search.

Per true segment >= 3 s (axle 3 is the reference axle, so its boundaries are exact for it):
axle_acc_3L and axle_acc_3R over the segment, Tukey(0.2) taper, periodogram I_k at f_k = k / T in
[max(1.5 Hz, 0.12 v_max), min(fmax, 4.8 v_min)] (fmax 45 Hz unless --fmax) (so n = f / v stays inside [0.1, 5] cycles/m).
Expected periodogram E_k = Gq P_k(w) + N: P_k(w) the linear nominal model's response PSD
(vehicles.linear, road Gq = 1 with waviness w, the surface coherence of the scenario, lam = 1)
averaged over the segment's speed samples (three speed quantiles), N the sensor noise PSD
(0.03 m/s^2 white at 200 Hz: sigma^2 / 100).  Whittle negative log-likelihood
sum_k ln E_k + I_k / E_k of both channels (their correlation ignored), minimised over ln Gq for
each w on a grid 1.2-3.0 (step 0.02), then the best w refined by a parabola through the
profile's three lowest neighbours (ln Gq interpolated likewise).  Scored like bench_inverse: class of Gq,
G(1 cycle/m) within 20 %, w error.

Usage (repository root): python results/inverse_blind/20261129-response-whittle/response_whittle.py DATA_ROOT [--seeds A B]
DATA_ROOT holds null-SEED datasets (made here with drives.synth.synth_command when missing).
"""
import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.signal.windows import tukey

sys.path.insert(0, ".")
from drives.format import read_drive                    # noqa: E402
from drives.synth import read_truth, synth_command      # noqa: E402
from roadlib.psd import N0, class_of                    # noqa: E402
from vehicles.linear import linear_model                # noqa: E402

CHANNELS = ["axle_acc_3L", "axle_acc_3R"]
W_GRID = np.round(np.arange(1.2, 3.0001, 0.02), 3)
NOISE_PSD = 0.03 ** 2 / 100.0


def periodograms(acc, m):
    """Tukey(0.2)-tapered one-sided periodograms [unit^2/Hz] of the channels ``acc`` over the samples
    ``m`` (200 Hz), each with its mean removed: (f, I) with I of shape (channels, nf)."""
    win = tukey(m.sum(), 0.2)
    scale = 1.0 / (200.0 * np.sum(win ** 2))
    f = np.fft.rfftfreq(m.sum(), 1 / 200.0)
    I = []
    for a in acc:
        x = a[m] - a[m].mean()
        I.append(2 * scale * np.abs(np.fft.rfft(x * win)) ** 2)
    return f, np.array(I)


def expected_psd(lm, H, f, road, speeds):
    """The linear model's response PSD of the channels of ``H`` (nf, channel, contact) for the road
    dict ``road``, averaged over ``speeds``: shape (channels, nf)."""
    P = np.zeros((H.shape[1], f.size))
    for sp in speeds:
        S = lm.road_cross_spectrum(road, sp, f)
        P += np.einsum("fod,fod->fo", H @ S, H.conj()).real.T / len(speeds)
    return P


def fit_segment(lm, H, t, acc, v, t0, t1, fmax=45.0):
    m = (t >= t0) & (t < t1)
    vs = v[m]
    T = m.sum() / 200.0
    f_lo, f_hi = max(1.5, 0.12 * vs.max()), min(fmax, 4.8 * vs.min())
    f, I = periodograms(acc, m)
    band = (f >= f_lo) & (f <= f_hi)
    fb = f[band]
    I = I[:, band]                                       # (2, nb)
    Hb = H[band] if H is not None else None
    speeds = np.quantile(vs, [1 / 6, 0.5, 5 / 6])
    prof, lgs = [], []
    for w in W_GRID:
        P = expected_psd(lm, Hb, fb, {"Gq_n0": 1.0, "w": float(w), "nmin": 0.01, "nmax": 100.0, "lam": 1.0}, speeds)

        def nll(lg):
            E = math.exp(lg) * P + NOISE_PSD
            return float(np.sum(np.log(E) + I / E))
        r = minimize_scalar(nll, bounds=(math.log(1e-8), math.log(1e-1)), method="bounded",
                            options={"xatol": 1e-6})
        prof.append(r.fun)
        lgs.append(r.x)
    prof = np.array(prof)
    i = int(np.argmin(prof))
    w_best, lg_best = float(W_GRID[i]), float(lgs[i])
    if 0 < i < W_GRID.size - 1:
        y0, y1, y2 = prof[i - 1:i + 2]
        den = y0 - 2 * y1 + y2
        if den > 0:
            d = 0.5 * (y0 - y2) / den                   # offset in grid steps, |d| <= 0.5
            w_best += d * (W_GRID[1] - W_GRID[0])
            lg_best += d * (lgs[i + 1] - lgs[i - 1]) / 2 if d else 0.0
    return {"Gq": math.exp(lg_best), "w": w_best, "n_bins": int(band.sum()), "f_band": [float(f_lo), float(f_hi)],
            "T": float(T), "w_at_edge": i in (0, W_GRID.size - 1)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("data_root")
    ap.add_argument("--seeds", nargs=2, type=int, default=[101, 140])
    ap.add_argument("--out", default=None)
    ap.add_argument("--fmax", type=float, default=45.0, help="top of the analysis band [Hz] (default 45)")
    a = ap.parse_args()
    root = Path(a.data_root)
    lm = linear_model("dump_truck_8x4")
    rows = []
    for seed in range(a.seeds[0], a.seeds[1] + 1):
        ds = root / f"null-{seed}"
        if not (ds / "truth" / "truth.json").is_file():
            synth_command(scenario="null", seed=seed, out=ds, force=True)
        dr = read_drive(ds)
        tr = read_truth(ds)
        t = np.asarray(dr.time, float)
        v = np.asarray(dr.speed, float)
        acc = [dr.channels[c].to_numpy() for c in CHANNELS]
        for s in tr["segments"]:
            t0, t1 = s["t_start"], s["t_end"]
            if t1 - t0 < 3.0:
                continue
            m = (t >= t0) & (t < t1)
            f = np.fft.rfftfreq(m.sum(), 1 / 200.0)
            H = lm.frf(f, CHANNELS)                     # (nf, channel, contact)
            r = fit_segment(lm, H, t, acc, v, t0, t1, a.fmax)
            g1 = lambda Gq, w: math.log(Gq) - w * math.log(1.0 / N0)
            row = dict(seed=seed, duration_s=t1 - t0, Gq_true=s["Gq_n0"], w_true=s["w"], class_true=class_of(s["Gq_n0"]),
                       Gq_fit=r["Gq"], w_fit=r["w"], class_fit=class_of(r["Gq"]),
                       lnG1_err=g1(r["Gq"], r["w"]) - g1(s["Gq_n0"], s["w"]), **{k: r[k] for k in ("n_bins", "f_band", "w_at_edge")})
            rows.append(row)
            print(f"seed {seed} {t1 - t0:5.1f} s class {row['class_true']}->{row['class_fit']} "
                  f"lnGq err {math.log(r['Gq'] / s['Gq_n0']):+.3f} w {s['w']:.2f}->{r['w']:.2f} lnG1 err {row['lnG1_err']:+.3f} "
                  f"bins {r['n_bins']} band {r['f_band'][0]:.1f}-{r['f_band'][1]:.1f} Hz", flush=True)
    if a.out:
        Path(a.out).write_text("".join(json.dumps(r) + "\n" for r in rows))
    e1 = np.array([r["lnG1_err"] for r in rows])
    ew = np.array([r["w_fit"] - r["w_true"] for r in rows])
    eg = np.array([math.log(r["Gq_fit"] / r["Gq_true"]) for r in rows])
    print(f"{len(rows)} segments >= 3 s: class right {100 * np.mean([r['class_fit'] == r['class_true'] for r in rows]):.1f} %, "
          f"G(1 cycle/m) within 20 % {100 * np.mean(np.abs(e1) <= math.log(1.2)):.1f} %, "
          f"sd ln G(1) {e1.std():.3f} (mean {e1.mean():+.3f}), sd ln Gq(n0) {eg.std():.3f} (mean {eg.mean():+.3f}), "
          f"sd w {ew.std():.3f} (mean {ew.mean():+.3f}); w at a grid edge {sum(r['w_at_edge'] for r in rows)}")


if __name__ == "__main__":
    main()
