"""Independent reference for the quarter truck of ``inverse.quarter`` (test helper).

Nothing here calls ``inverse.quarter``'s frequency responses or simulator: the 2-DOF
quarter car is assembled from its physical parameters as mass, damping and stiffness
matrices, and its response is computed (a) by a complex matrix solve per frequency,
(b) by time integration of a state-space model with ``scipy.signal.lsim``, and (c) by
hand formulas for its natural frequencies and limits.  The tests compare
``inverse.quarter`` against these.

Model (sprung mass ms at zs, unsprung mass mu at zu, road zr; up positive)::

    ms zs'' = -ks (zs - zu) - cs (zs' - zu')
    mu zu'' = +ks (zs - zu) + cs (zs' - zu') - kt (zu - zr) - ct (zu' - zr')

i.e. M q'' + C q' + K q = Kr zr + Cr zr' with q = (zs, zu).  Outputs:
``susp_disp`` = zu - zs (compression positive), ``axle_acc`` = zu'', ``body_acc`` = zs''.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.signal import lsim

QUANTITIES = ("susp_disp", "axle_acc", "body_acc")


def matrices(p):
    """M, C, K (2 x 2) and the road input vectors Kr, Cr (2,) of the quarter car."""
    M = np.diag([p.ms, p.mu])
    K = np.array([[p.ks, -p.ks], [-p.ks, p.ks + p.kt]])
    C = np.array([[p.cs, -p.cs], [-p.cs, p.cs + p.ct]])
    Kr = np.array([0.0, p.kt])
    Cr = np.array([0.0, p.ct])
    return M, C, K, Kr, Cr


def frf_matrix(p, f) -> dict:
    """Frequency responses road height -> outputs by solving (K + i w C - w^2 M) X = Kr + i w Cr.

    Returns
    -------
    dict
        quantity -> complex (len(f),) array.
    """
    M, C, K, Kr, Cr = matrices(p)
    f = np.atleast_1d(np.asarray(f, dtype=float))
    out = {q: np.empty(f.size, complex) for q in QUANTITIES}
    for i, fi in enumerate(f):
        w = 2.0 * math.pi * fi
        X = np.linalg.solve(K + 1j * w * C - w ** 2 * M, Kr + 1j * w * Cr)
        out["susp_disp"][i] = X[1] - X[0]
        out["axle_acc"][i] = -w ** 2 * X[1]
        out["body_acc"][i] = -w ** 2 * X[0]
    return out


def state_space(p):
    """(A, B, C, D) with state (zs, zu, zs', zu'), input (zr, zr'), output QUANTITIES."""
    M, C, K, Kr, Cr = matrices(p)
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((2, 2)), np.eye(2)], [-Mi @ K, -Mi @ C]])
    B = np.vstack([np.zeros((2, 2)), Mi @ np.column_stack([Kr, Cr])])
    Cout = np.vstack([[-1.0, 1.0, 0.0, 0.0], A[3], A[2]])
    Dout = np.vstack([[0.0, 0.0], B[3], B[2]])
    return A, B, Cout, Dout


def simulate_ode(p, t, zr, zr_dot) -> dict:
    """Time response from rest to a road input (lsim, input linear between samples).

    Parameters
    ----------
    p : QuarterTruckParams-like (ms, mu, ks, cs, kt, ct)
    t : (N,) uniform time [s]
    zr, zr_dot : (N,) road height [m] and its time derivative [m/s] under the wheel

    Returns
    -------
    dict
        quantity -> (N,) array.
    """
    A, B, C, D = state_space(p)
    t = np.asarray(t, dtype=float)
    _, y, _ = lsim((A, B, C, D), np.column_stack([zr, zr_dot]), t - t[0])
    return {q: y[:, i] for i, q in enumerate(QUANTITIES)}


def natural_frequencies(p) -> tuple:
    """Undamped natural frequencies [Hz] (body, axle) by hand.

    det(K - w^2 M) = 0 is ms mu w^4 - (ms (ks + kt) + mu ks) w^2 + ks kt = 0, a quadratic
    in w^2 whose two roots give the body-bounce and axle-hop modes.
    """
    a = p.ms * p.mu
    b = p.ms * (p.ks + p.kt) + p.mu * p.ks
    c = p.ks * p.kt
    disc = math.sqrt(b * b - 4.0 * a * c)
    w2 = ((b - disc) / (2.0 * a), (b + disc) / (2.0 * a))
    return tuple(math.sqrt(v) / (2.0 * math.pi) for v in w2)


