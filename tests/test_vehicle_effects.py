"""Effect switches: registry and parsing, and one physics test per effect.

Every physics test compares a run with the effect against the same run without it
(same road, same phases), so the differences are the effect's alone; no
statistical noise enters except where stated.  Band powers are Welch PSD sums
(512-sample segments at 200 Hz, 8 s records).
"""
import numpy as np
import pytest
import scipy.signal as ss
import scipy.stats as st

from eroad.errors import EroadInputError
from test_vehicle_model import _hand_static
from test_vehicle_support import GD0, random_road
from vehicles.effects import EFFECTS, parse_effects, resolve_effects
from vehicles.params import load_vehicle
from vehicles.simulate import simulate

T, V = 8.0, 10.0


def band(x, lo, hi, fs=200.0):
    f, p = ss.welch(x, fs, nperseg=512)
    m = (f >= lo) & (f < hi)
    return p[m].sum()


@pytest.fixture(scope="module")
def roads():
    return {c: random_road(length=T * V + 15.0, gd0=GD0[c], seed=21) for c in ("A", "C", "E")}


@pytest.fixture(scope="module")
def base(roads):
    return {c: simulate("dump_truck_8x4", r, V, T) for c, r in roads.items()}


def test_library_complete_and_described():
    assert set(EFFECTS) >= {"frame_flex", "tyre_enveloping", "leaf_friction", "bump_stop",
                            "damper_asymmetry", "payload", "speed_scale", "sensor"}
    for e in EFFECTS.values():
        assert e.description and e.parameters and e.primary in [p.name for p in e.parameters]
        for p in e.parameters:
            assert p.unit and p.doc and p.range[0] <= p.default <= p.range[1]


def test_parse_and_resolve():
    assert parse_effects(["leaf_friction=3000", "bump_stop.gap=0.03", "sensor"]) == \
        {"leaf_friction": {"force": 3000.0}, "bump_stop": {"gap": 0.03}, "sensor": {}}
    r = resolve_effects({"payload": 500.0})
    assert r["payload"] == {"mass": 500.0, "dx": 0.0, "dy": 0.0}
    with pytest.raises(EroadInputError, match="unknown effect"):
        parse_effects(["gremlins=1"])
    with pytest.raises(EroadInputError, match="no parameter 'gap_m'"):
        parse_effects(["bump_stop.gap_m=1"])
    with pytest.raises(EroadInputError, match="not a number"):
        parse_effects(["bump_stop=wide"])
    with pytest.raises(EroadInputError, match="outside the sensible range"):
        resolve_effects({"speed_scale": 3.0})


def test_effects_off_by_default(base):
    assert base["C"].meta["effects"] == {}


def test_frame_flex_adds_energy_near_frame_modes(roads, base):
    """Flexible frame (torsion 6 Hz, bending 8 Hz): the left-right difference of the
    front body accelerations (torsion) in 4-12 Hz grows by more than 5x (measured
    ~20x) and the rear body acceleration in 5-12 Hz by more than 5 % (measured 13 %)."""
    b = base["C"].channels
    f = simulate("dump_truck_8x4", roads["C"], V, T, effects={"frame_flex": 1.0}).channels
    lr = band(f["body_acc_1L"] - f["body_acc_1R"], 4, 12) / band(b["body_acc_1L"] - b["body_acc_1R"], 4, 12)
    assert lr > 5.0
    assert band(f["body_acc_3L"], 5, 12) / band(b["body_acc_3L"], 5, 12) > 1.05


def test_tyre_enveloping_cuts_high_frequency_axle_excitation(roads, base):
    """A 0.3 m footprint averages wavelengths below ~0.6 m (> 17 Hz at 10 m/s): axle
    acceleration power above 15 Hz drops below half (measured 0.2) while the
    suspension displacement RMS (long waves) changes by less than 3 %."""
    b = base["C"].channels
    e = simulate("dump_truck_8x4", roads["C"], V, T, effects={"tyre_enveloping": 0.3}).channels
    assert band(e["axle_acc_3L"], 15, 100) / band(b["axle_acc_3L"], 15, 100) < 0.5
    assert np.std(e["susp_disp_3L"]) == pytest.approx(np.std(b["susp_disp_3L"]), rel=0.03)


