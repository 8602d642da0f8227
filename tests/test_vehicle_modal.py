"""Modal analysis (vehicles.modal): closed-form estimates, ranges, labels, rigid limit,
stiffness scaling, CLI.

Where a closed-form estimate exists the modes are checked against it, computed here
from the vehicle files (read with ``tomllib``, not through ``vehicles.params``): axle
hop (unsprung mass on springs and tyres), body bounce (sprung mass on springs in series
with tyres, with the bounce-pitch coupling sizing the tolerance), body roll, and the
DCDC block on its mounts (closed form for bounce, and a two-rigid-body hand model of
block and free chassis for all six mount modes).  Each tolerance is sized from what
the estimate leaves out.  Where none exists, reference ranges of heavy road vehicles
apply (Cebon, Handbook of Vehicle-Road Interaction, 1999; Gillespie, Fundamentals of
Vehicle Dynamics, 1992, ride chapter): body bounce 1-3 Hz, pitch 1.5-4 Hz, axle tramp
(roll) 8-20 Hz, frame torsion and vertical bending 5-15 Hz.  The loaded vehicles here,
with leaf or air springs on a narrow spring track and no anti-roll bar, roll below
1 Hz (see ``test_body_roll_matches_hand_calculation``).
"""
from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from eroad.cli import main
from vehicles.modal import modal_analysis
from vehicles.params import load_vehicle

VEHICLES = ("dump_truck_8x4", "e_tractor")
PARAMS = Path(__file__).resolve().parents[1] / "vehicles" / "params"


def _toml(vehicle: str) -> dict:
    """The vehicle file as plain TOML (independent of vehicles.params)."""
    return tomllib.loads((PARAMS / f"{vehicle}.toml").read_text())


