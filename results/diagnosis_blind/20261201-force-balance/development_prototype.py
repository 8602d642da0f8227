"""Prototype: leaf friction from the body's own force balance (road-independent)."""
import sys
import numpy as np
from scipy.signal import butter, sosfiltfilt
from drives.format import read_drive
from vehicles.params import load_vehicle


def estimate(ds, v0=0.01, band=(0.5, 20.0), eqs=("heave", "pitch"), extra=True, vlp=25.0):
    d = read_drive(ds)
    fs = d.sample_rate_hz
    vp = load_vehicle(d.vehicle)
    sos = butter(4, band, btype="band", fs=fs, output="sos")
    lp = butter(4, vlp, fs=fs, output="sos")
    st = []
    for i, a in enumerate(vp.axles):
        for side, sy in (("L", 1.0), ("R", -1.0)):
            c = f"susp_disp_{i + 1}{side}"
            if c not in d.channels:
                continue
            s = d.channels[c].to_numpy(float)
            s = s - s.mean()
            v = np.gradient(sosfiltfilt(lp, s), 1 / fs)
            st.append(dict(x=a.x, y=sy * a.spring_track / 2, k=a.spring_stiffness, c=a.damping,
                           leaf=a.spring_type == "leaf", s=s, v=v,
                           acc=d.channels[f"body_acc_{i + 1}{side}"].to_numpy(float)))
    A = np.array([[1.0, s["x"], s["y"]] for s in st])
    acc = np.array([s["acc"] for s in st])                       # (n_st, N)
    q = np.linalg.lstsq(A, acc, rcond=None)[0]                   # h, p, r
    resid = acc - A @ q
    rb_frac = float(np.mean(sosfiltfilt(sos, resid) ** 2) / np.mean(sosfiltfilt(sos, acc) ** 2))
    rows_y, rows_X = [], []
    for eq in eqs:
        w = np.array([1.0 if eq == "heave" else s["x"] for s in st])
        y = sum(wi * (s["k"] * s["s"] + s["c"] * s["v"]) for wi, s in zip(w, st))
        fr = sum(wi * np.tanh(s["v"] / v0) for wi, s in zip(w, st) if s["leaf"])
        cols = [fr]
        names = ["F"]
        for e2 in eqs:                                            # free inertia coefficients per equation
            pass
        X = [fr, q[0], q[1]]
        if extra:
            X += [sum(wi * s["s"] for wi, s in zip(w, st)), sum(wi * s["v"] for wi, s in zip(w, st))]
        rows_y.append(sosfiltfilt(sos, y))
        rows_X.append([sosfiltfilt(sos, x) for x in X])
    # joint: F shared, the rest per equation
    ne = len(eqs)
    nx = len(rows_X[0])
    N = rows_y[0].size
    Y = np.concatenate(rows_y)
    cols = []
    cols.append(np.concatenate([rx[0] for rx in rows_X]))
    for e in range(ne):
        for j in range(1, nx):
            col = np.zeros(ne * N)
            col[e * N:(e + 1) * N] = rows_X[e][j]
            cols.append(col)
    Xm = np.stack(cols, axis=1)
    sc = np.std(Y)
    beta, *_ = np.linalg.lstsq(Xm / sc, Y / sc, rcond=None)
    r = Y - Xm @ beta
    # sd of F: residual autocorrelated -> block-bootstrap over 1 s blocks
    nb = int(N / fs)
    B = 200
    rng = np.random.default_rng(0)
    Fb = []
    for _ in range(B):
        idx = rng.integers(0, nb, nb)
        sel = np.concatenate([np.arange(b * int(fs), (b + 1) * int(fs)) for b in idx])
        sel = np.concatenate([sel + e * N for e in range(ne)])
        bb, *_ = np.linalg.lstsq(Xm[sel], Y[sel], rcond=None)
        Fb.append(bb[0])
    return -beta[0], float(np.std(Fb)), 1 - np.var(r) / np.var(Y), rb_frac


if __name__ == "__main__":
    for ds in sys.argv[1:]:
        for kw in (dict(), dict(extra=False), dict(eqs=("heave",)), dict(v0=0.03)):
            F, sd, r2, rb = estimate(ds, **kw)
            print(f"{ds.split('/')[-1]:12s} {str(kw):30s} F {F:8.0f} +- {sd:5.0f} N  R2 {r2:.4f}  rigid-body residual {rb:.4f}")
