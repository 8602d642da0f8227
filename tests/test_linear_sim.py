"""The linear integrator (vehicles.linear_sim) against closed-form properties of its scheme and
against Exudyn's own run of the same drive.

Tolerances, and why they are that size:
* the scheme: the spectral radius of one step tends to rho_inf as the step grows (the defining
  property of generalized-alpha, Chung and Hulbert 1993); at omega h = 1e4 it is within 2e-3
  of it (measured 0.6017 / 0.9015 / 1.0000 for 0.6 / 0.9 / 1), checked to 1e-2 (a wrong
  alpha_m or alpha_f moves it by 0.1 and more); the
  period of a slow oscillator (omega h = 0.05) is right to 1e-3 (the scheme's period error is
  of order (omega h)^2 / 12 = 2e-4); stepping two at a time gives the same states to 1e-9.
* against Exudyn, on a road so small (ISO level / 1e4) that the geometric nonlinearity Exudyn
  keeps is negligible, the two differ by 1.3e-4 of each channel's RMS (measured 2026-11-29):
  asserted < 1e-3, so a wrong step, spectral radius, initial state or output row fails it.
* on a class C road (256e-6 m^3) the difference is the geometric nonlinearity (rotations of
  5-15 mrad; it grows in proportion to the amplitude: 1.3e-4, 1.3e-3, 1.3e-2 of the RMS at
  levels 1e-4, 1e-2, 1 x class C): on this test's 8 s drive 1.35e-2 of the RMS and 0.025 in log
  band power at worst over the third-octave bands 0.5-50 Hz (measured 2026-11-29); asserted
  < 3e-2 and < 0.04 (Exudyn's own change when its step is halved reaches 0.18 in some band).
"""
from __future__ import annotations

import numpy as np
import pytest

from roadlib.segments import RoadSegment, segmented_surface
from vehicles import linear_sim
from vehicles.simulate import SpeedProfile, simulate

VEH = "dump_truck_8x4"


def _road(gq, seed=3):
    return segmented_surface([RoadSegment(Gq_n0=gq, share=120.0, nmin=0.011, nmax=5)], 120.0, 3.0,
                             0.05, 0.1, seed=seed)


def _both(gq, effects=None, duration=8.0):
    road = _road(gq)
    prof = SpeedProfile(np.array([0.0, duration]), np.array([8.0, 12.0]))
    a = simulate(VEH, road, prof, duration, effects=effects)
    b = simulate(VEH, road, prof, duration, effects=effects, solver="linear")
    return a, b


def _rel(a, b, name):
    x, y = a.channels[name], b.channels[name]
    return float(np.sqrt(np.mean((x - y) ** 2)) / np.std(x))


def test_step_spectral_radius_tends_to_rho_inf():
    for rho in (0.6, 0.9, 1.0):
        for k, h in ((1.0, 1e4), (1e8, 1.0)):
            Phi, _ = linear_sim.alpha_recurrence(np.eye(1), np.zeros((1, 1)), np.array([[k]]), h, rho)
            assert abs(np.abs(np.linalg.eigvals(Phi)).max() - rho) < 1e-2


def test_slow_oscillator_keeps_its_period():
    w, h = 2 * np.pi, 0.05 / (2 * np.pi)           # omega h = 0.05
    Phi, Gam = linear_sim.alpha_recurrence(np.eye(1), np.zeros((1, 1)), np.array([[w * w]]), h, 0.9)
    lam = np.linalg.eigvals(Phi)
    osc = lam[np.argmax(np.abs(lam.imag))]
    assert abs(abs(np.angle(osc)) / h / w - 1.0) < 1e-3


def test_stepping_several_at_a_time_is_the_same():
    rng = np.random.default_rng(1)
    n = 4
    A = rng.standard_normal((n, n))
    M, K, D = np.eye(n) + 0.1 * A @ A.T, np.diag([1e4, 3e4, 5e4, 8e4]), np.diag([50.0] * n)
    Phi, Gam = linear_sim.alpha_recurrence(M, D, K, 2.5e-3, 0.9)
    F = rng.standard_normal((401, n))
    x0 = np.zeros(4 * n)
    one = linear_sim.integrate(Phi, Gam, x0, F)
    two = linear_sim.integrate(Phi, Gam, x0, F, every=2)
    assert two.shape[0] == 201
    assert np.abs(two - one[::2]).max() <= 1e-9 * np.abs(one).max()


