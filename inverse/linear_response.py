"""The linear truck's TIME response to one road realisation: a time simulation without Exudyn.

What it is for: the realisation selection (``inverse.realisation.select_realisation_linear``)
ranks M candidate phase seeds by their Table 2 statistics.  Each candidate used to be a
full Exudyn time simulation of the nominal truck; for a truck whose model is linear
(the nominal one: one linear solve per step) the same numbers come from the linearised
vehicle (:mod:`vehicles.linear`) driven by the same road heights, in a small fraction of
the time.  :class:`LinearRealisation` is a drop-in for the simulator contract of
:mod:`inverse.sensitivity` (``(params (K, 4), seed) -> {channel: (N,) array}``) built
from an :class:`inverse.truck.TruckSimulator`: same road (``TruckSimulator.road``), same
layout (run-in, start position, speed profile), same channels.

What it is not: exact for nonlinear effects (leaf friction, bump stops, asymmetric
dampers are left out of the linear model, :func:`inverse.linear_features.linear_model_for`):
their share is what the selection's correction by simulated candidates carries
(docs/inverse.md, section 12).  Linear effects are in the linear model; tyre enveloping's
footprint filter is applied to the road as the effect applies it.

Method
------
* Road input, as ``vehicles.simulate.road_under_tyres`` computes it for the simulator:
  on the simulator's step grid (``dt`` = the vehicle's solver step rounded so that the
  output period is a whole number of steps), the distance travelled is the exact
  integral of the piecewise-linear speed profile (``vehicles.simulate.SpeedProfile``),
  the height under tyre c is the road's height at ``(x_front0 + x_axle + s, y_c)``
  (``RoadSurface.height``: linear along x on the tyre's own line, roadlib.surface
  "Exact lines") and its rate the slope of the linear interpolant
  along x times the speed.
* Dynamics: ``x' = A x + B u`` (``LinearModel.state_space``, x = [q, q'],
  u = [z_r, z_r']) discretised with a first-order hold at the step ``dt`` and
  diagonalised: each mode is a first-order recursion (``scipy.signal.lfilter``), so a
  30 s drive at 400 steps/s costs a few milliseconds per mode.  Outputs: displacements
  ``row q``, accelerations ``row q''`` = ``row (A[n:] x + B[n:] u)`` (the tyre forces
  act directly on the axle accelerations).
* Start: the simulator starts at static equilibrium on the road heights under the tyres
  at t = 0 (velocities zero); here the state starts at the steady state of the constant
  input ``[z_r(0), 0]`` and the response is that steady state plus the zero-state
  response to ``u - u(0)``.
* Output: the state at the end of every output period (the simulator's sensors), the
  record's samples after the run-in.

The differences from the Exudyn simulation that remain: the integrator (generalised-alpha
with numerical damping at high frequency against the exact discretisation here), the
geometric nonlinearity (second order), effects left out.  Measured on the luliang fit:
RMS within 0.1-0.3 % per channel, correlation 0.9998-0.99999 (docs/inverse.md section 12);
``tests/test_inverse_speed.py`` asserts 1 % and 0.999.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import cont2discrete, lfilter

from eroad.errors import EroadInputError

__all__ = ["LinearRealisation", "channel_stats"]


def channel_stats(channels: dict, names=None) -> dict:
    """Table 2 statistics per channel: ``{"rms": std [unit], "mean_abs": mean |y - mean y| [unit]}``.

    The RMS is about the mean (standard deviation) and the "mean" the rectified mean, as
    in :func:`inverse.validation.response_table`.
    """
    names = list(channels) if names is None else [c for c in names if c in channels]
    out = {}
    for c in names:
        y = np.asarray(channels[c], float)
        d = y - y.mean()
        out[c] = {"rms": float(np.std(y)), "mean_abs": float(np.mean(np.abs(d)))}
    return out


class LinearRealisation:
    """``(params, seed) -> channels``: the linear truck driven over the simulator's road.

    Parameters
    ----------
    simulator : inverse.truck.TruckSimulator
        The time simulator whose road, layout, vehicle, chassis, effects and channels
        are reproduced.
    channels : sequence of str, optional
        Channels to return (default the simulator's).
    linear_model : vehicles.linear.LinearModel, optional
        Default :func:`inverse.linear_features.linear_model_for` of the simulator's
        vehicle, chassis and effects (its linear effects only).

    Attributes
    ----------
    left_out : list of str
        Effects of the simulator the linear model leaves out (nonlinear ones).

    Picklable (no Exudyn objects are kept): a process pool can evaluate candidates.
    """

    def __init__(self, simulator, channels=None, linear_model=None):
        from vehicles.params import load_vehicle
        from vehicles.simulate import SpeedProfile

        self.simulator = simulator
        self.channels = tuple(channels if channels is not None else simulator.channels)
        if linear_model is None:
            from inverse.linear_features import linear_model_for

            lm, self.left_out = linear_model_for(simulator.vehicle, simulator.chassis, simulator.effects or None)
        else:
            lm, self.left_out = linear_model, []
        known = set(lm.channel_names)
        bad = [c for c in self.channels if c not in known]
        if bad:
            raise EroadInputError(f"LinearRealisation: the linear model has no channel {', '.join(bad)}")
        lay = simulator.layout()
        vp = load_vehicle(simulator.vehicle)
        # the simulator's step: the solver step rounded to a whole number per output period
        t_out = 1.0 / lay["fs"]
        dt_req = simulator.dt if simulator.dt is not None else float(vp.solver.dt)
        n_sub = max(1, int(round(t_out / dt_req)))
        dt = t_out / n_sub
        duration = float(lay["t_sim"][-1])
        n_steps = int(round(duration / dt))
        n_out = int(round(duration * lay["fs"])) + 1
        t_steps = np.arange(n_steps + 1) * dt
        prof = SpeedProfile(lay["t_sim"], lay["v_sim"])
        s = prof.distance(t_steps)
        self.v_steps = prof.speed(t_steps)
        self.s_steps = s
        self.x_contact = np.array([lay["x_front0"] + float(c["x"]) for c in lm.contacts])  # road x at s = 0
        self.y_tyre = np.array([float(c["y"]) for c in lm.contacts])                         # y_offset 0
        self.i_out = np.arange(n_out) * n_sub
        if self.i_out[-1] > n_steps:
            self.i_out = self.i_out[self.i_out <= n_steps]
        self.n_run, self.n_rec = int(lay["n_runin"]), int(simulator.time.size)
        self.footprint = float(getattr(lm, "footprint", 0.0) or 0.0)   # tyre_enveloping's contact length
        # effects that post-process the simulated channels (sensor dynamics and noise): applied
        # here as vehicles.simulate applies them, on the whole output (run-in included), to every
        # wheel-station channel in the simulator's order (the noise streams follow that order)
        from vehicles.effects import EFFECTS, resolve_effects
        from vehicles.effects.base import Effect

        self._effects = resolve_effects(simulator.effects) if simulator.effects else {}
        self._post = any(type(EFFECTS[n]).outputs is not Effect.outputs for n in self._effects)
        self._order = [f"{q}_{a + 1}{side}" for q in ("susp_disp", "axle_acc", "body_acc")
                       for a in range(len(vp.axles)) for side in ("L", "R")]
        self._chassis, self._fs = simulator.chassis, float(lay["fs"])
        self.dt, self.n_sub = dt, n_sub
        self._discretise(lm)

    # ------------------------------------------------------------------ model
    def _discretise(self, lm) -> None:
        A, B = lm.state_space()
        C, D = lm.output_matrices(self.channels, A, B)
        # steady state of a constant input u0 = [z0, 0]: x = -A^-1 B u0 (K is regular: tyres hold
        # every coordinate), outputs C x + D u0
        self.G_static = (-C @ np.linalg.solve(A, B) + D)[:, : B.shape[1] // 2]
        Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, D), self.dt, method="foh")
        lam, V = np.linalg.eig(Ad)
        Vi = np.linalg.inv(V)
        # a conjugate pair of modes is one recursion (the member with Im > 0, twice its real part)
        tol = 1e-12 * np.maximum(np.abs(lam), 1e-300)
        real = np.abs(lam.imag) <= tol
        keep = real | (lam.imag > tol)
        wt = np.where(real[keep], 1.0, 2.0)
        self.lam = lam[keep]
        self.Bm = Vi[keep] @ Bd
        self.Cm = (Cd @ V[:, keep]) * wt[None, :]
        self.Dd = Dd

    # ------------------------------------------------------------------ input
    def road_input(self, road) -> np.ndarray:
        """``u = [z_r; z_r']`` (2 n_contacts, steps) under the tyres on ``road`` (as the simulator;
        with the ``tyre_enveloping`` effect the road filtered by the footprint, as that effect does)."""
        if self.footprint > 0:
            road = road.footprint_filtered(self.footprint)
        gx = np.asarray(road.x, float)
        dx = float(road.dx)
        lo, hi = self.x_contact.min() + self.s_steps[0], self.x_contact.max() + self.s_steps[-1]
        if lo < gx[0] - 1e-9 or hi > gx[-1] + 1e-9:
            raise EroadInputError("LinearRealisation: the road does not cover the drive")
        tracks = road.tracks(self.y_tyre)                     # (nc, nx): interpolated in y on the grid x
        nc = self.y_tyre.size
        u = np.empty((2 * nc, self.s_steps.size))
        for c in range(nc):
            xq = self.x_contact[c] + self.s_steps
            u[c] = np.interp(xq, gx, tracks[c])
            i = np.clip(((xq - gx[0]) / dx).astype(np.intp), 0, gx.size - 2)
            u[nc + c] = (tracks[c][i + 1] - tracks[c][i]) / dx * self.v_steps
        return u

    # ------------------------------------------------------------------ response
    def response_to_input(self, u: np.ndarray) -> dict:
        """Channels on the record's samples for the input ``u`` (2 n_contacts, steps)."""
        nc = u.shape[0] // 2
        u0 = np.zeros(u.shape[0])
        u0[:nc] = u[:nc, 0]
        du = u - u0[:, None]
        g = self.Bm @ du                                      # (modes, steps), complex
        y = np.empty((len(self.channels), self.i_out.size))
        acc = np.zeros_like(y)
        for m, lm_ in enumerate(self.lam):
            xi = lfilter([0.0, 1.0], [1.0, -lm_], g[m])[self.i_out]
            acc += np.real(self.Cm[:, m:m + 1] * xi[None, :])
        y[:] = acc + self.Dd @ du[:, self.i_out] + (self.G_static @ u0[:nc])[:, None]
        if self._post:
            y = self._post_process(y)
        a, b = self.n_run, self.n_run + self.n_rec
        out = {}
        for k, c in enumerate(self.channels):
            v = y[k, a:b]
            if v.size < self.n_rec:
                v = np.concatenate([v, np.full(self.n_rec - v.size, v[-1])])
            out[c] = v
        return out

    def _post_process(self, y: np.ndarray) -> np.ndarray:
        from vehicles.effects import EFFECTS
        from vehicles.effects.base import EffectContext
        from vehicles.params import load_vehicle

        vp = load_vehicle(self.simulator.vehicle)
        ctx = EffectContext(vp=vp, reference_vp=vp, chassis=self._chassis, fs_out=self._fs, dt=self.dt, seed=0)
        for name, p in self._effects.items():
            EFFECTS[name].configure(ctx, p)
        mine = {c: k for k, c in enumerate(self.channels)}
        chans = {c: (y[mine[c]].copy() if c in mine else np.zeros(y.shape[1])) for c in self._order}
        chans.update({c: y[k].copy() for c, k in mine.items() if c not in chans})
        t = np.arange(y.shape[1]) / self._fs
        for name, p in self._effects.items():
            EFFECTS[name].outputs(t, chans, p, ctx)
        return np.array([chans[c] for c in self.channels])

    def response(self, road) -> dict:
        """Channel -> (N,) array on the record's time grid for ``road`` (noise-free)."""
        return self.response_to_input(self.road_input(road))

    def __call__(self, params, seed) -> dict:
        """The simulator contract: the linear response over the road of ``params`` and ``seed``."""
        return self.response(self.simulator.road(params, seed))