def _box_body(items) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass [kg], centre of gravity [m] and inertia tensor about it [kg m^2] of homogeneous
    boxes (TOML [[mass]] tables: x extent, width, height; a point mass has zero extent)."""
    m = sum(it["mass"] for it in items)
    centres = [np.array([(it["x_front"] + it["x_rear"]) / 2, it["y"], it["z"]]) for it in items]
    c = sum(it["mass"] * r for it, r in zip(items, centres)) / m
    J = np.zeros((3, 3))
    for it, r in zip(items, centres):
        L, W, H = it["x_front"] - it["x_rear"], it["width"], it["height"]
        d = r - c
        J += it["mass"] / 12 * np.diag([W * W + H * H, L * L + H * H, L * L + W * W])
        J += it["mass"] * (d @ d * np.eye(3) - np.outer(d, d))
    return m, c, J


def _dcdc_item(d: dict) -> dict:
    """The DCDC block as a mass item: a homogeneous box of its size, centre of gravity at
    cog_height above the mounting plane (the file gives no inertia; the box is its
    definition: length, width, height "for the inertia")."""
    return {"mass": d["mass"], "x_front": d["x"] + d["length"] / 2, "x_rear": d["x"] - d["length"] / 2,
            "y": d["y"], "z": d["z_base"] + d["cog_height"], "width": d["width"], "height": d["height"]}


def _hz(w2) -> np.ndarray:
    return np.sqrt(np.clip(w2, 0.0, None)) / (2 * math.pi)


@pytest.fixture(scope="module")
def results():
    """Modal analyses of both vehicles, rigid and flexible (about 1 s in all)."""
    return {(v, c): modal_analysis(v, c) for v in VEHICLES for c in ("rigid", "flexible")}


def _first(res, label):
    found = res.by_label(label)
    assert found, f"no mode labelled {label!r}: {[m.label for m in res.modes]}"
    return found[0]


def _axle_modes(res, kind, a):
    """Modes of kind (hop/tramp) that involve axle a (alone or shared with a tandem partner)."""
    out = []
    for m in res.modes:
        if not m.label.startswith(f"axle {kind} "):
            continue
        axles = m.label.split()[2].split("+")
        if str(a) in axles:
            out.append(m)
    return out


@pytest.mark.parametrize("chassis", ["rigid", "flexible"])
@pytest.mark.parametrize("vehicle", VEHICLES)
def test_body_and_tramp_modes_in_physical_ranges(results, vehicle, chassis):
    """Body bounce 1-3 Hz, pitch 1.5-4 Hz, every axle has a tramp mode in 8-20 Hz (ranges:
    module docstring; no closed form for tramp here: the lateral guides at seat height
    and the tyres' lateral stiffness move its roll centre), damping ratios of the
    suspension-damped body bounce 0.02-0.5 and of axle hop 0.1-0.5.  Hop frequencies:
    ``test_axle_hop_matches_closed_form``."""
    res = results[(vehicle, chassis)]
    assert 1.0 <= _first(res, "body bounce").freq_hz <= 3.0
    assert 1.5 <= _first(res, "body pitch").freq_hz <= 4.0
    for a in range(1, len(load_vehicle(vehicle).axles) + 1):
        tramp = _axle_modes(res, "tramp", a)
        assert tramp and all(8.0 <= m.freq_hz <= 20.0 for m in tramp), (a, [(m.label, m.freq_hz) for m in tramp])
    assert 0.02 <= _first(res, "body bounce").damping <= 0.5
    for m in _axle_modes(res, "hop", 1):
        assert 0.1 <= m.damping <= 0.5


#: hop against the closed form (test_axle_hop_matches_closed_form): see its docstring
HOP_TOL = 0.03


@pytest.mark.parametrize("chassis", ["rigid", "flexible"])
@pytest.mark.parametrize("vehicle", VEHICLES)
def test_axle_hop_matches_closed_form(results, vehicle, chassis):
    """Axle hop against the closed form of an unsprung mass between the frame and the
    road: ``f_a = sqrt((2 k_s + 2 n k_t) / m_u) / 2 pi`` per axle, with k_s the
    suspension stiffness per side (one spring per side: two per axle), n the tyres per
    side (duals: 2) and k_t the stiffness of one tyre, m_u the axle's unsprung mass
    (dump truck 9.14 Hz front, 10.26 Hz tandem; tractor 9.07 / 9.43 Hz).

    Every mode labelled as hop of axle a (alone, or in or out of phase with its tandem
    partner) has its natural frequency (``freq_hz`` = |lambda| / 2 pi) and the frequency
    of its best-matching undamped mode (``freq_undamped_hz``; the estimate is undamped)
    within 3 %.  What the estimate leaves out: the sprung mass is not fixed (quarter-car
    correction (k_s / (k_s + k_t))^2 m_u / m_s of the eigenvalue: <= 1 % here, < 0.5 %
    in frequency); the tandem axles couple through the frame (their in- and anti-phase
    hop modes are 0.3 % apart); the axles' guided fore-aft modes at 8-10 Hz and the
    neighbouring axle's hop lie within a few per cent and mix with hop through the seat
    height and the non-proportional damping (hop damping 0.15-0.32).  Measured
    deviations: -0.7 % to +0.5 % (freq_hz) and -0.1 % to +1.4 % (freq_undamped_hz).
    3 % keeps that with margin and still fails for a 10 % change of an axle's mass or of
    its springs-plus-tyres stiffness (4.7 % in frequency)."""
    doc = _toml(vehicle)
    res = results[(vehicle, chassis)]
    for a, ax in enumerate(doc["axle"], start=1):
        k = 2 * ax["spring_stiffness"] + 2 * ax["tyres_per_side"] * ax["tyre_stiffness"]
        f_est = math.sqrt(k / ax["unsprung_mass"]) / (2 * math.pi)
        hop = _axle_modes(res, "hop", a)
        assert hop, (a, [m.label for m in res.modes])
        for m in hop:
            assert m.freq_hz == pytest.approx(f_est, rel=HOP_TOL), (a, m.label, m.freq_hz, f_est)
            assert m.freq_undamped_hz == pytest.approx(f_est, rel=HOP_TOL), (a, m.label, m.freq_undamped_hz, f_est)
    n_hop = sum(m.label.startswith("axle hop") for m in res.modes)
    assert n_hop == len(doc["axle"])          # one hop mode per axle (one vertical DOF each)


@pytest.mark.parametrize("vehicle", VEHICLES)
def test_body_roll_matches_hand_calculation(results, vehicle):
    """Body roll against the textbook estimate (Gillespie, roll stiffness): sprung mass rolling
    about the spring-seat height on the suspension roll stiffness (springs at the
    spring track in series with the tyres at their lateral positions), reduced by
    the gravity term m g h, with inertia J_x + m h^2 (h: centre of gravity above the
    seats).  The estimate neglects the lateral compliance of guides and tyres, which
    lowers the model's frequency: accept -20 % .. +5 %.  The range 0.4-4 Hz holds for
    loaded heavy vehicles without anti-roll bars (high payload centre of gravity)."""
    vp = load_vehicle(vehicle)
    res = results[(vehicle, "rigid")]
    model = res.linear.model
    sprung = model.segments + ([model.dcdc] if model.dcdc is not None else [])
    m = sum(b.mass for b in sprung)
    zc = sum(b.mass * b.cog[2] for b in sprung) / m
    jx = sum(b.inertia[0, 0] + b.mass * (b.cog[2] - zc) ** 2 + b.mass * b.cog[1] ** 2 for b in sprung)
    k_roll = 0.0
    for ax in vp.axles:
        k_s = 2 * ax.spring_stiffness * (ax.spring_track / 2) ** 2
        ys = [ax.track / 2] if ax.tyres_per_side == 1 else \
            [ax.track / 2 - ax.dual_spacing / 2, ax.track / 2 + ax.dual_spacing / 2]
        k_t = 2 * ax.tyre_stiffness * sum(y * y for y in ys)
        k_roll += 1.0 / (1.0 / k_s + 1.0 / k_t)
    h = zc - np.mean([ax.seat_height for ax in vp.axles])
    f_hand = math.sqrt((k_roll - m * 9.81 * h) / (jx + m * h * h)) / (2 * math.pi)
    roll = _first(res, "body roll")
    assert 0.4 <= roll.freq_hz <= 4.0
    assert 0.8 * f_hand <= roll.freq_hz <= 1.05 * f_hand, (roll.freq_hz, f_hand)


def _bounce_estimates(doc: dict) -> tuple[float, float]:
    """Body bounce [Hz]: the closed form sqrt(sum k / m) / 2 pi of the sprung mass on the
    axle ends' springs in series with their tyres, and the bounce root of the 2x2
    bounce-pitch problem of the same springs at their axle positions (rigid beam with
    the sprung mass's pitch inertia)."""
    items = list(doc["mass"]) + ([_dcdc_item(doc["dcdc"])] if "dcdc" in doc else [])
    m, c, J = _box_body(items)
    k = np.array([2 / (1 / ax["spring_stiffness"] + 1 / (ax["tyres_per_side"] * ax["tyre_stiffness"]))
                  for ax in doc["axle"]])
    x = np.array([ax["x"] for ax in doc["axle"]]) - c[0]
    f_simple = math.sqrt(k.sum() / m) / (2 * math.pi)
    K = np.array([[k.sum(), -(k * x).sum()], [-(k * x).sum(), (k * x * x).sum()]])
    Mb = np.diag([m, J[1, 1]])
    w2, V = scipy.linalg.eigh(K, Mb)
    # the bounce root: the mode with the larger share of kinetic energy in z
    share = Mb[0, 0] * V[0] ** 2 / np.einsum("ij,ik,kj->j", V, Mb, V)
    return f_simple, float(_hz(w2[int(np.argmax(share))]))


@pytest.mark.parametrize("vehicle", VEHICLES)
def test_body_bounce_matches_hand_calculation(results, vehicle):
    """Bounce of the sprung mass (mass items and DCDC block) on the axle ends' springs in
    series with their tyres: f = sqrt(sum k_s k_t / (k_s + k_t) / m) / 2 pi (1.71 Hz
    truck, 1.37 Hz tractor).  Its main omission is the bounce-pitch coupling (the
    springs' stiffness centre is 0.27 m (truck) and 0.06 m (tractor) from the centre
    of gravity); its size is the shift of the bounce root of the 2x2 bounce-pitch
    problem from the closed form (+4.8 % truck, -0.1 % tractor).  The rest (unsprung
    masses riding along with about a quarter of the body's amplitude: ~1 % of the
    kinetic energy; seat geometry; damping) is below 2 %.  Accept |f / f_hand - 1| <=
    |coupling| + 2 % (6.8 % truck, 2.1 % tractor; measured +2.9 % and -0.4 %)."""
    res = results[(vehicle, "rigid")]
    f_hand, f_coupled = _bounce_estimates(_toml(vehicle))
    tol = abs(f_coupled / f_hand - 1) + 0.02
    f = _first(res, "body bounce").freq_undamped_hz
    assert abs(f / f_hand - 1) <= tol, (f, f_hand, f_coupled)


@pytest.mark.parametrize("vehicle", VEHICLES)
def test_frame_modes_flexible(results, vehicle):
    """Flexible chassis: the first modes labelled frame torsion and frame bending lie
    in 5-15 Hz (heavy-truck ladder frames, module docstring); the torsion mode is
    within 10 % of the target the frame was tuned to (vehicle file).  Vertical bending
    mixes with the axles' fore-aft (guide) modes at 8-10 Hz, so its strain energy is
    spread over several modes: the tuning (vehicles.frame.frame_mode_frequencies)
    takes the lowest mode with >= 30 % of its strain energy in the bending springs,
    the label the first mode dominated by frame deformation; check that the former
    lies within 10 % of the bending target.  The rigid chassis has no frame mode."""
    vp = load_vehicle(vehicle)
    res = results[(vehicle, "flexible")]
    tors = _first(res, "frame torsion")
    bend = _first(res, "frame bending")
    assert 5.0 <= tors.freq_hz <= 15.0, tors.freq_hz
    assert 5.0 <= bend.freq_hz <= 15.0, bend.freq_hz
    assert tors.freq_hz == pytest.approx(vp.frame.target_torsion_hz, rel=0.10)
    tuned = [m for m in res.modes if m.strain.get("frame bending", 0.0) >= 0.30]
    assert tuned[0].freq_hz == pytest.approx(vp.frame.target_bending_hz, rel=0.10)
    assert not [m for m in results[(vehicle, "rigid")].modes if m.label.startswith("frame")]


def _skew(r) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _dcdc_two_body(doc: dict) -> dict:
    """The DCDC block and the rigid chassis as two free rigid bodies joined by the four
    mounts (point springs at the corners of the block's base, TOML stiffnesses times
    mount_stiffness_factor): 12 DOF, six rigid-body modes of the pair at 0 Hz and six
    mount modes, named by the largest component of the block's kinetic energy relative
    to the chassis (x longitudinal, y lateral, z bounce, about x roll, y pitch, z yaw).

    Returns {kind: frequency [Hz]}, plus the closed forms ``bounce_fixed`` (block on
    fixed ground) and ``bounce_closed`` (block against the chassis's effective mass at
    the mount centre, 1/m_eff = 1/M + g^T J^-1 g with g = r x e_z)."""
    d = doc["dcdc"]
    Mc, cc, Jc = _box_body(doc["mass"])
    item = _dcdc_item(d)
    md, cd, Jd = _box_body([item])
    f = d["mount_stiffness_factor"]
    kp = f * np.diag([d["mount_longitudinal_stiffness"], d["mount_lateral_stiffness"],
                      d["mount_vertical_stiffness"]])
    Mb = scipy.linalg.block_diag(Mc * np.eye(3), Jc, md * np.eye(3), Jd)
    K = np.zeros((12, 12))
    for sx in (-0.5, 0.5):
        for sy in (-0.5, 0.5):
            p = np.array([d["x"] + sx * d["mount_x_spacing"], d["y"] + sy * d["mount_y_spacing"], d["z_base"]])
            # spring elongation: block point motion minus chassis point motion (u + theta x r)
            T = np.hstack([-np.eye(3), _skew(p - cc), np.eye(3), -_skew(p - cd)])
            K += T.T @ kp @ T
    w2, V = scipy.linalg.eigh(K, Mb)
    kinds = ("longitudinal", "lateral", "bounce", "roll", "pitch", "yaw")
    out = {}
    for j in range(6, 12):
        v = V[:, j]
        # chassis rigid motion carried to the block's centre of gravity
        carried = np.concatenate([v[0:3] - _skew(cd - cc) @ v[3:6], v[3:6]])
        rel = v[6:12] - carried
        e = np.diag(Mb)[6:12] * rel ** 2
        out[kinds[int(np.argmax(e))]] = float(_hz(w2[j]))
    assert len(out) == 6, out
    assert np.all(_hz(w2[:6]) < 1e-3)           # the pair's free rigid-body motions
    kz = 4 * f * d["mount_vertical_stiffness"]
    g = np.cross(np.array([d["x"], d["y"], d["z_base"]]) - cc, [0.0, 0.0, 1.0])
    m_eff = 1.0 / (1.0 / Mc + g @ np.linalg.solve(Jc, g))
    out["bounce_fixed"] = math.sqrt(kz / md) / (2 * math.pi)
    out["bounce_closed"] = math.sqrt(kz * (1 / md + 1 / m_eff)) / (2 * math.pi)
    return out


#: DCDC mount modes against the two-body estimates: see test_dcdc_modes_tractor
DCDC_TOL = 0.03


def test_dcdc_modes_tractor(results):
    """The tractor's DCDC block on its four mounts, rigid chassis, against estimates from
    the vehicle file.

    Closed form for the vertical mode: on fixed ground sqrt(4 k_v / m) / 2 pi = 33.2 Hz;
    at 37 Hz, though, the chassis is far above its own suspension modes (<= 3.3 Hz) and
    moves as a free body, so the mount spring acts between the block and the chassis's
    effective mass at the mount centre (9.4 t with the chassis's pitch inertia):
    sqrt(4 k_v (1/m + 1/m_eff)) / 2 pi = 37.0 Hz.  The size of that coupling,
    sqrt(1 + m / m_eff) = 1.115, is why the fixed-ground estimate is 11 % low: the test
    asserts both (fixed ground below the model by 8-15 %, the two-body closed form within
    3 %).  The other five mount modes couple translation and rocking (the centre of
    gravity is 0.65 m above the mounts) and the chassis's roll and pitch: they are
    compared with the 12-DOF eigenproblem of the two free rigid bodies on the four mount
    springs.  What the two-body estimates leave out is the chassis's suspension and
    tyres and the axles behind them: at the mount modes (16-43 Hz) these add at most
    (3.3 / 16)^2 = 4 % to the chassis side's dynamic stiffness, which enters the mode
    only through the chassis-side correction (2-43 % of the eigenvalue against fixed
    ground), so < 2 % of the eigenvalue and < 1 % of the frequency; measured deviations
    0.0-0.9 %.  3 % keeps
    that with margin and fails for a 10 % change of the mount stiffness or of the
    block's mass (4.9 % in frequency).  The dump truck has no DCDC modes."""
    doc = _toml("e_tractor")
    est = _dcdc_two_body(doc)
    res = results[("e_tractor", "rigid")]
    for kind in ("longitudinal", "lateral", "bounce", "roll", "pitch", "yaw"):
        m = _first(res, f"DCDC {kind}")
        assert m.freq_undamped_hz == pytest.approx(est[kind], rel=DCDC_TOL), (kind, m.freq_undamped_hz, est)
    bounce = _first(res, "DCDC bounce").freq_undamped_hz
    assert bounce == pytest.approx(est["bounce_closed"], rel=DCDC_TOL)
    assert 1.08 <= bounce / est["bounce_fixed"] <= 1.15, (bounce, est["bounce_fixed"])
    for chassis in ("rigid", "flexible"):
        assert not [m for m in results[("dump_truck_8x4", chassis)].modes if m.label.startswith("DCDC")]


def test_dcdc_modes_flexible_chassis_are_mount_modes(results):
    """On the flexible chassis the block sits on one frame segment whose neighbours are
    joined by the frame springs, with frame modes (6-44 Hz) among the mount modes, so
    no closed form applies (the lateral mode moves from 16 to 24 Hz, the longitudinal
    from 16 to 14.5 Hz).  What must hold: the six DCDC modes exist and the mounts hold
    the largest share of their strain energy (measured 0.66-0.95)."""
    res = results[("e_tractor", "flexible")]
    for kind in ("longitudinal", "lateral", "bounce", "roll", "pitch", "yaw"):
        m = _first(res, f"DCDC {kind}")
        assert max(m.strain, key=m.strain.get) == "DCDC mounts", (kind, m.strain)


@pytest.mark.parametrize("vehicle", VEHICLES)
def test_very_stiff_frame_reproduces_rigid_modes(results, vehicle):
    """Frame stiffness x 1e4 moves the frame modes above 30 Hz (x 100 in frequency);
    below 30 Hz the flexible model then has the rigid model's modes: same count, same
    labels, frequencies within 2 % and damping ratios within 0.01 (the segments add
    up exactly to the rigid chassis; what is left is the joints' finite stiffness)."""
    rigid = [m for m in results[(vehicle, "rigid")].modes if m.freq_hz < 30.0]
    stiff = [m for m in modal_analysis(vehicle, "flexible", stiffness_factor=1e4).modes if m.freq_hz < 30.0]
    assert len(stiff) == len(rigid)
    for r, s in zip(rigid, stiff):
        assert s.label == r.label
        assert s.freq_hz == pytest.approx(r.freq_hz, rel=0.02)
        assert s.damping == pytest.approx(r.damping, abs=0.01)


@pytest.mark.parametrize("vehicle", VEHICLES)
def test_stiffness_factor_scales_frame_frequencies(vehicle):
    """A frame mode's frequency grows with the square root of the frame stiffness where
    the frame springs dominate its strain energy: factor 4 gives about 2x the first
    torsion and bending frequencies; the suspension and tyres, which do not scale,
    make it deviate: accept 1.7-2.3."""
    base = modal_analysis(vehicle, "flexible", stiffness_factor=1.0)
    four = modal_analysis(vehicle, "flexible", stiffness_factor=4.0)
    for label in ("frame torsion", "frame bending"):
        ratio = _first(four, label).freq_hz / _first(base, label).freq_hz
        assert 1.7 <= ratio <= 2.3, (label, ratio)


def test_mode_bookkeeping(results):
    """Energy shares sum to 1, shapes are scaled to a unit largest component, the
    table is sorted, damped/undamped frequencies agree for lightly damped modes
    (|f_n - f_u| <= zeta^2 f_n + 1 %: proportional damping would give equality), the
    stiff modes above 100 Hz are counted, and the frequency definition is
    f_n^2 = f_d^2 / (1 - zeta^2)."""
    for (vehicle, chassis), res in results.items():
        freqs = [m.freq_hz for m in res.modes]
        assert freqs == sorted(freqs)
        assert all(f <= res.f_max for f in freqs)
        for m in res.modes:
            assert sum(sum(d.values()) for d in m.kinetic.values()) == pytest.approx(1.0, abs=1e-9)
            assert sum(abs(v) for v in m.strain.values()) == pytest.approx(1.0, abs=1e-9)
            assert sum(sum(d.values()) for d in m.indicators.values()) == pytest.approx(1.0, abs=1e-9)
            assert np.max(np.abs(m.shape)) == pytest.approx(1.0)
            assert m.freq_damped_hz == pytest.approx(m.freq_hz * math.sqrt(1 - m.damping ** 2), rel=1e-6)
            if m.damping < 0.1 and m.mac > 0.99:
                assert abs(m.freq_undamped_hz - m.freq_hz) <= (m.damping ** 2 + 0.01) * m.freq_hz
        n_total = len(res.modes) + res.n_stiff
        assert n_total == res.n_dof   # one mode per degree of freedom (no overdamped pairs here)
    assert results[("dump_truck_8x4", "flexible")].n_stiff > 0   # quasi-rigid joint translations


def test_labels_unique_and_summary(results):
    """Labels are unique within a table (repeats numbered) and the summary is JSON."""
    for res in results.values():
        labels = [m.label for m in res.modes]
        assert len(labels) == len(set(labels))
        doc = json.loads(json.dumps(res.summary()))
        assert doc["n_stiff_modes"] == res.n_stiff and len(doc["modes"]) == len(res.modes)


def test_cli_modes_json(capsys, tmp_path):
    """``eroad modes --json`` prints a list of {label, freq_hz, damping}; ``--out`` writes
    the summary and refuses to overwrite it; bad input exits 2 with one line."""
    assert main(["modes", "--vehicle", "e_tractor", "--chassis", "flexible", "--frame-stiffness", "2",
                 "--json", "--out", str(tmp_path / "modes.json")]) == 0
    table = json.loads(capsys.readouterr().out)
    assert {"label", "freq_hz", "damping"} <= set(table[0])
    assert any(m["label"] == "frame torsion" for m in table)
    summary = json.loads((tmp_path / "modes.json").read_text())
    assert summary["chassis"] == "flexible" and summary["stiffness_factor"] == 2.0
    assert main(["modes", "--vehicle", "e_tractor", "--out", str(tmp_path / "modes.json")]) == 2
    assert "exists" in capsys.readouterr().err
    assert main(["modes", "--vehicle", "no_such_vehicle"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no_such_vehicle" in err
    assert main(["modes", "--vehicle", "dump_truck_8x4", "--frame-stiffness", "2"]) == 2
