"""Unilateral tyres: a tyre that leaves the road carries no force.

What it is for: the Exudyn model's tyres (:mod:`vehicles.builder`) are linear
spring-dampers from the axle to the ground, fed with the road as a known force
``k z_r + c dz_r/dt``.  Such a tyre also pulls the axle down when the wheel rises
above the road.  :func:`unilateral_prestep` returns the ``PreStep`` function that
cancels that pull: per tyre, the force the linear tyre would carry is

    F_lin = k d + c dd/dt,   d = d_static + z_r - z_c   (deflection, > 0 pressed)

and the tyre's true force is ``F = max(F_lin, 0)`` while it touches the road
(``d > 0``) and ``0`` when it does not.  The difference ``F - F_lin`` is added to the
road force of that tyre, so the spring-damper in the implicit system stays linear
(the Jacobian is factorised once, as before) and the one-sidedness is an external
force.

Accuracy: the correction is set once per step from the state at the start of the
step, extrapolated to the step's end with the velocity and acceleration
(``z_c + dt v + dt^2 a / 2``).  While a tyre is off the road the implicit spring and
the explicit correction then differ by ``k dt^3 (da/dt) / 6``, and switching on or off
happens at the step in which the extrapolated force crosses zero (the force is
continuous there, so a step late costs ``dF/dt dt`` at most).  The contact
displacement is the first-order map of the axle nodes' coordinates
(``road_input_matrix`` transposed) about the static state at the start of the drive;
the axles rotate by ~1e-3 rad.  ``tests/test_tyre_contact.py`` checks the result
against the independently written truck (:mod:`drives.independent_truck`, RK4,
its own lift-off) and against the same drive at a quarter of the step.

What it is not: a tyre model beyond the point contact (no footprint lift-off of part
of the tyre, no enveloping: that is the ``tyre_enveloping`` effect's road filter).
"""
from __future__ import annotations

import numpy as np

#: the tyre models :func:`vehicles.simulate.simulate` knows
TYRE_CONTACTS = ("unilateral", "bilateral")


def tyre_forces(deflection, rate, k, c) -> np.ndarray:
    """Unilateral tyre force [N] (pressing positive) from deflection [m] and its rate [m/s].

    ``max(k d + c dd/dt, 0)`` where ``d > 0``, else 0; arrays broadcast.
    """
    d = np.asarray(deflection, float)
    f = k * d + c * np.asarray(rate, float)
    return np.where(d > 0.0, np.maximum(f, 0.0), 0.0)


def unilateral_prestep(model, Q, B, zr, zr_t, k, c, dt):
    """PreStep function that sets the road forces of unilateral tyres.

    Parameters
    ----------
    model : vehicles.builder.VehicleModel
        At its static state on the road at the start of the drive (the state the
        time integration starts from); its flat-road static reference recorded.
    Q : ndarray (n_steps + 3, n_inj)
        Generalised road forces of the linear tyres per step (``f_c @ B.T``).
    B : ndarray (n_inj, n_contacts)
        ``model.road_input_matrix()`` at that state.
    zr, zr_t : ndarray (n_steps + 1, n_contacts)
        Road height [m] and its rate [m/s] under each tyre on the step grid.
    k, c : ndarray (n_contacts,)
        Tyre stiffness [N/m] and damping [N s/m].
    dt : float
        Time step [s].

    Returns
    -------
    (prestep, counter)
        ``prestep(mbs, t)`` for ``SetPreStepUserFunction``; ``counter`` is a dict whose
        ``"steps_off"`` counts the steps in which at least one tyre was corrected.
    """
    mbs = model.mbs
    sd = mbs.systemData
    idx = model.coordinate_indices()
    n = sd.ODE2Size()
    rows = np.concatenate([idx[b.name] for b in model.axles])
    # the contact height and rate at the step's end from q, v, a over all coordinates:
    # [z; dz/dt] = P @ [q, v, a] + p0, with z = zc0 + B^T (q - q0) + dt v + dt^2 a / 2
    Bt = np.zeros((B.shape[1], n))
    Bt[:, rows] = B.T
    nc = B.shape[1]
    P = np.zeros((2 * nc, 3 * n))
    P[:nc, :n], P[:nc, n:2 * n], P[:nc, 2 * n:] = Bt, dt * Bt, 0.5 * dt * dt * Bt
    P[nc:, n:2 * n], P[nc:, 2 * n:] = Bt, dt * Bt
    q0 = np.asarray(sd.GetODE2Coordinates(), float).copy()
    # contact height above the flat-road static state at the start (exact kinematics)
    zc0 = np.array([model.point_position(model.axles[ct.axle].name, ct.local)[2]
                    - _static_z(model, ct) for ct in model.contacts])
    # deflection d = d_static + zr - z = base + zr - (P q)[:nc]
    base = model.static_tyre_loads() / k - zc0 + Bt @ q0
    n_last = zr.shape[0] - 1
    inv_dt = 1.0 / dt
    set_obj = mbs.SetObjectParameter
    inj = model.injector
    get_q, get_v, get_a = sd.GetODE2Coordinates, sd.GetODE2Coordinates_t, sd.GetODE2Coordinates_tt
    concat = np.concatenate
    counter = {"steps_off": 0}

    def prestep(mbs_, t):   # t is the end of the step
        i = int(t * inv_dt + 0.5)
        j = i if i <= n_last else n_last
        zz = P @ concat((get_q(), get_v(), get_a()))
        d = base + zr[j] - zz[:nc]
        f_lin = k * d + c * (zr_t[j] - zz[nc:])
        if d.min() > 0.0 and f_lin.min() >= 0.0:
            set_obj(inj, "forceVector", Q[i])
            return True
        counter["steps_off"] += 1
        corr = np.where(d > 0.0, np.maximum(f_lin, 0.0), 0.0) - f_lin
        set_obj(inj, "forceVector", Q[i] + B @ corr)
        return True

    return prestep, counter


def _static_z(model, ct) -> float:
    ab = model.axles[ct.axle]
    p, R = model.static[ab.name]
    return float((p + R @ np.asarray(ct.local, float))[2])
