"""The second truth family (drives.independent_truck): statics, a closed-form quarter-truck
check of equations and integrator, lift-off, dual-tyre lateral sampling, determinism, the
``second`` scenario as a readable dataset, effects, and agreement with the Exudyn model
under the nominal options.
"""
from __future__ import annotations

import hashlib
import math
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import tomli_w

from drives import independent_truck as it
from drives import synth
from drives.format import read_drive
from eroad.errors import EroadInputError
from roadlib.surface import RoadSurface

TRUCK = it.PARAMS_DIR / "dump_truck_8x4.toml"


def flat_sine_road(length=400.0, amp=0.0, wavelength=4.0, width=3.0, dx=0.02, dy=0.1,
                   tilt=0.0) -> RoadSurface:
    x = np.arange(int(round(length / dx)) + 1) * dx
    y = (np.arange(int(round(width / dy)) + 1) - round(width / dy) / 2) * dy
    z = amp * np.sin(2 * np.pi * x / wavelength)[:, None] + tilt * y[None, :]
    return RoadSurface(x, y, z)


# --------------------------------------------------------------------------- statics

@pytest.mark.parametrize("options", [it.NOMINAL_OPTIONS, {}], ids=["nominal", "defaults"])
def test_static_loads_sum_to_weight(options):
    m = it.build_truck("dump_truck_8x4", options=options)
    st = m.static
    # tolerance 0.1 % (brief); the solve is exact to round-off, so anything above 1e-9
    # would be a bookkeeping error (a load counted twice or a body left out)
    assert st["tyre_loads"].sum() == pytest.approx(st["weight"], rel=1e-3)
    assert st["spring_loads"].sum() == pytest.approx(st["sprung_weight"], rel=1e-3)
    assert abs(st["tyre_loads"].sum() / st["weight"] - 1) < 1e-9
    if options == {}:   # cab on its own mounts: the four mounts carry the cab
        assert st["cab_mount_loads"].sum() == pytest.approx(st["cab_weight"], rel=1e-9)
    assert st["weight"] / it.G == pytest.approx(30700.0, rel=1e-9)
    # axle loads: docs/vehicles.md gives 5.9 / 5.5 / 10.0 / 9.3 t for the Exudyn model (one
    # decimal: +-0.05 t, plus its 0.4 % geometric terms -> 0.1 t)
    assert m.static["axle_loads"] / 1000 == pytest.approx([5.9, 5.5, 10.0, 9.3], abs=0.1)


def test_nominal_modes_match_the_documented_exudyn_modes():
    # docs/vehicles.md lists the rigid Exudyn truck's modes: roll/sway 0.53, pitch 1.55,
    # bounce 1.76 Hz (two digits: +-0.02 Hz allowed, ~1 %), axle hop 9.1-10.3 Hz
    f = it.modal_frequencies(it.build_truck(options=it.NOMINAL_OPTIONS))
    for target in (0.53, 1.55, 1.76):
        assert np.min(np.abs(f - target)) < 0.02, (target, f[:8])
    assert np.sum((f > 9.05) & (f < 10.4)) >= 4


# --------------------------------------------------------------------------- closed form

def two_axle_vehicle(tmp_path) -> Path:
    """A symmetric two-axle test truck: identical axles 4 m apart, one sprung box centred
    between them with its centre of gravity at the spring-seat height (no pendulum terms), so
    that its symmetric bounce is exactly the two-DOF quarter truck."""
    doc = tomllib.loads(TRUCK.read_text())
    ax = dict(doc["axle"][0], tyres_per_side=1, dual_spacing=0.0, spring_stiffness=3.0e5,
              damping=1.0e4, tyre_stiffness=1.0e6, tyre_damping=1500.0, unsprung_mass=1000.0)
    doc["axle"] = [dict(ax, x=0.0), dict(ax, x=-4.0, steered=False)]
    doc["frame"] = dict(doc["frame"], x_front=1.0, x_rear=-5.0)
    doc["mass"] = [dict(doc["mass"][0], name="sprung box", mass=10000.0, x_front=-1.0,
                        x_rear=-3.0, z=ax["seat_height"], width=2.0, height=1.0)]
    p = tmp_path / "two_axle.toml"
    p.write_text(tomli_w.dumps(doc))
    return p


