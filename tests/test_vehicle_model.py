"""The Exudyn vehicle model: statics against a hand calculation, road input, and the
very stiff flexible frame against the rigid chassis.  (The frame tuning and the
shipped frames' modes: tests/test_vehicle_frame.py, read with vehicles.modal.)"""
import numpy as np
import pytest
from dataclasses import replace

from test_vehicle_support import GD0, flat_road, random_road
from vehicles.builder import GRAVITY, build_model
from vehicles.frame import combine, segment_bounds, segment_masses
from vehicles.params import load_vehicle
from vehicles.simulate import simulate


def _hand_static(vp):
    """Static suspension compressions of a rigid sprung mass on 2*n_axles supports.

    Hand calculation: the sprung mass is a rigid beam (bounce z, pitch theta) on one
    support per axle: the two springs (2 k_s) in series with the axle's tyres
    (2 n k_t), since the unsprung weight goes straight to the tyres.  Equilibrium of
    vertical force and pitch moment gives a 2x2 system:
        sum k_i (z + theta x_i) = W,   sum k_i x_i (z + theta x_i) = W x_cg
    with W the sprung weight (the vehicle is symmetric, so no roll).  The load of
    axle i's springs is k_i (z + theta x_i); the compression of one spring is that
    load / (2 k_s).
    """
    m = sum(it.mass for it in vp.sprung)
    xcg = sum(it.mass * 0.5 * (it.x_front + it.x_rear) for it in vp.sprung) / m
    W = m * GRAVITY
    x = np.array([a.x for a in vp.axles])
    ks = np.array([2 * a.spring_stiffness for a in vp.axles])
    kt = np.array([2 * a.tyres_per_side * a.tyre_stiffness for a in vp.axles])
    k = ks * kt / (ks + kt)
    A = np.array([[k.sum(), (k * x).sum()], [(k * x).sum(), (k * x * x).sum()]])
    z, th = np.linalg.solve(A, [W, W * xcg])
    load = k * (z + th * x)
    return load / ks, load


def test_static_sag_matches_hand_calculation():
    """Spring compressions at static equilibrium (Exudyn static solver) equal the
    2x2 hand calculation within 1 %: the model adds only geometric second-order
    effects (rotations ~5e-3 rad change lever arms by ~1e-5) and the axle guides,
    which carry no vertical load; 1 % covers them with margin."""
    vp = load_vehicle("dump_truck_8x4")
    model = build_model(vp, chassis="rigid")
    comp, load = _hand_static(vp)
    got = np.array([s.static_compression for s in model.suspensions]).reshape(-1, 2)
    np.testing.assert_allclose(got[:, 0], comp, rtol=0.01)
    np.testing.assert_allclose(got[:, 1], comp, rtol=0.01)
    # all weight reaches the road
    assert model.static_tyre_loads().sum() == pytest.approx(vp.total_mass * GRAVITY, rel=1e-6)


def test_starts_at_static_equilibrium_on_flat_road():
    """On a flat road nothing moves: |susp_disp| < 1e-6 m and |acc| < 1e-3 m/s^2 over
    2 s (a start off equilibrium would oscillate by centimetres)."""
    for vid, ch in (("dump_truck_8x4", "rigid"), ("e_tractor", "flexible")):
        res = simulate(vid, flat_road(60.0), 8.0, 2.0, chassis=ch)
        for name, x in res.channels.items():
            if name.startswith("susp_disp") or name.startswith("dcdc"):
                assert np.abs(x).max() < 1e-6, name
            elif "acc" in name:
                assert np.abs(x).max() < 1e-3, name


def test_degrees_of_freedom_and_bodies():
    vp = load_vehicle("dump_truck_8x4")
    assert build_model(vp, chassis="rigid").n_dof == 6 * 5
    m = build_model(vp, chassis="flexible")
    assert m.n_dof == 6 * (4 + 4) and len(m.segments) == 4
    tr = build_model(load_vehicle("e_tractor"), chassis="flexible", frame_segments=6)
    assert tr.n_dof == 6 * (6 + 3 + 1) and tr.dcdc is not None
    idx = tr.coordinate_indices()
    assert set(idx) == {b.name for b in tr.bodies} and all(len(v) == 7 for v in idx.values())


