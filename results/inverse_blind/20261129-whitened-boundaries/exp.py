"""Segmentation-only experiment: whitened band power vs the default (design drives)."""
import glob, json, sys, math
import numpy as np
from scipy.signal import welch, butter, sosfreqz
sys.path.insert(0, '.')   # run from the repository root
import inverse.segmentation as S
from drives.format import read_drive

def whiten(x, fs, f_hp, f_lp, nper_s=2.0, order=4):
    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    f, p = welch(x, fs, nperseg=int(nper_s * fs))
    fr = np.fft.rfftfreq(n, 1 / fs)
    pi = np.exp(np.interp(fr, f, np.log(np.maximum(p, 1e-300))))
    sos = butter(order, [f_hp, f_lp], btype="bandpass", fs=fs, output="sos")
    _, h = sosfreqz(sos, worN=fr, fs=fs)
    g = np.abs(h) ** 2 / np.sqrt(pi)
    y = np.fft.irfft(np.fft.rfft(x) * g, n)
    return y / np.sqrt(np.mean(y * y))

def neff_cross(sigs, fs, T, nper_s=8.0):
    # 2 T (int tr S)^2 / int ||S||_F^2  (one-sided, as effective_bandwidth)
    from scipy.signal import csd
    J = len(sigs); nper = int(nper_s * fs)
    tr = 0; fro = 0
    for a in range(J):
        for b in range(J):
            f, s = csd(sigs[a], sigs[b], fs, nperseg=nper)
            df = f[1] - f[0]
            if a == b: tr = tr + s.real
            fro = fro + np.abs(s) ** 2
    return 2 * T * (tr.sum() * df) ** 2 / (fro.sum() * df)

def core(y, n_eff, n, min_len, penalty=1.0, kmax=8):
    scale = n_eff / n
    back, final = S._partition_all(y, min(kmax, n // min_len), min_len, "variance")
    crit = [scale * c + penalty * 2 * (i + 1) * math.log(n_eff) for i, c in enumerate(final)]
    b = S._backtrack(back, int(np.argmin(crit)) + 1, n)
    return b

def run(item, variant, penalty=1.0):
    tr, t, ch, v, fs = item
    step = int(round(fs / 20.0)); nb = t.size // step
    vnorm = (np.maximum(v, 1e-3) / np.mean(v)) ** 1.0
    T = t[-1] - t[0] + 1 / fs
    if variant == "default":
        return S.segment(t, {k: ch[k] for k in ("susp_disp_3L", "susp_disp_3R")}, v, penalty=penalty).t_bounds
    names, kind, neffkind = variant.split(":")
    sel = {"d3": ["susp_disp_3L", "susp_disp_3R"], "dall": [c for c in ch if c.startswith("susp_disp_")],
           "a3": ["axle_acc_3L", "axle_acc_3R"], "aall": [c for c in ch if c.startswith("axle_acc_")]}[names]
    if kind == "white":
        sigs = [whiten(ch[c], fs, 3.0, 20.0) for c in sel]
    else:
        sigs = [S.band_pass(ch[c], fs, 3.0, 20.0) for c in sel]
        sigs = [s / np.sqrt(np.mean(s * s)) for s in sigs]
    sq = np.mean([s ** 2 for s in sigs], axis=0) / vnorm
    y = sq[:nb * step].reshape(nb, step).mean(axis=1)
    if neffkind == "mean":
        n_eff = 2 * np.mean([S.effective_bandwidth(s, fs) for s in sigs]) * T
    else:
        n_eff = neff_cross(sigs, fs, T)
    b = core(y, n_eff, nb, 10, penalty)
    return np.concatenate([[t[0]], t[b[1:-1] * step], [t[-1]]]), n_eff

def score(items, variant, penalty=1.0):
    kr = kl = kh = 0; found = ntrue = spur = nfit = 0; ne = []
    for it in items:
        tr = it[0]
        r = run(it, variant, penalty)
        if isinstance(r, tuple): tf, n_eff = r; ne.append(n_eff)
        else: tf = r
        ts = tr['segments']; tt = np.array([s['t_end'] for s in ts[:-1]])
        K, Kf = len(ts), len(tf) - 1
        kr += K == Kf; kl += Kf < K; kh += Kf > K
        fb = np.asarray(tf[1:-1])
        for b in tt:
            ntrue += 1; found += fb.size > 0 and np.min(np.abs(fb - b)) < 0.5
        for b in fb:
            nfit += 1; spur += tt.size == 0 or np.min(np.abs(tt - b)) > 1.0
    print(f'{variant:22s} pen {penalty}: K right {kr} low {kl} high {kh}; found {found}/{ntrue}; fitted {nfit}, spurious(>1s) {spur}; n_eff {np.mean(ne) if ne else float("nan"):.0f}', flush=True)

if __name__ == "__main__":
    root = sys.argv[1]; seeds = range(int(sys.argv[2]), int(sys.argv[3]))
    items = []
    for s in seeds:
        d = f"{root}/null-{s}"
        if not glob.glob(f'{d}/truth/truth.json'): continue
        tr = json.load(open(f'{d}/truth/truth.json')); dr = read_drive(d)
        t = np.asarray(dr.time, float)
        items.append((tr, t, {c: dr.channels[c].to_numpy() for c in dr.channels.columns if c.startswith(("susp_disp_", "axle_acc_"))}, np.asarray(dr.speed), 1 / np.mean(np.diff(t))))
    print(len(items), "drives")
    for var in sys.argv[4:]:
        v, _, pen = var.partition("@")
        score(items, v, float(pen) if pen else 1.0)
