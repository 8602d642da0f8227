"""A stand-in simulator for the diagnosis: two quarter-cars in tandem on a random road.

What it is for: the tests and the worked example of the callables that
``diagnosis.which`` needs (``fit`` and ``simulate``), with no Exudyn.  Front
(axle 1) and rear (axle 3) corners of one side run over the same track, the rear
one ``wheelbase`` later; each is a linear two-mass quarter-car (sprung and unsprung
mass, suspension spring and damper, tyre spring) discretised exactly for a
piecewise-linear road input (first-order hold; a zero-order hold is badly wrong for
the axle acceleration, whose tyre-force feedthrough then sees the road half a step
early) and run with ``scipy.signal.lfilter``; an optional cubic hardening spring
switches to a fixed-step RK4 integration.  Toy "effects" mimic the library's:

``tyre_stiffness.scale`` (k_t factor), ``payload.mass_scale`` (sprung-mass factor),
``damper.scale`` (damping factor), ``sensor.cutoff_hz`` (2nd-order Butterworth
low-pass on every channel), ``speed_scale.scale`` (true speed / recorded speed),
``cubic_spring.k3`` (N/m^3, nonlinear, time domain only).

``fit`` identifies the road (ISO 8608 level ``Gq(n0)`` and waviness ``w``) from
measured band powers with the analytic frequency response, the way the inverse fit
identifies the road for the truck.

What it is not: a vehicle model for studies (see ``vehicles``).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np
from scipy import optimize, signal

from .bandpower import band_powers, third_octave_bands, var_log_power
from .signals import Signals, as_signals
from .which import Candidate, Param

__all__ = ["QuarterCar", "ToyRoad", "ToyState", "TOY_CANDIDATES", "CHANNELS", "make_state",
           "simulate_drive", "simulate", "fit", "expected_band_powers"]

N0 = 0.1  # cycles/m, ISO 8608 reference spatial frequency
CHANNELS = [f"{q}_{a}L" for a in (1, 3) for q in ("susp_disp", "axle_acc", "body_acc")]
#: white sensor noise, standard deviation per quantity (m, m/s^2, m/s^2)
NOISE = {"susp_disp": 2e-5, "axle_acc": 0.02, "body_acc": 0.005}


@dataclass(frozen=True)
class QuarterCar:
    """One corner of a loaded heavy truck.

    Parameters
    ----------
    m_s : float, kg      sprung mass (body share of the corner)
    m_u : float, kg      unsprung mass (axle end with dual tyres)
    k_s : float, N/m     suspension stiffness
    c_s : float, N s/m   suspension damping
    k_t : float, N/m     tyre stiffness
    k3 : float, N/m^3    cubic hardening of the suspension spring (0 = linear)

    Body bounce about 1.46 Hz (damping ratio 0.19), axle hop about 11.6 Hz (0.35).
    """

    m_s: float = 4000.0
    m_u: float = 400.0
    k_s: float = 4.0e5
    c_s: float = 2.0e4
    k_t: float = 1.8e6
    k3: float = 0.0


@dataclass(frozen=True)
class ToyRoad:
    """ISO 8608 displacement PSD ``Gq (n / n0)^-w`` between ``n_min`` and ``n_max``.

    Parameters
    ----------
    gq : float, m^3      level at n0 = 0.1 cycles/m
    w : float            waviness
    n_min, n_max : float, cycles/m
    """

    gq: float = 256e-6
    w: float = 2.0
    n_min: float = 0.01
    n_max: float = 10.0


@dataclass(frozen=True)
class ToyState:
    """A fitted toy model: vehicle with effects, road, sensors.

    Parameters
    ----------
    car : QuarterCar
    road : ToyRoad
    effects : mapping effect -> {parameter: value}
    sensor_cutoff_hz : float or None
    speed_scale : float      true speed / recorded speed
    wheelbase : float, m     axle 1 to axle 3
    noise : bool             add white sensor noise (``NOISE``)
    """

    car: QuarterCar = QuarterCar()
    road: ToyRoad = ToyRoad()
    effects: Mapping = field(default_factory=dict)
    sensor_cutoff_hz: float | None = None
    speed_scale: float = 1.0
    wheelbase: float = 4.0
    noise: bool = True


def make_state(effects: Mapping[str, Mapping[str, float]] | None = None, *,
               base: QuarterCar = QuarterCar(), road: ToyRoad = ToyRoad(),
               wheelbase: float = 4.0, noise: bool = True) -> ToyState:
    """Apply toy effects to the nominal corner.

    Parameters
    ----------
    effects : mapping effect -> {parameter: value}, optional
        Names and parameters as in the module docstring.
    base, road, wheelbase, noise : see :class:`ToyState`

    Returns
    -------
    ToyState
    """
    effects = {k: dict(v) for k, v in (effects or {}).items()}
    car, cutoff, vs = base, None, 1.0
    for name, p in effects.items():
        if name == "tyre_stiffness":
            car = dataclasses.replace(car, k_t=car.k_t * p["scale"])
        elif name == "payload":
            car = dataclasses.replace(car, m_s=car.m_s * p["mass_scale"])
        elif name == "damper":
            car = dataclasses.replace(car, c_s=car.c_s * p["scale"])
        elif name == "sensor":
            cutoff = float(p["cutoff_hz"])
        elif name == "speed_scale":
            vs = float(p["scale"])
        elif name == "cubic_spring":
            car = dataclasses.replace(car, k3=float(p["k3"]))
        else:
            raise KeyError(f"toy model has no effect {name!r}")
    return ToyState(car, road, effects, cutoff, vs, wheelbase, noise)


#: candidate effects for ``diagnosis.which`` on the toy model
TOY_CANDIDATES = [
    Candidate("tyre_stiffness", (Param("scale", 0.5, 2.0, log=True),)),
    Candidate("payload", (Param("mass_scale", 0.7, 1.5),)),
    Candidate("damper", (Param("scale", 0.5, 2.0, log=True),)),
    Candidate("sensor", (Param("cutoff_hz", 5.0, 80.0, log=True),)),
]


def _ss(car: QuarterCar):
    ms, mu, ks, cs, kt = car.m_s, car.m_u, car.k_s, car.c_s, car.k_t
    A = np.array([[0, 0, 1, 0], [0, 0, 0, 1],
                  [-ks / ms, ks / ms, -cs / ms, cs / ms],
                  [ks / mu, -(ks + kt) / mu, cs / mu, -cs / mu]])
    B = np.array([[0.0], [0.0], [0.0], [kt / mu]])
    C = np.vstack([[-1.0, 1.0, 0.0, 0.0], A[3], A[2]])      # susp (compression +), axle, body
    D = np.array([[0.0], [kt / mu], [0.0]])
    return A, B, C, D


def _road(rng, length: float, road: ToyRoad, dx: float = 0.02):
    n = int(2 ** np.ceil(np.log2(length / dx + 2)))
    nk = np.arange(n // 2 + 1) / (n * dx)
    G = np.zeros_like(nk)
    m = (nk >= road.n_min) & (nk <= road.n_max)
    G[m] = road.gq * (nk[m] / N0) ** (-road.w)
    dn = 1.0 / (n * dx)
    c = (n / 2) * np.sqrt(G * dn) * (rng.standard_normal(nk.size) + 1j * rng.standard_normal(nk.size))
    c[0] = 0.0
    return np.arange(n) * dx, np.fft.irfft(c, n)


def _rk4_cubic(car: QuarterCar, u: np.ndarray, fs: float, sub: int = 4) -> np.ndarray:
    """Nonlinear corners (cubic suspension spring); u (ncorner, N) road, returns (3, ncorner, N)."""
    dt = 1.0 / (fs * sub)
    ms, mu, ks, cs, kt, k3 = car.m_s, car.m_u, car.k_s, car.c_s, car.k_t, car.k3

    def acc(z, r):
        d = z[:, 1] - z[:, 0]
        fsus = ks * d + k3 * d ** 3 + cs * (z[:, 3] - z[:, 2])
        return np.stack([z[:, 2], z[:, 3], fsus / ms, (-fsus + kt * (r - z[:, 1])) / mu], axis=1)

    nc, N = u.shape
    z = np.zeros((nc, 4))
    out = np.zeros((3, nc, N))
    for k in range(N):
        r0 = u[:, k]
        r1 = u[:, min(k + 1, N - 1)]
        a = acc(z, r0)
        out[:, :, k] = (z[:, 1] - z[:, 0], a[:, 3], a[:, 2])
        for j in range(sub):
            ra, rm, rb = (r0 + (r1 - r0) * (j / sub), r0 + (r1 - r0) * ((j + 0.5) / sub),
                          r0 + (r1 - r0) * ((j + 1) / sub))
            k1 = acc(z, ra)
            k2 = acc(z + 0.5 * dt * k1, rm)
            k3_ = acc(z + 0.5 * dt * k2, rm)
            k4 = acc(z + dt * k3_, rb)
            z = z + dt / 6 * (k1 + 2 * k2 + 2 * k3_ + k4)
    return out


def simulate_drive(state: ToyState, duration: float, speed, seed, *, fs: float = 200.0,
                   run_in: float = 5.0) -> Signals:
    """Drive the toy over a fresh road realisation.

    Parameters
    ----------
    state : ToyState
    duration : float, s
    speed : float or (N,) array, m/s
        RECORDED speed; the model moves at ``state.speed_scale`` times it.
    seed : int or numpy.random.SeedSequence
        Road phases use ``SeedSequence(seed).spawn(2)[0]``, sensor noise ``[1]``.
    fs : float, Hz
    run_in : float, s
        Simulated and discarded before the record starts (transients).

    Returns
    -------
    Signals
        Channels ``CHANNELS`` (m, m/s^2), ``speed`` the recorded speed.
    """
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    s_road, s_noise = ss.spawn(2)
    n = int(round(duration * fs))
    n0 = int(round(run_in * fs))
    v_rec = np.broadcast_to(np.asarray(speed, dtype=float), (n,))
    v = np.concatenate([np.full(n0, v_rec[0]), v_rec]) * state.speed_scale
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) / fs)])
    wb = state.wheelbase
    xr, zr = _road(np.random.default_rng(s_road), x[-1] + wb + 1.0, state.road)
    u = np.vstack([np.interp(x + wb, xr, zr), np.interp(x, xr, zr)])   # front, rear
    if state.car.k3 != 0.0:
        y = _rk4_cubic(state.car, u, fs)
    else:
        Ad, Bd, Cd, Dd, _ = signal.cont2discrete(_ss(state.car), 1.0 / fs, method="foh")
        y = np.zeros((3, 2, u.shape[1]))
        for i in range(3):
            num, den = signal.ss2tf(Ad, Bd, Cd[i:i + 1], Dd[i:i + 1])
            y[i] = signal.lfilter(num[0], den, u, axis=-1)
    if state.sensor_cutoff_hz is not None:
        bb, aa = signal.butter(2, min(state.sensor_cutoff_hz, 0.45 * fs), fs=fs)
        y = signal.lfilter(bb, aa, y, axis=-1)
    y = y[:, :, n0:]
    rng = np.random.default_rng(s_noise)
    chans = {}
    for ci, a in enumerate(("1", "3")):
        for qi, qname in enumerate(("susp_disp", "axle_acc", "body_acc")):
            sig = y[qi, ci].copy()
            if state.noise:
                sig += NOISE[qname] * rng.standard_normal(n)
            chans[f"{qname}_{a}L"] = sig
    units = {c: ("m" if c.startswith("susp") else "m/s^2") for c in chans}
    return Signals(np.arange(n) / fs, chans, units, np.array(v_rec), {"model": "toy"})


def simulate(state: ToyState, window, seed: int) -> Signals:
    """The ``simulate`` callable of ``diagnosis.which``: same duration, rate and speed as ``window``.

    Parameters
    ----------
    state : ToyState
    window : Signals-like
        Measured window whose duration, sample rate and recorded speed are reproduced.
    seed : int
        Road-phase seed.
    """
    w = as_signals(window)
    return simulate_drive(state, w.duration, w.speed if w.speed is not None else 10.0, seed, fs=w.fs)


def _frf2(state: ToyState, f: np.ndarray) -> np.ndarray:
    """|H|^2 from road height to (susp, axle, body) at f (Hz), sensor included; (3, nf)."""
    A, B, C, D = _ss(state.car)
    s = 2j * np.pi * np.asarray(f, dtype=float)
    M = s[:, None, None] * np.eye(4)[None] - A[None]
    X = np.linalg.solve(M, np.broadcast_to(B, (s.size, 4, 1)))          # (nf, 4, 1)
    H = (np.einsum("oi,fi->of", C, X[:, :, 0]) + D)                     # (3, nf)
    g = np.abs(H) ** 2
    if state.sensor_cutoff_hz is not None:
        bb, aa = signal.butter(2, state.sensor_cutoff_hz, fs=200.0)
        _, h = signal.freqz(bb, aa, worN=f, fs=200.0)
        g = g * np.abs(h) ** 2
    return g


def expected_band_powers(state: ToyState, bands: np.ndarray, speed: float, fs: float = 200.0,
                         _frf=None) -> np.ndarray:
    """Analytic band powers of the linear toy on its road (noise included).

    Parameters
    ----------
    state : ToyState
    bands : (nb, 3) array, Hz
    speed : float, m/s, recorded speed
    fs : float, Hz (sets the white-noise PSD level)

    Returns
    -------
    (6, nb) array
        Rows in ``CHANNELS`` order (axle 1 then 3; they are equal), units^2.
    """
    f = np.exp(np.linspace(np.log(bands[:, 0]), np.log(bands[:, 2]), 48, axis=1))   # (nb, 48)
    g = _frf2(state, f.ravel()).reshape(3, *f.shape) if _frf is None else _frf
    v = speed * state.speed_scale
    n = f / v
    r = state.road
    Gz = np.where((n >= r.n_min) & (n <= r.n_max), r.gq * (n / N0) ** (-r.w) / v, 0.0)
    P = np.trapezoid(g * Gz, f, axis=-1)                                               # (3, nb)
    if state.noise:
        P = P + np.array([NOISE[q] ** 2 for q in ("susp_disp", "axle_acc", "body_acc")])[:, None] \
            * 2.0 / fs * (bands[:, 2] - bands[:, 0])
    return np.vstack([P, P])


def fit(effects: Mapping[str, Mapping[str, float]] | None, data: Sequence) -> ToyState:
    """The ``fit`` callable of ``diagnosis.which``: identify the road with effects fixed.

    Least squares over ``ln Gq`` and ``w`` (bounded 1-3) of the log band powers of all
    channels and windows, weighted by ``1 / trigamma(nu/2)``; the model's band powers are
    analytic (linear part of the model, mean recorded speed of each window).

    Parameters
    ----------
    effects : mapping effect -> {parameter: value}, or None for the nominal model
    data : sequence of Signals-like (or one)
        Measured windows.

    Returns
    -------
    ToyState
    """
    windows = [as_signals(d) for d in (data if isinstance(data, (list, tuple)) else [data])]
    state = make_state(effects)
    bands = third_octave_bands()
    f = np.exp(np.linspace(np.log(bands[:, 0]), np.log(bands[:, 2]), 48, axis=1))
    g = _frf2(state, f.ravel()).reshape(3, *f.shape)
    obs = []
    for w in windows:
        bs = band_powers(np.vstack([w.channels[c] for c in CHANNELS]), w.fs, bands)
        v = float(np.mean(w.speed)) if w.speed is not None else 10.0
        ok = bs.nu >= 6
        obs.append((v, w.fs, np.log(np.where(ok, bs.power, 1.0)),
                    np.where(ok, 1.0 / np.sqrt(var_log_power(np.maximum(bs.nu, 1))), 0.0)))

    def resid(p):
        st = dataclasses.replace(state, road=dataclasses.replace(state.road, gq=np.exp(p[0]), w=p[1]))
        out = [(np.log(expected_band_powers(st, bands, v, fs, _frf=g)) - lp) * sw
               for v, fs, lp, sw in obs]
        return np.concatenate([o.ravel() for o in out])

    sol = optimize.least_squares(resid, [np.log(state.road.gq), state.road.w],
                                 bounds=([np.log(1e-7), 1.0], [np.log(1e-1), 3.0]), x_scale=[1.0, 0.3])
    return dataclasses.replace(state, road=dataclasses.replace(state.road, gq=float(np.exp(sol.x[0])),
                                                               w=float(sol.x[1])))