def test_agrees_with_exudyn_where_the_model_is_linear():
    a, b = _both(256e-6 * 1e-4)
    assert b.meta["solver"] == "linear" and a.meta["solver"] == "exudyn"
    worst = max(_rel(a, b, c) for c in a.channels if c != "speed")
    assert worst < 1e-3, worst


def test_class_c_road_differs_by_the_geometric_nonlinearity_only():
    a, b = _both(256e-6)
    assert b.meta["solver"] == "linear"
    worst = max(_rel(a, b, c) for c in a.channels if c != "speed")
    assert worst < 3e-2, worst
    from scipy.signal import welch
    edges = 0.5 * 2 ** (np.arange(21) / 3)
    for c in a.channels:
        if c == "speed":
            continue
        f, pa = welch(a.channels[c], fs=200.0, nperseg=512)
        _, pb = welch(b.channels[c], fs=200.0, nperseg=512)
        for lo, hi in zip(edges[:-1], edges[1:]):
            m = (f >= lo) & (f < hi)
            if m.any():     # the lowest bands hold no Welch bin at this resolution (0.39 Hz)
                assert abs(np.log(pb[m].sum() / pa[m].sum())) < 0.04, (c, lo)


@pytest.mark.parametrize("effects", [{"payload": {"mass": 5000.0}}, {"sensor": {"cutoff": 15.0}},
                                     {"tyre_enveloping": {"length": 0.3}}])
def test_linear_effects_take_the_linear_path_and_agree(effects):
    a, b = _both(256e-6 * 1e-2, effects=effects)
    assert b.meta["solver"] == "linear"
    for c in a.channels:
        if c == "speed":
            continue
        # a payload's static sag is part of the suspension displacement (nominal zero)
        assert abs(np.mean(b.channels[c]) - np.mean(a.channels[c])) <= 0.02 * abs(np.mean(a.channels[c])) + 1e-5
        assert _rel(a, b, c) < 5e-3


def test_nonlinear_effect_goes_to_exudyn():
    road = _road(256e-6 * 1e-2)
    b = simulate(VEH, road, 10.0, 4.0, effects={"leaf_friction": {"force": 1000.0}}, solver="linear")
    assert b.meta["solver"] == "exudyn"


def test_lift_off_corrected_as_exudyn_corrects_it():
    """A class D-E road at 15 m/s: tyres off the road in 57 % of the output samples.  The
    unilateral correction (the same explicit rule as Exudyn's prestep) gives the same share of
    samples off the road and of corrected steps: measured 0.576 against 0.573 and 2316 against
    2305 steps; asserted within 0.02 and 3 % (lift-off switches on small differences of state,
    so the two runs drift apart where a tyre is about to touch down)."""
    road = segmented_surface([RoadSegment(Gq_n0=4096e-6, share=300.0, nmin=0.011, nmax=5)], 300.0,
                             3.0, 0.05, 0.1, seed=5)
    a = simulate(VEH, road, 15.0, 10.0, lift_off_expected=True)
    b = simulate(VEH, road, 15.0, 10.0, lift_off_expected=True, solver="linear")
    assert b.meta["solver"] == "linear" and b.meta["tyre_contact_run"] == "unilateral"
    assert a.meta["tyre_lift_off_fraction"] > 0.3
    assert abs(b.meta["tyre_lift_off_fraction"] - a.meta["tyre_lift_off_fraction"]) < 0.02
    assert abs(b.meta["tyre_off_steps"] / a.meta["tyre_off_steps"] - 1.0) < 0.03
    # and a linear first run that finds a pulling tyre is repeated unilateral, as with Exudyn
    c = simulate(VEH, road, 15.0, 10.0, solver="linear")
    assert c.meta["tyre_contact_run"] == "unilateral" and c.meta["solver"] == "linear"


def test_unknown_solver_refused():
    from eroad.errors import EroadInputError
    with pytest.raises(EroadInputError, match="solver must be one of"):
        simulate(VEH, _road(1e-8), 10.0, 1.0, solver="fast")