def test_leaf_friction_raises_body_acceleration_at_small_amplitudes(roads, base):
    """On a smooth (class A) road leaf friction (2 kN) locks the springs: body
    acceleration power in 4-8 Hz rises by more than 2x (measured ~5x) and the
    suspension travel falls; on a class E road the same friction matters much less
    (ratio below half the class-A ratio): friction is an amplitude-dependent effect."""
    ra = simulate("dump_truck_8x4", roads["A"], V, T, effects={"leaf_friction": 2000.0}).channels
    ba = base["A"].channels
    ratio_a = band(ra["body_acc_3L"], 4, 8) / band(ba["body_acc_3L"], 4, 8)
    assert ratio_a > 2.0
    assert np.std(ra["susp_disp_3L"]) < 0.7 * np.std(ba["susp_disp_3L"])
    re = simulate("dump_truck_8x4", roads["E"], V, T, effects={"leaf_friction": 2000.0}).channels
    ratio_e = band(re["body_acc_3L"], 4, 8) / band(base["E"].channels["body_acc_3L"], 4, 8)
    assert ratio_e < 0.5 * ratio_a


def test_bump_stop_raises_peaks_at_large_amplitudes(roads, base):
    """Bump stops 20 mm above static: on a class E road (suspension peaks ~0.1 m) they
    clip the compression peaks (max below 0.75x; measured 0.66x) and, with tyres that stay
    on the road, make body acceleration heavy-tailed (excess kurtosis up by more than 0.4,
    measured -0.69 -> -0.14).  On this road some tyre is off the ground in 80 % of the
    samples; with the (default) one-sided tyres the lift-off is a nonlinearity of its own
    and the kurtosis of body_acc_3L no longer moves (-0.44 -> -0.45; at axle 1 it does,
    -0.01 -> 0.49), so the heavy tail is checked with bilateral tyres, which isolate the
    effect.  On a class A road (peaks 6 mm) nothing changes (RMS within 0.5 %)."""
    b = base["E"].channels
    e = simulate("dump_truck_8x4", roads["E"], V, T, effects={"bump_stop": 0.02}).channels
    assert e["susp_disp_3L"].max() < 0.75 * b["susp_disp_3L"].max()
    bb = simulate("dump_truck_8x4", roads["E"], V, T, tyres="bilateral").channels
    eb = simulate("dump_truck_8x4", roads["E"], V, T, effects={"bump_stop": 0.02},
                  tyres="bilateral").channels
    assert st.kurtosis(eb["body_acc_3L"]) > st.kurtosis(bb["body_acc_3L"]) + 0.4
    a = simulate("dump_truck_8x4", roads["A"], V, T, effects={"bump_stop": 0.02}).channels
    assert np.std(a["body_acc_3L"]) == pytest.approx(np.std(base["A"].channels["body_acc_3L"]), rel=0.005)


def test_damper_asymmetry_shifts_the_mean(roads, base):
    """Rebound 3x compression (mean damping kept): the suspension 'jacks down' - its
    mean moves into compression by more than 5 % of its RMS on a class E road
    (measured ~12 %; the symmetric model's mean is the quasi-static response to the
    mean road slope of this window, the same in both runs, so the difference is the
    effect's); the shift grows with the road amplitude (class A: 4x smaller road,
    shift more than 3x smaller, as the effect is of second order in amplitude)."""
    b = base["E"].channels["susp_disp_3L"]
    e = simulate("dump_truck_8x4", roads["E"], V, T, effects={"damper_asymmetry": 3.0}).channels["susp_disp_3L"]
    shift_e = np.mean(e) - np.mean(b)
    assert shift_e > 0.05 * np.std(b)
    a = simulate("dump_truck_8x4", roads["A"], V, T, effects={"damper_asymmetry": 3.0}).channels["susp_disp_3L"]
    shift_a = np.mean(a) - np.mean(base["A"].channels["susp_disp_3L"])
    assert 0 < shift_a < shift_e / 3