def quarter_truck(ms, mu, ks, cs, kt, ct, w):
    """Complex amplitudes (body, axle) of the 2-DOF quarter truck per unit road amplitude."""
    A = np.array([[-w * w * ms + 1j * w * cs + ks, -(1j * w * cs + ks)],
                  [-(1j * w * cs + ks), -w * w * mu + 1j * w * (cs + ct) + ks + kt]])
    return np.linalg.solve(A, np.array([0.0, kt + 1j * w * ct]))


def test_quarter_truck_frequencies_closed_form(tmp_path):
    m = it.build_truck(two_axle_vehicle(tmp_path), options=it.NOMINAL_OPTIONS)
    ms, mu, ks, kt = 5000.0, 1000.0, 2 * 3.0e5, 2 * 1.0e6      # per axle, both sides
    # undamped 2-DOF: (ks/ms - l)((ks+kt)/mu - l) = ks^2/(ms mu)
    b = ks / ms + (ks + kt) / mu
    c = ks * kt / (ms * mu)
    lam = np.array([(b - math.sqrt(b * b - 4 * c)) / 2, (b + math.sqrt(b * b - 4 * c)) / 2])
    f_ref = np.sqrt(lam) / (2 * math.pi)
    f = it.modal_frequencies(m)
    for fr in f_ref:   # eigen-solver round-off only: 1e-6 relative
        assert np.min(np.abs(f / fr - 1)) < 1e-6, (fr, f)


def test_sine_road_steady_state_matches_hand_solution(tmp_path):
    # wavelength = wheelbase: both axles see the same input, pure bounce = quarter truck
    m = it.build_truck(two_axle_vehicle(tmp_path), options=it.NOMINAL_OPTIONS)
    v, lam, amp, fs = 8.0, 4.0, 0.005, 200.0
    road = flat_sine_road(length=150.0, amp=amp, wavelength=lam)
    res = it.simulate_independent(m, road, t_speed=[0.0, 20.0], v_speed=[v, v], duration=12.0,
                                  fs_out=fs, x_start=10.0)
    w = 2 * math.pi * v / lam
    zb, zu = quarter_truck(5000.0, 1000.0, 6e5, 2e4, 2e6, 3000.0, w)
    sel = res.time >= 8.0   # transient (slowest decay ~0.3 s) long gone; 8 whole periods
    t = res.time[sel]

    def amplitude(x):       # least-squares sine fit at the known frequency
        X = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
        c = np.linalg.lstsq(X, x, rcond=None)[0]
        return math.hypot(c[0], c[1])

    # tolerance 0.5 %: RK4 at 1 ms has a phase/amplitude error ~(w dt)^4 ~ 1e-7 at 2 Hz; the
    # bilinear road on a 2 cm grid flattens a 4 m sine by ~1e-4; what is left is the fit
    assert amplitude(res.channels["susp_disp_1L"][sel]) == pytest.approx(abs(zu - zb) * amp, rel=5e-3)
    assert amplitude(res.channels["axle_acc_2R"][sel]) == pytest.approx(w * w * abs(zu) * amp, rel=5e-3)
    assert amplitude(res.channels["body_acc_1R"][sel]) == pytest.approx(w * w * abs(zb) * amp, rel=5e-3)


# --------------------------------------------------------------------------- tyres

def test_lift_off_has_no_tension():
    # a 1 m long, 12 cm high bump at 15 m/s throws the axles off the road
    road = flat_sine_road(length=200.0)
    bump = (road.x > 60.0) & (road.x < 61.0)
    road.z[bump, :] += 0.12
    out = {}
    for lo in (1.0, 0.0):
        m = it.build_truck(options={"tyre_liftoff": lo})
        out[lo] = it.simulate_independent(m, road, t_speed=[0.0, 10.0], v_speed=[15.0, 15.0],
                                          duration=6.0, fs_out=200.0, x_start=20.0)
    f1 = out[1.0].extra["tyre_force"]
    assert out[1.0].meta["tyre_lift_off_fraction"] > 0     # it did lift off
    assert f1.min() >= 0.0                                  # never pulled down: exactly 0 N
    assert np.any(f1 == 0.0)
    assert out[0.0].extra["tyre_force"].min() < -1000.0     # bilateral tyre: tension


