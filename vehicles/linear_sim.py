"""Time response of the linearised vehicle, integrated with the simulator's own scheme.

What it is for: drives whose model is linear (no nonlinear effect, every tyre on the road)
are the bulk of what the gap diagnosis simulates -- the nominal truck on dozens of road
realisations per window, and the candidates that only change the road under the tyres, the
speed or the sensors.  For those, :func:`vehicles.simulate.simulate` with
``solver="linear"`` integrates ``M q'' + D q' + K q = Bk z_r + Bc z_r'``
(:mod:`vehicles.linear`, Exudyn's linearisation at static equilibrium) with the same
generalized-alpha scheme, step and spectral radius Exudyn uses, on the same road forces
step by step, and reads the same output points.  The recurrence is a fixed matrix per
model, so a drive costs a matrix product per step instead of an Exudyn solve.

What it is not: an approximation in frequency (no FFT, no periodic wrap, the run-in and the
speed profile are those of the time simulation) nor a replacement where the model is not
linear beyond local suspension forces: forced Newton iterations and effects whose forces have no
element kind go to Exudyn (:func:`applies`). A vehicle with a DCDC body (the electric tractor) is
covered: its four top-face points are output rows of the linear model and the top's rigid-body
motion (``SimResult.extra["dcdc_ref"]``) is read from its rows as Exudyn's run reads it
(:func:`dcdc_reference`).  Tyre lift-off is
not a reason: the unilateral run corrects the tyre forces step by step exactly as Exudyn's
does (:func:`integrate_unilateral`).  Nor are the library's nonlinear effects (leaf friction,
asymmetric dampers, bump stops): each is a force on one axle side that depends on that side's
compression and rate only, solved implicitly at every step's end
(:mod:`vehicles.suspension_forces`, :func:`suspension_elements`).

Agreement with Exudyn (``tests/test_linear_sim.py``): the difference is the geometric
nonlinearity Exudyn keeps (rotations of a few milliradians) and the two rotation
parameterisations (Euler parameters there, Tait-Bryan angles here); measured on the dump
truck over class C and class D roads, see the test for the numbers and tolerances.

Scheme (Arnold and Bruls 2007, the generalized-alpha form Exudyn documents):
``alpha_m = (2 rho - 1) / (rho + 1)``, ``alpha_f = rho / (rho + 1)``,
``gamma = 1/2 + alpha_f - alpha_m``, ``beta = (gamma + 1/2)^2 / 4``; with ``a`` the
acceleration and ``ab`` the algorithmic acceleration::

    (1 - alpha_m) ab1 = (1 - alpha_f) a1 + alpha_f a0 - alpha_m ab0
    q1 = q0 + h v0 + h^2 (1/2 - beta) ab0 + h^2 beta ab1
    v1 = v0 + h (1 - gamma) ab0 + h gamma ab1
    M a1 + D v1 + K q1 = F1
"""
from __future__ import annotations

import pickle
import time as _time
from collections import OrderedDict

import numpy as np

from vehicles.effects import EFFECTS
from vehicles.effects.base import Effect
from vehicles.linear import DCDC_MOTIONS

#: linear models kept per process (key: the configured vehicle and chassis)
CACHE_SIZE = 16
_models: OrderedDict = OrderedDict()


def alpha_parameters(rho: float) -> tuple:
    """(alpha_m, alpha_f, gamma, beta) of the generalized-alpha scheme for spectral radius
    ``rho`` at infinite step."""
    rho = float(rho)
    am = (2.0 * rho - 1.0) / (rho + 1.0)
    af = rho / (rho + 1.0)
    gamma = 0.5 + af - am
    beta = 0.25 * (gamma + 0.5) ** 2
    return am, af, gamma, beta