def test_segments_add_up_to_rigid_chassis():
    """Mass, centre of gravity and inertia of the frame segments add up to the rigid
    chassis exactly (round-off), for any number of segments."""
    vp = load_vehicle("dump_truck_8x4")
    rigid = combine([(s.mass, s.cog, s.inertia) for s in
                     segment_masses(vp.sprung, segment_bounds(vp.frame, 1))])
    for n in (2, 4, 7):
        segs = segment_masses(vp.sprung, segment_bounds(vp.frame, n))
        M, c, J = combine([(s.mass, s.cog, s.inertia) for s in segs])
        assert M == pytest.approx(rigid[0], rel=1e-12)
        np.testing.assert_allclose(c, rigid[1], atol=1e-12)
        np.testing.assert_allclose(J, rigid[2], rtol=1e-10, atol=1e-6)


def test_road_injector_equals_road_loads():
    """The injector (one generalised-force object, used in time simulation) applies
    the same generalised forces as the exact road loads (force + roll torque per
    axle): the static response to the same road forces agrees to 1e-6 relative."""
    vp = load_vehicle("dump_truck_8x4")
    rng = np.random.default_rng(1)
    f = rng.normal(0.0, 2e4, 12)                     # road forces per tyre [N]
    a = build_model(vp)
    Bf, Bt = a.road_force_matrices()
    a.set_road_forces(Bf @ f, Bt @ f)
    a.solve_static()
    b = build_model(vp)
    b.set_injector(b.road_input_matrix() @ f)
    b.solve_static()
    for s_a, s_b in zip(a.suspensions, b.suspensions):
        za = a.point_position(a.axles[s_a.axle].name, s_a.local_axle)[2]
        zb = b.point_position(b.axles[s_b.axle].name, s_b.local_axle)[2]
        za0 = a.static[a.axles[s_a.axle].name][0][2]
        assert zb - za0 == pytest.approx(za - za0, rel=1e-6, abs=1e-9)


def test_very_stiff_flexible_frame_reproduces_rigid_modes():
    """With the frame 1e4 times stiffer, the flexible model's modes below 25 Hz equal
    the rigid model's within 1 % (the frame modes move to ~100x their frequency)."""
    import scipy.linalg

    vp = load_vehicle("dump_truck_8x4")
    out = []
    for ch, f in (("rigid", 1.0), ("flexible", 1e4)):
        m = build_model(vp, chassis=ch, stiffness_factor=f, node_type="Rxyz")
        M, K = m.linearized_mass_stiffness()
        w2 = scipy.linalg.eigh(K, M, eigvals_only=True)
        fr = np.sqrt(np.maximum(w2, 0)) / (2 * np.pi)
        out.append(fr[fr < 25.0])
    assert out[0].size == out[1].size
    np.testing.assert_allclose(out[1], out[0], rtol=0.01)


def test_very_stiff_flexible_frame_reproduces_rigid_response():
    """Time response on a class-C road, 8 s: every channel's RMS of the flexible
    model with 1e3x frame stiffness (frame modes near 200-250 Hz, above the 100 Hz
    output band) is within 1 % of the rigid model's (measured 0.44 %; the rest is
    the residual compliance of the joints and the integration of different models)."""
    road = random_road(length=110.0, gd0=GD0["C"], seed=5)
    r = simulate("dump_truck_8x4", road, 10.0, 8.0, chassis="rigid")
    f = simulate("dump_truck_8x4", road, 10.0, 8.0, effects={"frame_flex": 1e3})
    assert f.meta["chassis"] == "flexible"
    for name in r.channels:
        a, b = np.std(r.channels[name]), np.std(f.channels[name])
        if name != "speed":
            assert b == pytest.approx(a, rel=0.01), name