def test_progressive_tyre_stiffens():
    m = it.build_truck(options={"tyre_progressivity": 0.3})
    t = m.tyres
    d = t["d_static"]
    f = it._tyre_force
    k_lo = (f(d, 0 * d, t["k"], 0 * t["c"], 0.3, t["d_ref"], True)
            - f(0.5 * d, 0 * d, t["k"], 0 * t["c"], 0.3, t["d_ref"], True)) / (0.5 * d)
    k_hi = (f(1.5 * d, 0 * d, t["k"], 0 * t["c"], 0.3, t["d_ref"], True)
            - f(d, 0 * d, t["k"], 0 * t["c"], 0.3, t["d_ref"], True)) / (0.5 * d)
    # the force is quadratic, so a secant stiffness is the tangent at the interval's middle:
    # k_t (1 + p (delta / delta_ref - 1)); exact up to round-off
    r = d / t["d_ref"]
    np.testing.assert_allclose(k_hi / k_lo, (1 + 0.3 * (1.25 * r - 1)) / (1 + 0.3 * (0.75 * r - 1)),
                               rtol=1e-9)
    assert np.all(k_hi > 1.15 * k_lo)
    # the tangent at the static deflection stays near the TOML stiffness (within p/2 x the
    # static shift from delta_ref, here a few per cent)
    assert np.all(np.abs((1 + 0.3 * (r - 1)) - 1) < 0.06)


@pytest.mark.parametrize("dual", [1.0, 0.0])
def test_dual_tyres_sample_their_own_lateral_position(dual):
    # the road is a plane tilted across (z = 0.01 y): the height under each contact is its y
    road = flat_sine_road(length=100.0, tilt=0.01)
    m = it.build_truck(options={"dual_contacts": dual})
    res = it.simulate_independent(m, road, t_speed=[0.0, 2.0], v_speed=[10.0, 10.0],
                                  duration=0.5, fs_out=200.0, x_start=20.0)
    y = res.extra["contact_y"]
    np.testing.assert_allclose(res.extra["road_z"][0], 0.01 * y, atol=1e-12)
    rear_left = np.sort(y[(res.extra["contact_x"] == -5.0) & (y > 0)])
    expected = [0.93 - 0.17, 0.93 + 0.17] if dual else [0.93]
    np.testing.assert_allclose(rear_left, expected, atol=1e-12)


def test_options_and_effects_are_checked():
    with pytest.raises(EroadInputError, match="unknown option"):
        it.resolve_options({"anti_roll": 1.0})
    with pytest.raises(EroadInputError, match="outside"):
        it.resolve_options({"tyre_progressivity": 2.0})
    with pytest.raises(EroadInputError, match="not available"):
        it.resolve_effects({"bump_stop": {}})


def test_payload_sag_and_friction():
    base = it.build_truck(options=it.NOMINAL_OPTIONS)
    m = it.build_truck(options=it.NOMINAL_OPTIONS, effects={"payload": {"mass": 2000.0}})
    assert m.static["weight"] - base.static["weight"] == pytest.approx(2000.0 * it.G, rel=1e-12)
    off = dict(zip(m.outputs, m.static_offset))
    # extra sag of the tandem springs: 2 t at the payload centre (x = -4.55 m), mostly on the
    # tandem; per spring about (extra load) / k; the rigid body shares it with the front, so
    # only bounds: 2-8 mm on the tandem, less at the front
    assert 0.002 < off["susp_disp_3L"] < 0.008 and off["susp_disp_1L"] < off["susp_disp_3L"]
    f = it.build_truck(options=it.NOMINAL_OPTIONS, effects={"leaf_friction": {"force": 3000.0}})
    assert f.friction["G"].shape[0] == 8 and np.all(f.friction["force"] == 3000.0)


# --------------------------------------------------------------------------- datasets

SHORT_SECOND = """
[scenario]
name = "second-short"
dataset_name = "second-short-{seed}"
duration_s = 4.0
runin_s = 1.0
[speed]
kind = "smooth_random"
min_mps = 8.0
max_mps = 12.0
knot_spacing_s = 2.0
[road]
dx_m = 0.05
[road.random]
n_segments = [1, 2]
min_segment_s = 1.5
[truth]
model = "independent"
[truth.independent]
arb_front = [1.0e5, 3.0e5]
cab_mount_stiffness = [0.8e5, 2.0e5]
[noise]
susp_disp_m = 1e-4
axle_acc_mps2 = 0.03
body_acc_mps2 = 0.03
"""


