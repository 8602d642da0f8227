"""Local nonlinear suspension forces on the linearised vehicle: the elements and their step.

What it is for: the gap diagnosis simulates the nonlinear library effects (leaf friction, bump
stops, asymmetric dampers) hundreds of times per drive.  Each is a force between a frame seat
and an axle seat that depends only on that side's compression ``u`` and its rate ``v``; the
rest of the truck is the linear model.  Integrated with the linear model's own
generalized-alpha recurrence (:mod:`vehicles.linear_sim`), such a force is a small implicit
problem per step -- one unknown per element, a handful per truck -- solved by Newton's
method inside a compiled loop (numba), instead of an Exudyn run with Newton iterations over
every coordinate.

The elements (``kind``, parameters) an effect declares through
:meth:`vehicles.effects.base.Effect.suspension_elements`, force pushing axle and frame apart:

``tanh_force`` (a, b)
    ``a tanh(v / b)``: a smoothed Coulomb force (leaf friction).
``tanh_damper`` (a, b)
    ``a tanh(v / b) v``: a damping change that switches sign with the stroke direction
    (asymmetric damper).
``softplus`` (k, g, s)
    ``k s (softplus((u - g) / s) - softplus(-g / s))``: a stiff spring engaging after a free
    travel ``g`` (bump stop); zero at static equilibrium.

Each effect's elements must give the force its Exudyn terms give
(:meth:`vehicles.effects.base.Effect.suspension_terms`, symbolic): tested point by point in
``tests/test_linear_sim.py``, and whole drives against Exudyn there.

What it is not: a general nonlinear solver.  A force that couples sides, or depends on
anything but its own ``u`` and ``v``, has no element kind and runs in Exudyn.
"""
from __future__ import annotations

import math

import numba
import numpy as np

#: element kinds and their parameter counts (the kernel's integer codes are the positions)
KINDS = ("tanh_force", "tanh_damper", "softplus")
N_PARAMS = {"tanh_force": 2, "tanh_damper": 2, "softplus": 3}
#: Newton's stopping rule per step: every element's force residual below
#: ATOL + RTOL * |force| [N].  1e-3 N is 1e-7 of a 10 kN friction and far below what any
#: output resolves; the relative part keeps stiff bump stops (MN/m) from asking for more
#: digits than double precision holds
ATOL, RTOL = 1e-3, 1e-9
#: iterations per step before the step counts as failed (the caller halves the step, as a
#: failed Exudyn Newton run is retried).  Measured on class C and D windows (9.5 s): 1.0 (bump
#: stop) to 3.2 (friction 12 kN at 5 mm/s, after one halving) iterations per step on average
MAX_ITER = 60


def element_arrays(elements) -> tuple[np.ndarray, np.ndarray]:
    """``[(kind, params), ...]`` -> (kind codes (m,), parameters (m, 3))."""
    kinds = np.zeros(len(elements), dtype=np.int64)
    prm = np.zeros((len(elements), 3))
    for i, (kind, params) in enumerate(elements):
        if kind not in N_PARAMS or len(params) != N_PARAMS[kind]:
            raise ValueError(f"suspension element {kind!r} with {len(params)} parameters")
        kinds[i] = KINDS.index(kind)
        prm[i, :len(params)] = params
    return kinds, prm


def forces(kinds, prm, u, v):
    """Forces and their derivatives (f, df/du, df/dv) of the elements at ``u``, ``v``
    (arrays (m,)); the kernel's formulas, for tests and callers outside the loop."""
    f, du, dv = np.zeros(len(kinds)), np.zeros(len(kinds)), np.zeros(len(kinds))
    for i in range(len(kinds)):
        f[i], du[i], dv[i] = _element(int(kinds[i]), float(prm[i, 0]), float(prm[i, 1]),
                                      float(prm[i, 2]), float(u[i]), float(v[i]))
    return f, du, dv


@numba.njit(cache=True)
def _softplus(x):
    return max(x, 0.0) + math.log1p(math.exp(-abs(x)))


@numba.njit(cache=True)
def _sigmoid(x):
    if x >= 0.0:
        return 1.0 / (1.0 + math.exp(-x))
    e = math.exp(x)
    return e / (1.0 + e)


@numba.njit(cache=True)
def _element(kind, a, b, c, u, v):
    """(force, d force / du, d force / dv) of one element (kind: position in KINDS)."""
    if kind == 0:                          # tanh_force: a tanh(v / b)
        t = math.tanh(v / b)
        return a * t, 0.0, a / b * (1.0 - t * t)
    if kind == 1:                          # tanh_damper: a tanh(v / b) v
        t = math.tanh(v / b)
        return a * t * v, 0.0, a * (t + v / b * (1.0 - t * t))
    # softplus: k s (softplus((u - g) / s) - softplus(-g / s))
    x = (u - b) / c
    return a * c * (_softplus(x) - _softplus(-b / c)), a * _sigmoid(x), 0.0


