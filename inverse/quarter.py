"""A fast linear quarter-truck reference simulator for the inverse fit.

What it is for: a response simulator that honours the inverse fit's simulator
contract (see :class:`QuarterTruckSimulator`) and runs in milliseconds, so the
fit can be developed, tested and benchmarked without the Exudyn truck; and a
closed-form linear model (:class:`QuarterTruck`) whose response RMS per road class
feeds the segmentation's initial class guess.  What it is not: the vehicle model
of the project (``vehicles``), nor a road library (``roadlib``).  It carries its
own small harmonic synthesis because the fit needs phases that stay put when the
parameters move (common random numbers): here one phase per bin of a fixed
frequency grid, whereas ``roadlib.synthesis`` starts its harmonic grid and its
phase draws at nmin, so a 10% change of nmin gives a new road.

Model
-----
One quarter truck per wheel track (left ``L`` and right ``R`` of one axle, default
axle 3), each a sprung mass ``ms`` on a suspension spring-damper (``ks``, ``cs``)
over an unsprung mass ``mu`` on a tyre spring-damper (``kt``, ``ct``) to the road.
Left and right tracks get independent road profiles.  Outputs (names and signs of
shared/docs/measurement-format.md): ``susp_disp_<a><s>`` = zu - zs [m], positive in
compression; ``axle_acc_<a><s>`` = d^2 zu / dt^2 and ``body_acc_<a><s>`` =
d^2 zs / dt^2 [m/s^2], positive up.

Integration is exact for a linear time-invariant system: the road height under
the wheel, sampled at ``oversample`` times the output rate along the travelled
distance x(t) (so a varying speed is handled), is filtered by the frequency
response in the FFT domain and decimated by an ideal low-pass (no aliasing).  A
lead-in of road before the record (at the initial speed, at least ``lead_in_s``)
absorbs the start-up and the circular wrap of the FFT, so the record is the
stationary response with no transient.

Road synthesis (local, eq 3 of the paper)
-----------------------------------------
Each segment k and track j has its own profile over the whole road,
z_kj(x) = sum_i a_i cos(2 pi n_i x + phi_kji), on a uniform frequency grid
n_i = i dn (dn = 1 / L_fft) with one-sided ISO PSD Gd(n) = Gq_n0 (n / n0)^-w and
a_i = sqrt(2 Gd(n_i) dn f_i), f_i the fraction of the bin [n_i - dn/2, n_i + dn/2]
inside [nmin, nmax] (soft band edges make the response a continuous function of
nmin and nmax).  Phases phi are uniform on [0, 2 pi) and drawn for EVERY bin of the
grid from ``numpy.random.SeedSequence(seed, spawn_key=(k, j))``, independently
of the parameters: the same seed gives the same phases for any parameter values
(common random numbers).  Segments are joined by power-complementary raised-cosine
cross-fades of length ``blend_m`` centred on the boundaries (weights c_k with
sum c_k^2 = 1, so the variance is kept through a junction).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError
from inverse.spectral import N0

_SIDES = ("L", "R")
_QUANTITIES = ("susp_disp", "axle_acc", "body_acc")


@dataclass(frozen=True)
class QuarterTruckParams:
    """Parameters of one wheel station of a loaded heavy-truck rear axle.

    Engineering estimates for one side of one rear axle of a loaded 8x4 dump truck
    (about 9 t per rear axle, dual tyres); they put body bounce near 2 Hz and
    axle hop near 12 Hz with body damping about 0.2, the ranges of heavy trucks.

    Parameters
    ----------
    ms : float
        Sprung mass per wheel station [kg].
    mu : float
        Unsprung mass (half axle, wheel hub, dual tyres) [kg].
    ks : float
        Suspension stiffness [N/m].
    cs : float
        Suspension damping [N s/m].
    kt : float
        Tyre stiffness (dual tyres together) [N/m].
    ct : float
        Tyre damping [N s/m].
    """

    ms: float = 4000.0
    mu: float = 500.0
    ks: float = 1.0e6
    cs: float = 2.5e4
    kt: float = 2.0e6
    ct: float = 1.0e3

    def __post_init__(self):
        for name in ("ms", "mu", "ks", "kt"):
            if not getattr(self, name) > 0:
                raise EroadInputError(f"QuarterTruckParams.{name} must be positive")
        if self.cs < 0 or self.ct < 0:
            raise EroadInputError("QuarterTruckParams: damping must be non-negative")


class QuarterTruck:
    """Closed-form linear quarter truck: frequency responses and response PSDs.

    Parameters
    ----------
    params : QuarterTruckParams
    """

    def __init__(self, params: QuarterTruckParams = QuarterTruckParams()):
        self.params = params

    def frf(self, f, quantity: str) -> np.ndarray:
        """Frequency response from road height to one output.

        Parameters
        ----------
        f : array_like
            Frequency [Hz].
        quantity : {'susp_disp', 'axle_acc', 'body_acc'}
            Output: suspension displacement [m/m], axle or body acceleration
            [(m/s^2)/m].

        Returns
        -------
        ndarray of complex
        """
        p = self.params
        s = 2j * np.pi * np.asarray(f, dtype=float)
        Ks = p.cs * s + p.ks
        Kt = p.ct * s + p.kt
        body = p.ms * s ** 2 + Ks
        Hu = Kt / (p.mu * s ** 2 + Ks + Kt - Ks ** 2 / body)
        Hs = Ks * Hu / body
        if quantity == "susp_disp":
            return Hu - Hs
        if quantity == "axle_acc":
            return s ** 2 * Hu
        if quantity == "body_acc":
            return s ** 2 * Hs
        raise EroadInputError(f"QuarterTruck: unknown quantity {quantity!r}, use one of {_QUANTITIES}")

    def response_psd(self, f, quantity: str, Gq_n0: float, w: float, speed: float,
                     nmin: float = 0.01, nmax: float = 10.0) -> np.ndarray:
        """One-sided response PSD at constant speed.

        Parameters
        ----------
        f : array_like
            Frequency [Hz].
        quantity : str
            See :meth:`frf`.
        Gq_n0 : float
            Road PSD level [m^3] at n0 = 0.1 cycles/m.
        w : float
            Waviness [-].
        speed : float
            [m/s].
        nmin, nmax : float
            Road band [cycles/m].

        Returns
        -------
        ndarray
            PSD [unit^2/Hz] of the output; the road's temporal PSD is Gd(f/v) / v.
        """
        f = np.asarray(f, dtype=float)
        n = f / speed
        inside = (n >= nmin) & (n <= nmax) & (n > 0)
        Gd = np.where(inside, Gq_n0 * (np.where(n > 0, n, 1.0) / N0) ** (-w), 0.0)
        return np.abs(self.frf(f, quantity)) ** 2 * Gd / speed

    def predict_rms(self, Gq_n0: float, w: float, speed: float, quantity: str = "susp_disp",
                    nmin: float = 0.01, nmax: float = 10.0, f_band=(0.0, np.inf)) -> float:
        """Response RMS on a road of the given spectrum at constant speed.

        Parameters
        ----------
        Gq_n0, w, speed, nmin, nmax : float
            As :meth:`response_psd`.
        quantity : str
            See :meth:`frf`.
        f_band : (float, float)
            Only power between these frequencies [Hz] counts.

        Returns
        -------
        float
            RMS [m or m/s^2]; proportional to sqrt(Gq_n0).
        """
        lo = max(nmin * speed, f_band[0], 1e-3)
        hi = min(nmax * speed, f_band[1])
        if hi <= lo:
            return 0.0
        f = np.geomspace(lo, hi, 4000)
        psd = self.response_psd(f, quantity, Gq_n0, w, speed, nmin, nmax)
        return float(math.sqrt(np.trapezoid(psd, f)))


def _soft_band(n: np.ndarray, dn: float, nmin: float, nmax: float) -> np.ndarray:
    """Fraction of each bin [n - dn/2, n + dn/2] that lies in [nmin, nmax]."""
    lo = np.maximum(n - dn / 2, nmin)
    hi = np.minimum(n + dn / 2, nmax)
    return np.clip((hi - lo) / dn, 0.0, 1.0)


def harmonic_profile(n_points: int, dx: float, Gq_n0: float, w: float, nmin: float,
                     nmax: float, phases: np.ndarray) -> np.ndarray:
    """Harmonic-superposition road profile on a periodic uniform grid (eq 3).

    Parameters
    ----------
    n_points : int
        Number of grid points N (even); the profile is periodic with length N dx.
    dx : float
        Grid step [m]; frequencies up to 1 / (2 dx) are representable.
    Gq_n0, w, nmin, nmax : float
        Spectral parameters (see :mod:`inverse.spectral`).
    phases : ndarray, shape (N // 2 + 1,)
        Phase of each frequency bin n_i = i / (N dx) [rad]; drawn once per seed.

    Returns
    -------
    ndarray, shape (N,)
        z [m] at x_i = i dx; one-sided PSD Gd between nmin and nmax, zero mean.
    """
    if nmax > 0.5 / dx * (1 + 1e-9):
        raise EroadInputError(f"harmonic_profile: nmax {nmax} exceeds the grid Nyquist 1/(2 dx) = {0.5 / dx}")
    dn = 1.0 / (n_points * dx)
    n = np.arange(n_points // 2 + 1) * dn
    frac = _soft_band(n, dn, nmin, nmax)
    frac[0] = 0.0
    frac[-1] = 0.0
    Gd = Gq_n0 * (np.where(n > 0, n, 1.0) / N0) ** (-w)
    amp = np.sqrt(2.0 * Gd * dn * frac)
    spec = (0.5 * n_points) * amp * np.exp(1j * phases)
    return np.fft.irfft(spec, n=n_points)


def _phases(seed: int, segment: int, track: int, size: int) -> np.ndarray:
    ss = np.random.SeedSequence(seed, spawn_key=(segment, track))
    return np.random.default_rng(ss).uniform(0.0, 2.0 * np.pi, size)


def travelled_distance(time, speed) -> np.ndarray:
    """Distance along the road x(t) [m] from 0 at time[0], trapezoidal in speed.

    Parameters
    ----------
    time : (N,) array, s
    speed : float or (N,) array, m/s

    Returns
    -------
    ndarray, shape (N,)
    """
    t = np.asarray(time, dtype=float)
    v = np.broadcast_to(np.asarray(speed, dtype=float), t.shape)
    return np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])


@dataclass
class QuarterTruckSimulator:
    """Response simulator with the inverse fit's contract, on quarter trucks.

    Contract (every simulator the fit accepts)::

        simulate(params, seed) -> dict[str, ndarray]

    ``params`` is a (K, 4) array of per-segment physical road parameters with
    columns (Gq_n0 [m^3], w [-], nmin [cycles/m], nmax [cycles/m]) (see
    :mod:`inverse.spectral`); ``seed`` fixes the road phases, which must not depend
    on ``params`` (common random numbers: the same seed gives the same phases for
    every parameter point).  The result maps channel names to arrays of shape
    ``time.shape`` on the record's time grid.  The segment layout (here
    ``x_bounds``) is bound into the simulator when it is made.

    Parameters
    ----------
    time : (N,) array
        Output time grid [s], uniform.
    speed : float or (N,) array
        Vehicle speed [m/s] at ``time``.
    x_bounds : (K + 1,) array
        Segment boundaries along the road [m], x = 0 at time[0]; the first and last
        are ignored (segment 0 extends backwards through the lead-in, the last one
        forwards).
    vehicle : QuarterTruckParams
    axle : int
        Axle number in the channel names.
    quantities : tuple of str
        Outputs per side, from ('susp_disp', 'axle_acc', 'body_acc').
    oversample : int
        Internal rate / output rate (power of 2); the road is sampled at this rate.
    dx : float
        Road grid step [m]; must resolve the largest nmax asked for (1/(2 dx)).
    lead_in_s : float
        Minimum road before the record [s] (absorbs start-up and FFT wrap).
    blend_m : float
        Length of the cross-fade at each segment boundary [m].
    """

    time: np.ndarray
    speed: object
    x_bounds: np.ndarray
    vehicle: QuarterTruckParams = field(default_factory=QuarterTruckParams)
    axle: int = 3
    quantities: tuple = _QUANTITIES
    oversample: int = 4
    dx: float = 0.01
    lead_in_s: float = 3.0
    blend_m: float = 1.0

    def __post_init__(self):
        t = np.asarray(self.time, dtype=float)
        if t.ndim != 1 or t.size < 16:
            raise EroadInputError("QuarterTruckSimulator: time must be a 1-D array of >= 16 samples")
        step = np.diff(t)
        if np.any(step <= 0) or np.ptp(step) > 1e-6 * step.mean():
            raise EroadInputError("QuarterTruckSimulator: time must be uniform and increasing")
        if self.oversample < 1 or (self.oversample & (self.oversample - 1)):
            raise EroadInputError("QuarterTruckSimulator: oversample must be a power of 2")
        for q in self.quantities:
            if q not in _QUANTITIES:
                raise EroadInputError(f"QuarterTruckSimulator: unknown quantity {q!r}")
        self.time = t
        v = np.broadcast_to(np.asarray(self.speed, dtype=float), t.shape).copy()
        if np.any(v <= 0):
            raise EroadInputError("QuarterTruckSimulator: speed must be positive")
        self.speed = v
        self.x_bounds = np.asarray(self.x_bounds, dtype=float)
        if self.x_bounds.ndim != 1 or self.x_bounds.size < 2 or np.any(np.diff(self.x_bounds) <= 0):
            raise EroadInputError("QuarterTruckSimulator: x_bounds must be K+1 increasing values")
        fs = 1.0 / step.mean()
        self.fs = fs
        n_out = t.size
        n_lead_min = int(math.ceil(self.lead_in_s * fs))
        n_fft_out = 1 << int(math.ceil(math.log2(n_out + n_lead_min)))
        self._n_lead = n_fft_out - n_out
        self._n_fft = n_fft_out * self.oversample
        fs_sim = fs * self.oversample
        # travelled distance on the internal grid: lead-in at the initial speed
        t_sim = (np.arange(self._n_fft) - self._n_lead * self.oversample) / fs_sim
        v_sim = np.interp(t_sim, t - t[0], v)
        x_rec = travelled_distance(t - t[0], v)
        self._x_sim = np.where(t_sim < 0, v[0] * t_sim, np.interp(t_sim, t - t[0], x_rec))
        # extrapolate past the last output sample (only the tail of the oversampled grid)
        tail = t_sim > t[-1] - t[0]
        self._x_sim[tail] = x_rec[-1] + v[-1] * (t_sim[tail] - (t[-1] - t[0]))
        del v_sim
        x0 = self._x_sim[0] - 2 * self.dx
        length = self._x_sim[-1] - x0 + 4 * self.dx
        self._n_road = 1 << int(math.ceil(math.log2(length / self.dx)))
        self._x0 = x0
        freqs = np.fft.rfftfreq(self._n_fft, 1.0 / fs_sim)
        keep = n_fft_out // 2 + 1
        model = QuarterTruck(self.vehicle)
        self._H = {q: model.frf(freqs[:keep], q) for q in self.quantities}
        self._keep = keep
        self._weights = self._segment_weights()

    @property
    def n_segments(self) -> int:
        """Number of road segments K."""
        return self.x_bounds.size - 1

    @property
    def channels(self) -> list:
        """Channel names this simulator returns."""
        return [f"{q}_{self.axle}{s}" for q in self.quantities for s in _SIDES]

    def _segment_weights(self) -> np.ndarray:
        """Power-complementary weights (K, n_sim) along the internal distance grid."""
        x = self._x_sim
        K = self.n_segments
        inner = self.x_bounds[1:-1]
        half = 0.5 * self.blend_m
        # partition of unity by raised-cosine ramps, then square roots
        u = np.ones((K, x.size))
        for k, xb in enumerate(inner):
            r = np.clip((x - (xb - half)) / max(self.blend_m, 1e-12), 0.0, 1.0)
            ramp = 0.5 - 0.5 * np.cos(np.pi * r)  # 0 before, 1 after the boundary
            u[k] *= 1.0 - ramp
            u[k + 1:] *= ramp
        return np.sqrt(u)

    def road_heights(self, params, seed: int) -> np.ndarray:
        """Road height under each wheel on the internal time grid.

        Parameters
        ----------
        params : (K, 4) array
            Per-segment (Gq_n0, w, nmin, nmax).
        seed : int
            Root seed of the road phases; phases of segment k, track j (0 = L,
            1 = R) come from SeedSequence(seed, spawn_key=(k, j)).

        Returns
        -------
        ndarray, shape (2, n_sim)
            z [m] under the left and right wheel.
        """
        P = np.atleast_2d(np.asarray(params, dtype=float))
        if P.shape != (self.n_segments, 4):
            raise EroadInputError(f"QuarterTruckSimulator: params must have shape ({self.n_segments}, 4), got {P.shape}")
        if np.any(P[:, 3] > 0.5 / self.dx):
            raise EroadInputError(f"QuarterTruckSimulator: nmax above the road grid Nyquist {0.5 / self.dx} cycles/m")
        xq = (self._x_sim - self._x0) / self.dx
        out = np.zeros((2, xq.size))
        for k in range(self.n_segments):
            Gq, w, nmin, nmax = P[k]
            for j in range(2):
                ph = _phases(seed, k, j, self._n_road // 2 + 1)
                z = harmonic_profile(self._n_road, self.dx, Gq, w, nmin, nmax, ph)
                out[j] += self._weights[k] * np.interp(xq, np.arange(self._n_road), z)
        return out

    def __call__(self, params, seed: int) -> dict:
        """Simulate the record; see the class docstring for the contract.

        Returns
        -------
        dict
            Channel name -> (N,) array on ``time`` [m or m/s^2].
        """
        zr = self.road_heights(params, seed)
        m = self.oversample
        n_out_fft = self._n_fft // m
        out = {}
        for j, side in enumerate(_SIDES):
            U = np.fft.rfft(zr[j])[: self._keep]
            U[-1] = 0.0
            for q in self.quantities:
                y = np.fft.irfft(self._H[q] * U, n=n_out_fft) / m
                out[f"{q}_{self.axle}{side}"] = y[self._n_lead:]
        return out


def add_sensor_noise(channels: dict, std: dict, seed: int) -> dict:
    """Add white Gaussian sensor noise to channels (for synthetic 'measured' data).

    Parameters
    ----------
    channels : dict
        Channel name -> (N,) array.
    std : dict
        Channel name or quantity prefix ('susp_disp', 'axle_acc', 'body_acc')
        -> noise standard deviation [channel unit]; channels not named get none.
    seed : int
        Root seed; channel i (in sorted name order) uses SeedSequence(seed,
        spawn_key=(1000 + i,)).

    Returns
    -------
    dict
        New dict with noisy copies.
    """
    out = {}
    for i, name in enumerate(sorted(channels)):
        x = np.asarray(channels[name], dtype=float)
        s = std.get(name, std.get(name.rsplit("_", 1)[0], 0.0))
        if s > 0:
            rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(1000 + i,)))
            x = x + rng.normal(0.0, s, x.shape)
        out[name] = x
    return out
