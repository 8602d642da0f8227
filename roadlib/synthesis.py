"""Harmonic-superposition synthesis of ISO 8608 road profiles and surfaces (eq (3)).

What this module is for: turning a spectral parameter set P = {Gq(n0), w, nmin,
nmax, dx, dy, lam} and a seed into a random road -- a 1D profile z(x) or a 3D
surface z(x, y) -- either on a uniform grid (fast path, an inverse FFT) or at
arbitrary points (exact cosine sum of the very same harmonics).  What it is
not: segment concatenation and junction patches (``roadlib.segments``), the
road object with interpolation and file io (``roadlib.surface``), or PSD
estimation (``roadlib.metrics``).

The model (docs/roadlib.md has the derivation)::

    z(x, y) = sum_k sum_l a_kl cos(2 pi (n_k x + m_l y) + phi_kl)
    n_k = k dn,  dn = 1 / (N_x dx),   nmin <= n_k <= nmax           (one-sided, cycles/m)
    m_l = l dm,  dm = 1 / P_y,        |m_l| < 1 / (2 dy)            (two-sided, cycles/m)
    a_kl^2 / 2 = Gd(n_k) dn q_kl,     q_kl = p(m_l | n_k) / sum_l p(m_l | n_k)
    phi_kl ~ U[0, 2 pi) independent

``Gd`` is the one-sided ISO PSD (or, with ``w2`` and ``n_break``, the two-slope
PSD of ``roadlib.psd.two_slope_psd``) and ``p`` the lateral density of the surface PSD
(``roadlib.psd.lateral_density``, eq (5)).  Because sum_l q_kl = 1, every
longitudinal track z(x, y0) has the 1D PSD Gd(n_k) at every harmonic exactly in
expectation, whatever lam; lam only moves variance between lateral
wavenumbers, i.e. sets the lateral coherence.  A 1D profile is the case of a
single lateral harmonic m = 0 (deterministic amplitudes a_k = sqrt(2 Gd dn)).

Grid path: the harmonics sit on the FFT grid of a period N_x dx >= the road
length and >= 2 / GRID_NMIN (400 m; 2 / nmin only if nmin < GRID_NMIN), so on
x_i = x0 + i dx the sum is an inverse real FFT along x after a small matrix
product across y; the numbers equal the explicit cosine sum to round-off
(tests check it).

Common random numbers: the frequency grid depends on the road length, dx and
``n_fft`` only, never on the band.  One phase is drawn for EVERY bin
k = 0 .. N_x/2 and every lateral harmonic l, in that order, whatever the band;
the band [nmin, nmax] is an amplitude mask, fractional for the bins straddling
an edge (weight = the share of the bin [n_k - dn/2, n_k + dn/2] inside the
band), so with one seed a change of Gq_n0, w, nmin, nmax or lam changes the
amplitudes only and the road changes continuously with every parameter
(``inverse.sensitivity`` relies on this: docs/inverse.md).

Seeds: ``seed`` (int or ``numpy.random.SeedSequence``) is used as
``SeedSequence(seed)``; its generator draws the phases of the whole grid, row by
row in k, then l.  Same seed and parameters, same bytes.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from functools import lru_cache

import numpy as np
import scipy.fft

from eroad.errors import EroadInputError
from roadlib.psd import ISO_BAND, ISO_CLASSES, _check_two_slope, class_gd0, lateral_density, road_psd

#: lateral period of the surface harmonics, as a multiple of the road width
#: (plus one dy): wide enough that the field does not repeat across the road
LATERAL_PERIOD_FACTOR = 4.0
#: longitudinal period is at least this many longest wavelengths 1/nmin
MIN_PERIODS_OF_NMIN = 2.0
#: the frequency grid resolves down to this frequency [cycles/m] whatever nmin
#: is (period >= MIN_PERIODS_OF_NMIN / GRID_NMIN = 400 m), so the grid -- and the
#: phases, keyed by bin -- do not move with nmin (common random numbers)
GRID_NMIN = 0.005


@dataclass(frozen=True)
class SpectralParams:
    """Spectral parameter set P of the paper (Table 1) plus the anisotropy lam.

    Parameters
    ----------
    Gq_n0 : float
        ISO 8608 displacement PSD level Gd(n0) at n0 = 0.1 cycles/m [m^3] (one-sided).
    w : float
        Waviness exponent [-], 2 in ISO 8608.
    nmin, nmax : float
        Spatial frequency band of the synthesis [cycles/m]; 0 < nmin < nmax.
    dx, dy : float
        Grid spacing along and across the road [m].  ``nmax`` must not exceed the
        Nyquist frequency 1/(2 dx).
    lam : float
        Anisotropy factor [-] of the surface PSD (eq (5)); 1 is isotropic,
        > 1 more coherent across the road.
    w2, n_break : float, optional
        A two-slope spectrum (``roadlib.psd.two_slope_psd``): waviness ``w2`` [-]
        above the break frequency ``n_break`` [cycles/m], ``w`` below it.  Both or
        neither; None (default) is the one-slope ISO spectrum, synthesised exactly as
        before the option existed (same bytes).  The lateral density of a surface
        uses the local waviness (``w`` below the break, ``w2`` above).

    Raises
    ------
    EroadInputError
        Any parameter out of range, naming the parameter and its value.
    """

    Gq_n0: float
    w: float = 2.0
    nmin: float = ISO_BAND[0]
    nmax: float = ISO_BAND[1]
    dx: float = 0.1
    dy: float = 0.1
    lam: float = 1.0
    w2: float | None = None
    n_break: float | None = None

    def __post_init__(self):
        for name in ("Gq_n0", "w", "nmin", "nmax", "dx", "dy", "lam"):
            v = getattr(self, name)
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise EroadInputError(f"SpectralParams.{name} must be a number, got {v!r}") from None
            if not math.isfinite(v) or v <= 0:
                raise EroadInputError(f"SpectralParams.{name} must be positive and finite, got {v!r}")
            object.__setattr__(self, name, v)
        if not self.w < 6:
            raise EroadInputError(f"SpectralParams.w = {self.w} is outside (0, 6)")
        for name in ("w2", "n_break"):
            v = getattr(self, name)
            if v is None:
                continue
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise EroadInputError(f"SpectralParams.{name} must be a number, got {v!r}") from None
            object.__setattr__(self, name, v)
        try:
            _check_two_slope(self.w2, self.n_break)
        except EroadInputError as e:
            raise EroadInputError(f"SpectralParams: {e}") from None
        h_top = ISO_CLASSES["H"].nominal_bounds[1]
        if self.Gq_n0 >= h_top:
            raise EroadInputError(
                f"SpectralParams.Gq_n0 = {self.Gq_n0:g} m^3 is implausible: above the range of ISO 8608's "
                f"roughest class H (up to {h_top:.3g} m^3); give Gd(n0) in m^3, e.g. 256e-6 for class C")
        if self.nmin >= self.nmax:
            raise EroadInputError(
                f"SpectralParams: nmin = {self.nmin} must be below nmax = {self.nmax} cycles/m")
        nyq = 1.0 / (2.0 * self.dx)
        if self.nmax > nyq * (1 + 1e-12):
            raise EroadInputError(
                f"SpectralParams: nmax = {self.nmax:g} cycles/m exceeds the Nyquist frequency "
                f"1/(2 dx) = {nyq:g} cycles/m of dx = {self.dx:g} m; use dx <= {1 / (2 * self.nmax):g} m "
                f"or nmax <= {nyq:g} cycles/m (docs/roadlib.md, 'Table 1')")

    @classmethod
    def from_class(cls, name: str, **kw) -> "SpectralParams":
        """Parameters with the geometric-mean level of ISO class ``name`` ("A" ... "H")."""
        return cls(Gq_n0=class_gd0(name), **kw)

    def to_dict(self) -> dict:
        """Plain dict (for metadata / JSON); ``w2`` and ``n_break`` only for a
        two-slope spectrum (a one-slope dict is what it was before they existed)."""
        d = asdict(self)
        if self.w2 is None:
            d.pop("w2")
            d.pop("n_break")
        return d

    @property
    def two_slope(self) -> bool:
        """True for a two-slope spectrum (``w2`` and ``n_break`` given)."""
        return self.w2 is not None

    @property
    def nyquist(self) -> float:
        """Longitudinal Nyquist frequency 1/(2 dx) [cycles/m]."""
        return 1.0 / (2.0 * self.dx)


def _grid_count(extent: float, step: float, what: str) -> int:
    if not (math.isfinite(extent) and extent >= 0):
        raise EroadInputError(f"{what} must be a non-negative finite number of metres, got {extent!r}")
    n = int(math.floor(extent / step + 1e-9)) + 1
    return n


@dataclass
class HarmonicField:
    """A realised set of harmonics: the road as a function z(x, y).

    Attributes
    ----------
    n : (K,) array
        Longitudinal frequencies n_k = k dn [cycles/m].
    k : (K,) int array
        Harmonic indices on the FFT grid of ``n_fft`` points of ``dx``.
    m : (L,) array
        Lateral frequencies m_l [cycles/m] (just [0.] for a profile).
    coef : (K, L) complex array
        a_kl exp(i phi_kl) [m].
    dx : float
        Grid spacing the harmonics are laid out for [m].
    n_fft : int
        FFT length N_x; period N_x dx [m].
    """

    n: np.ndarray
    k: np.ndarray
    m: np.ndarray
    coef: np.ndarray
    dx: float
    n_fft: int

    @property
    def n_harmonics(self) -> int:
        """Number of (n_k, m_l) harmonics with non-zero amplitude."""
        return int(np.count_nonzero(self.coef))

    def variance(self) -> float:
        """Expected mean-square height sum a^2/2 [m^2] of any track."""
        return float(0.5 * np.sum(np.abs(self.coef) ** 2))

    def evaluate(self, x, y=0.0, chunk: int = 2_000_000) -> np.ndarray:
        """Exact harmonic sum at arbitrary points.

        Parameters
        ----------
        x, y : array_like
            Positions [m], broadcast together.
        chunk : int
            Work-array size limit (points x harmonics) per block.

        Returns
        -------
        ndarray
            z [m], the broadcast shape of ``x`` and ``y``.
        """
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        shape = x.shape
        xf, yf = x.ravel(), y.ravel()
        out = np.empty(xf.size)
        K, L = self.coef.shape
        step = max(1, chunk // K)
        two_pi = 2.0 * np.pi
        for s in range(0, xf.size, step):
            xs, ys = xf[s:s + step], yf[s:s + step]
            ex = np.exp(1j * two_pi * np.outer(xs, self.n))           # (P, K)
            if L == 1 and self.m[0] == 0.0:
                b = np.broadcast_to(self.coef[:, 0], ex.shape)
            else:
                ey = np.exp(1j * two_pi * np.outer(ys, self.m))       # (P, L)
                b = ey @ self.coef.T                                  # (P, K)
            out[s:s + step] = np.einsum("pk,pk->p", ex, b).real
        return out.reshape(shape)

    def row(self, x: float, y=0.0) -> np.ndarray:
        """Exact harmonic sum at one position ``x`` and lateral positions ``y``: what
        :meth:`evaluate` gives there, with the x-sum done once for all ``y``
        (O(K L + ny L) instead of O(ny K L); the junction heights of a segmented road).

        Returns
        -------
        ndarray
            z [m], shape (ny,).
        """
        y = np.atleast_1d(np.asarray(y, float))
        c = np.exp(1j * 2.0 * np.pi * self.n * float(x)) @ self.coef               # (L,)
        if self.m.size == 1 and self.m[0] == 0.0:
            return np.full(y.size, c[0].real)
        return (np.exp(1j * 2.0 * np.pi * np.outer(y, self.m)) @ c).real

    def grid(self, x0: float, nx: int, y=None) -> np.ndarray:
        """Fast path: z on x_i = x0 + i dx (i < nx) and lateral positions ``y``.

        Parameters
        ----------
        x0 : float
            First x [m].
        nx : int
            Number of x samples (<= ``n_fft``).
        y : array_like, optional
            Lateral positions [m] (default [0.]).

        Returns
        -------
        ndarray
            z [m], shape (nx, ny).
        """
        y = np.atleast_1d(np.asarray(0.0 if y is None else y, float))
        if nx > self.n_fft:
            raise EroadInputError(f"grid: nx = {nx} exceeds the field period of {self.n_fft} samples")
        two_pi = 2.0 * np.pi
        d = self.coef * np.exp(1j * two_pi * (self.n * x0))[:, None]
        if self.m.size == 1 and self.m[0] == 0.0:
            b = np.repeat(d, y.size, axis=1)                          # (K, ny)
        else:
            b = d @ np.exp(1j * two_pi * np.outer(self.m, y))         # (K, ny)
        spec = np.zeros((self.n_fft // 2 + 1, y.size), dtype=complex)
        spec[self.k] = b
        # irfft(X)[i] = (1/N) [X0 + 2 Re sum_k X_k e^{2 pi i k i/N} (+ Nyquist)]
        if self.n_fft % 2 == 0:
            spec[-1] *= 2.0  # Nyquist bin enters irfft once, not twice
        z = scipy.fft.irfft(spec, n=self.n_fft, axis=0, workers=1)[:nx]
        z *= self.n_fft / 2.0
        return z


def band_weights(n, dn: float, nmin: float, nmax: float) -> np.ndarray:
    """Share of each frequency bin [n - dn/2, n + dn/2] inside [nmin, nmax] [-].

    The amplitude mask of the synthesis: 1 inside the band, 0 outside, the
    overlap fraction for a bin straddling an edge, so the synthesised variance
    is the integral of the PSD over the band and moves continuously with nmin
    and nmax.

    Parameters
    ----------
    n : array_like
        Bin centres [cycles/m].
    dn : float
        Bin width [cycles/m].
    nmin, nmax : float
        Band [cycles/m].

    Returns
    -------
    ndarray
        Weights in [0, 1], the shape of ``n``.
    """
    n = np.asarray(n, float)
    lo = np.maximum(n - 0.5 * dn, nmin)
    hi = np.minimum(n + 0.5 * dn, nmax)
    return np.clip((hi - lo) / dn, 0.0, 1.0)


@lru_cache(maxsize=16)
def _amplitudes(params: SpectralParams, n_fft: int, width: float, lateral: bool):
    """The harmonics' bins ``k``, frequencies ``n`` [cycles/m], lateral wavenumbers ``m``
    [cycles/m] and amplitudes (n.size, m.size) [m] of a field: everything but the phases.
    Cached (read-only arrays): the inversion and the diagnosis draw many seeds of one
    spectrum (the realisation selection, one road per candidate)."""
    dx = params.dx
    dn = 1.0 / (n_fft * dx)
    n_bins = n_fft // 2 + 1
    weight = band_weights(np.arange(n_bins) * dn, dn, params.nmin, params.nmax)
    weight[0] = 0.0
    if params.nmax - params.nmin < dn or not np.any(weight > 0):
        raise EroadInputError(
            f"no harmonic between nmin = {params.nmin} and nmax = {params.nmax} cycles/m "
            f"at frequency step {dn:.3g} cycles/m; widen the band or lengthen the road")
    k = np.flatnonzero(weight > 0)
    n = k * dn
    gd = road_psd(n, params.Gq_n0, params.w, params.w2, params.n_break)
    if lateral:
        period_y = LATERAL_PERIOD_FACTOR * (width + params.dy)
        dm = 1.0 / period_y
        l_max = int(math.ceil(1.0 / (2.0 * params.dy) / dm)) - 1     # |m_l| < 1/(2 dy)
        m = np.arange(-l_max, l_max + 1) * dm
        p = lateral_density(m[None, :], n[:, None], params.w, params.lam)
        if params.two_slope:   # local waviness above the break
            hi = n > params.n_break
            if np.any(hi):
                p[hi] = lateral_density(m[None, :], n[hi, None], params.w2, params.lam)
        q = p / p.sum(axis=1, keepdims=True)
    else:
        m = np.zeros(1)
        q = np.ones((n.size, 1))
    amp = np.sqrt(2.0 * gd[:, None] * dn * weight[k][:, None] * q)
    for a in (k, n, m, amp):
        a.setflags(write=False)
    return k, n, m, amp


def harmonic_field(params: SpectralParams, length: float, width: float = 0.0,
                   seed=0, n_fft: int | None = None, lateral: bool | None = None) -> HarmonicField:
    """Draw the harmonics of a road of the given size.

    Parameters
    ----------
    params : SpectralParams
        Spectrum and grid.
    length : float
        Road length [m] the field must cover without repeating.
    width : float
        Road width [m]; 0 (or ``lateral=False``) gives a 1D profile field.
    seed : int or numpy.random.SeedSequence
        Root of the phase stream.
    n_fft : int, optional
        Force the FFT length (default: fast length >= length/dx + 1 and
        >= 2/(min(nmin, GRID_NMIN) dx)).  The phases are keyed by the bins of
        this grid, so keep it fixed (the default is, for nmin >= GRID_NMIN)
        when comparing roads of one seed with different parameters.
    lateral : bool, optional
        Force lateral harmonics on/off (default: on when width > 0).

    Returns
    -------
    HarmonicField
    """
    if not isinstance(params, SpectralParams):
        raise EroadInputError(f"expected SpectralParams, got {type(params).__name__}")
    dx = params.dx
    nx = _grid_count(length, dx, "road length")
    if nx < 2:
        raise EroadInputError(f"road length {length!r} m is shorter than one dx = {dx} m")
    if width < 0 or not math.isfinite(width):
        raise EroadInputError(f"road width must be >= 0 m, got {width!r}")
    need = max(nx, int(math.ceil(MIN_PERIODS_OF_NMIN / (min(params.nmin, GRID_NMIN) * dx))))
    if n_fft is None:
        n_fft = scipy.fft.next_fast_len(need, real=True)
    elif n_fft < nx:
        raise EroadInputError(f"n_fft = {n_fft} is shorter than the road ({nx} samples)")
    k, n, m, amp = _amplitudes(params, int(n_fft), float(width), bool(width > 0 if lateral is None else lateral))
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    rng = np.random.default_rng(ss)
    # one phase per bin of the whole grid (k = 0 .. n_fft/2) and lateral harmonic,
    # whatever the band: the phases depend on (seed, k, l) only.  The stream is drawn in
    # row order, one 64-bit output per double, so the rows k[0] .. k[-1] are those after
    # k[0] * m.size outputs: PCG64 jumps there (bit-identical to drawing the whole grid and
    # indexing it, in a quarter of the time for the usual band)
    rng.bit_generator.advance(int(k[0]) * m.size)
    phi = rng.uniform(0.0, 2.0 * np.pi, size=(int(k[-1] - k[0]) + 1, m.size))[k - k[0]]
    # amp e^(i phi) written as its real and imaginary parts: bit-identical to
    # ``amp * np.exp(1j * phi)`` (e^0 = 1 exactly) and a third faster, the costliest line of
    # a road (the inversion's realisation selection draws one road per candidate)
    coef = np.empty(phi.shape, dtype=complex)
    np.multiply(amp, np.cos(phi), out=coef.real)
    np.multiply(amp, np.sin(phi), out=coef.imag)
    return HarmonicField(n=n, k=k, m=m, coef=coef, dx=dx, n_fft=int(n_fft))


def _lateral_axis(width: float, dy: float) -> np.ndarray:
    ny = _grid_count(width, dy, "road width")
    y = np.arange(ny) * dy
    return y - 0.5 * (y[-1] if ny > 1 else 0.0)


def synth_profile(params: SpectralParams, length: float, seed=0, x0: float = 0.0):
    """Random 1D ISO 8608 profile on x = x0 + i dx, 0 <= i dx <= length.

    Parameters
    ----------
    params : SpectralParams
        Level, waviness, band, dx (dy and lam unused).
    length : float
        Profile length [m].
    seed : int or numpy.random.SeedSequence
        Root seed of the phases.
    x0 : float
        Start position [m].

    Returns
    -------
    x : (nx,) ndarray
        Positions [m].
    z : (nx,) ndarray
        Heights [m], zero-mean in expectation, one-sided PSD Gd(n) in the band.
    """
    field = harmonic_field(params, length, 0.0, seed)
    nx = _grid_count(length, params.dx, "road length")
    x = x0 + np.arange(nx) * params.dx
    return x, field.grid(x0, nx)[:, 0]


def synth_surface(params: SpectralParams, length: float, width: float, seed=0,
                  x0: float = 0.0, meta: dict | None = None):
    """Random 3D ISO 8608 surface z(x, y) as a :class:`roadlib.surface.RoadSurface`.

    Parameters
    ----------
    params : SpectralParams
        Spectrum, grid spacing and anisotropy.
    length : float
        Length along x [m]; x = x0 + i dx.
    width : float
        Width [m], centred on y = 0 (y positive to the left); y = -width/2 + j dy.
        0 gives a single track at y = 0.
    seed : int or numpy.random.SeedSequence
        Root seed of the phases.
    x0 : float
        Start position [m].
    meta : dict, optional
        Extra metadata merged into the surface's ``meta``.

    Returns
    -------
    RoadSurface
        With ``meta`` holding the generator, parameters and seed.
    """
    from roadlib.surface import RoadSurface

    y = _lateral_axis(width, params.dy)
    field = harmonic_field(params, length, width, seed, lateral=y.size > 1)
    nx = _grid_count(length, params.dx, "road length")
    x = x0 + np.arange(nx) * params.dx
    z = field.grid(x0, nx, y)
    info = {"generator": "roadlib.synthesis.synth_surface", "params": params.to_dict(),
            "seed": _seed_repr(seed), "n_harmonics": field.n_harmonics,
            "period_x_m": field.n_fft * params.dx}
    info.update(meta or {})

    def lines(ys):   # the field itself at lateral positions ys (RoadSurface "Exact lines")
        return field.grid(x0, nx, np.asarray(ys, float))

    return RoadSurface(x, y, z, info, lines=lines if y.size > 1 else None)


def regenerate_surface(meta: dict, x, y):
    """The road a ``synth_surface`` metadata describes, on the grid of its file (for
    :class:`roadlib.surface.RoadSurface`'s exact lines after loading); None where the
    seed is not a plain integer."""
    seed = meta.get("seed")
    if not isinstance(seed, int):
        return None
    params = SpectralParams(**meta["params"])
    x = np.asarray(x, float)
    return synth_surface(params, float(x[-1] - x[0]), float(y[-1] - y[0]), seed=seed, x0=float(x[0]))


def _seed_repr(seed):
    if isinstance(seed, np.random.SeedSequence):
        return {"entropy": str(seed.entropy), "spawn_key": list(seed.spawn_key)}
    return seed