@numba.njit(cache=True)
def _kernel(PhiT, W, x0, every, n_out, Cq, Gu, Gv, GsT, kinds, prm,
            PT, GBT, base, kc, cc, zr, zr_t, unilateral):
    """The stepping loop of :func:`integrate` (compiled)."""
    n4 = x0.size
    n = n4 // 4
    m = kinds.size
    nc = base.size
    X = np.empty((n_out, n4))
    x = x0.copy()
    X[0] = x
    f = np.zeros(m)
    up = np.empty(m)
    vp = np.empty(m)
    r = np.empty(m)
    J = np.empty((m, m))
    phi = np.empty(m)
    dfu = np.empty(m)
    dfv = np.empty(m)
    corr = np.zeros(nc)
    n_steps = W.shape[0]
    off = 0
    iters = 0
    k_out = 1
    for i in range(1, n_steps + 1):
        # tyre lift-off: the correction of linear_sim.integrate_unilateral, from the step's start
        corr_any = False
        if unilateral:
            zz = x @ PT
            for j in range(nc):
                d = base[j] + zr[i, j] - zz[j]
                fl = kc[j] * d + cc[j] * (zr_t[i, j] - zz[nc + j])
                corr[j] = 0.0
                if d <= 0.0 or fl < 0.0:
                    corr[j] = -fl
                    corr_any = True
        xp = x @ PhiT + W[i - 1]
        if corr_any:
            off += 1
            xp = xp + corr @ GBT
        # each element's compression and rate without its own force (x1 = xp - f Gs^T)
        for e in range(m):
            su = 0.0
            sv = 0.0
            for j in range(n):
                su += Cq[e, j] * xp[j]
                sv += Cq[e, j] * xp[n + j]
            up[e] = su
            vp[e] = sv
        ok = False
        for _it in range(MAX_ITER):
            for e in range(m):
                su = up[e]
                sv = vp[e]
                for j in range(m):
                    su += Gu[e, j] * f[j]
                    sv += Gv[e, j] * f[j]
                ph, du, dv = _element(kinds[e], prm[e, 0], prm[e, 1], prm[e, 2], su, sv)
                phi[e] = ph
                dfu[e] = du
                dfv[e] = dv
            conv = True
            for e in range(m):
                r[e] = f[e] - phi[e]
                if abs(r[e]) > ATOL + RTOL * abs(phi[e]):
                    conv = False
            if conv:
                ok = True
                break
            for e in range(m):
                for j in range(m):
                    J[e, j] = -(dfu[e] * Gu[e, j] + dfv[e] * Gv[e, j])
                J[e, e] += 1.0
            f = f + np.linalg.solve(J, -r)
            iters += 1
        if not ok:
            return X[:k_out], off, iters, i
        x = xp - f @ GsT
        if i % every == 0 and k_out < n_out:
            X[k_out] = x
            k_out += 1
    return X[:k_out], off, iters, -1


def integrate(Phi, Gam, x0, F, every: int, n_out: int, Cq, kinds, prm, unilateral=None):
    """States at steps 0, every, 2 every, ... (``n_out`` of them) of the linear recurrence
    ``x[k + 1] = Phi x[k] + Gam (F[k + 1] - Cq^T f[k + 1])`` with the element forces ``f``
    solved implicitly at each step's end (``Cq`` (m, n): each element's compression from
    ``q``; its rate from the velocities alike).

    ``unilateral``: None, or ``(Bu, rows, base, kc, cc, zr, zr_t, dt)`` as
    :func:`vehicles.linear_sim.integrate_unilateral` takes them (the lift-off correction
    from the step's start, then the elements' forces).

    Returns (X, tyre-corrected steps, Newton iterations, failed step or -1)."""
    n = Cq.shape[1]
    W = np.ascontiguousarray(F[1:] @ Gam.T)
    Gq, Gv_ = Gam[:n], Gam[n:2 * n]
    Gu = -Cq @ Gq @ Cq.T
    Gv = -Cq @ Gv_ @ Cq.T
    GsT = np.ascontiguousarray((Gam @ Cq.T).T)
    if unilateral is None:
        PT = np.zeros((x0.size, 0))
        GBT = np.zeros((0, x0.size))
        base = kc = cc = np.zeros(0)
        zr = zr_t = np.zeros((F.shape[0], 0))
        uni = False
    else:
        from vehicles.linear_sim import contact_prediction

        Bu, rows, base, kc, cc, zr, zr_t, dt = unilateral
        PT = contact_prediction(rows, dt, x0.size)
        GBT = np.ascontiguousarray((Gam @ Bu).T)
        uni = True
    return _kernel(np.ascontiguousarray(Phi.T), W, np.ascontiguousarray(x0, dtype=float), int(every),
             int(n_out), np.ascontiguousarray(Cq, dtype=float), np.ascontiguousarray(Gu),
             np.ascontiguousarray(Gv), GsT, kinds, prm, PT, GBT,
             np.asarray(base, float), np.asarray(kc, float), np.asarray(cc, float),
             np.ascontiguousarray(zr, dtype=float), np.ascontiguousarray(zr_t, dtype=float), uni)