def alpha_recurrence(M, D, K, h: float, rho: float) -> tuple:
    """One step of the scheme as a linear map of the state ``x = [q, v, a, ab]``.

    Returns
    -------
    (Phi, Gam) : ndarrays (4n, 4n), (4n, n)
        ``x1 = Phi x0 + Gam F1``.
    """
    n = M.shape[0]
    am, af, gamma, beta = alpha_parameters(rho)
    c = (1.0 - af) / (1.0 - am)                  # ab1 = c a1 + r, r = (af a0 - am ab0) / (1 - am)
    S = M + h * gamma * c * D + h * h * beta * c * K
    Si = np.linalg.inv(S)
    Z, I = np.zeros((n, n)), np.eye(n)
    # r, q~ and v~ (the parts of ab1, q1, v1 known before a1) as maps of x0
    R = np.hstack([Z, Z, af / (1 - am) * I, -am / (1 - am) * I])
    Qt = np.hstack([I, h * I, Z, h * h * (0.5 - beta) * I]) + h * h * beta * R
    Vt = np.hstack([Z, I, Z, h * (1 - gamma) * I]) + h * gamma * R
    A1 = -Si @ (D @ Vt + K @ Qt)                 # a1 = A1 x0 + Si F1
    Phi = np.vstack([Qt + h * h * beta * c * A1, Vt + h * gamma * c * A1, A1, c * A1 + R])
    Gam = np.vstack([h * h * beta * c * Si, h * gamma * c * Si, Si, c * Si])
    return Phi, Gam


def integrate(Phi, Gam, x0, F, every: int = 1) -> np.ndarray:
    """States ``x[0], x[every], x[2 every], ...`` of ``x[k + 1] = Phi x[k] + Gam F[k + 1]``
    (``F``: (n_steps + 1, n) forces on the step grid).

    The steps in between are not kept, so the recurrence is stepped ``every`` steps at a time
    (``Phi^every`` and the forces of the skipped steps folded in): the same numbers to
    rounding, ``every`` times fewer Python iterations (the output period is ``every`` steps)."""
    W = F[1:] @ Gam.T                                    # (n_steps, 4n)
    L = max(1, int(every))
    nb = W.shape[0] // L
    P = [np.eye(Phi.shape[0])]
    for _ in range(L - 1):
        P.append(Phi @ P[-1])                            # Phi^0 .. Phi^(L-1)
    # block b input: sum_j Phi^(L-1-j) W[b L + j]
    Wb = sum(W[j:nb * L:L] @ P[L - 1 - j].T for j in range(L))
    PhiT = np.ascontiguousarray((Phi @ P[-1]).T)         # (Phi^L)^T
    X = np.empty((nb + 1, x0.size))
    x = X[0] = x0
    for k in range(nb):
        x = x @ PhiT + Wb[k]
        X[k + 1] = x
    return X


#: step the unilateral tyres in the compiled loop of :mod:`vehicles.suspension_forces` (no
#: element), not in :func:`integrate_unilateral`'s Python loop: the same states to rounding
#: (``test_compiled_lift_off_loop_is_the_numpy_statement``: 3e-14 of the sd).  Measured
#: 2026-11-30 (results/pantograph_chassis/20261130-compiled-lift-off/): the chassis study's
#: 63 drives 1.60x faster (their simulations 19.7 s against 31.5 s, the study 33.1 against
#: 44.2 s, serial), every number of the study the same; one 30 s truck drive with lift-off
#: 0.078 s against 0.147 s; the luliang diagnosis 26.0 against 28.7 s (little lift-off there)
COMPILED_UNILATERAL = True


def integrate_unilateral(Phi, Gam, x0, F, Bu, rows, base, kc, cc, zr, zr_t, dt: float):
    """:func:`integrate` with unilateral tyres, every step: the tyre forces of the linear
    model corrected where a tyre would pull or is off the road, as
    :func:`vehicles.tyre_contact.unilateral_prestep` corrects Exudyn's (the contact's height
    and rate at the step's end predicted from the state at its start, ``q + h v + h^2 a / 2``
    and ``v + h a``; the force ``max(k d + c d', 0)`` where the deflection ``d > 0``, else 0).

    ``Bu`` (n, n_contacts): generalised force per newton under each tyre; ``rows``
    (n_contacts, n): contact heights from ``q``; ``base``: static deflections [m].
    Returns the states at every step and the number of steps with a correction."""
    nc = rows.shape[0]
    W = F[1:] @ Gam.T
    GB = Gam @ Bu
    PT = contact_prediction(rows, dt, x0.size)
    X = np.empty((F.shape[0], x0.size))
    x = X[0] = x0
    PhiT = np.ascontiguousarray(Phi.T)
    off = 0
    for i in range(1, F.shape[0]):
        zz = x @ PT
        d = base + zr[i] - zz[:nc]
        f_lin = kc * d + cc * (zr_t[i] - zz[nc:])
        x = x @ PhiT + W[i - 1]
        if d.min() <= 0.0 or f_lin.min() < 0.0:
            off += 1
            x = x + GB @ (np.where(d > 0.0, np.maximum(f_lin, 0.0), 0.0) - f_lin)
        X[i] = x
    return X, off


