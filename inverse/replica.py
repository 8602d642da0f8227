"""The road replica: the left and right wheel-track profiles a drive went over,
reconstructed from its response channels and speed (issue 17).

What it is for: the actual profiles z_L(x), z_R(x) under the two wheel tracks on a
distance grid -- for replaying a drive, driving the identified road in another
simulator, IRI -- where :mod:`inverse.pipeline` only identifies the road's
statistics.  What it is not: a statistical road model (no phases are drawn; where
the vehicle cannot sense the road the replica is the prior's mean, i.e. smooth, and
is marked not identified), nor a nonlinear estimator (nonlinear effects are left out
of the linear model, as in :func:`inverse.linear_features.linear_model_for`).

Method (docs/replica.md gives the reasons)
------------------------------------------
Input estimation on the linearised vehicle (:func:`vehicles.linear.linear_model`),
in the time domain, exact for a varying speed:

* unknowns: the two track profiles on a distance grid ``x_j = x_0 + j dx``
  (dx = 0.1 m), x measured from the first axle's position at the first sample;
* the road height under tyre c at time t is the linear interpolation of its side's
  profile at ``s(t) + x_c`` (s the distance travelled, the trapezoid integral of the
  speed channel; x_c <= 0 the axle position), its rate the profile slope times the
  speed -- the numbers ``vehicles.simulate.road_under_tyres`` feeds the simulator;
  every axle crosses the same profile with its wheelbase delay by construction;
* the state-space form of the linear model (``LinearModel.state_space``) is
  discretised with a first-order hold at ``substeps`` times the sample rate and
  diagonalised, so one evaluation of the map G: profiles -> channels is one
  first-order recursion per mode (``scipy.signal.lfilter``); its adjoint runs the
  same recursions backwards.  The simulation starts at rest ``runin_s`` before the
  record (speed held at its first value), so the unknown initial state is explained
  by the profile behind the record rather than ignored;
* estimate: ``z = argmin sum_c ||(y_c - (G z)_c) / sigma_c||^2 + alpha ||D z||^2 +
  eps ||z||^2`` with D the first difference of each track: the maximum a posteriori
  estimate under white sensor noise (standard deviation sigma_c per channel) and a
  road prior whose slope is white -- the ISO 8608 shape with waviness w = 2, for
  which ``alpha = 1 / var(z_{j+1} - z_j) = 2 / (G_s dx)``, G_s = (2 pi n0)^2 Gd(n0)
  the one-sided slope PSD.  Solved by conjugate gradients on the normal equations.
* sigma_c: given (``noise_sd``) or estimated from the top of each channel's
  spectrum (:func:`inverse.features.estimate_noise_psd`).
* alpha (the road level Gd(n0)) and a per-channel model-error floor are chosen by
  the data: empirical Bayes, i.e. maximising the marginal likelihood by EM --
  :func:`reconstruct` docstring.

Identified band: per speed, the regularised resolution of each track at spatial
frequency n in the constant-speed frequency-domain picture,
``R(n) = diag[(H^H W H + alpha |d(n)|^2)^-1 H^H W H]`` with H from
``LinearModel.track_frf`` at f = n v (wheelbase delays included), W the channel
weights times the number of samples per metre, d(n) the first difference's
transfer function; wavelengths where R >= ``RESOLUTION_MIN`` on both tracks are
identified (:func:`resolution`).

Units: SI; x and wavelengths [m], spatial frequency [cycles/m], heights [m].
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sps
from scipy.signal import cont2discrete, lfilter

from eroad.errors import EroadInputError

#: distance grid step of the replica [m] (issue: <= 0.1 m)
DX = 0.1
#: integration sub-steps per sample of the discretised linear model
SUBSTEPS = 1
#: simulated run-in before the record [s] (the vehicle starts at rest)
RUNIN_S = 2.0
#: regularised resolution above which a wavelength counts as identified [-]
RESOLUTION_MIN = 0.5
#: response quantities used (DCDC channels are not wheel-station responses)
RESPONSE_QUANTITIES = ("susp_disp", "axle_acc", "body_acc")
#: initial road level Gd(n0) [m^3] of the prior (ISO class C centre); EM moves it
GD0_START = 256e-6
#: ISO reference spatial frequency [cycles/m]
N0 = 0.1
#: tiny ridge on the heights (the mean height is invisible to the vehicle) [-, relative to alpha]
EPS_REL = 1e-6


def response_channels(names) -> list:
    """The wheel-station response channels among ``names`` (susp_disp, axle_acc, body_acc)."""
    return [c for c in names if c.rsplit("_", 1)[0] in RESPONSE_QUANTITIES]


def axle_of(channel: str) -> int:
    """Axle number of a wheel-station channel name (``axle_acc_2L`` -> 2)."""
    return int(channel.rsplit("_", 1)[1][:-1])


# --------------------------------------------------------------------------- the linear map
class ReplicaOperator:
    """The linear map G from the two track profiles to the response channels.

    Parameters
    ----------
    lm : vehicles.linear.LinearModel
    time : (T,) array
        Record time [s], uniform.
    speed : (T,) array
        Speed [m/s], > 0.
    channels : list of str
        Output channels (names of ``lm.outputs``).
    dx : float
        Profile grid step [m].
    substeps : int
        Integration steps per sample.
    runin_s : float
        Run-in before the record [s].

    Attributes
    ----------
    x : (N,) array
        Profile grid [m], 0 = first axle at the first sample.
    n_grid : int
        N; the unknown vector is ``[z_L (N), z_R (N)]``.
    covered : (N,) bool
        Grid points some tyre runs over during the record (not only in the run-in).
    """

    def __init__(self, lm, time, speed, channels, dx: float = DX, substeps: int = SUBSTEPS,
                 runin_s: float = RUNIN_S, lines: str = "track"):
        time = np.asarray(time, float)
        speed = np.asarray(speed, float)
        self.lm, self.channels, self.dx = lm, list(channels), float(dx)
        self.fs = 1.0 / float(np.median(np.diff(time)))
        sub = int(substeps)
        T = time.size
        n_run = int(round(runin_s * self.fs))
        h = 1.0 / (self.fs * sub)
        nf = (n_run + T - 1) * sub + 1
        self.i_out = n_run * sub + np.arange(T) * sub
        tf = (np.arange(nf) - n_run * sub) * h
        vf = np.interp(tf, time - time[0], speed)       # run-in: the first speed held
        sf = np.concatenate([[0.0], np.cumsum(0.5 * (vf[1:] + vf[:-1]) * h)])
        sf -= sf[n_run * sub]                           # s = 0 at the first sample
        self.s_record = sf[self.i_out]
        xs = np.array([c["x"] for c in lm.contacts], float)
        self.blocks, blocks_of = unknown_blocks(lm.contacts, lines)
        self.lines, self.blocks_of = lines, blocks_of
        j0 = math.floor((sf[0] + xs.min()) / dx) - 2
        j1 = math.ceil((sf[-1] + xs.max()) / dx) + 2
        N = j1 - j0 + 1
        self.x = (j0 + np.arange(N)) * dx
        self.n_grid = N
        nc = len(xs)
        rows, cols, vals = [], [], []
        ii = np.arange(nf)
        covered = np.zeros(N, bool)
        for c in range(nc):
            pos = (sf + xs[c] - self.x[0]) / dx
            j = np.clip(np.floor(pos).astype(int), 0, N - 2)
            fr = pos - j
            for b in blocks_of[c]:          # the track of its side, and its own line's deviation
                off = b * N
                rows += [c * nf + ii, c * nf + ii, (nc + c) * nf + ii, (nc + c) * nf + ii]
                cols += [off + j, off + j + 1, off + j, off + j + 1]
                vals += [1.0 - fr, fr, -vf / dx, vf / dx]
            jr = j[self.i_out]
            covered[np.arange(jr.min(), jr.max() + 2)] = True
        self.covered = covered
        self.n_blocks = len(self.blocks)
        self.Mu = sps.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                 shape=(2 * nc * nf, self.n_blocks * N))
        self.nf, self.nc = nf, nc
        # continuous state space x = [q, q'], u = [z_r, z_r'] -> outputs; one piece per model of a
        # BlockModel (the leaf friction's damper along the drive), else one piece
        sched = getattr(lm, "pieces", None) or [(0, lm)]
        starts = [0] + [n_run * sub + int(k) * sub for k, _ in sched[1:]]
        self.pieces = [self._discretised(m, h, a, b)
                       for (_, m), a, b in zip(sched, starts, starts[1:] + [nf])]
        self.Dd = self.pieces[0]["Dd"]

    def _discretised(self, lm, h: float, a: int, b: int) -> dict:
        """One piece [a, b) of the fine grid: ``lm`` discretised (first-order hold) and diagonalised.
        Its modal coordinates xi (one per real mode, one per conjugate pair with weight 2) give the
        state ``x = Re(W xi)`` handed to the next piece, which takes ``xi' = T x`` (the hold's
        state is carried as it is: its difference between two pieces is O(h^2) of the damper's
        change times the road input)."""
        A, B = lm.state_space()
        C, Dm = lm.output_matrices(self.channels, A, B)
        Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, Dm), h, method="foh")
        lam, V = np.linalg.eig(Ad)
        Vi = np.linalg.inv(V)
        # conjugate pairs: keep the member with Im > 0 (weight 2), real modes weight 1
        keep = lam.imag > 1e-12 * np.abs(lam) if np.any(lam.imag > 0) else np.zeros(lam.size, bool)
        real = np.abs(lam.imag) <= 1e-12 * np.abs(lam)
        sel = keep | real
        wt = np.where(real[sel], 1.0, 2.0)
        out_idx = np.flatnonzero((self.i_out >= a) & (self.i_out < b))
        return {"a": a, "b": b, "lam": lam[sel], "Bm": Vi[sel] @ Bd, "Cm": (Cd @ V[:, sel]) * wt[None, :],
                "Dd": Dd, "W": V[:, sel] * wt[None, :], "T": Vi[sel], "k": out_idx,
                "f": self.i_out[out_idx] - a}

    @property
    def lam(self):
        """Modal poles of the (first) piece."""
        return self.pieces[0]["lam"]

    @property
    def n_unknowns(self) -> int:
        return self.n_blocks * self.n_grid

    def line_heights(self, u: np.ndarray) -> list:
        """Heights [m] of every tyre line (track plus the line's deviation) from the
        unknown vector ``u``: list of (side, y [m], (N,) array), left lines first."""
        u = np.asarray(u, float).reshape(self.n_blocks, self.n_grid)
        out = []
        for b, blk in enumerate(self.blocks):
            if blk["kind"] == "line":
                out.append((blk["side"], blk["y"], u[blk["track"]] + u[b]))
        if not out:   # one line per side (or lines="track"): the tracks are the lines
            out = [(blk["side"], blk["y"], u[b].copy()) for b, blk in enumerate(self.blocks)]
        return out

    def forward(self, z: np.ndarray) -> np.ndarray:
        """Channels (n_channels, T) [channel units] for profiles ``z`` = [z_L, z_R] (2N,) [m]."""
        u = (self.Mu @ np.asarray(z, float)).reshape(2 * self.nc, self.nf)
        Y = np.empty((len(self.channels), self.i_out.size))
        x = None                                   # the state handed on (at rest before the run-in)
        for p in self.pieces:
            up = u[:, p["a"]:p["b"]]
            g = p["Bm"].real @ up + 1j * (p["Bm"].imag @ up)
            x0 = p["T"] @ x if x is not None else np.zeros(p["lam"].size, complex)
            xi = np.empty_like(g)
            xend = np.empty(p["lam"].size, complex)
            for m, lm_ in enumerate(p["lam"]):
                xi[m], zf = lfilter([0.0, 1.0], [1.0, -lm_], g[m], zi=[x0[m]])
                xend[m] = zf[0]
            xo = xi[:, p["f"]]
            Y[:, p["k"]] = (p["Cm"].real @ xo.real - p["Cm"].imag @ xo.imag + p["Dd"] @ up[:, p["f"]])
            x = (p["W"] @ xend).real
        return Y

    def adjoint(self, Y: np.ndarray) -> np.ndarray:
        """Adjoint of :meth:`forward`: (n_channels, T) -> (2N,)."""
        Y = np.asarray(Y, float)
        ub = np.zeros((2 * self.nc, self.nf))
        sig = None                                 # adjoint of the state handed on
        for p in reversed(self.pieces):
            a, b = p["a"], p["b"]
            Yp = Y[:, p["k"]]
            ub[:, a + p["f"]] += p["Dd"].T @ Yp
            s = np.zeros((p["lam"].size, b - a), complex)
            s[:, p["f"]] = p["Cm"].conj().T @ Yp
            zeta = p["W"].conj().T @ sig if sig is not None else np.zeros(p["lam"].size, complex)
            eta = np.empty_like(s)
            lam0 = np.empty(p["lam"].size, complex)
            for m, lm_ in enumerate(p["lam"]):
                e, zf = lfilter([0.0, 1.0], [1.0, -np.conj(lm_)], s[m, ::-1], zi=[zeta[m]])
                eta[m] = e[::-1]
                lam0[m] = zf[0]
            ub[:, a:b] += p["Bm"].real.T @ eta.real + p["Bm"].imag.T @ eta.imag
            sig = (p["T"].conj().T @ lam0).real
        return self.Mu.T @ ub.ravel()

    def profile_input(self, z_left, z_right=None) -> tuple:
        """Road height and rate under each tyre on the fine time grid (for checks)."""
        z = np.concatenate([z_left, z_left if z_right is None else z_right])
        u = (self.Mu @ z).reshape(2 * self.nc, self.nf)
        return u[:self.nc], u[self.nc:]


#: how the unknowns are laid out: "tyre" (default of :func:`reconstruct`): per side a track
#: plus, for every distinct lateral tyre position of that side, the line's deviation from
#: it; "track": one profile per side for all its tyres (dual tyres and different track
#: widths taken as one track)
LINE_MODES = ("tyre", "track")
#: lateral positions closer than this are one tyre line [m]
LINE_Y_TOL = 0.02
#: smallest lateral distance of a line from its side's centre used in its prior [m]
LINE_DY_MIN = 0.05


def unknown_blocks(contacts, lines: str = "track") -> tuple:
    """Blocks of N unknowns and which blocks each tyre's road height sums.

    Returns ``(blocks, blocks_of)``: ``blocks`` a list of dicts -- ``{"kind": "track",
    "side", "y"}`` for the two tracks (y the mean of the side's line positions), then
    ``{"kind": "line", "side", "y", "track": index, "dy": distance from the track's y}``
    per tyre line of a side with more than one line (mode "tyre"); ``blocks_of[c]`` the
    block indices whose sum is tyre c's road height.
    """
    if lines not in LINE_MODES:
        raise EroadInputError(f"replica lines {lines!r}: use one of {', '.join(LINE_MODES)}")
    per_side = {"L": [], "R": []}
    for c in contacts:
        ys = per_side[c["side"]]
        if not any(abs(c["y"] - y) <= LINE_Y_TOL for y in ys):
            ys.append(float(c["y"]))
    blocks = [{"kind": "track", "side": s, "y": float(np.mean(per_side[s])) if per_side[s] else 0.0}
              for s in ("L", "R")]
    line_index = {}
    if lines == "tyre":
        for t, s in enumerate(("L", "R")):
            if len(per_side[s]) < 2:
                continue
            for y in sorted(per_side[s], key=abs):
                line_index[(s, y)] = len(blocks)
                blocks.append({"kind": "line", "side": s, "y": y, "track": t,
                               "dy": max(abs(y - blocks[t]["y"]), LINE_DY_MIN)})
    blocks_of = []
    for c in contacts:
        b = [0 if c["side"] == "L" else 1]
        for (s, y), k in line_index.items():
            if s == c["side"] and abs(c["y"] - y) <= LINE_Y_TOL:
                b.append(k)
        blocks_of.append(b)
    return blocks, blocks_of


def block_frf(lm, n, speed: float, channels, blocks_of, n_blocks: int) -> np.ndarray:
    """FRFs (nf, n_channels, n_blocks) from each unknown block's profile at spatial
    frequency ``n`` and constant ``speed`` (wheelbase delays included; the
    generalisation of ``LinearModel.track_frf`` to the tyre-line blocks)."""
    f = np.asarray(n, float) * speed
    H = lm.frf(f, channels)
    xs = np.array([c["x"] for c in lm.contacts])
    E = np.exp(1j * 2 * np.pi * f[:, None] * xs[None, :] / speed)
    out = np.zeros(H.shape[:2] + (n_blocks,), complex)
    for c, bs in enumerate(blocks_of):
        for b in bs:
            out[:, :, b] += H[:, :, c] * E[:, c][:, None]
    return out


def line_weights(blocks, alpha: float, dx: float = DX) -> np.ndarray:
    """Prior weight [1/m^2] on the squared deviation of each block (0 for the tracks).

    DECISION (docs/replica.md): the deviation e of a tyre line at lateral distance dy
    from its side's track is taken as white with the variance of the height difference
    of an isotropic road at that distance.  For the w = 2 road of the prior the
    structure function is linear, D(r) = E[(z(p) - z(p + r))^2] = r / (alpha dx)
    (alpha = 1 / D(dx) along x, the same in every direction when the road is
    isotropic), so the weight is 1 / D(dy) = alpha dx / dy.
    """
    return np.array([0.0 if b["kind"] == "track" else alpha * dx / b["dy"] for b in blocks])


def side_tracks(op, u) -> dict:
    """The wheel track of each side: the mean of the road under that side's tyres (every
    tyre counted once, so a dual pair weighs twice), from the unknowns ``u``; with
    ``lines="track"`` the track itself."""
    U = np.asarray(u, float).reshape(op.n_blocks, op.n_grid)
    out = {}
    for side in ("L", "R"):
        rows = [U[bs].sum(axis=0) for c, bs in zip(op.lm.contacts, op.blocks_of) if c["side"] == side]
        out[side] = np.mean(rows, axis=0)
    return out


def first_difference(N: int) -> sps.csr_matrix:
    """First difference of each of the two tracks, (2(N-1), 2N)."""
    d = sps.diags([-np.ones(N - 1), np.ones(N - 1)], [0, 1], shape=(N - 1, N))
    return sps.block_diag([d, d]).tocsr()


# --------------------------------------------------------------------------- resolution / band
def resolution(lm, channels, sigma, speed: float, n, alpha: float, dx: float = DX, fs: float = 200.0):
    """Regularised resolution of each track per spatial frequency at constant speed.

    ``R = diag[(H^H W H + alpha |d|^2 I)^-1 H^H W H]`` with H (n_ch, 2) from
    ``LinearModel.track_frf`` at f = n v, W = diag(1 / sigma_c^2) times the samples per
    grid step (fs dx / v, so that data and prior are counted per metre alike) and
    |d|^2 = |2 sin(pi n dx)|^2 the first difference's power gain.

    Parameters
    ----------
    lm : LinearModel
    channels : list of str
    sigma : array (n_ch,)
        Noise (plus model-error) standard deviation per channel [channel unit].
    speed : float
        [m/s].
    n : array
        Spatial frequencies [cycles/m], > 0.
    alpha : float
        Prior weight on the squared first differences [1/m^2].

    Returns
    -------
    (n_f, 2) array
        Resolution of the left and right track in [0, 1].
    """
    n = np.asarray(n, float)
    H = lm.track_frf(n * speed, speed, channels)                 # (nf, nch, 2)
    w = (fs * dx / speed) / np.asarray(sigma, float) ** 2
    HWH = np.einsum("foa,o,fob->fab", H.conj(), w, H)
    d2 = (2 * np.sin(np.pi * n * dx)) ** 2
    Rg = HWH + alpha * d2[:, None, None] * np.eye(2)[None]
    R = np.linalg.solve(Rg, HWH)
    return np.clip(np.real(np.stack([R[:, 0, 0], R[:, 1, 1]], axis=1)), 0.0, 1.0)


def identified_band(lm, channels, sigma, speed: float, alpha: float, dx: float = DX,
                    fs: float = 200.0, n_points: int = 240) -> tuple:
    """Shortest and longest identified wavelength [m] at one speed (both tracks R >= 0.5).

    The band is the contiguous run of identified frequencies that holds the most
    grid points of a logarithmic grid from 1/(200 m) to the grid's Nyquist 1/(2 dx);
    (nan, nan) when no frequency is identified.
    """
    n = np.geomspace(1 / 200.0, 0.5 / dx, n_points)
    R = resolution(lm, channels, sigma, speed, n, alpha, dx, fs)
    ok = np.all(R >= RESOLUTION_MIN, axis=1)
    if not ok.any():
        return float("nan"), float("nan")
    best, cur, start, bs = 0, 0, 0, 0
    for i, v in enumerate(ok):
        if v:
            if cur == 0:
                start = i
            cur += 1
            if cur > best:
                best, bs = cur, start
        else:
            cur = 0
    return float(1.0 / n[bs + best - 1]), float(1.0 / n[bs])


# --------------------------------------------------------------------------- the estimate
@dataclass
class Replica:
    """A reconstructed pair of wheel tracks.

    Attributes
    ----------
    x : (N,) array
        Distance [m] (0: first axle at the first sample).
    z_left, z_right : (N,) arrays
        Track heights [m]: the mean of the road under each side's tyres (:func:`side_tracks`).
    covered : (N,) bool
        Grid points a tyre ran over during the record.
    lambda_min, lambda_max : (N,) arrays
        Identified wavelength band at each point [m] (from the speed at which the
        vehicle crossed it; nan outside ``covered``).
    channels : list of str
        Channels used.
    sigma : dict
        Channel -> standard deviation used as its noise (sensor noise, raised to the
        residual's where the model misses more) [unit].
    sigma_sensor : dict
        Channel -> sensor-noise standard deviation (given or estimated) [unit].
    alpha : float
        Prior weight [1/m^2]; ``gd0`` the road level it stands for [m^3].
    fitted : dict
        Channel -> (T,) the linear model's response on the replica [unit].
    info : dict
        Iterations, timings, EM history.
    """

    x: np.ndarray
    z_left: np.ndarray
    z_right: np.ndarray
    covered: np.ndarray
    lambda_min: np.ndarray
    lambda_max: np.ndarray
    channels: list
    sigma: dict
    sigma_sensor: dict
    alpha: float
    gd0: float
    fitted: dict
    info: dict = field(default_factory=dict)
    operator: object = None
    u: np.ndarray = None
    lines: list = field(default_factory=list)

    def predict(self, channels) -> dict:
        """Responses of the linear model on the replica for any channels (e.g. held out)."""
        return _predict(self.operator, self, list(channels))


def _predict(op: ReplicaOperator, rep: Replica, channels) -> dict:
    other = ReplicaOperator(op.lm, op._time, op._speed, channels, op.dx, op._substeps, op._runin_s,
                            lines=op.lines)
    Y = other.forward(rep.u)
    return {c: Y[k] for k, c in enumerate(channels)}


def alpha_of_gd0(gd0: float, dx: float = DX) -> float:
    """Prior weight for a road of level Gd(n0) with w = 2: 1 / var(first difference)."""
    gs = (2 * np.pi * N0) ** 2 * gd0          # one-sided slope PSD [m]
    return 2.0 / (gs * dx)


def gd0_of_alpha(alpha: float, dx: float = DX) -> float:
    return 2.0 / (alpha * dx) / (2 * np.pi * N0) ** 2


def _cg(apply_A, b, x0, tol: float, max_iter: int, precond=None):
    """Conjugate gradients for a symmetric positive definite operator."""
    x = x0.copy()
    r = b - apply_A(x)
    zr = precond(r) if precond else r
    p = zr.copy()
    rz = r @ zr
    bn = np.linalg.norm(b) or 1.0
    it = 0
    for it in range(1, max_iter + 1):
        Ap = apply_A(p)
        a = rz / (p @ Ap)
        x += a * p
        r -= a * Ap
        if np.linalg.norm(r) <= tol * bn:
            break
        zr = precond(r) if precond else r
        rz_new = r @ zr
        p = zr + (rz_new / rz) * p
        rz = rz_new
    return x, it, float(np.linalg.norm(r) / bn)


def _fourier_preconditioner(lm, names, sig, speed, alpha, eps, N, dx, fs, covered, v_local):
    """Approximate inverse of the normal operator: the constant-speed (median speed)
    frequency-domain picture, a 2x2 matrix per spatial frequency of the grid's FFT
    (circulant approximation; only speeds CG up, never changes the solution)."""
    n = np.fft.rfftfreq(N, dx)
    n1 = n.copy()
    n1[0] = n[1]
    H = lm.track_frf(n1 * speed, speed, names)
    w = (fs * dx / speed) / np.asarray(sig, float) ** 2
    HWH = np.einsum("foa,o,fob->fab", H.conj(), w, H)
    d2 = (2 * np.sin(np.pi * n * dx)) ** 2
    floor = max(eps, alpha * (2 * np.sin(np.pi * n[1] * dx)) ** 2)
    P = np.linalg.inv(HWH + (alpha * d2 + floor)[:, None, None] * np.eye(2)[None])

    cov = np.asarray(covered, bool)
    scale = np.sqrt(np.asarray(v_local, float) / speed)    # data per metre ~ 1 / local speed
    unc = np.flatnonzero(~cov)
    if unc.size:   # where no tyre runs during the record only the prior acts: its exact inverse
        from scipy.sparse.linalg import splu

        m = unc.size
        d = sps.diags([-np.ones(m - 1), np.ones(m - 1)], [0, 1], shape=(m - 1, m))
        lu = splu((alpha * (d.T @ d) + floor * sps.eye(m)).tocsc())

    def apply(r):
        r2 = r.reshape(2, N)
        Z = np.fft.rfft(np.where(cov, r2 * scale, 0.0), axis=1)             # (2, nf)
        out = np.fft.irfft(np.einsum("fab,bf->af", P, Z), N, axis=1) * scale
        out[:, ~cov] = 0.0
        if unc.size:
            out[:, unc] = lu.solve(np.ascontiguousarray(r2[:, unc].T)).T
        return out.ravel()
    return apply


def noise_sd(channels: dict, fs: float, given: dict | None = None) -> dict:
    """Sensor-noise standard deviation per channel: given, else from the top of its
    spectrum (:func:`inverse.features.estimate_noise_psd`, white: sd^2 = PSD fs / 2)."""
    from inverse.features import estimate_noise_psd

    out = {}
    for c, y in channels.items():
        if given and c in given:
            out[c] = float(given[c])
        else:
            out[c] = float(math.sqrt(estimate_noise_psd(y, fs) * 0.5 * fs))
        if not (out[c] > 0 and math.isfinite(out[c])):
            out[c] = 1e-12 + 1e-6 * float(np.std(y))
    return out


def _local_speed(op: ReplicaOperator, lm, speed) -> np.ndarray:
    """Mean speed [m/s] at which the axles crossed each grid point (interpolated
    between crossings, held beyond them)."""
    N, dx = op.n_grid, op.dx
    acc = np.zeros(N)
    cnt = np.zeros(N)
    for xc in np.unique([c["x"] for c in lm.contacts]):
        j = np.clip(np.round((op.s_record + xc - op.x[0]) / dx).astype(int), 0, N - 1)
        np.add.at(acc, j, speed)
        np.add.at(cnt, j, 1)
    idx = np.flatnonzero(cnt > 0)
    return np.interp(op.x, op.x[idx], acc[idx] / cnt[idx])


def reconstruct(lm, time, speed, channels: dict, *, noise: dict | None = None, dx: float = DX,
                substeps: int = SUBSTEPS, runin_s: float = RUNIN_S, em_rounds: int = 3,
                alpha: float | None = None, tol: float = 1e-6, max_iter: int = 120, first_iter: int = 40,
                lines: str = "tyre", progress=None) -> Replica:
    """Reconstruct the two wheel tracks from response channels (module docstring).

    Regularisation weight and channel weights (DECISION, docs/replica.md): empirical
    Bayes by EM.  Start with sigma_c the sensor noise and alpha for an ISO class C road;
    each round solves for z, then sets

    * sigma_c^2 = max(sensor noise^2, mean squared residual of channel c): a channel
      the model cannot follow (model gap, nonlinearity) is down-weighted to what it
      can explain, never below its sensor noise;
    * alpha = 1 / (mean squared first difference of z over the covered grid + its
      posterior variance), the posterior variance from the constant-speed
      frequency-domain picture at the median speed (per frequency
      ``(H^H W H + alpha |d|^2)^-1``, see :func:`resolution`).

    ``em_rounds`` solves (3: the sensor-noise start, then two with updated weights;
    the first rounds stop after ``first_iter`` CG iterations, they only set the weights).
    A given ``alpha`` skips its update.

    Parameters
    ----------
    lm : LinearModel
    time, speed : (T,) arrays
        [s], [m/s].
    channels : dict
        Channel name -> (T,) measured signal [SI].
    noise : dict, optional
        Channel -> sensor-noise sd [unit]; others estimated.

    Returns
    -------
    Replica
    """
    t0 = _time.perf_counter()
    names = list(channels)
    if not names:
        raise EroadInputError("replica: no response channel to reconstruct from")
    speed = np.asarray(speed, float)
    if speed.size != np.asarray(time).size:
        raise EroadInputError("replica: speed and time differ in length")
    if not np.all(np.isfinite(speed)) or np.min(speed) <= 0.5:
        raise EroadInputError("replica: needs a moving vehicle (speed > 0.5 m/s throughout)")
    op = ReplicaOperator(lm, time, speed, names, dx, substeps, runin_s, lines=lines)
    op._time, op._speed, op._substeps, op._runin_s = np.asarray(time, float), speed, substeps, runin_s
    Y = np.array([np.asarray(channels[c], float) for c in names])
    Y = Y - Y.mean(axis=1, keepdims=True)          # static offsets (sensor zero) are not road
    fs = op.fs
    sensor = noise_sd(dict(zip(names, Y)), fs, noise)
    sig0 = np.array([sensor[c] for c in names])
    sig = sig0.copy()
    N = op.n_grid
    nb = op.n_blocks
    Dm = first_difference(N)
    DtD = (Dm.T @ Dm).tocsr()          # the two tracks' first differences (2N, 2N)
    v_loc = _local_speed(op, lm, speed)
    fixed_alpha = alpha is not None
    al = float(alpha) if fixed_alpha else alpha_of_gd0(GD0_START, dx)
    z = np.zeros(nb * N)
    hist = []
    v_med = float(np.median(speed))
    n_fft = np.fft.rfftfreq(4096, dx)[1:]
    total_it = 0
    rounds = max(1, int(em_rounds))
    for rnd in range(rounds):
        last = rnd == rounds - 1
        w = 1.0 / sig ** 2
        eps = EPS_REL * al
        beta = np.repeat(line_weights(op.blocks, al, dx), N)      # tyre-line deviations

        def normal(v, w=w, al=al, eps=eps, beta=beta):
            out = op.adjoint(w[:, None] * op.forward(v)) + eps * v + beta * v
            out[:2 * N] += al * (DtD @ v[:2 * N])
            return out

        b = op.adjoint(w[:, None] * Y)
        z, it, rel = _cg(normal, b, z, tol, max_iter if last else first_iter)
        total_it += it
        R = Y - op.forward(z)
        ms = np.mean(R ** 2, axis=1)
        entry = {"round": rnd, "alpha": al, "gd0": gd0_of_alpha(al, dx), "cg_iter": it, "cg_rel_res": rel,
                 "chi2_per_sample": float(np.mean(ms / sig ** 2))}
        hist.append(entry)
        if progress:
            progress(f"replica round {rnd}: alpha {al:.3g} (Gd(n0) {entry['gd0']:.3g} m^3), "
                     f"CG {it} it, chi2/sample {entry['chi2_per_sample']:.2f}")
        if last:
            break
        # EM updates
        sig = np.sqrt(np.maximum(sig0 ** 2, ms))
        cov = np.concatenate([op.covered[:-1], op.covered[:-1]])
        dz = (Dm @ z[:2 * N])[cov]
        # posterior variance of a first difference, constant-speed picture (per metre)
        H = lm.track_frf(n_fft * v_med, v_med, names)
        wpm = (fs * dx / v_med) / sig ** 2
        HWH = np.einsum("foa,o,fob->fab", H.conj(), wpm, H)
        d2 = (2 * np.sin(np.pi * n_fft * dx)) ** 2
        P = np.linalg.inv(HWH + al * d2[:, None, None] * np.eye(2)[None])
        post = float(np.mean(d2 * np.real(P[:, 0, 0] + P[:, 1, 1]) / 2.0))
        if not fixed_alpha:
            al = 1.0 / (float(np.mean(dz ** 2)) + post)
    # identified band per grid point from the speed at which it was crossed
    fitted = op.forward(z)
    speeds = np.quantile(speed, [0.05, 0.25, 0.5, 0.75, 0.95])
    bands = np.array([identified_band(lm, names, sig, v, al, dx, fs) for v in speeds])
    v_at = v_loc
    lam_min = np.interp(v_at, speeds, bands[:, 0])
    lam_max = np.interp(v_at, speeds, bands[:, 1])
    lam_min[~op.covered] = np.nan
    lam_max[~op.covered] = np.nan
    info = {"cg_iterations": total_it, "em": hist, "wall_s": _time.perf_counter() - t0,
            "n_unknowns": nb * N, "n_samples": int(Y.size), "substeps": substeps, "runin_s": runin_s,
            "speed_quantiles_mps": speeds.tolist(), "band_at_speed_m": bands.tolist(),
            "linear_model_notes": list(lm.meta.get("notes", []))}
    info["lines"] = lines
    info["line_blocks"] = [{k: v for k, v in b.items()} for b in op.blocks]
    tracks = side_tracks(op, z)
    return Replica(x=op.x, z_left=tracks["L"], z_right=tracks["R"], covered=op.covered,
                   lambda_min=lam_min, lambda_max=lam_max, channels=names,
                   sigma=dict(zip(names, sig.tolist())), sigma_sensor=sensor, alpha=al,
                   gd0=gd0_of_alpha(al, dx), fitted={c: fitted[k] + 0.0 for k, c in enumerate(names)},
                   info=info, operator=op, u=z, lines=op.line_heights(z))


# --------------------------------------------------------------------------- the linear model
#: low-pass before differentiating a suspension displacement for its velocity [Hz]
#: (suspension motion lies below ~15 Hz; the sensor noise above would inflate the sd)
VELOCITY_LOWPASS_HZ = 25.0


class BlockModel:
    """A linear model whose statistically linearised nonlinear effects change along the drive.

    ``pieces``: ``[(k0, LinearModel), ...]``, the record sample at which each model takes over
    (the first at 0; the first also serves the run-in); ``reference``: the model for what needs one
    linear model (identified band, EM's posterior variance, CG's preconditioner, contacts, outputs),
    which every other attribute is read from; ``values``: per linearised effect, its equivalent
    coefficient in each piece (``leaf_friction``: damper [N s/m per spring]; ``bump_stop``: stiffness
    [N/m per suspension]); ``measured``: what it came from (velocity RMS [m/s], displacement RMS [m]).
    :class:`ReplicaOperator` switches between the pieces' state spaces, carrying the state.
    """

    def __init__(self, reference, pieces, values, measured):
        self.reference = reference
        self.pieces = list(pieces)
        self.values = {k: list(v) for k, v in values.items()}
        self.measured = {k: list(v) for k, v in measured.items()}

    @property
    def damping(self) -> list:
        """The leaf friction's equivalent damper per piece [N s/m per spring] ([] without it)."""
        return self.values.get("leaf_friction", [])

    @property
    def speed_rms(self) -> list:
        """The suspension velocity RMS per piece the friction was linearised on [m/s]."""
        return self.measured.get("leaf_friction", [])

    def __getattr__(self, name):
        if name in ("reference", "pieces", "values", "measured"):   # not set yet (copy, unpickle)
            raise AttributeError(name)
        return getattr(self.reference, name)


#: blocks [s] over which nonlinear effects are linearised (:func:`replica_linear_model`)
FRICTION_BLOCK_S = 5.0
#: neighbouring blocks whose equivalent coefficients all lie within this factor of each other share
#: one linear model, linearised on their joint samples (a damper or stiffness within ~+-9 % of a
#: block's own changes the replica far less than the noise does; fewer pieces, fewer model switches)
FRICTION_LEVEL_STEP = 2.0 ** 0.25
#: the friction's equivalent damper from the measured velocity distribution, F mean|v| / mean(v^2)
#: (True), or from its RMS through the Gaussian form F sqrt(2/pi) / RMS (False); read when called.
#: True since its stated test (results/replica/20261201-block-linearisation/decision_empirical.txt):
#: stick makes the velocity peaky, the Gaussian form 9-19 % too stiff on quiet blocks; the replica's
#: median abs ln PSD error at 0.5-2 m 0.107 -> 0.074 (our truck), 0.114 -> 0.079 (independent truck)
FRICTION_EMPIRICAL = True
#: equivalent bump-stop stiffnesses below this count as none when blocks are joined, and are not
#: handed to the model [N/m] (0.1-0.3 % of the truck's suspension springs)
BUMP_STOP_FLOOR = 5.0e3


def statistical_damper(force: float, velocity: float, s: float, mean_abs: float | None = None) -> float:
    """Equivalent viscous damper [N s/m] of a Coulomb force ``force``: E[F sign(v) v] / E[v^2] =
    F mean|v| / mean(v^2) for measured velocities of RMS ``s`` and mean magnitude ``mean_abs``; without
    ``mean_abs``, the Gaussian form F sqrt(2/pi) / s (Roberts & Spanos).  No stiffer than the smoothed
    force's own slope at rest ``force / velocity``."""
    a = s * math.sqrt(2.0 / math.pi) if mean_abs is None else mean_abs
    return force / max(velocity, s * s / max(a, 1e-300))


def bump_stop_force(u, gap: float, stiffness: float, smoothing: float) -> np.ndarray:
    """The bump stop's force [N] at compression ``u`` [m] from static equilibrium: the effect's own law
    (vehicles/effects/bump_stop.py), ``k s softplus((u - gap) / s)``, zero at u = 0."""
    x = (np.asarray(u, float) - gap) / smoothing
    f0 = stiffness * smoothing * math.log1p(math.exp(-gap / smoothing))
    return stiffness * smoothing * (np.maximum(x, 0.0) + np.log1p(np.exp(-np.abs(x)))) - f0


@dataclass
class Equivalent:
    """One nonlinear effect's statistical linearisation over stretches of the record.

    ``value(k0, k1)``: ``(coefficient, measured RMS)`` over samples [k0, k1); ``params(c)``: the
    effect's parameters whose slope at rest is ``c`` (what :func:`vehicles.linear.linear_model`
    linearises), or None where nothing is to be added; ``floor``: coefficients below it count as one
    level when blocks are joined."""

    effect: str
    value: object
    params: object
    floor: float = 0.0


def linearisation_blocks(equivalents, m: int, fs: float) -> list:
    """Sample ranges ``(k0, k1)`` of :data:`FRICTION_BLOCK_S` blocks of an ``m``-sample record,
    neighbours joined while every equivalent coefficient stays within :data:`FRICTION_LEVEL_STEP` of
    its others in the piece (coefficients below their ``floor`` count as the floor); the last
    part-block joins the last block."""
    n = int(round(FRICTION_BLOCK_S * fs))
    if n < 2 or m < 2 * n:
        return [(0, m)]
    edges = [i * n for i in range(m // n)] + [m]
    out = []                     # [k0, k1, lows, highs] per piece
    for k0, k1 in zip(edges, edges[1:]):
        v = [max(e.value(k0, k1)[0], e.floor, 1e-300) for e in equivalents]
        if out:
            lo = [min(a, b) for a, b in zip(out[-1][2], v)]
            hi = [max(a, b) for a, b in zip(out[-1][3], v)]
            if all(h <= FRICTION_LEVEL_STEP * lw for lw, h in zip(lo, hi)):
                out[-1][1:] = [k1, lo, hi]
                continue
        out.append([k0, k1, v, v])
    return [(k0, k1) for k0, k1, _, _ in out]


def block_table(lm, time) -> list:
    """The linearised effects' coefficients along the record, for summary.json: one row per piece of
    a :class:`BlockModel` (``t_start_s``, ``t_end_s`` record time; ``damping_N_s_per_m`` per spring and
    ``suspension_velocity_rms_m_per_s`` for the friction; ``bump_stop_stiffness_N_per_m`` per
    suspension and ``suspension_displacement_rms_m`` for bump stops); [] for one model (its
    coefficients are in ``effects``)."""
    if not isinstance(lm, BlockModel):
        return []
    time = np.asarray(time, float)
    dt = float(np.median(np.diff(time)))
    ks = [k for k, _ in lm.pieces] + [time.size]
    cols = {"leaf_friction": ("damping_N_s_per_m", "suspension_velocity_rms_m_per_s"),
            "bump_stop": ("bump_stop_stiffness_N_per_m", "suspension_displacement_rms_m")}
    rows = []
    for i, (a, b) in enumerate(zip(ks, ks[1:])):
        row = {"t_start_s": float(time[a]), "t_end_s": float(time[b - 1] + dt)}
        for eff, (cv, cm) in cols.items():
            if eff in lm.values:
                row[cv], row[cm] = float(lm.values[eff][i]), float(lm.measured[eff][i])
        rows.append(row)
    return rows


#: high-pass [Hz] of a suspension velocity integrated from accelerations: the integral's drift and the
#: accelerometers' low-frequency error go, the suspension's own motion (body bounce 1-2 Hz, axle hop
#: ~10 Hz) stays
VELOCITY_HIGHPASS_HZ = 0.5


def suspension_velocities(channels: dict, vp, axles, fs: float) -> tuple:
    """Suspension (compression) velocities [m/s] at the spring seats of ``axles``, and where they came
    from.

    From ``susp_disp_<a><s>`` (measured at the spring seat): its derivative, low-passed at
    :data:`VELOCITY_LOWPASS_HZ` (the displacement's noise would inflate it above).  Where a drive logs
    no displacement on those axles (the format allows any subset of channels), from the accelerations:
    ``axle_acc`` is measured at the axle END, so the spring seat's is rebuilt from both ends of the
    axle, ``(a_L + a_R) / 2 +- r (a_L - a_R) / 2`` with r = spring track / wheel track (a rigid axle;
    without it the axle's roll counts about twice), minus ``body_acc`` of that seat, integrated
    (trapezoid), its linear trend removed and band-passed from :data:`VELOCITY_HIGHPASS_HZ` to
    :data:`VELOCITY_LOWPASS_HZ`.  ``vp``: the vehicle (VehicleParams).  Returns ``([arrays], source)``,
    ``source`` '' for displacements, a phrase for the note otherwise; ``([], '')`` when neither is
    there (a station needs both axle ends and its body acceleration).
    """
    from scipy.signal import butter, sosfiltfilt

    lo = butter(4, min(VELOCITY_LOWPASS_HZ, 0.4 * fs), fs=fs, output="sos")
    disp = [np.asarray(y, float) for c, y in channels.items()
            if c.startswith("susp_disp_") and axle_of(c) in axles]
    if disp:
        return [np.gradient(sosfiltfilt(lo, d - d.mean())) * fs for d in disp], ""
    band = butter(4, [VELOCITY_HIGHPASS_HZ, min(VELOCITY_LOWPASS_HZ, 0.4 * fs)], btype="band", fs=fs, output="sos")
    vel = []
    for a in sorted(axles):
        ends = [channels.get(f"axle_acc_{a}{s}") for s in "LR"]
        if any(e is None for e in ends):
            continue
        aL, aR = (np.asarray(e, float) for e in ends)
        r = vp.axles[a - 1].spring_track / vp.axles[a - 1].track
        for side, sign in (("L", 1.0), ("R", -1.0)):
            body = channels.get(f"body_acc_{a}{side}")
            if body is None:
                continue
            rel = 0.5 * (aL + aR) + sign * r * 0.5 * (aL - aR) - np.asarray(body, float)
            v = np.concatenate([[0.0], np.cumsum(0.5 * (rel[1:] + rel[:-1]))]) / fs
            k = np.arange(v.size)
            vel.append(sosfiltfilt(band, v - np.polyval(np.polyfit(k, v, 1), k)))
    if not vel:
        return [], ""
    return vel, (f" (suspension velocity from the accelerations, axle at its spring seat minus body, "
                 f"integrated, {VELOCITY_HIGHPASS_HZ:g}-{VELOCITY_LOWPASS_HZ:g} Hz: no susp_disp on the "
                 f"leaf-spring axles)")


def replica_linear_model(vehicle, effects, channels: dict, fs: float, t0: float = 0.0,
                         per_block: bool = True) -> tuple:
    """The linear model of the replica with the given effects.

    Linear effects enter as they are.  Nonlinear ones enter by STATISTICAL LINEARISATION
    (DECISION, docs/replica.md), each as the linear coefficient that best replaces its force in the
    mean-square sense over the measured motion, handed to the linear model as the effect's parameters
    whose slope at rest is that coefficient:

    * ``leaf_friction``: the Coulomb force F sign(v) is best replaced by c_eq = E[F sign(v) v] / E[v^2]
      (Roberts & Spanos, Random Vibration and Statistical Linearization), evaluated on the measured
      suspension velocity of the leaf-spring stations (:func:`suspension_velocities`: from
      ``susp_disp_*``, or from axle and body accelerations where a drive logs no displacement there):
      F mean|v| / mean(v^2) (:data:`FRICTION_EMPIRICAL`; for a Gaussian v of sd s this is F sqrt(2 / pi)
      / s, for a sine of amplitude a the describing function 4 F / (pi a)); the smoothed force
      F tanh(v / v0) has slope F / v0 at rest, so the force handed over is c_eq v0;
    * ``bump_stop``: an equivalent stiffness k_eq = sum mean(F(u) u) / sum mean(u^2) over the stations,
      F the effect's own force law (:func:`bump_stop_force`) and u the measured ``susp_disp`` about its
      mean -- the measured amplitude distribution, no Gaussian assumption; handed over as a bump stop
      of gap 0, whose slope at rest is half its stiffness.  Needs ``susp_disp`` (else left out).
    * ``damper_asymmetry`` keeps the mean damping, so its linearisation for a symmetric velocity is
      the nominal damper: left out, exactly.

    ``per_block`` (default): the coefficients are taken per :data:`FRICTION_BLOCK_S` block of the
    record (:func:`linearisation_blocks`) and the model returned is a :class:`BlockModel` that
    switches between them: friction that nearly locks the springs on a smooth stretch and slips on a
    rough one is not one damper (one damper for the whole drive made the embedded drive's class A
    segment 5-8x too smooth at 0.5-2 m, results/replica/20261201-smooth-segment/; per block:
    results/replica/20261201-block-linearisation/), and a bump stop engages only where the road is
    rough.  ``per_block=False``: one model for the whole drive, with a warning where a block would
    need a friction damper more than ``FRICTION_BLOCK_RATIO`` times stiffer
    (:func:`friction_block_spread`; ``t0``: the record time of the first sample, for the notes' times).

    Returns
    -------
    (model, left_out, notes) : the model (a LinearModel, or a BlockModel), the effects left out,
    lines for the report.
    """
    from inverse.linear_features import split_linear_effects
    from vehicles.linear import linear_model
    from vehicles.params import load_vehicle

    vp = load_vehicle(vehicle)
    keep, nonlinear = split_linear_effects(effects)
    notes, eqs, vel, source = [], [], None, ""
    m = min((len(np.asarray(y)) for y in channels.values()), default=0)
    if "leaf_friction" in nonlinear and nonlinear["leaf_friction"]["force"] > 0:
        leaf_axles = {i + 1 for i, a in enumerate(vp.axles) if getattr(a, "spring_type", "") == "leaf"}
        vel, source = suspension_velocities(channels, vp, leaf_axles, fs)
        if vel:
            pf = dict(nonlinear["leaf_friction"])

            def friction_value(k0, k1, vel=vel, pf=pf):
                s = math.sqrt(np.mean([np.mean(np.asarray(v[k0:k1]) ** 2) for v in vel]))
                a = float(np.mean([np.mean(np.abs(v[k0:k1])) for v in vel])) if FRICTION_EMPIRICAL else None
                return statistical_damper(pf["force"], pf["velocity"], s, a), s
            eqs.append(Equivalent("leaf_friction", friction_value,
                                  lambda c, pf=pf: {"force": c * pf["velocity"], "velocity": pf["velocity"]}))
    if "bump_stop" in nonlinear:
        U = np.array([np.asarray(y, float) - np.mean(y) for c, y in channels.items() if c.startswith("susp_disp_")])
        if U.size:
            pb = dict(nonlinear["bump_stop"])

            def stop_value(k0, k1, U=U, pb=pb):
                u = U[:, k0:k1]
                f = bump_stop_force(u, pb["gap"], pb["stiffness"], pb["smoothing"])
                uu = float(np.sum(np.mean(u * u, axis=1)))
                return (float(np.sum(np.mean(f * u, axis=1))) / uu if uu > 0 else 0.0), \
                    float(np.sqrt(np.mean(u * u)))
            from vehicles.effects import get_effect
            k_top = next(q.range[1] for q in get_effect("bump_stop").parameters if q.name == "stiffness")
            eqs.append(Equivalent("bump_stop", stop_value,     # slope at rest k/2 (its range's top at most)
                                  lambda k, pb=pb: ({"gap": 0.0, "stiffness": min(2.0 * k, k_top),
                                                     "smoothing": pb["smoothing"]}
                                                    if k >= BUMP_STOP_FLOOR else None), BUMP_STOP_FLOOR))
    left = sorted(set(nonlinear) - set(keep) - {e.effect for e in eqs})
    if not eqs:
        return linear_model(vp, "rigid", effects=keep or None), left, notes   # applied in the effects' own order

    def model_over(k0, k1):
        vals = {e.effect: e.value(k0, k1) for e in eqs}
        eff = dict(keep)
        for e in eqs:
            par = e.params(vals[e.effect][0])
            if par is not None:
                eff[e.effect] = par
        return linear_model(vp, "rigid", effects=eff), vals

    ref, ref_vals = model_over(0, m)
    blocks = linearisation_blocks(eqs, m, fs) if per_block else [(0, m)]
    if len(blocks) > 1:
        made = [model_over(k0, k1) for k0, k1 in blocks]
        values = {e.effect: [v[e.effect][0] for _, v in made] for e in eqs}
        measured = {e.effect: [v[e.effect][1] for _, v in made] for e in eqs}
        for e in eqs:
            notes.append(_linearised_note(e.effect, nonlinear[e.effect], values[e.effect], measured[e.effect],
                                          ref_vals[e.effect][0], len(blocks), source))
        return BlockModel(ref, [(k0, mod) for (k0, _), (mod, _) in zip(blocks, made)], values, measured), left, notes
    for e in eqs:
        notes.append(_linearised_note(e.effect, nonlinear[e.effect], [ref_vals[e.effect][0]],
                                      [ref_vals[e.effect][1]], None, 1, source))
    if not per_block and vel:
        spread = friction_block_spread(vel, fs, ref_vals["leaf_friction"][1], t0)
        if spread is not None:
            notes.append(spread)
    return ref, left, notes


def _linearised_note(effect: str, p: dict, values: list, measured: list, drive_value, pieces: int,
                     source: str) -> str:
    """The report line of one statistically linearised effect (one model, or ``pieces`` blocks)."""
    def span(v, scale=1.0, fmt="{:.0f}"):
        lo, hi = fmt.format(min(v) * scale), fmt.format(max(v) * scale)
        return lo if lo == hi else f"{lo}-{hi}"
    where = f" per {FRICTION_BLOCK_S:.0f} s block" if pieces > 1 else ""
    tail = f" in {pieces} pieces (one for the drive: {drive_value:.0f})" if pieces > 1 else ""
    if effect == "leaf_friction":
        return (f"leaf_friction {p['force']:.0f} N statistically linearised{where}{source}: suspension velocity "
                f"RMS {span(measured, 1e3)} mm/s -> damping {span(values)} N s/m per spring{tail}")
    return (f"bump_stop (gap {p['gap'] * 1e3:.0f} mm) statistically linearised{where} over the measured "
            f"suspension displacement (RMS {span(measured, 1e3, '{:.1f}')} mm): equivalent stiffness "
            f"{span(values)} N/m per suspension{tail}")


#: the prefix of a linear-model note that is a warning (:func:`note_warnings` finds them)
WARNING_PREFIX = "WARNING: "


def note_warnings(notes) -> list:
    """The warnings among the replica's linear-model notes (``summary["linear_model"]["notes"]``),
    without their prefix: what ``eroad replica`` prints as warnings and ``eroad reproduce`` puts
    at the top of its manifest."""
    return [str(n)[len(WARNING_PREFIX):] for n in notes or [] if str(n).startswith(WARNING_PREFIX)]


#: a block whose equivalent friction damper would be this many times the drive's gets a note.
#: Why 3: on the embedded drive (results/replica/20261201-smooth-segment/) the class A segment's
#: damper would be 9.1x the drive's and its replica came out 5-8x too smooth at 0.5-2 m (ln -1.4 to
#: -2.1); the C segment's, 1.3x, only ln -0.1 to -0.4; the same stretch replicated alone, with its
#: own damper, within ln 0.3 at every band.  3 sits between what did no harm and what did.
FRICTION_BLOCK_RATIO = 3.0


def friction_block_spread(vel, fs: float, s_drive: float, t0: float = 0.0) -> str | None:
    """A warning where one statistically linearised friction damper is far too soft for part of
    the drive, else None.

    ``vel``: the leaf-spring stations' suspension velocities [m/s] as
    :func:`replica_linear_model` computes them; ``s_drive``: their RMS over the drive.  Over
    blocks of :data:`FRICTION_BLOCK_S` the damper c_eq ~ 1 / s would be s_drive / s_block times
    the drive's; blocks where that exceeds :data:`FRICTION_BLOCK_RATIO` are named with their record
    times: there the friction nearly locks the springs, the linear model takes them for soft, and the
    replica reads the small strokes as a smoother road."""
    n = int(round(FRICTION_BLOCK_S * fs))
    m = min(len(v) for v in vel)
    if n < 2 or m < 2 * n:
        return None
    k = m // n
    s_blk = np.sqrt(np.mean([np.mean(np.asarray(v[:k * n]).reshape(k, n) ** 2, axis=1) for v in vel], axis=0))
    ratio = s_drive / np.maximum(s_blk, 1e-12)
    stiff = np.flatnonzero(ratio > FRICTION_BLOCK_RATIO)
    if stiff.size == 0:
        return None
    spans = ", ".join(f"{t0 + i * FRICTION_BLOCK_S:.0f}-{t0 + (i + 1) * FRICTION_BLOCK_S:.0f} s" for i in stiff)

    def span(a, b):
        lo, hi = f"{a:.0f}", f"{b:.0f}"
        return lo if lo == hi else f"{lo}-{hi}"
    return (f"{WARNING_PREFIX}one friction damper serves the whole drive, but on {spans} the suspension moves at "
            f"{span(1e3 * float(s_blk[stiff].min()), 1e3 * float(s_blk[stiff].max()))} mm/s RMS against "
            f"{1e3 * s_drive:.0f} mm/s for the drive: there the friction nearly locks the springs (a damper "
            f"{span(float(ratio[stiff].min()), float(ratio[stiff].max()))} times stiffer would fit), so the "
            f"replica there is too smooth at short wavelengths (embedded drive: 5-8x in PSD at 0.5-2 m). "
            f"Replicate such a stretch alone (eroad data cut --window T0 T1, then eroad replica on it) "
            f"-- docs/replica.md")


# --------------------------------------------------------------------------- scoring helpers
def band_filter(z, dx: float, band_m=(0.5, 20.0)) -> np.ndarray:
    """Profile band-passed to wavelengths within ``band_m`` [m] (FFT mask, mean and
    linear trend removed first)."""
    z = np.asarray(z, float)
    xx = np.arange(z.size)
    z = z - np.polyval(np.polyfit(xx, z, 1), xx)
    Z = np.fft.rfft(z)
    n = np.fft.rfftfreq(z.size, dx)
    keep = (n >= 1.0 / band_m[1]) & (n <= 1.0 / band_m[0])
    return np.fft.irfft(Z * keep, z.size)


def band_correlation(z_est, z_true, dx: float, band_m=(0.5, 20.0)) -> float:
    """Correlation of two profiles on the same grid in a wavelength band [-]."""
    a = band_filter(z_est, dx, band_m)
    b = band_filter(z_true, dx, band_m)
    return float(np.dot(a, b) / math.sqrt(np.dot(a, a) * np.dot(b, b)))


def nrmse(pred, meas) -> float:
    """RMS(pred - meas) / RMS(meas - mean) [-]."""
    meas = np.asarray(meas, float)
    m = meas - meas.mean()
    p = np.asarray(pred, float) - np.mean(pred)
    return float(np.sqrt(np.mean((p - m) ** 2)) / np.sqrt(np.mean(m ** 2)))


# --------------------------------------------------------------------------- against the inversion
def inversion_segment_psd(seg: dict, n) -> np.ndarray:
    """The PSD [m^3] an inversion segment (summary.json row) reports at ``n`` [cycles/m]:
    its two-slope refit where the road model chose two slopes, else the one-slope fit."""
    from inverse.road_model import segment_spectrum
    from roadlib.psd import road_psd

    return road_psd(np.asarray(n, float), *segment_spectrum(seg))


def segment_psd_rows(rep: Replica, time, segments: list, band_m=(0.5, 20.0)) -> list:
    """Per inversion segment: the replica's PSD over the stretch axle 1 drove during the
    segment (every tyre line's periodogram averaged -- the inversion's PSD is one line's, and a
    side track, the mean of that side's lines, has less power at short waves where they differ;
    the side tracks where the replica has no lines; Welch segments of at most 1/4 of it)
    against the inversion's fitted PSD there.

    Returns a list of dicts: segment, t_start, t_end [s], x_start, x_end [m], the
    replica PSD (``n``, ``G``), the fitted PSD on the same ``n``, and the mean log ratio
    replica / fit over ``band_m`` and the segment's own band (``ln_ratio``, [-];
    nan where under 3 Welch bins fall in it).
    """
    from inverse.report import class_label

    from roadlib.metrics import profile_psd

    t = np.asarray(time, float)
    s_rec = rep.operator.s_record
    dx = float(rep.x[1] - rep.x[0])
    rows = []
    for k, seg in enumerate(segments):
        x0, x1 = np.interp([seg["t_start"], seg["t_end"]], t, s_rec)
        m = (rep.x >= x0) & (rep.x <= x1)
        if m.sum() < 64:
            continue
        profiles = [zl for _, _, zl in (getattr(rep, "lines", None) or [])] or [rep.z_left, rep.z_right]
        est = profile_psd(np.stack([z[m] for z in profiles], axis=1), dx,
                          nperseg=int(2 ** math.floor(math.log2(max(32, m.sum() // 4)))))
        n, G = est.n[1:], est.G[1:]
        fit = inversion_segment_psd(seg, n)
        lo = max(1.0 / band_m[1], seg.get("nmin", 0.0))
        hi = min(1.0 / band_m[0], seg.get("nmax", np.inf))
        sel = (n >= lo) & (n <= hi)
        lr = float(np.mean(np.log(G[sel] / fit[sel]))) if sel.sum() >= 3 else float("nan")
        rows.append({"segment": k + 1, "t_start": float(seg["t_start"]), "t_end": float(seg["t_end"]),
                     "x_start": float(x0), "x_end": float(x1), "n": n, "G": G, "fit": fit,
                     "band": (float(lo), float(hi)), "ln_ratio": lr,
                     "road_model": seg.get("road_model", "one_slope"), "class": class_label(seg)})
    return rows


def plot_segment_psd(rows: list, path, title: str = "") -> None:
    """One panel per segment: replica PSD against the inversion's fitted PSD."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    k = max(1, len(rows))
    cols = min(k, 3)
    nr = int(math.ceil(k / cols))
    fig, axes = plt.subplots(nr, cols, figsize=(4.2 * cols, 3.4 * nr + 0.6), squeeze=False)
    for ax, r in zip(axes.ravel(), rows):
        ax.loglog(r["n"], r["G"], "C0", lw=1.0, label="replica (every tyre line)")
        ax.loglog(r["n"], r["fit"], "k--", lw=1.2,
                  label=f"inversion fit ({r['road_model'].replace('_', ' ')}, class {r['class']})")
        ax.axvspan(*r["band"], color="0.92", zorder=0)
        ax.set_title(f"segment {r['segment']}: {r['t_start']:.1f}-{r['t_end']:.1f} s, "
                     f"{r['x_end'] - r['x_start']:.0f} m\nmean ln(replica / fit) in grey band "
                     f"{r['ln_ratio']:+.2f}", fontsize=8)
        ax.set_xlabel("n [cycles/m]", fontsize=8)
        ax.set_ylabel("Gd(n) [m^3]", fontsize=8)
        ax.legend(fontsize=7, loc="lower left")
    for ax in axes.ravel()[len(rows):]:
        ax.axis("off")
    fig.suptitle(f"Replica against the statistical inversion, per segment {title}\n"
                 "grey: the segment's fitted band within 0.5-20 m", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# --------------------------------------------------------------------------- the run folder
#: run-folder format version of ``eroad replica``
RUN_FORMAT = 1
#: lateral road grid of the written 3D road [m]: half width and step (0.02 m puts every
#: tyre line of the trucks here, |y| = 0.76, 1.02, 1.10 m, on a grid line, so a tyre at
#: its own lateral position reads its line exactly)
ROAD_Y_HALF_WIDTH, ROAD_DY = 1.5, 0.02


def line_column(side: str, y: float) -> str:
    """tracks.csv column of a tyre line, e.g. ``z_L_y1.02_m``."""
    return f"z_{side}_y{abs(float(y)):.2f}_m"


def replica_surface(rep: Replica):
    """The replica as a RoadSurface: every reconstructed line at its lateral position,
    linear in y between neighbouring lines, held beyond the outermost ones.

    DECISION (docs/replica.md): the lateral field is the conditional mean of the road
    prior given the lines, not a random draw.  Across y at fixed x, a w = 2 road is a
    random walk (structure function linear in distance), and the conditional mean of a
    random walk between two known points is the straight line between them, beyond the
    last known point its value there -- so linear interpolation and holding is the
    prior's best estimate, and no texture that the data did not show is invented.  Its
    uncertainty grows with the distance r to the nearest line, sd ~ sqrt(r / (alpha dx))
    (``summary.json`` ``lateral_field``).  With ``lines="track"`` each track covers the
    lateral span of its side's tyres (every tyre reads its track exactly).
    """
    from roadlib.surface import RoadSurface

    y = np.round(np.arange(-ROAD_Y_HALF_WIDTH, ROAD_Y_HALF_WIDTH + 1e-9, ROAD_DY), 10)
    knots = []                      # (y, profile) sorted by y, a side's span as two knots
    op = rep.operator
    if rep.lines and op is not None and op.lines == "tyre" and len(rep.lines) > 2:
        knots = [(float(yl), z) for _, yl, z in rep.lines]
    else:
        for side, z in (("L", rep.z_left), ("R", rep.z_right)):
            ys = [c["y"] for c in op.lm.contacts if c["side"] == side] if op is not None else [0.96 if side == "L" else -0.96]
            knots += [(float(min(ys)), z), (float(max(ys)), z)]
    knots.sort(key=lambda k: k[0])
    yk = np.array([k[0] for k in knots])
    Z = np.stack([k[1] for k in knots], axis=1)              # (N, n_knots)
    z = np.empty((rep.x.size, y.size))
    for i, yi in enumerate(y):
        if yi <= yk[0]:
            z[:, i] = Z[:, 0]
        elif yi >= yk[-1]:
            z[:, i] = Z[:, -1]
        else:
            k = int(np.searchsorted(yk, yi, side="right")) - 1
            a = 0.0 if yk[k + 1] == yk[k] else (yi - yk[k]) / (yk[k + 1] - yk[k])
            z[:, i] = (1 - a) * Z[:, k] + a * Z[:, k + 1]
    meta = {"generator": "inverse.replica",
            "lines_y_m": ", ".join(f"{v:.2f}" for v in yk),
            "lateral": "linear between reconstructed lines, held beyond (conditional mean of a w = 2 road)",
            "x_origin": "first axle at the dataset's first sample"}
    return RoadSurface(rep.x, y, z, meta)


def _holdout_axle(holdout, names) -> tuple:
    """The held-out axle of :func:`run_replica` and a note (empty unless none could be held
    out); an axle asked for that cannot be held out is refused before any reconstruction."""
    axles = sorted({a for a in (axle_of(c) for c in names) if a is not None})
    if holdout is None:
        return None, "no axle held out (--holdout none)"
    if holdout == "auto":
        if len(axles) < 2:
            return None, (f"no axle held out: the drive logs one axle ({', '.join(map(str, axles))}), so the "
                          "replica cannot be checked against channels it was not made from")
        return (2 if 2 in axles else axles[-1]), ""
    a = int(holdout)
    if a not in axles or len(axles) < 2:
        raise EroadInputError(f"--holdout {a}: the drive has no channels of axle {a}, or only those (axles "
                              f"logged: {', '.join(map(str, axles)) or 'none'}); use --holdout none")
    return a, ""


def run_replica(dataset, out, *, effects=None, noise_sd=None, holdout="auto", force: bool = False,
                argv=None, progress=None, lines: str = "tyre", inversion=None) -> dict:
    """``eroad replica``: reconstruct, score the hold-out, write the run folder.

    RUN (written into a temporary sibling folder and renamed into place, like
    ``eroad invert``)::

        tracks.csv          x_m, z_left_m, z_right_m, identified, lambda_min_m, lambda_max_m,
                            z_<side>_y<|y|>_m per tyre line (lines="tyre")
        iri.csv             track, segment_m (20, 100), start_m, end_m, iri_m_per_km
        psd.csv             n_cpm, G_left_m3, G_right_m3 (Welch over the identified stretch)
        road.npz, road.crg  the two tracks as a 3D road (replica_surface)
        figures/replica_time.png, replica_psd.png, replica_tracks.png
        summary.json, config.toml, run.json

    Parameters
    ----------
    dataset : str or Path
    out : str or Path
    effects : dict, optional
        Effects of the linear model (nonlinear ones are left out, as in the linear fit).
    noise_sd : dict, optional
        Channel or quantity -> sensor noise sd [SI]; the rest estimated.
    holdout : int, "auto" or None
        Axle whose channels are left out of a second reconstruction and predicted
        from it (validation); None: none; "auto" (default): axle 2 where the drive
        logs it and another axle, else the highest-numbered of two or more logged axles,
        else none (a drive logged on one axle has nothing to hold out; the summary says so).
    lines : {"tyre", "track"}
        Unknowns per side: a line per lateral tyre position (default) or one track.
    inversion : str or Path, optional
        An ``eroad invert`` run folder of the same dataset: its segments' fitted PSDs are
        compared with the replica's (psd_segments.csv, figures/replica_vs_inversion.png).
    """
    import json
    import os
    import shutil
    from pathlib import Path

    import pandas as pd

    from drives.format import read_drive, swap_into_place, temp_folder_beside
    from inverse.run import dataset_path
    from roadlib.iri import iri_segments
    from roadlib.metrics import fit_iso_psd, profile_psd
    from eroad.archive import finish_run_info, run_info, write_json_atomic, write_run_json

    t0 = _time.perf_counter()
    out = Path(out)
    record = run_info("replica", run_id=out.name, command=list(argv) if argv else ["run_replica"])
    if out.exists() and not out.is_dir():
        raise EroadInputError(f"{out}: exists and is not a folder")
    if out.exists() and any(out.iterdir()) and not force:
        raise EroadInputError(f"{out}: exists and is not empty; choose another --out or use --force")
    drive = read_drive(dataset)
    from drives.cut import require_road_record
    from drives.rate import for_road_methods
    drive, resampled = for_road_methods(drive)   # above the vehicle's solver rate: to 200 Hz
    names = response_channels(drive.channel_names)
    if not names:
        raise EroadInputError(f"{drive.path}: eroad replica needs response channels "
                              f"(susp_disp_*, axle_acc_*, body_acc_*); present: "
                              f"{', '.join(drive.channel_names) or 'none'}")
    require_road_record(drive, "eroad replica")   # the road methods run in distance
    holdout, holdout_note = _holdout_axle(holdout, names)
    chans = {c: drive.channels[c].to_numpy(float) for c in names}
    lm, left_out, lin_notes = replica_linear_model(drive.vehicle, effects, chans, drive.sample_rate_hz,
                                                   t0=float(drive.time[0]))
    missing = [c for c in names if c not in lm.channel_names]
    if missing:
        raise EroadInputError(f"{drive.path}: channel(s) {', '.join(missing)} have no counterpart in "
                              f"vehicle {lm.meta.get('vehicle')} (axles {len(lm.vp.axles)})")
    noise = None
    if noise_sd:
        from inverse.cli import noise_psd_from_sd
        psd = noise_psd_from_sd(noise_sd, names, drive.sample_rate_hz)
        noise = {c: math.sqrt(p * 0.5 * drive.sample_rate_hz) for c, p in psd.items()}
    if lines not in LINE_MODES:
        raise EroadInputError(f"--lines {lines!r}: use one of {', '.join(LINE_MODES)}")
    rep = reconstruct(lm, drive.time, drive.speed, chans, noise=noise, progress=progress, lines=lines)
    held, pred, rep2 = [], {}, None
    if holdout is not None:
        held = [c for c in names if axle_of(c) == int(holdout)]
        keep = [c for c in names if axle_of(c) != int(holdout)]
        lm2 = lm if not lin_notes else replica_linear_model(      # no held-out data in the linearisation
            drive.vehicle, effects, {c: chans[c] for c in keep}, drive.sample_rate_hz)[0]
        rep2 = reconstruct(lm2, drive.time, drive.speed, {c: chans[c] for c in keep}, noise=noise,
                           progress=progress, lines=lines)
        pred = rep2.predict(held)
    dx = float(rep.x[1] - rep.x[0])
    cov = rep.covered
    xc = rep.x[cov]
    ident = cov & np.isfinite(rep.lambda_min)

    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_folder_beside(out)
    (tmp / "figures").mkdir()
    try:
        cols = {"x_m": rep.x, "z_left_m": rep.z_left, "z_right_m": rep.z_right,
                "identified": ident.astype(int), "lambda_min_m": rep.lambda_min,
                "lambda_max_m": rep.lambda_max}
        if rep.operator.lines == "tyre":
            cols.update({line_column(side, yl): zl for side, yl, zl in rep.lines})
        pd.DataFrame(cols).to_csv(tmp / "tracks.csv", index=False, float_format="%.9g")
        rows = []
        iri = {}
        for side, z in (("left", rep.z_left), ("right", rep.z_right)):
            for L in (20.0, 100.0):
                if xc[-1] - xc[0] < L:          # a drive shorter than the segment: no IRI of that length
                    iri[f"{side}_{int(L)}m"] = []
                    continue
                segs = iri_segments(xc, z[cov], L, start=float(xc[0]))
                rows += [{"track": side, "segment_m": L, "start_m": s.start, "end_m": s.end,
                          "iri_m_per_km": s.iri} for s in segs]
                iri[f"{side}_{int(L)}m"] = [s.iri for s in segs]
        pd.DataFrame(rows).to_csv(tmp / "iri.csv", index=False, float_format="%.6g")
        est = profile_psd(rep.z_left[cov], dx)
        est_r = profile_psd(rep.z_right[cov], dx)
        pd.DataFrame({"n_cpm": est.n, "G_left_m3": est.G, "G_right_m3": est_r.G}).to_csv(
            tmp / "psd.csv", index=False, float_format="%.6g")
        lam_lo = float(np.nanmedian(rep.lambda_min[cov]))
        lam_hi = float(np.nanmedian(rep.lambda_max[cov]))
        fits = {}
        for side, e in (("left", est), ("right", est_r)):
            band = (max(1.0 / min(lam_hi, 20.0), e.n[1]), min(1.0 / lam_lo, 2.83))
            try:
                fits[side] = fit_iso_psd(e, band=band).to_dict()
            except EroadInputError as exc:
                fits[side] = {"error": str(exc)}
        seg_rows, inv_info = [], None
        if inversion is not None:
            inv_sum = Path(inversion) / "summary.json"
            if not inv_sum.is_file():
                raise EroadInputError(f"--inversion {inversion}: not an 'eroad invert' run folder (no summary.json)")
            inv = json.loads(inv_sum.read_text())
            seg_rows = segment_psd_rows(rep, drive.time, inv.get("segments", []))
            pd.DataFrame([{"segment": r["segment"], "t_start_s": r["t_start"], "t_end_s": r["t_end"],
                           "n_cpm": n, "G_replica_m3": g, "G_inversion_m3": f}
                          for r in seg_rows for n, g, f in zip(r["n"], r["G"], r["fit"])]).to_csv(
                tmp / "psd_segments.csv", index=False, float_format="%.6g")
            if seg_rows:
                plot_segment_psd(seg_rows, tmp / "figures" / "replica_vs_inversion.png", title=drive.name)
            inv_info = {"run": os.path.relpath(Path(inversion).resolve(), Path(out).resolve()),
                        "segments": [{k: r[k] for k in ("segment", "t_start", "t_end", "x_start", "x_end",
                                                        "road_model", "class", "ln_ratio")} for r in seg_rows],
                        "ln_ratio_meaning": "mean ln(replica PSD / inversion PSD) over the segment's band "
                                            "within 0.5-20 m; 0: the two methods agree"}
        surf = replica_surface(rep)
        surf.save(tmp / "road.npz")
        surf.save(tmp / "road.crg")
        figs = write_replica_figures(tmp / "figures", drive, rep, est, est_r, fits, held, pred, title=drive.name)
        if seg_rows:
            figs.append("replica_vs_inversion.png")
        holdout_scores = {c: nrmse(pred[c], chans[c]) for c in held}
        fit_scores = {c: nrmse(rep.fitted[c], chans[c]) for c in names}
        summary = {
            "format": RUN_FORMAT,
            "dataset": {"name": drive.name, "path": dataset_path(dataset, out), "vehicle": str(drive.vehicle),
                        "duration_s": drive.duration_s, "sample_rate_hz": drive.sample_rate_hz,
                        "warnings": list(drive.warnings), "resampled": resampled,
                        "speed_check": drive.speed_check},
            "method": "time-domain MAP input estimation on the linear model (docs/replica.md)",
            "lines": {"layout": rep.operator.lines,
                      "tyre_lines": [{"side": side, "y_m": float(yl), "column": line_column(side, yl)}
                                     for side, yl, _ in rep.lines] if rep.operator.lines == "tyre" else [],
                      "tracks": ("z_left_m / z_right_m: the mean of the road under each side's tyres (a dual "
                                 "pair counted twice), inverse.replica.side_tracks"),
                      "accuracy": ("per line at short waves see docs/replica.md 'Line by line': the two "
                                   "lines of a dual pair are told apart by the prior, not the data")
                                if rep.operator.lines == "tyre" else "one profile per side for all its tyres",
                      "lateral_field": {"method": "linear between lines, held beyond (conditional mean)",
                                        "sd_at_0.5m_from_a_line_m": float(math.sqrt(0.5 / (rep.alpha * dx)))}},
            "grid": {"dx_m": dx, "x_start_m": float(rep.x[0]), "x_end_m": float(rep.x[-1]),
                     "covered_m": [float(xc[0]), float(xc[-1])]},
            "identified_band_m": {"median_lambda_min": lam_lo, "median_lambda_max": lam_hi,
                                  "at_speed": dict(zip([f"{v:.2f}" for v in rep.info["speed_quantiles_mps"]],
                                                       rep.info["band_at_speed_m"])),
                                  "criterion": f"regularised resolution >= {RESOLUTION_MIN} on both tracks"},
            "regularisation": {"alpha_per_m2": rep.alpha, "road_level_gd0_m3": rep.gd0,
                               "choice": "empirical Bayes (EM): road level and channel model-error floors",
                               "em": rep.info["em"]},
            "channels": {"used": names, "sigma_used": rep.sigma, "sigma_sensor": rep.sigma_sensor,
                         "fit_nrmse": fit_scores},
            "holdout": {"axle": holdout, "channels": held, "nrmse": holdout_scores, "note": holdout_note,
                        "nrmse_definition": "RMS(pred - meas) / RMS(meas), means removed"},
            "iri_m_per_km": iri,
            "psd_iso_fit": fits,
            "against_inversion": inv_info,
            "linear_model": {"effects": {k: dict(v) for k, v in lm.meta.get("effects", {}).items()},
                             "effects_left_out": left_out, "notes": rep.info["linear_model_notes"] + lin_notes,
                             "blocks": block_table(lm, drive.time)},
            "figures": figs,
            "files": ["tracks.csv", "iri.csv", "psd.csv", "road.npz", "road.crg"]
                     + (["psd_segments.csv"] if inversion is not None else []),
            "timing": {"reconstruct_s": rep.info["wall_s"],
                       "holdout_s": rep2.info["wall_s"] if rep2 is not None else 0.0,
                       "cg_iterations": rep.info["cg_iterations"],
                       "total_s": _time.perf_counter() - t0},
        }
        write_json_atomic(tmp / "summary.json", summary)
        import tomli_w
        cfg = {"dataset": dataset_path(dataset, out), "effects": json.dumps(effects or {}),
               "noise_sd": dict(noise_sd or {}), "holdout": -1 if holdout is None else int(holdout),
               "dx_m": dx, "substeps": rep.info["substeps"], "runin_s": rep.info["runin_s"], "lines": lines}
        (tmp / "config.toml").write_text(tomli_w.dumps(cfg))
        write_run_json(tmp, finish_run_info(record, "complete", wall_s=_time.perf_counter() - t0))
        swap_into_place(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return summary


def write_replica_figures(folder, drive, rep: Replica, est_l, est_r, fits, held, pred, title="") -> list:
    """Time-domain comparison (measured vs the linear model on the replica, held-out
    channels predicted from the replica made without them), PSD and track plots."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(drive.time, float)
    # one channel of each kind, axle 3's where fitted (the paper's), else the first fitted
    shown = []
    for q, pref in (("susp_disp", "susp_disp_3L"), ("axle_acc", "axle_acc_3L"), ("body_acc", "body_acc_3R")):
        kind = sorted(c for c in rep.fitted if c.startswith(q + "_"))
        if kind:
            shown.append(pref if pref in kind else kind[0])
    rows = [(c, rep.fitted[c], "fitted") for c in shown] + [(c, pred[c], "held out") for c in held[:3]]
    fig, axes = plt.subplots(len(rows), 1, figsize=(10, 1.9 * len(rows) + 0.6), sharex=True)
    axes = np.atleast_1d(axes)
    t_mid = 0.5 * (t[0] + t[-1])
    zoom = (t >= t_mid - 2.5) & (t <= t_mid + 2.5)
    for ax, (c, p, kind) in zip(axes, rows):
        m = drive.channels[c].to_numpy(float)
        ax.plot(t[zoom], (m - m.mean())[zoom], "k", lw=1.0, label="measured")
        ax.plot(t[zoom], (p - np.mean(p))[zoom], "C3" if kind == "held out" else "C0", lw=1.0,
                label=f"linear model on replica ({kind}), nRMSE {nrmse(p, m):.2f}")
        ax.set_ylabel(f"{c}\n[{drive.units.get(c, '')}]", fontsize=8)
        ax.legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("time [s]")
    legend = "blue: channels used in the reconstruction" + (
        "; red: channels held out of it, predicted" if held else " (none held out)")
    fig.suptitle(f"Replica, time domain (5 s of the record) {title}\n{legend}", fontsize=9)
    fig.tight_layout()
    files = []
    p = folder / "replica_time.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    files.append(p.name)

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for e, side, col in ((est_l, "left", "C0"), (est_r, "right", "C1")):
        ax.loglog(e.n[1:], e.G[1:], col, label=f"replica {side}")
        f = fits.get(side, {})
        if "Gd_n0" in f:
            n = np.geomspace(*f["band"], 50)
            ax.loglog(n, f["Gd_n0"] * (n / 0.1) ** (-f["w"]), col + "--",
                      label=f"ISO fit {side}: Gd(n0) {f['Gd_n0']:.3g} m^3, w {f['w']:.2f} (class {f['class']})")
    lo = float(np.nanmedian(rep.lambda_min[rep.covered]))
    hi = float(np.nanmedian(rep.lambda_max[rep.covered]))
    ax.axvspan(1.0 / hi, 1.0 / lo, color="0.9", zorder=0, label=f"identified {lo:.2g}-{hi:.3g} m (median)")
    ax.set_xlabel("spatial frequency n [cycles/m]")
    ax.set_ylabel("PSD Gd(n) [m^3]")
    ax.set_title(f"Replica track PSD {title}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    p = folder / "replica_psd.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    files.append(p.name)

    fig, ax = plt.subplots(figsize=(10, 3.5))
    cov = rep.covered
    ax.plot(rep.x[cov], 1e3 * rep.z_left[cov], "C0", lw=0.8, label="left")
    ax.plot(rep.x[cov], 1e3 * rep.z_right[cov], "C1", lw=0.8, label="right")
    ax.set_xlabel("x [m] (0: first axle at the first sample)")
    ax.set_ylabel("height [mm]")
    ax.set_title(f"Replica tracks {title}", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    p = folder / "replica_tracks.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    files.append(p.name)
    return files