def complex_amplitude(t, y, f) -> complex:
    """Complex amplitude Y of y(t) ~ Re(Y exp(i 2 pi f t)) by least squares (plus an offset)."""
    w = 2.0 * math.pi * f
    X = np.column_stack([np.cos(w * t), -np.sin(w * t), np.ones_like(t)])
    c, *_ = np.linalg.lstsq(X, y, rcond=None)
    return complex(c[0], c[1])


# --------------------------------------------------------------------------- a drive of another generator

def profile_and_slope(field, x0: float, nx: int):
    """Height z and slope dz/dx [m/m] of a ``roadlib.synthesis.HarmonicField`` profile on
    x0 + i dx, summed from its harmonics here (z = Re sum c_k exp(2 pi i n_k x))."""
    spec = np.zeros(field.n_fft // 2 + 1, complex)
    c = field.coef[:, 0] * np.exp(2j * math.pi * field.n * x0)
    spec[field.k] = c
    scale = field.n_fft / 2.0
    z = np.fft.irfft(spec, n=field.n_fft)[:nx] * scale
    spec[field.k] = 2j * math.pi * field.n * c
    dz = np.fft.irfft(spec, n=field.n_fft)[:nx] * scale
    return z, dz


def ode_drive(p, segments, durations, speed: float, seed: int, fs: float = 200.0, fs_int: float = 1000.0,
              lead_s: float = 5.0, blend_m: float = 2.0, noise_std=None):
    """A quarter-truck drive over roadlib profiles, integrated with the state-space ODE.

    Each segment k and track j (L, R) has its own ``roadlib.synthesis.harmonic_field``
    profile (seed ``SeedSequence(seed, (k, j))``); consecutive segments are joined by a
    power-complementary cross-fade of ``blend_m`` centred on the boundary.  The ODE runs
    from rest ``lead_s`` before the record at ``fs_int`` (the road content, <= nmax v, lies
    far below its Nyquist frequency) and is sampled at ``fs`` (the response holds no
    content above nmax v < fs / 2, so taking every (fs_int / fs)-th sample aliases nothing).

    Parameters
    ----------
    p : QuarterTruckParams-like
    segments : list of (Gq_n0, w, nmin, nmax)
    durations : list of float [s]
    speed : float [m/s], constant
    seed : int
    noise_std : dict, optional
        quantity -> white sensor-noise sd.

    Returns
    -------
    time (N,), channels dict, t_bounds (K + 1,)
    """
    from roadlib.synthesis import SpectralParams, harmonic_field

    step = int(round(fs_int / fs))
    T = float(sum(durations))
    n_lead = int(round(lead_s * fs_int))
    n_int = n_lead + int(round(T * fs_int))
    t_int = (np.arange(n_int) - n_lead) / fs_int
    dx = speed / fs_int                       # one road sample per integration step
    x = speed * t_int
    x0 = x[0]
    length = x[-1] - x0 + dx
    tb = np.concatenate([[0.0], np.cumsum(durations)])
    xb = speed * tb[1:-1]
    # power-complementary weights: raised-cosine ramps, squared weights sum to one
    u = np.ones((len(segments), n_int))
    for k, b in enumerate(xb):
        r = np.clip((x - (b - blend_m / 2)) / blend_m, 0.0, 1.0)
        ramp = 0.5 - 0.5 * np.cos(math.pi * r)
        u[k] *= 1.0 - ramp
        u[k + 1:] *= ramp
    wts = np.sqrt(u)
    dwts = np.gradient(wts, dx, axis=1)       # slope of the weights along x [1/m]
    rng_noise = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(99,)))
    t_out = np.arange(int(round(T * fs))) / fs
    channels = {}
    for j, side in enumerate("LR"):
        zr = np.zeros(n_int)
        dzr = np.zeros(n_int)
        for k, (gq, w, nmin, nmax) in enumerate(segments):
            sp = SpectralParams(Gq_n0=gq, w=w, nmin=nmin, nmax=nmax, dx=dx)
            field = harmonic_field(sp, length, 0.0, seed=np.random.SeedSequence(seed, spawn_key=(k, j)))
            z, dz = profile_and_slope(field, x0, n_int)
            zr += wts[k] * z
            dzr += (wts[k] * dz + dwts[k] * z) * speed  # d/dt = v d/dx
        y = simulate_ode(p, t_int, zr, dzr)
        for q in QUANTITIES:
            yy = y[q][n_lead::step][: t_out.size]
            if noise_std:
                yy = yy + rng_noise.normal(0.0, noise_std.get(q, 0.0), yy.size)
            channels[f"{q}_3{side}"] = yy
    tb_out = tb.copy()
    tb_out[-1] = t_out[-1] + 1.0 / fs
    return t_out, channels, tb_out