def contact_prediction(rows, dt: float, size: int) -> np.ndarray:
    """(size, 2 nc): the contacts' [height, rate] at a step's end as predicted from the state
    ``x = [q, v, a, ab]`` at its start (``q + h v + h^2 a / 2`` and ``v + h a``, the rule of
    Exudyn's unilateral prestep), transposed for ``x @ PT``."""
    nc, n = rows.shape
    P = np.zeros((2 * nc, size))
    P[:nc, :n], P[:nc, n:2 * n], P[:nc, 2 * n:3 * n] = rows, dt * rows, 0.5 * dt * dt * rows
    P[nc:, n:2 * n], P[nc:, 2 * n:3 * n] = rows, dt * rows
    return np.ascontiguousarray(P.T)


def applies(eff: dict, vp, chassis: str, stiffness_factor: float, newton) -> bool:
    """Whether :func:`run` gives what Exudyn gives for this drive: a linear model, with tyre
    lift-off (corrected as Exudyn's run does) and local nonlinear suspension forces (effects
    with :meth:`~vehicles.effects.base.Effect.suspension_elements`, solved per step) allowed."""
    from vehicles.simulate import STIFF_FRAME_NEWTON

    if newton:
        return False
    if chassis == "flexible" and stiffness_factor > STIFF_FRAME_NEWTON:
        return False
    local = False
    for name in eff:
        e = EFFECTS[name]
        elements = type(e).suspension_elements is not Effect.suspension_elements
        if (e.nonlinear or type(e).suspension_terms is not Effect.suspension_terms) and not elements:
            return False
        local = local or elements
    if local:
        # the local nonlinear forces are stepped by a compiled loop; without numba they run
        # in Exudyn (the same forces, its own Newton iterations)
        try:
            import numba  # noqa: F401
        except ImportError:  # pragma: no cover - numba is a dependency
            return False
    return True


def suspension_elements(entry, eff: dict, ctx) -> tuple:
    """The local nonlinear suspension forces of the effects in ``eff`` on the model of
    ``entry`` (:func:`model_for`): ``(elements, Cq)``, the element list of
    :mod:`vehicles.suspension_forces` and each element's compression row (m, n)."""
    model = entry["lm"].model
    elements, rows = [], []
    for k, su in enumerate(model.suspensions):
        for name, p in eff.items():
            e = EFFECTS[name]
            if type(e).suspension_elements is Effect.suspension_elements:
                continue
            for el in e.suspension_elements(su, p, ctx) or []:
                elements.append(el)
                rows.append(entry["susp_rows"][k])
    n = entry["lm"].n_dof
    return elements, (np.array(rows) if rows else np.zeros((0, n)))


def model_for(vp, chassis: str, frame_segments, stiffness_factor: float):
    """The linear model (and its recurrence inputs) of a configured vehicle, cached."""
    from vehicles.linear import _Kinematics, linear_model

    key = (pickle.dumps(vp), chassis, frame_segments, float(stiffness_factor))
    hit = _models.get(key)
    if hit is not None:
        _models.move_to_end(key)
        return hit
    lm = linear_model(vp, chassis=chassis, frame_segments=frame_segments,
                      stiffness_factor=stiffness_factor)
    kin = _Kinematics(lm.model)
    m = lm.model
    # tyre contact points (vertical), for the deflection and lift-off check
    rows = np.array([kin.point(m.axles[ct.axle].name, ct.local)[2] for ct in m.contacts])
    # each axle side's compression u = z(axle seat) - z(frame seat) (vehicles.builder.Suspension)
    susp = np.array([kin.point(m.axles[su.axle].name, su.local_axle)[2]
                     - kin.point(m.segments[su.segment].name, su.local_frame)[2]
                     for su in m.suspensions]) if m.suspensions else np.zeros((0, lm.n_dof))
    entry = {"key": key, "lm": lm, "contact_rows": rows, "susp_rows": susp,
             "f_static": m.static_tyre_loads(), "recurrence": {}, "offsets": {}}
    _models[key] = entry
    while len(_models) > CACHE_SIZE:
        _models.popitem(last=False)
    return entry


