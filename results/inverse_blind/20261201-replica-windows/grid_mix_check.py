"""Exploration (stop 72): the replica tyre lines against the TRUE road at the reference axle's own tyre positions
(y = +-0.93 m, between the simulator's 0.1 m grid lines) and the ISO truth, per true segment >= 3 s, on the true
window; also with lines="track".  python grid_mix_check.py DATA SEED ... (after replica_windows.py made the data)."""
import json, math, sys
from pathlib import Path
import numpy as np
from benchmarks.bench_inverse import _true_road_fit, reference_axle_x
from drives.format import read_drive
from drives.synth import read_truth
from inverse.replica import reconstruct, replica_linear_model, response_channels, DX
from roadlib.metrics import fit_iso_psd, profile_psd
from roadlib.surface import RoadSurface

def distortion(lm, names, sig, v, alpha, n, fs):
    H = lm.track_frf(n * v, v, names)
    w = (fs * DX / v) / np.asarray(sig) ** 2
    HWH = np.einsum("foa,o,fob->fab", H.conj(), w, H)
    d2 = (2 * np.sin(np.pi * n * DX)) ** 2
    G = HWH + alpha * d2[:, None, None] * np.eye(2)[None]
    Gi = np.linalg.inv(G)
    R = Gi @ HWH
    a = np.abs(R[:, 0, 0]) ** 2 + np.abs(R[:, 0, 1]) ** 2
    b = 2 * DX * np.real((Gi @ HWH @ Gi.conj().transpose(0, 2, 1))[:, 0, 0])
    return a, b, np.real(R[:, 0, 0])

out = []
DATA = Path(sys.argv[1])
for seed in [int(s) for s in sys.argv[2:]]:
    ds = DATA / f"null-{seed}"; blind = DATA / f"null-{seed}-blind"
    truth = read_truth(ds); road = RoadSurface.load(ds / "truth" / "road.npz")
    d = read_drive(blind); names = response_channels(d.channel_names)
    ch = {c: d.channels[c].to_numpy(float) for c in names}
    lm, _, _ = replica_linear_model(d.vehicle, None, ch, d.sample_rate_hz)
    for lines in ("tyre", "track"):
        rep = reconstruct(lm, d.time, d.speed, ch, lines=lines)
        sig = [rep.sigma[c] for c in names]
        x_a1 = float(reference_axle_x(truth, [float(d.time[0])], axle=1)[0])
        for s in truth["segments"]:
            if s["t_end"] - s["t_start"] < 3: continue
            x0, x1 = s["x_start"] - x_a1, s["x_end"] - x_a1
            sel = rep.covered & (rep.x >= x0) & (rep.x < x1)
            if sel.sum() < 64: continue
            band = (s["nmin"], s["nmax"])
            if lines == "tyre":
                z = np.vstack([zl[sel] for _, _, zl in rep.lines]).T; ys = [y if sd == "L" else -y for sd, y, _ in rep.lines]
            else:
                z = np.vstack([rep.z_left[sel], rep.z_right[sel]]).T; ys = None
            pe = profile_psd(z, DX, nperseg=int(sel.sum()))
            fr = fit_iso_psd(pe, band=band)
            tr = _true_road_fit(road, s["x_start"], s["x_end"], band, (-0.93, 0.93))
            g1r = fr.Gd_n0 * 10 ** -fr.w; g1t = tr["Gq"] * 10 ** -tr["w"]; g1iso = s["Gq_n0"] * 10 ** -s["w"]
            tsel = (d.time >= s["t_start"]) & (d.time < s["t_end"])
            v = float(np.median(d.speed[tsel]))
            a, b, R = distortion(lm, names, sig, v, rep.alpha, np.array([1.0]), d.sample_rate_hz)
            out.append({"seed": seed, "lines": lines, "cls": s["class"] if "class" in s else "", "v": v,
                        "ln_r": math.log(g1r / g1t), "ln_iso": math.log(g1r / g1iso), "ln_real_iso": math.log(g1t / g1iso),
                        "ln_pred": math.log(a[0] + b[0] / g1t), "R": float(R[0]), "a": float(a[0]), "b_over_S": float(b[0] / g1t)})
    print(seed, flush=True)
json.dump(out, open("grid_mix_check_1-10.json", "w"))