def digest(folder: Path) -> dict:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_second_family_dataset_is_readable_and_deterministic(tmp_path):
    cfgp = tmp_path / "short.toml"
    cfgp.write_text(SHORT_SECOND)
    a = synth.synth_command(config=cfgp, seed=7, out=tmp_path / "a",
                            effects=["leaf_friction=2500", "payload.mass=1500"])
    b = synth.synth_command(config=cfgp, seed=7, out=tmp_path / "b",
                            effects=["leaf_friction=2500", "payload.mass=1500"])
    assert a["channels"] == b["channels"] and len(a["channels"]) == 25
    assert digest(tmp_path / "a") == digest(tmp_path / "b")          # same seed, same bytes
    drive = read_drive(tmp_path / "a")
    assert drive is not None
    truth = synth.read_truth(tmp_path / "a")
    opts = truth["vehicle"]["truth"]["independent"]
    # the out-of-library options are recorded in the truth: the front anti-roll bar's default is
    # 1.5e5 N m/rad (drives.independent_truck OPTIONS); the band (x0.67 to x2) accepts a
    # retuned default while catching an unrecorded (0) or unit-slipped value; the rear roll
    # centre is its default, 0.95 m, exactly
    assert 1.0e5 <= opts["arb_front"] <= 3.0e5 and opts["roll_centre_height_rear"] == 0.95
    assert truth["vehicle"]["simulate_kwargs"]["effects"]["leaf_friction"]["force"] == 2500.0
    # the explicit scenario regenerates the same bytes
    c = synth.synth_command(config=tmp_path / "a" / "truth" / "scenario.toml", out=tmp_path / "c")
    assert c["channels"] == a["channels"]
    assert digest(tmp_path / "c")["channels.csv"] == digest(tmp_path / "a")["channels.csv"]
    with pytest.raises(EroadInputError, match="not available"):
        synth.synth_command(config=cfgp, seed=7, out=tmp_path / "d", effects=["bump_stop=0.02"])


def test_builtin_second_scenario_resolves():
    cfg, path = synth.load_scenario("second")
    r = synth.resolve_scenario(cfg, 3, src=path)
    opts = r["truth"]["independent"]
    assert r["truth"]["model"] == "independent"
    for key, rng in cfg["truth"]["independent"].items():
        if isinstance(rng, list):
            assert rng[0] <= opts[key] <= rng[1]
    assert synth.resolve_scenario(cfg, 3, src=path) == r                # drawn from the seed


def test_profile_road(tmp_path):
    cfgp = tmp_path / "p.toml"
    cfgp.write_text(SHORT_SECOND.replace("[road.random]\nn_segments = [1, 2]\nmin_segment_s = 1.5",
                                         'profile = "profile_1"'))
    synth.synth_command(config=cfgp, seed=1, out=tmp_path / "p")
    truth = synth.read_truth(tmp_path / "p")
    assert len(truth["segments"]) == 1 and truth["segments"][0]["label"] in "ABCDEFGH"
    road = RoadSurface.load(truth["road_file"])
    xp, zp = synth.read_profile("profile_1")
    # the left road edge is the measured profile itself (detrended): at the profile's own
    # chainages it is the measured height (to rounding), between them band-limited
    on = np.isin(np.round(road.x / 0.25, 9) % 1, [0.0]) & (road.x <= xp[-1])
    np.testing.assert_allclose(road.z[on, -1], np.interp(road.x[on], xp, zp), atol=1e-12)
    raw = np.loadtxt(synth.PROFILE_DIR / "profile_1.txt")
    assert raw.shape == (2177, 2)
    with pytest.raises(EroadInputError, match="unknown"):
        synth.resolve_scenario(tomllib.loads(cfgp.read_text().replace("profile_1", "nope")))