def _static_offsets(own, ref, names) -> dict:
    """Per channel: the configured vehicle's static value against the reference vehicle's
    (what a payload's sag adds to a suspension displacement read from the nominal zero, or to
    a DCDC point's position read from the reference vehicle's static point, as
    :func:`vehicles.simulate.simulate` reads both)."""
    from vehicles.simulate import _static_point, output_points

    own, ref = own["lm"].model, ref["lm"].model
    pts = {ch: (body, wp) for ch, kind, body, wp in output_points(own) if kind in ("z_pos", "yz_pos")}
    off = {}
    for name in names:
        if name.startswith(("dcdc_y_", "dcdc_z_")):
            body, wp = pts[name[len("dcdc_y_"):]]
            axis = 1 if name.startswith("dcdc_y_") else 2
            off[name] = float(_static_point(own, body, wp)[axis] - _static_point(ref, body, wp)[axis])
            continue
        if not name.startswith("susp_disp_"):
            continue
        tag = name[len("susp_disp_"):]
        d = 0.0
        for sign, ch in ((1.0, f"seat_axle_{tag}"), (-1.0, f"seat_body_{tag}")):
            body, wp = pts[ch]
            d += sign * (_static_point(own, body, wp)[2] - _static_point(ref, body, wp)[2])
        off[name] = d
    return off


def dcdc_reference(own, ref, rows: dict, q, v, a) -> dict:
    """The DCDC top's rigid-body motion (``SimResult.extra`` ``dcdc_ref`` ...) from the linear
    model's output rows ``rows`` (``vehicles.linear.DCDC_MOTIONS``: the top-face centre's
    displacement and the block's small global rotation, each from the configured vehicle's
    static state) and the states ``q``, ``v``, ``a``; read, as Exudyn's run reads them, from the
    REFERENCE vehicle's static point and orientation (the two statics differ where an effect
    changes the vehicle)."""
    from vehicles.simulate import _small_rotation, _static_point, dcdc_extra, dcdc_top

    mo, mr = own["lm"].model, ref["lm"].model
    d = mo.vp.dcdc
    T = np.vstack([rows[f"dcdc_T{c}"] for c in "xyz"])
    R = np.vstack([rows[f"dcdc_R{c}"] for c in "xyz"])
    top = dcdc_top(d)
    p_off = _static_point(mo, "dcdc", top) - _static_point(mr, "dcdc", top)
    r_off = _small_rotation(mo.static["dcdc"][1][None], mr.static["dcdc"][1])[0]
    return dcdc_extra(d, q @ T.T + p_off, q @ R.T + r_off, a @ T.T, a @ R.T, v @ R.T)


