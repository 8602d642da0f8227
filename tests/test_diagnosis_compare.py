"""Road-independent comparisons and time-history metrics (diagnosis.compare)."""
import numpy as np
import pytest

from diagnosis import toy
from diagnosis.compare import (distribution_shape, front_rear, gcc_delay, russell, sprague_geers,
                               transmissibility)


def _drive(state, seed, duration=60.0):
    return toy.simulate_drive(state, duration, 10.0, seed)


def test_sprague_geers_closed_form_keeps_the_square_root():
    """Sprague and Geers (2004): computed = a * measured gives M = a - 1 exactly and P = 0
    (the version without the square root would give a^2 - 1 = 0.44 for a = 1.2); a pure phase
    shift phi over whole periods gives M = 0, P = phi / pi."""
    t = np.linspace(0, 10, 10000, endpoint=False)
    m = np.sin(2 * np.pi * t)
    M, P, C = sprague_geers(m, 1.2 * m)
    assert M == pytest.approx(0.2, abs=1e-12) and P == pytest.approx(0.0, abs=1e-6)
    assert C == pytest.approx(0.2, abs=1e-6)
    M, P, _ = sprague_geers(m, np.sin(2 * np.pi * t + 0.6))
    assert M == pytest.approx(0.0, abs=1e-9) and P == pytest.approx(0.6 / np.pi, abs=1e-9)


def test_russell_closed_form():
    """Russell (1997): c = 2 m gives m_r = (4B - B)/sqrt(4B B) = 1.5, RM = log10(2.5), RP = 0."""
    m = np.sin(np.linspace(0, 20, 5000))
    RM, RP, RC = russell(m, 2 * m)
    assert RM == pytest.approx(np.log10(2.5), abs=1e-12)
    assert RP == pytest.approx(0.0, abs=1e-6)
    assert RC == pytest.approx(np.sqrt(np.pi / 4) * np.log10(2.5), abs=1e-6)


def test_time_history_metrics_are_blind_on_independent_roads():
    """Why Sprague-Geers is not used on random-road responses: two realisations of the SAME
    model on independent road phases score a phase error of about 0.5 (orthogonal signals;
    |P - 0.5| < 0.05 for 60 s of body acceleration, many correlation times), the same as a
    wrong model would.  Driven over the same road, the model scores P ~ 0."""
    st = toy.make_state(noise=False)
    a, b = _drive(st, 1), _drive(st, 2)
    _, P, _ = sprague_geers(a.channels["body_acc_1L"], b.channels["body_acc_1L"])
    assert abs(P - 0.5) < 0.05
    _, P_same, _ = sprague_geers(a.channels["body_acc_1L"], _drive(st, 1).channels["body_acc_1L"])
    assert P_same < 1e-6


def test_transmissibility_cancels_the_road_and_sees_the_suspension():
    """Axle-to-body transmissibility of a quarter-car depends on the suspension only: a 1.5x
    tyre stiffness (which changes every band power) flags nothing, a 0.6x damper flags the
    bands above the body resonance."""
    nom = toy.make_state()
    sim = _drive(nom, 2)
    tyre = transmissibility(_drive(toy.make_state({"tyre_stiffness": {"scale": 1.5}}), 1), sim)
    assert tyre.significant.sum() == 0
    damp = transmissibility(_drive(toy.make_state({"damper": {"scale": 0.6}}), 1), sim)
    fl = damp.bands[damp.significant.any(axis=0), 1]
    assert fl.size >= 8 and fl.min() < 3.0
    # less damping -> less transmission above resonance -> sim / meas > 1 there
    hi = damp.bands[:, 1] > 5
    assert np.all(damp.log_ratio[:, hi][damp.significant[:, hi]] > 0)


def test_front_rear_delay_exposes_speed_scale_error():
    """True speed 1.1x the recorded one: the measured axle-1 to axle-3 delay is
    wheelbase / (1.1 v); the apparent speed scale is 1.1 within 1 % and flagged; with a correct
    speed signal the delay ratio interval contains 1 (not flagged)."""
    nom = toy.make_state()
    sim = _drive(nom, 2)
    fr = front_rear(_drive(toy.make_state({"speed_scale": {"scale": 1.1}}), 1), sim, wheelbase=4.0)
    assert fr.pairs == [("axle_acc_1L", "axle_acc_3L")]
    assert fr.speed_scale[0] == pytest.approx(1.1, rel=0.01)
    assert fr.delay_ratio[0] == pytest.approx(1 / 1.1, rel=0.01)
    # the ratio shown is that of the two whole-record delays shown beside it
    assert fr.delay_ratio[0] == pytest.approx(fr.delay_meas[0] / fr.delay_sim[0], rel=1e-12)
    assert fr.delay_ratio_lo[0] <= fr.delay_ratio[0] <= fr.delay_ratio_hi[0]
    assert fr.delay_significant[0]
    fr0 = front_rear(_drive(nom, 3), sim, wheelbase=4.0)
    assert not fr0.delay_significant[0]
    assert fr0.delay_meas[0] == pytest.approx(0.4, abs=0.005)
    assert fr0.significant.sum() == 0