def test_profile_road_keeps_the_measured_spectrum():
    """The road built from a 0.25 m profile keeps the profile's PSD up to 0.9 of its Nyquist
    wavenumber (2 cycles/m): within 2 % from 0.3 to 1.8 cycles/m (Welch estimates of the same
    samples, so only the interpolation differs; 2 % is the read-out's sinc^4 at 1.8 cycles/m on
    the 1/4-step fine grid, 0.4 %, plus margin); linear interpolation loses 34 % at 1 cycle/m,
    which steepened w by about 0.5 (the failure this guards)."""
    from scipy.signal import welch

    xp, zp = synth.read_profile("profile_1")
    dx = 0.025
    x = np.arange(0.0, 300.0, dx)
    xf, zf = synth.bandlimited_profile(xp, zp, dx)
    z = np.interp(x, xf, zf)
    n0, g0 = welch(zp[xp < 300.0], fs=4.0, nperseg=512, detrend="linear")
    n1, g1 = welch(z, fs=1 / dx, nperseg=5120, detrend="linear")
    band = (n0 >= 0.3) & (n0 <= 1.8)
    ratio = np.interp(n0[band], n1, g1) / g0[band]
    assert np.all(np.abs(ratio - 1) < 0.02), ratio
    lin = np.interp(x, xp, zp)
    _, gl = welch(lin, fs=1 / dx, nperseg=5120, detrend="linear")
    assert np.interp(1.0, n1, gl) / np.interp(1.0, n0, g0) < 0.75
    with pytest.raises(EroadInputError, match="uniform"):
        synth.bandlimited_profile(np.array([0.0, 0.25, 0.6]), np.zeros(3), dx)


# --------------------------------------------------------------------------- agreement

BANDS = [(0.5, 2.0), (2.0, 5.0), (5.0, 8.0), (8.0, 12.0), (12.0, 20.0), (20.0, 40.0)]


def band_rms_ratio(a: pd.DataFrame, b: pd.DataFrame, fs: float) -> pd.DataFrame:
    from scipy.signal import welch

    rows = {}
    for c in a.columns:
        if c in ("time", "speed"):
            continue
        f, pa = welch(a[c].to_numpy(), fs=fs, nperseg=1024)
        _, pb = welch(b[c].to_numpy(), fs=fs, nperseg=1024)
        rows[c] = [math.sqrt(pb[(f >= lo) & (f < hi)].sum() / pa[(f >= lo) & (f < hi)].sum()) - 1
                   for lo, hi in BANDS]
    return pd.DataFrame(rows, index=[f"{lo:g}-{hi:g} Hz" for lo, hi in BANDS]).T


# ~6 s per seed (one Exudyn and one independent 30 s drive): seed 1 runs by default, seed 5
# (a second road, not used while choosing the guide damping) with -m slow
@pytest.mark.parametrize("seed", [1, pytest.param(5, marks=pytest.mark.slow)])
def test_nominal_agrees_with_exudyn(tmp_path, seed):
    """Same road, speed and seed: the Exudyn null case and the independent model with the
    nominal options; band RMS of the clean channels (Welch, 5.12 s windows).

    Measured (docs/second_family.md): largest deviation over the 24 channels 2.4 / 1.4 / 2.1 /
    4.4 / 1.4 / 3.4 % (seed 1) and 1.3 / 0.8 / 0.8 / 3.2 / 2.2 / 3.2 % (seed 5) in the six
    bands.  Tolerance 8 %: the brief's 5-10 % with room for other roads (the 8-12 Hz band holds
    the axle wind-up modes whose damping in the Exudyn model is not documented and was matched
    by its response, so it moves most from road to road)."""
    ex = tmp_path / "exudyn"
    synth.synth_command(scenario="null", seed=seed, out=ex)
    cfg = tomllib.loads((ex / "truth" / "scenario.toml").read_text())
    cfg["truth"] = {"model": "independent", "independent": dict(it.NOMINAL_OPTIONS), "effects": {}}
    ind = tmp_path / "independent"
    synth.synthesize(synth.resolve_scenario(cfg, src="test"), ind)
    a = pd.read_csv(ex / "truth" / "channels_clean.csv")
    b = pd.read_csv(ind / "truth" / "channels_clean.csv")
    assert list(a.columns) == list(b.columns)
    np.testing.assert_allclose(a["speed"], b["speed"], rtol=1e-9)
    d = band_rms_ratio(a, b, 200.0)
    worst = d.abs().max()
    assert (worst < 0.08).all(), (100 * d).round(1).to_string()