def run(pl, road, y_offset: float, wall0: float, cpu0: float, unilateral: bool = False):
    """The drive of plan ``pl`` (:func:`vehicles.simulate._plan_drive`) on the linear model;
    the result as :func:`vehicles.simulate.simulate` makes it (``meta["solver"]`` "linear").
    ``unilateral``: tyres that lift off carry no force (:func:`integrate_unilateral`)."""
    import exudyn as exu
    from eroad.errors import SimulationError
    from vehicles.simulate import _finish_result, check_road_width, road_under_tyres

    ctx = pl.ctx
    own = model_for(ctx.vp, ctx.chassis, ctx.frame_segments, ctx.stiffness_factor)
    ref = own if ctx.reference_vp is ctx.vp else model_for(ctx.reference_vp, ctx.chassis,
                                                           ctx.frame_segments, ctx.stiffness_factor)
    lm = own["lm"]
    model = lm.model
    check_road_width(road, model, y_offset)
    zr, zr_t = road_under_tyres(pl.road_used, model, pl.x_start, y_offset, pl.s_steps,
                                pl.profile.speed(pl.t_steps))
    rho = pl.vp.solver.spectral_radius
    rkey = (round(pl.dt, 15), float(rho))
    rec = own["recurrence"].get(rkey)
    if rec is None:
        rec = own["recurrence"][rkey] = alpha_recurrence(lm.M, lm.D, lm.K, pl.dt, rho)
    Phi, Gam = rec
    n = lm.n_dof
    solve0, solve_cpu0 = _time.perf_counter(), _time.process_time()
    F = zr @ lm.Bk.T + zr_t @ lm.Bc.T                      # (n_steps + 1, n)
    # start: static on the road under the tyres at t = 0 (heights only, as Exudyn's static
    # solve), at rest; the initial acceleration Exudyn computes there is zero (its road force
    # before the first step is the one the static solve balanced: measured, a0 from the full
    # force F[0] left 2e-3 of the output's RMS against 1e-4 with a0 = 0 on a small road)
    q0 = np.linalg.solve(lm.K, zr[0] @ lm.Bk.T)
    a0 = np.zeros(n)
    x0 = np.concatenate([q0, np.zeros(n), a0, a0])
    kc = np.array([c.stiffness for c in model.contacts])
    cc = np.array([c.damping for c in model.contacts])
    off = 0
    elements, Cq = suspension_elements(own, pl.eff, ctx)
    uni = None
    if unilateral:
        Bu = lm.Bk / kc[None, :]
        # the contact heights as Exudyn's correction reads them: the transpose of the road
        # input map (tyre_contact.unilateral_prestep)
        uni = (Bu, np.ascontiguousarray(Bu.T), own["f_static"] / kc, kc, cc, zr, zr_t, pl.dt)
    if elements or (uni is not None and COMPILED_UNILATERAL):
        # the compiled loop: the local suspension forces, and the lift-off correction before
        # them (with no element, that correction alone: integrate_unilateral's rule)
        from vehicles import suspension_forces as sf
        from vehicles.simulate import _failure_message

        kinds, prm = sf.element_arrays(elements)
        X, off, _iters, failed = sf.integrate(Phi, Gam, x0, F, pl.n_sub, pl.n_out, Cq,
                                              kinds, prm, unilateral=uni)
        if failed >= 0 or X.shape[0] < pl.n_out:
            t_fail = (failed if failed >= 0 else X.shape[0] * pl.n_sub) * pl.dt
            exc = SimulationError(_failure_message(
                t_fail, pl.duration, pl.eff, pl.dt,
                f"the local Newton iterations of the suspension forces did not converge "
                f"within {sf.MAX_ITER}"))
            exc.newton, exc.dt, exc.smaller_dt_may_help = True, pl.dt, True
            raise exc
    elif uni is not None:
        X, off = integrate_unilateral(Phi, Gam, x0, F, *uni)
        X = X[np.arange(pl.n_out) * pl.n_sub]
    else:
        X = integrate(Phi, Gam, x0, F, every=pl.n_sub)
        if X.shape[0] < pl.n_out:        # a duration that is not a whole number of output periods
            X = integrate(Phi, Gam, x0, F)[np.arange(pl.n_out) * pl.n_sub]
        X = X[:pl.n_out]
    solve_s, solve_cpu = _time.perf_counter() - solve0, _time.process_time() - solve_cpu0
    out_cpu0 = _time.process_time()
    q, a = X[:, :n], X[:, 2 * n:3 * n]
    offsets = own["offsets"].get(ref["key"])
    if offsets is None:
        offsets = own["offsets"][ref["key"]] = _static_offsets(own, ref, lm.channel_names)
    channels = {}
    ref6 = {}
    for o in lm.outputs:
        if o.name in DCDC_MOTIONS:      # the DCDC top's rigid-body motion: an extra, as in Exudyn's run
            ref6[o.name] = o.row
            continue
        channels[o.name] = (q if o.order == 0 else a) @ o.row + offsets.get(o.name, 0.0)
    extra = {} if not ref6 else dcdc_reference(own, ref, ref6, q, X[:, n:2 * n], a)
    time = np.arange(pl.n_out) * pl.t_out
    channels["speed"] = pl.profile.speed(time)
    zc = q @ own["contact_rows"].T
    run_info = {"chassis": lm.chassis, "frame_segments": lm.meta["frame_segments"],
                "frame_stiffness_factor": lm.meta["stiffness_factor"], "steps": pl.n_steps,
                "solve_s": solve_s, "solve_cpu_s": solve_cpu, "n_dof": n,
                "n_bodies": len(model.bodies), "newton": bool(elements), "tyre_off_steps": off,
                "tyre_contact_run": "unilateral" if unilateral else "linear",
                "exudyn_version": exu.__version__,
                "solver": "linear"}
    return _finish_result(pl, channels, extra, zc, zr, zr_t, kc, cc, own["f_static"], unilateral, run_info,
                          road, y_offset, wall0, cpu0, out_cpu0)