def test_gcc_delay_recovers_a_known_shift():
    """Band-limited noise and a copy 37 samples later (0.185 s at 200 Hz): error < 0.5 sample."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(8000)
    y = np.concatenate([np.zeros(37), x[:-37]]) + 0.3 * rng.standard_normal(8000)
    assert gcc_delay(x, y, 200.0, max_lag=0.5) == pytest.approx(0.185, abs=0.0025)


def test_distribution_shape_sees_a_cubic_spring_and_not_noise():
    """A cubic hardening suspension spring (k3 = 5e9 N/m^3, about +35 % stiffness at one
    standard deviation of deflection) makes the suspension deflection platykurtic and the body
    acceleration leptokurtic: flagged on body_acc.  Linear vs linear on other phases: over 8
    pairs at most one pair with any flag (per-pair rate <= 5 % by BH; P(X >= 2) = 0.06)."""
    nom = toy.make_state()
    cub = toy.make_state({"cubic_spring": {"k3": 5e9}})
    sh = distribution_shape(toy.simulate_drive(cub, 40.0, 10.0, 1), _drive(nom, 2, 40.0))
    i = sh.channels.index("body_acc_1L")
    assert sh.significant_kurt[i] and sh.kurt_meas[i] > 0.5
    j = sh.channels.index("susp_disp_1L")
    assert sh.kurt_meas[j] < -0.5
    n_any = sum(distribution_shape(_drive(nom, 10 + k, 40.0), _drive(nom, 20 + k, 40.0)).significant.any()
                for k in range(8))
    assert n_any <= 1


def test_front_rear_speed_scale_while_the_speed_changes():
    """Truck speeding up from 7 to 12 m/s over 30 s, axles 5 m apart, the speed signal
    reading 0.93 x the true speed: the apparent speed scale (true / recorded) is 1/0.93
    within 0.5 % with an interval that excludes 1 (the lags are taken in recorded distance,
    :func:`diagnosis.compare.distance_lag`; as delays in time the scale came out 1.10 and
    5.3 on the two sides of a blind case like this).  Against a correct speed signal the
    delay ratio interval contains 1."""
    from diagnosis.compare import distance_lag
    from diagnosis.signals import Signals

    fs, T, d = 200.0, 30.0, 5.0
    t = np.arange(int(T * fs)) / fs
    x = 10.0 + 7.0 * t + 2.5 * t ** 2 / T                      # true distance, 7 -> 12 m/s
    v_true = 7.0 + 5.0 * t / T
    rng = np.random.default_rng(5)
    n = np.linspace(0.1, 3.0, 300)
    amp, ph = n ** -1.0, rng.uniform(0, 2 * np.pi, n.size)

    def road(xx):
        return np.sin(2 * np.pi * np.outer(xx, n) + ph) @ amp

    ch = {"axle_acc_1L": road(x), "axle_acc_3L": road(x - d)}
    right = Signals(t, ch, speed=v_true)
    wrong = Signals(t, ch, speed=0.93 * v_true)
    assert distance_lag(ch["axle_acc_1L"], ch["axle_acc_3L"], 0.93 * v_true, fs,
                        max_lag=2 * d) == pytest.approx(0.93 * d, rel=0.005)
    fr = front_rear(wrong, right, wheelbase=d, sides=("L",))
    assert fr.speed_scale[0] == pytest.approx(1 / 0.93, rel=0.005)
    assert fr.speed_scale_lo[0] > 1.0
    fr0 = front_rear(right, right, wheelbase=d, sides=("L",))
    assert fr0.speed_scale[0] == pytest.approx(1.0, rel=0.005)
    assert fr0.delay_ratio_lo[0] <= 1.0 <= fr0.delay_ratio_hi[0]
