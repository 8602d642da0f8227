"""Linear frequency response of a vehicle to road input, from Exudyn's linearisation.

What it is for: fast, noise-free answers to "how does this vehicle respond to a road
of this spectrum at this speed" -- the frequency response functions (FRFs) from the
road height under each tyre to every output channel, and the response PSD and RMS
of each channel for an ISO 8608 road (level Gd(n0), waviness w, band nmin-nmax) with a
model of the lateral coherence between the tyre tracks.  It serves the inverse fit
(predicted response level per road class), quick checks and the modal analysis
(:mod:`vehicles.modal` reuses the linearised matrices).

What it is not: a time simulation (:mod:`vehicles.simulate`) -- nonlinear effects
(friction, bump stops, tyre lift-off) are absent or linearised at rest -- nor a road
generator (:mod:`roadlib.synthesis`).

Method
------
The vehicle (``vehicles.builder.build_model`` with Tait-Bryan ``Rxyz`` nodes, so no
constraints) is linearised at its static equilibrium by
``exudyn.solver.ComputeLinearizedSystem``::

    M q'' + D q' + K q = Bk z_r + Bc z_r'

with ``q`` the ODE2 coordinates (6 per body: displacement of the centre of gravity
and Tait-Bryan angles) and ``z_r`` (n_contacts,) the road heights under the tyres.
A tyre force is ``k_t (z_r - u) + c_t (z_r' - u')``: the ``-k_t u - c_t u'`` part is in
``K`` and ``D``, the known part ``k_t z_r + c_t z_r'`` enters as generalised forces
``B (k_t z_r + c_t z_r')`` with ``B`` the builder's road-input map (the one the
simulation's force injector uses, :func:`road_input_matrix`; it equals the
generalised forces of the builder's road loads: vertical force at the axle centre
line plus roll moment per axle), so ``Bk = B diag(k_t)``, ``Bc = B diag(c_t)``.
Outputs are linear in ``q``: a body-fixed point
moves by ``dp = J_p dq``, ``J_p = [I, -[R r]x G]`` with ``G`` the map from angle rates to
the angular velocity; accelerations are ``-omega^2`` times displacements (the
centripetal terms are of second order).  The points are those of
:func:`vehicles.simulate.output_points`, so channels mean the same in both.

FRF::

    H(f) = C (K + j w D - w^2 M)^-1 (Bk + j w Bc),   w = 2 pi f

[m/m for displacements, (m/s^2)/m for accelerations, rad/m for rotations].

Road input: a tyre at vehicle position (x_c, y_c) (x_c <= 0 behind the first axle)
sees the road ``z(x0 + v t + x_c, y_c)``.  With the temporal one-sided road PSD
``G(f) = Gd(n) / v`` at ``n = f / v`` [m^2/Hz] (zero outside nmin-nmax), the cross
spectral density of the inputs is::

    S_cd(f) = G(f) gamma(n, |y_c - y_d|) exp(j 2 pi f (x_c - x_d) / v)

and the output PSD is ``S_yy = diag(H S H^H)`` (one-sided, unit^2/Hz).  The lateral
coherence ``gamma`` is

* ``"correlated"``: 1 (every tyre on the same profile: bounce and pitch only);
* ``"independent"``: 1 on the same side, 0 between left and right tracks;
* ``"surface"`` (default): the coherence of roadlib's surface PSD (eq (5),
  :func:`roadlib.psd.lateral_density`): the Fourier transform of the lateral density,
  a Matern function ``gamma = r^nu K_nu(r) / (Gamma(nu) 2^(nu-1))``, ``nu = w/2``,
  ``r = 2 pi n |dy| / lam`` (for w = 2: ``r K_1(r)``);
* a callable ``gamma(n [cycles/m], dy [m]) -> [-]``.

With the ``tyre_enveloping`` effect the road PSD is multiplied by ``sinc(n L)^2``
(moving average over the footprint length L).  A road given on a grid and
interpolated linearly (``RoadSurface.height``) carries less power than its PSD near
its Nyquist frequency (about ``sinc(n dx)^4``): use a grid step well below the
shortest wavelength that matters (dx <= 1/(10 nmax)) when comparing with simulations.

Units: SI throughout; frequencies in Hz, spatial frequencies in cycles/m.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError

#: Rxyz coordinate names of one body, in Exudyn's order
DOF_NAMES = ("x", "y", "z", "rx", "ry", "rz")
#: DCDC rigid-motion channels (top-face centre, from static): name -> unit
DCDC_MOTIONS = {"dcdc_Tx": "m", "dcdc_Ty": "m", "dcdc_Tz": "m",
                "dcdc_Rx": "rad", "dcdc_Ry": "rad", "dcdc_Rz": "rad"}
COHERENCE_MODELS = ("surface", "correlated", "independent")


@dataclass(frozen=True)
class OutputChannel:
    """One linear output channel ``y = row @ q`` (times ``-w^2`` for accelerations).

    Attributes
    ----------
    name : str
        Channel name (``susp_disp_3L``, ``axle_acc_1R``, ``dcdc_z_P2``, ``dcdc_Ry``...).
    unit : str
        ``m``, ``m/s^2`` or ``rad``.
    row : ndarray (n,)
        Output row in the ODE2 coordinates.
    order : int
        0 for a displacement (or angle), 2 for an acceleration.
    """

    name: str
    unit: str
    row: np.ndarray
    order: int


@dataclass
class LinearModel:
    """The vehicle linearised at static equilibrium, with road inputs and outputs.

    Attributes
    ----------
    vp : VehicleParams
        The vehicle (after effect configuration).
    chassis : str
        ``"rigid"`` or ``"flexible"``.
    model : vehicles.builder.VehicleModel
        The Exudyn model it was linearised from (``node_type="Rxyz"``).
    M, K, D : ndarray (n, n)
        Mass [kg, kg m^2], stiffness [N/m, N m/rad] and damping matrices in the ODE2
        coordinates (``K`` and ``D`` as Exudyn returns them, not symmetrised).
    Bk, Bc : ndarray (n, n_contacts)
        Generalised road force per metre of road height (``Bk``, includes k_t) and per
        m/s of road height rate (``Bc``, includes c_t) under each contact.
    contacts : list of dict
        ``{"axle": a (1-based), "side": "L"|"R", "x": [m], "y": [m]}`` per tyre, in the
        order of the columns of ``Bk``.
    outputs : list of OutputChannel
    dof_names : list of str
        ``"<body>.<dof>"`` for each coordinate.
    body_dofs : dict
        ``{body name: ndarray of coordinate indices}``.
    meta : dict
        Vehicle id, chassis, stiffness factor, frame segments, effects, n_dof.
    footprint : float
        Tyre footprint length [m] of the ``tyre_enveloping`` effect (0: none): the road
        input is filtered by the moving average ``sinc(n L) = sin(pi n L) / (pi n L)``.
    """

    vp: object
    chassis: str
    model: object
    M: np.ndarray
    K: np.ndarray
    D: np.ndarray
    Bk: np.ndarray
    Bc: np.ndarray
    contacts: list
    outputs: list
    dof_names: list
    body_dofs: dict
    meta: dict = field(default_factory=dict)
    footprint: float = 0.0

    # ------------------------------------------------------------------ basics
    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    @property
    def channel_names(self) -> list:
        return [o.name for o in self.outputs]

    def output(self, name: str) -> OutputChannel:
        for o in self.outputs:
            if o.name == name:
                return o
        raise EroadInputError(f"unknown output channel {name!r}; known: {', '.join(self.channel_names)}")

    def _select(self, channels):
        if channels is None:
            return list(self.outputs)
        return [self.output(c) for c in channels]

    def state_space(self):
        """First-order form ``x' = A x + B u`` with ``x = [q, q']``, ``u = [z_r, z_r']``.

        Returns
        -------
        (A, B) : ndarrays (2n, 2n), (2n, 2 n_contacts)
        """
        n = self.n_dof
        Minv = np.linalg.inv(self.M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ self.D]])
        B = np.vstack([np.zeros((n, 2 * self.Bk.shape[1])), Minv @ np.hstack([self.Bk, self.Bc])])
        return A, B

    def output_matrices(self, channels, A=None, B=None) -> tuple:
        """Output equation ``y = C x + D u`` of :meth:`state_space` for ``channels``.

        Displacements read the coordinates; accelerations are the second derivative,
        i.e. the acceleration rows of A and B (so they feel the road input directly).

        Returns
        -------
        (C, D) : ndarrays (n_channels, 2n), (n_channels, 2 n_contacts)
        """
        if A is None or B is None:
            A, B = self.state_space()
        n = self.n_dof
        C = np.zeros((len(channels), 2 * n))
        D = np.zeros((len(channels), B.shape[1]))
        for k, name in enumerate(channels):
            o = self.output(name)
            if o.order == 0:
                C[k, :n] = o.row
            else:
                C[k] = o.row @ A[n:, :]
                D[k] = o.row @ B[n:, :]
        return C, D

    # ------------------------------------------------------------------ FRFs
    def coordinate_frf(self, freqs) -> np.ndarray:
        """Coordinate response to a unit road height under each contact.

        Parameters
        ----------
        freqs : array_like (nf,)
            Frequencies [Hz], >= 0.

        Returns
        -------
        ndarray (nf, n, n_contacts), complex
            [m/m or rad/m].
        """
        f = _freqs(freqs)
        out = np.empty((f.size, self.n_dof, self.Bk.shape[1]), complex)
        for i, fi in enumerate(f):
            w = 2 * np.pi * fi
            Z = self.K + 1j * w * self.D - w * w * self.M
            out[i] = np.linalg.solve(Z, self.Bk + 1j * w * self.Bc)
        return out

    def frf(self, freqs, channels=None) -> np.ndarray:
        """FRFs from the road height under each tyre to the output channels.

        Parameters
        ----------
        freqs : array_like (nf,)
            Frequencies [Hz], >= 0.
        channels : list of str, optional
            Default: all of :attr:`outputs`, in that order.

        Returns
        -------
        ndarray (nf, n_channels, n_contacts), complex
            [m/m], [(m/s^2)/m] or [rad/m].
        """
        f = _freqs(freqs)
        outs = self._select(channels)
        # the same grid and channels are asked for again and again (a response RMS per
        # lateral-coherence alternative, per segment): the last few FRFs are kept
        key = (f.tobytes(), tuple(o.name for o in outs))
        cache = self.__dict__.setdefault("_frf_cache", {})
        if key in cache:
            return cache[key]
        X = self.coordinate_frf(f)
        C = np.array([o.row for o in outs])
        H = np.einsum("on,fnc->foc", C, X)
        w2 = (2 * np.pi * f) ** 2
        for j, o in enumerate(outs):
            if o.order == 2:
                H[:, j, :] *= -w2[:, None]
        H.flags.writeable = False
        if len(cache) >= 8:
            cache.pop(next(iter(cache)))
        cache[key] = H
        return H

    def track_frf(self, freqs, speed: float, channels=None) -> np.ndarray:
        """FRFs from the left and right track profiles (wheelbase delays included).

        Every tyre of side L sees the left track delayed by ``-x_c / v`` behind the
        first axle, likewise R (dual tyres and different track widths are taken as
        the same track of their side).

        Parameters
        ----------
        freqs : array_like (nf,)
            [Hz].
        speed : float
            [m/s], > 0.
        channels : list of str, optional

        Returns
        -------
        ndarray (nf, n_channels, 2), complex
            Columns: left track, right track; reference: the first axle's position.
        """
        v = _speed(speed)
        f = _freqs(freqs)
        H = self.frf(f, channels)
        xs = np.array([c["x"] for c in self.contacts])
        E = np.exp(1j * 2 * np.pi * f[:, None] * xs[None, :] / v)
        out = np.zeros(H.shape[:2] + (2,), complex)
        for c, ct in enumerate(self.contacts):
            out[:, :, 0 if ct["side"] == "L" else 1] += H[:, :, c] * E[:, c][:, None]
        return out

    # ------------------------------------------------------------------ road spectra
    def road_cross_spectrum(self, road, speed: float, freqs, coherence="surface") -> np.ndarray:
        """Cross spectral density matrix of the road heights under the tyres.

        Parameters
        ----------
        road : SpectralParams or dict
            ``Gq_n0`` [m^3], ``w`` [-], ``nmin``, ``nmax`` [cycles/m], optional ``lam`` [-].
        speed : float
            [m/s].
        freqs : array_like (nf,)
            [Hz].
        coherence : {"surface", "correlated", "independent"} or callable
            Lateral coherence model (module docstring).

        Returns
        -------
        ndarray (nf, n_contacts, n_contacts), complex
            One-sided [m^2/Hz].
        """
        v = _speed(speed)
        f = _freqs(freqs)
        G = temporal_road_psd(road, v, f)
        n = f / v
        ys = np.array([c["y"] for c in self.contacts])
        xs = np.array([c["x"] for c in self.contacts])
        sides = np.array([c["side"] for c in self.contacts])
        dy = np.abs(ys[:, None] - ys[None, :])
        # a coherence is a function of (n, dy) pair by pair: evaluated on the few distinct
        # track distances (an 8x4 truck's 16 tyres have 7) and gathered into the matrix
        udy, inv = np.unique(dy, return_inverse=True)
        inv = inv.reshape(dy.shape)
        if callable(coherence):
            # one broadcast call (n (nf, 1), distinct dy (1, K)) where the callable allows
            # it, else one call per frequency on the whole matrix
            try:
                g = np.asarray(coherence(n[:, None], udy[None, :]), float)
            except (TypeError, ValueError):
                g = None
            if g is not None and g.shape == (f.size, udy.size):
                gam = g[:, inv]
            else:
                gam = np.empty((f.size,) + dy.shape)
                for i, ni in enumerate(n):
                    gam[i] = np.asarray(coherence(ni, dy), float)
        elif coherence == "correlated":
            gam = np.ones((f.size,) + dy.shape)
        elif coherence == "independent":
            gam = np.broadcast_to((sides[:, None] == sides[None, :]).astype(float),
                                  (f.size,) + dy.shape).copy()
        elif coherence == "surface":
            p = _road_dict(road)
            gam = surface_coherence(n[:, None], udy[None, :], p["w"], p["lam"])[:, inv]
        else:
            raise EroadInputError(f"unknown coherence model {coherence!r}; use one of "
                                  f"{', '.join(COHERENCE_MODELS)} or a callable gamma(n, dy)")
        E = np.exp(1j * 2 * np.pi * f[:, None, None] * (xs[:, None] - xs[None, :])[None] / v)
        if self.footprint > 0:
            G = G * np.sinc(n * self.footprint) ** 2
        return G[:, None, None] * gam * E

    def response_psd(self, road, speed: float, freqs, coherence="surface", channels=None) -> dict:
        """Response PSD of each channel for a random road.

        Parameters
        ----------
        road : SpectralParams or dict
            ISO road: ``Gq_n0`` [m^3], ``w``, ``nmin``, ``nmax`` [cycles/m], ``lam``.
        speed : float
            [m/s].
        freqs : array_like (nf,)
            [Hz].
        coherence : str or callable
            See :meth:`road_cross_spectrum`.
        channels : list of str, optional

        Returns
        -------
        dict
            ``{channel: ndarray (nf,)}`` one-sided PSD [unit^2/Hz].
        """
        f = _freqs(freqs)
        outs = self._select(channels)
        H = self.frf(f, [o.name for o in outs])
        S = self.road_cross_spectrum(road, speed, f, coherence)
        # P[f, o] = sum_cd H[f, o, c] S[f, c, d] conj(H[f, o, d]) as one batched product
        P = np.einsum("fod,fod->fo", H @ S, H.conj()).real
        return {o.name: np.maximum(P[:, j], 0.0) for j, o in enumerate(outs)}

    def response_rms(self, road, speed: float, coherence="surface", channels=None,
                     band: tuple | None = None, n_freq: int = 3000) -> dict:
        """RMS of each channel for a random road (integral of the response PSD).

        Parameters
        ----------
        road, speed, coherence, channels
            As in :meth:`response_psd`.
        band : (float, float), optional
            Frequency band [Hz]; default the road band ``(nmin v, nmax v)``.
        n_freq : int
            Points of the logarithmic frequency grid (trapezoidal rule).

        Returns
        -------
        dict
            ``{channel: rms}`` [unit].
        """
        v = _speed(speed)
        p = _road_dict(road)
        lo, hi = band if band is not None else (p["nmin"] * v, p["nmax"] * v)
        if not 0 < lo < hi:
            raise EroadInputError(f"frequency band must satisfy 0 < lo < hi, got ({lo}, {hi})")
        f = np.geomspace(lo, hi, int(n_freq))
        psd = self.response_psd(road, v, f, coherence, channels)
        return {k: float(np.sqrt(np.trapezoid(s, f))) for k, s in psd.items()}


    def expected_welch_psd(self, road, speed: float, fs: float, nperseg: int, coherence="surface",
                           channels=None, window="hann", f_max: float | None = None) -> tuple:
        """Expected value of a Welch PSD estimate of each channel (leakage included).

        What :func:`scipy.signal.welch` (``window``, ``nperseg``, one-sided density)
        returns on average for a record of the response; compare it with measured or
        simulated Welch estimates instead of the raw PSD when resonances are narrower
        than a few bins (see :func:`welch_expectation`).

        Parameters
        ----------
        road, speed, coherence, channels
            As in :meth:`response_psd`.
        fs : float
            Sample rate [Hz].
        nperseg : int
            Welch segment length [samples].
        window : str
            Window name for :func:`scipy.signal.get_window`.
        f_max : float, optional
            Upper end of the PSD integral [Hz] (default fs/2).

        Returns
        -------
        (f, dict)
            Welch bin frequencies [Hz] (nperseg // 2 + 1,) and ``{channel: expected
            PSD [unit^2/Hz]}``.
        """
        def psd(f):
            return self.response_psd(road, speed, f, coherence, channels)

        return welch_expectation(psd, fs, nperseg, window, f_max=f_max)


# --------------------------------------------------------------------------- helpers
def welch_expectation(psd, fs: float, nperseg: int, window="hann", oversample: int = 8,
                      f_max: float | None = None, return_kernel: bool = False,
                      detrend: bool = False) -> tuple:
    """Expected Welch estimate of a process with a known one-sided PSD.

    ``E[P(f_k)] = (1/U) integral_0^inf S(f) (|W(f_k - f)|^2 + |W(f_k + f)|^2) df`` with
    ``W`` the window's DTFT and ``U = fs sum(w^2)`` (scipy's density scaling); the
    integral runs on a grid ``oversample`` times finer than the Welch bins, up to
    ``f_max`` (default fs/2, no aliasing).

    Parameters
    ----------
    psd : callable
        ``psd(f [Hz]) -> dict of arrays`` (or one array), the one-sided PSD [unit^2/Hz].
    fs : float
        Sample rate [Hz].
    nperseg : int
        Segment length [samples].
    window : str
    oversample : int
    f_max : float, optional
        [Hz]
    return_kernel : bool
        Also return the fine grid ``ff`` [Hz], the PSD on it and the kernel matrix
        (n_bins, n_fine) with ``expected = kernel @ psd(ff)``.
    detrend : bool
        Model scipy's default ``detrend='constant'`` (each segment's mean removed before
        windowing): the window of bin k becomes g_m = w_m e^{-j 2 pi k m / N} - W(k) / N,
        which changes the rows of the bins where W(k) != 0 (0 and 1 for a periodic Hann
        window). Default False: no mean removal.

    Returns
    -------
    (f, expected) or (f, expected, ff, psd_ff, kernel)
        Bin frequencies [Hz] and expected estimates (same structure as ``psd``'s
        return value).
    """
    import scipy.signal

    nperseg = int(nperseg)
    w = scipy.signal.get_window(window, nperseg)
    U = fs * np.sum(w ** 2)
    nfft = nperseg * int(oversample)
    df = fs / nfft
    f_max = fs / 2 if f_max is None else float(f_max)
    ff = np.arange(0, int(f_max / df) + 1) * df
    ff = ff + 0.5 * df * (ff == 0)             # avoid f = 0 (road PSD singular)
    Wk = np.abs(np.fft.fft(w, nfft)) ** 2      # |W(m df)|^2, periodic in fs
    fk = np.arange(nperseg // 2 + 1) * fs / nperseg
    mk = np.arange(fk.size) * oversample
    mj = np.arange(ff.size)
    # kernel (n_bins, n_fine): |W(f_k - f_j)|^2 + |W(f_k + f_j)|^2
    Kmat = (Wk[(mk[:, None] - mj[None, :]) % nfft] + Wk[(mk[:, None] + mj[None, :]) % nfft]) * df / U
    if detrend:
        m = np.arange(nperseg)
        for k in range(fk.size):
            e = np.exp(-2j * np.pi * k * m / nperseg)
            mean_w = np.sum(w * e) / nperseg
            if abs(mean_w) < 1e-12 * np.sum(w):
                continue       # the mean removal leaves this bin's window unchanged
            A = np.abs(np.fft.fft(w * e - mean_w, nfft)) ** 2
            Kmat[k] = (A[mj % nfft] + A[(-mj) % nfft]) * df / U
    S = psd(ff)
    if isinstance(S, dict):
        out = {k: Kmat @ np.asarray(v) for k, v in S.items()}
    else:
        out = Kmat @ np.asarray(S)
    if return_kernel:
        return fk, out, ff, S, Kmat
    return fk, out


def _freqs(freqs) -> np.ndarray:
    f = np.atleast_1d(np.asarray(freqs, float))
    if f.ndim != 1 or not np.all(np.isfinite(f)) or np.any(f < 0):
        raise EroadInputError("frequencies must be a 1-D array of finite values >= 0 Hz")
    return f


def _speed(speed) -> float:
    try:
        v = float(speed)
    except (TypeError, ValueError):
        raise EroadInputError(f"speed must be a number [m/s], got {speed!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise EroadInputError(f"speed must be > 0 m/s, got {speed!r}")
    return v


def _road_dict(road) -> dict:
    """Gq_n0, w, nmin, nmax, lam from SpectralParams or a dict (validated); plus
    ``w2`` and ``n_break`` for a two-slope road (``roadlib.psd.two_slope_psd``;
    both or neither)."""
    from roadlib.synthesis import SpectralParams

    if isinstance(road, SpectralParams):
        out = {"Gq_n0": road.Gq_n0, "w": road.w, "nmin": road.nmin, "nmax": road.nmax,
               "lam": road.lam}
        if road.w2 is not None:
            out.update(w2=road.w2, n_break=road.n_break)
        return out
    if not isinstance(road, dict):
        raise EroadInputError(f"road must be SpectralParams or a dict, got {type(road).__name__}")
    known = {"Gq_n0", "w", "nmin", "nmax", "lam", "dx", "dy", "w2", "n_break"}
    bad = set(road) - known
    if bad:
        raise EroadInputError(f"road parameters: unknown key(s) {', '.join(sorted(bad))}")
    if "Gq_n0" not in road:
        raise EroadInputError("road parameters: missing 'Gq_n0' [m^3]")
    from roadlib.psd import ISO_BAND
    out = {"Gq_n0": road["Gq_n0"], "w": road.get("w", 2.0), "nmin": road.get("nmin", ISO_BAND[0]),
           "nmax": road.get("nmax", ISO_BAND[1]), "lam": road.get("lam", 1.0)}
    two = [k for k in ("w2", "n_break") if road.get(k) is not None]
    if len(two) == 1:
        raise EroadInputError("road parameters: a two-slope road needs both 'w2' and 'n_break'")
    if two:
        out.update(w2=road["w2"], n_break=road["n_break"])
    for k, v in out.items():
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise EroadInputError(f"road parameters: {k} must be a positive number, got {v!r}")
    if not out["nmin"] < out["nmax"]:
        raise EroadInputError(f"road parameters: nmin = {out['nmin']} must be below nmax = {out['nmax']}")
    return {k: float(v) for k, v in out.items()}


def temporal_road_psd(road, speed: float, freqs) -> np.ndarray:
    """One-sided temporal road PSD seen by a tyre: ``G(f) = Gd(f/v) / v``.

    Parameters
    ----------
    road : SpectralParams or dict
        ``Gq_n0`` [m^3], ``w`` [-], ``nmin``, ``nmax`` [cycles/m]; optional ``w2`` [-]
        and ``n_break`` [cycles/m] for a two-slope spectrum
        (``roadlib.psd.two_slope_psd``, ``w`` below the break, ``w2`` above).
    speed : float
        [m/s].
    freqs : array_like
        [Hz].

    Returns
    -------
    ndarray
        [m^2/Hz]; zero outside ``nmin v <= f <= nmax v``.
    """
    from roadlib.psd import road_psd

    v = _speed(speed)
    p = _road_dict(road)
    f = _freqs(freqs)
    n = f / v
    inside = (n >= p["nmin"]) & (n <= p["nmax"])
    G = np.zeros_like(f)
    G[inside] = road_psd(n[inside], p["Gq_n0"], p["w"], p.get("w2"), p.get("n_break")) / v
    return G


def surface_coherence(n, dy, w: float = 2.0, lam: float = 1.0) -> np.ndarray:
    """Lateral coherence of two tracks ``dy`` apart on roadlib's surface PSD (eq (5)).

    ``gamma(n, dy) = integral p(n_y | n) cos(2 pi n_y dy) dn_y`` with ``p`` from
    :func:`roadlib.psd.lateral_density`, in closed form
    ``r^nu K_nu(r) / (Gamma(nu) 2^(nu - 1))``, ``nu = w/2``, ``r = 2 pi n |dy| / lam``
    (the characteristic function of a Student-t density with w degrees of freedom).

    Parameters
    ----------
    n : array_like
        Spatial frequency [cycles/m], > 0.
    dy : array_like
        Lateral distance [m] (broadcast with ``n``).
    w : float
        Waviness [-].
    lam : float
        Anisotropy factor [-].

    Returns
    -------
    ndarray
        Coherence in [0, 1] (real: the surface is symmetric in n_y).
    """
    import scipy.special as sp

    nu = 0.5 * float(w)
    r = 2 * np.pi * np.abs(np.asarray(n, float)) * np.abs(np.asarray(dy, float)) / float(lam)
    r = np.asarray(r, float)
    out = np.ones_like(r)
    pos = r > 1e-12
    rp = r[pos]
    with np.errstate(under="ignore"):
        out[pos] = rp ** nu * sp.kv(nu, rp) / (math.gamma(nu) * 2 ** (nu - 1))
    return np.clip(np.nan_to_num(out, nan=0.0), 0.0, 1.0)


def _rotation_map(theta) -> tuple[np.ndarray, np.ndarray]:
    """Rotation matrix of Tait-Bryan angles and G (angular velocity = G theta')."""
    from exudyn.rigidBodyUtilities import RotXYZ2RotationMatrix

    theta = np.asarray(theta, float)
    R = np.asarray(RotXYZ2RotationMatrix(theta))
    G = np.empty((3, 3))
    h = 1e-7
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        dR = (np.asarray(RotXYZ2RotationMatrix(theta + e)) - np.asarray(RotXYZ2RotationMatrix(theta - e))) / (2 * h)
        W = dR @ R.T
        G[:, k] = [0.5 * (W[2, 1] - W[1, 2]), 0.5 * (W[0, 2] - W[2, 0]), 0.5 * (W[1, 0] - W[0, 1])]
    return R, G


def _skew(v) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class _Kinematics:
    """Linearised kinematics of body-fixed points at the current (static) state."""

    def __init__(self, model):
        import exudyn as exu

        self.model = model
        self.idx = model.coordinate_indices()
        self.n = sum(len(v) for v in self.idx.values())
        self.R, self.G = {}, {}
        for b in model.bodies:
            theta = np.asarray(model.mbs.GetNodeOutput(b.node, exu.OutputVariableType.Coordinates))[3:6] \
                + np.asarray(model.mbs.GetNode(b.node)["referenceCoordinates"])[3:6]
            R, G = _rotation_map(theta)
            R_exu = np.asarray(model.mbs.GetNodeOutput(b.node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
            if not np.allclose(R, R_exu, atol=1e-9):  # pragma: no cover - parameterisation check
                raise RuntimeError("Rxyz rotation parameterisation differs from Exudyn's")
            self.R[b.name], self.G[b.name] = R, G

    def point(self, body: str, local) -> np.ndarray:
        """(3, n) Jacobian of the world position of a body-fixed point (``local``
        relative to the body's centre of gravity in body axes)."""
        J = np.zeros((3, self.n))
        i = self.idx[body]
        d = self.R[body] @ np.asarray(local, float)
        J[:, i[:3]] = np.eye(3)
        J[:, i[3:6]] = -_skew(d) @ self.G[body]
        return J

    def rotation(self, body: str) -> np.ndarray:
        """(3, n) Jacobian of the small global rotation vector of a body."""
        J = np.zeros((3, self.n))
        J[:, self.idx[body][3:6]] = self.G[body]
        return J


def _load_generalized_force(model, kin: _Kinematics, load: int) -> np.ndarray:
    """Generalised force (n,) of a unit value of a builder road load (force or torque)."""
    mbs = model.mbs
    ld = mbs.GetLoad(load)
    mk = mbs.GetMarker(ld["markerNumber"])
    body = next(b for b in model.bodies if int(b.body) == int(mk["bodyNumber"]))
    vec = np.asarray(ld["loadVector"], float)
    kind = ld["loadType"]
    if kind == "ForceVector":
        local = np.asarray(mk.get("localPosition", [0.0, 0.0, 0.0]), float)
        return kin.point(body.name, local)[2]
    if kind == "TorqueVector":
        return kin.rotation(body.name)[0]
    raise RuntimeError(f"unexpected road load type {kind!r} (load {load}, vector {vec})")  # pragma: no cover


def road_input_matrix(model, kin: _Kinematics | None = None, from_loads: bool = False) -> np.ndarray:
    """Generalised force per newton of road force under each tyre, (n, n_contacts).

    The builder's own map (``VehicleModel.road_input_matrix_global``, the one the
    simulation's road-force injector uses) when it has one; otherwise, or with
    ``from_loads``, the generalised forces of the builder's road loads (a vertical
    force at the axle's centre line and a roll moment ``y_c f_c`` per axle,
    ``VehicleModel.road_force_matrices``), computed here from the kinematics.

    Parameters
    ----------
    model : vehicles.builder.VehicleModel
    kin : _Kinematics, optional
    from_loads : bool

    Returns
    -------
    ndarray (n, n_contacts)
        [1] for translations, [m] for rotations (generalised force per N).
    """
    if not from_loads and hasattr(model, "road_input_matrix_global"):
        return np.asarray(model.road_input_matrix_global(), float)
    kin = kin or _Kinematics(model)
    Bf, Bt = model.road_force_matrices()
    qf = [_load_generalized_force(model, kin, lf) for lf, _ in model.road_loads]
    qt = [_load_generalized_force(model, kin, lt) for _, lt in model.road_loads]
    nc = len(model.contacts)
    B = np.zeros((kin.n, nc))
    for c in range(nc):
        for a in range(len(model.axles)):
            B[:, c] += Bf[a, c] * qf[a] + Bt[a, c] * qt[a]
    return B


def _outputs(model, kin: _Kinematics) -> list:
    from vehicles.simulate import output_points

    rows = {}
    kinds = {}
    for ch, kind, body, wp in output_points(model):
        b = model.body(body)
        J = kin.point(body, np.asarray(wp, float) - b.cog)
        rows[ch] = J
        kinds[ch] = kind
    vp = model.vp
    outs = []
    tags = [f"{a + 1}{s}" for a in range(len(vp.axles)) for s in ("L", "R")]
    for t in tags:
        outs.append(OutputChannel(f"susp_disp_{t}", "m", rows[f"seat_axle_{t}"][2] - rows[f"seat_body_{t}"][2], 0))
    for t in tags:
        outs.append(OutputChannel(f"axle_acc_{t}", "m/s^2", rows[f"axle_acc_{t}"][2], 2))
    for t in tags:
        outs.append(OutputChannel(f"body_acc_{t}", "m/s^2", rows[f"body_acc_{t}"][2], 2))
    if vp.dcdc is not None:
        pk = sorted(k for k in rows if kinds[k] == "yz_pos")
        for k in pk:
            outs.append(OutputChannel(f"dcdc_y_{k}", "m", rows[k][1], 0))
        for k in pk:
            outs.append(OutputChannel(f"dcdc_z_{k}", "m", rows[k][2], 0))
        d = vp.dcdc
        b = model.body("dcdc")
        top = np.array([d.x, d.y, d.z_base + d.height]) - b.cog
        T = kin.point("dcdc", top)
        Rj = kin.rotation("dcdc")
        rows6 = list(T) + list(Rj)
        for j, (name, unit) in enumerate(DCDC_MOTIONS.items()):
            outs.append(OutputChannel(name, unit, rows6[j], 0))
    return outs


def configured_build(vp, chassis: str = "rigid", frame_segments: int | None = None,
                     stiffness_factor: float = 1.0, effects=None):
    """Build the Rxyz model for linearisation, with the effects' configuration hooks.

    Effects change the vehicle or chassis through :meth:`Effect.configure` (payload,
    frame flexibility, ...); suspension terms are installed so that Exudyn linearises
    them at rest (a smoothed Coulomb friction becomes a large viscous damping -- the
    stuck suspension -- a bump stop with a gap does nothing, an asymmetric damper
    its mean); ``tyre_enveloping`` becomes the footprint filter of the road input
    (:attr:`LinearModel.footprint`); other road and output hooks (sensor dynamics,
    speed scale) are not part of the linear model and are listed in the notes.

    Returns
    -------
    (model, ctx, notes, effects) : VehicleModel, EffectContext, list of str, dict
        ``effects`` are the resolved effect parameters.
    """
    from vehicles.builder import build_model
    from vehicles.effects import EFFECTS, resolve_effects, suspension_terms_of
    from vehicles.effects.base import Effect, EffectContext
    from vehicles.params import load_vehicle

    vp0 = load_vehicle(vp)
    eff = resolve_effects(effects)
    ctx = EffectContext(vp=vp0, reference_vp=vp0, chassis=chassis, stiffness_factor=float(stiffness_factor),
                        frame_segments=frame_segments)
    notes = []
    for name, p in eff.items():
        EFFECTS[name].configure(ctx, p)
        e = type(EFFECTS[name])
        if name != "tyre_enveloping" and (e.road is not Effect.road or e.outputs is not Effect.outputs):
            notes.append(f"effect {name}: its road/output hook is not part of the linear model")
        if EFFECTS[name].nonlinear:
            notes.append(f"effect {name}: nonlinear, linearised at rest (static equilibrium)")
    terms_of = suspension_terms_of(eff, ctx)
    model = build_model(ctx.vp, chassis=ctx.chassis, frame_segments=ctx.frame_segments,
                        stiffness_factor=ctx.stiffness_factor, node_type="Rxyz",
                        suspension_terms=terms_of)
    return model, ctx, notes, eff


def linear_model(vp, chassis: str = "rigid", frame_segments: int | None = None,
                 stiffness_factor: float = 1.0, effects=None) -> LinearModel:
    """Linearise a vehicle at static equilibrium with road inputs and output channels.

    Parameters
    ----------
    vp : str or Path or VehicleParams
        Built-in id, TOML file or parameters.
    chassis : {"rigid", "flexible"}
    frame_segments : int, optional
        Segments of the flexible frame (default ``vp.frame.segments``).
    stiffness_factor : float
        Frame stiffness scale [-] (flexible chassis).
    effects : dict or list of str, optional
        Effects whose configuration applies (see :func:`configured_build`).

    Returns
    -------
    LinearModel
    """
    model, ctx, notes, eff = configured_build(vp, chassis, frame_segments, stiffness_factor, effects)
    M, K, D = model.linearized_system()
    kin = _Kinematics(model)
    Bunit = road_input_matrix(model, kin)
    kc = np.array([c.stiffness for c in model.contacts])
    cc = np.array([c.damping for c in model.contacts])
    idx = kin.idx
    dof_names = [""] * M.shape[0]
    for name, ii in idx.items():
        for j, i in enumerate(ii):
            dof_names[i] = f"{name}.{DOF_NAMES[j]}"
    contacts = [{"axle": ct.axle + 1, "side": ct.side, "x": float(ctx.vp.axles[ct.axle].x), "y": float(ct.y)}
                for ct in model.contacts]
    meta = {"vehicle": ctx.vp.id, "chassis": model.chassis, "stiffness_factor": model.stiffness_factor,
            "frame_segments": len(model.segments) if model.chassis == "flexible" else 1,
            "effects": {k: dict(v) for k, v in eff.items()}, "notes": notes, "n_dof": int(M.shape[0])}
    footprint = float(eff["tyre_enveloping"]["length"]) if "tyre_enveloping" in eff else 0.0
    return LinearModel(vp=ctx.vp, chassis=model.chassis, model=model, M=M, K=K, D=D,
                       Bk=Bunit * kc[None, :], Bc=Bunit * cc[None, :], contacts=contacts,
                       outputs=_outputs(model, kin), dof_names=dof_names,
                       body_dofs={k: np.asarray(v) for k, v in idx.items()}, meta=meta,
                       footprint=footprint)


def response_psd(vp, road_params, speed: float, freqs, coherence="surface", chassis: str = "rigid",
                 channels=None, frame_segments: int | None = None, stiffness_factor: float = 1.0,
                 effects=None) -> dict:
    """Response PSD of each output channel of a vehicle on an ISO 8608 road.

    Parameters
    ----------
    vp : str or Path or VehicleParams or LinearModel
        The vehicle (a :class:`LinearModel` is used as it is).
    road_params : SpectralParams or dict
        ``Gq_n0`` = Gd(n0) [m^3], ``w`` [-], ``nmin``, ``nmax`` [cycles/m], ``lam`` [-]
        (anisotropy, used by ``coherence="surface"``).
    speed : float
        [m/s].
    freqs : array_like
        [Hz].
    coherence : {"surface", "correlated", "independent"} or callable
        Lateral coherence of the tyre tracks (module docstring).
    chassis, frame_segments, stiffness_factor, effects
        As in :func:`linear_model`.
    channels : list of str, optional

    Returns
    -------
    dict
        ``{channel: ndarray}`` one-sided PSD [unit^2/Hz] at ``freqs``.
    """
    lm = vp if isinstance(vp, LinearModel) else linear_model(vp, chassis, frame_segments,
                                                             stiffness_factor, effects)
    return lm.response_psd(road_params, speed, freqs, coherence, channels)


def response_rms(vp, road_params, speed: float, coherence="surface", chassis: str = "rigid",
                 channels=None, band: tuple | None = None, frame_segments: int | None = None,
                 stiffness_factor: float = 1.0, effects=None) -> dict:
    """RMS of each output channel on an ISO 8608 road (see :func:`response_psd`).

    Parameters
    ----------
    band : (float, float), optional
        Frequency band [Hz]; default the road's band ``(nmin v, nmax v)``.

    Returns
    -------
    dict
        ``{channel: rms}`` [unit].
    """
    lm = vp if isinstance(vp, LinearModel) else linear_model(vp, chassis, frame_segments,
                                                             stiffness_factor, effects)
    return lm.response_rms(road_params, speed, coherence, channels, band)