def test_payload_shifts_sag_and_lowers_bounce(roads, base):
    """+8 t payload: the mean suspension displacement (zeroed on the nominal vehicle)
    equals the hand-calculated extra static compression within 5 % (dynamics add a
    mean of ~1e-4 m), and body acceleration power moves to lower frequencies (the
    spectral centroid in 0.5-4 Hz drops, as bounce ~ sqrt(k / m))."""
    from dataclasses import replace

    vp = load_vehicle("dump_truck_8x4")
    items = [replace(m, mass=m.mass + 8000.0) if m.payload else m for m in vp.sprung]
    d_comp = _hand_static(replace(vp, sprung=tuple(items)))[0] - _hand_static(vp)[0]
    p = simulate("dump_truck_8x4", roads["C"], V, T, effects={"payload": 8000.0}).channels
    for a in range(4):
        assert np.mean(p[f"susp_disp_{a + 1}L"]) == pytest.approx(d_comp[a], rel=0.05)

    def centroid(x):
        f, s = ss.welch(x, 200.0, nperseg=1024)
        m = (f >= 0.5) & (f <= 4.0)
        return (f[m] * s[m]).sum() / s[m].sum()
    b = base["C"].channels
    assert centroid(p["body_acc_1L"]) < 0.97 * centroid(b["body_acc_1L"])


def test_speed_scale_changes_only_the_recorded_speed(roads, base):
    s = simulate("dump_truck_8x4", roads["C"], V, T, effects={"speed_scale": 1.05})
    np.testing.assert_allclose(s["speed"], 1.05 * base["C"]["speed"], rtol=1e-12)
    for name in base["C"].channels:
        if name != "speed":
            np.testing.assert_array_equal(s[name], base["C"][name])


def test_sensor_low_pass_and_seeded_noise(roads, base):
    """A 20 Hz sensor low-pass (2nd order) cuts axle-acceleration power in 35-50 Hz
    (the top of the road band at 10 m/s) below 12 % (Butterworth power gain
    1/(1 + (f/fc)^4): 0.096 at 35 Hz, 0.025 at 50 Hz); noise is reproducible from
    the seed, differs between seeds, and has the requested level (std of the added
    noise within 10 % of 0.2 m/s^2 over 1601 samples)."""
    b = base["C"].channels
    lp = simulate("dump_truck_8x4", roads["C"], V, T,
                  effects={"sensor": {"cutoff": 20.0, "acc_noise": 0.0, "disp_noise": 0.0}}).channels
    assert band(lp["axle_acc_3L"], 35, 50) < 0.12 * band(b["axle_acc_3L"], 35, 50)
    eff = {"sensor": {"cutoff": 500.0, "acc_noise": 0.2, "disp_noise": 0.0}}
    n1 = simulate("dump_truck_8x4", roads["C"], V, T, effects=eff, seed=5).channels
    n2 = simulate("dump_truck_8x4", roads["C"], V, T, effects=eff, seed=5).channels
    n3 = simulate("dump_truck_8x4", roads["C"], V, T, effects=eff, seed=6).channels
    np.testing.assert_array_equal(n1["body_acc_2R"], n2["body_acc_2R"])
    assert not np.array_equal(n1["body_acc_2R"], n3["body_acc_2R"])
    assert np.std(n1["body_acc_2R"] - b["body_acc_2R"]) == pytest.approx(0.2, rel=0.1)
    np.testing.assert_array_equal(n1["susp_disp_1L"], b["susp_disp_1L"])
