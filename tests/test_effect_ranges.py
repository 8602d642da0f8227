"""Effect ranges (issue 15, item 4): every advertised range is one in which the vehicle
stays physical and the simulator runs.

* values outside a range -- the parameter's own or the vehicle's (payload) -- are
  refused by the CLI with one line and exit code 2;
* range ends simulate: a fast subset here (leaf friction at its largest force, also
  with its smallest smoothing velocity; the empty and the 100 %-overloaded vehicle),
  the full sweep of ``benchmarks/effect_ranges.py`` under ``-m slow``;
* the friction force that used to stop the simulator (16.4 kN, issue 15) runs through
  the step halving of :func:`vehicles.simulate.simulate`.

Drives: ``eroad synth``'s ``null`` scenario (random road and speed from the seed), short.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from eroad.errors import EroadInputError
from vehicles.effects import EFFECTS
from vehicles.params import load_vehicle
from vehicles.simulate import MAX_DT_HALVINGS, simulate

VEHICLES = ("dump_truck_8x4", "e_tractor")


def _drive(vehicle, seed=1, duration=3.0):
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    try:
        import effect_ranges
    finally:
        sys.path.pop(0)
    return effect_ranges, effect_ranges.drive(vehicle, seed, duration)


def _sim(vehicle, d, effects, **kw):
    return simulate(vehicle, d["road"], d["speed"], d["duration"], fs_out=d["fs"],
                    x_start=d["x_start"], effects=effects, **kw)


# ------------------------------------------------------------------ refused values

@pytest.mark.parametrize("vehicle, item, pattern", [
    ("dump_truck_8x4", "payload.mass=-1e6", r"payload: mass = .* outside the sensible range \[-50000, 50000\]"),
    ("dump_truck_8x4", "payload.mass=-16001",
     r"payload: mass = -16001 kg is outside the range for vehicle dump_truck_8x4: \[-16000, 16000\] kg"),
    ("e_tractor", "payload=-12000",
     r"payload: mass = -12000 kg is outside the range for vehicle e_tractor: \[-10000, 10000\] kg"),
    ("e_tractor", "payload.mass=10001", r"range for vehicle e_tractor: \[-10000, 10000\] kg"),
    ("dump_truck_8x4", "payload.dy=0.5", r"payload: dy = .* outside the sensible range \[-0.3, 0.3\]"),
    ("dump_truck_8x4", "leaf_friction.force=16400", r"leaf_friction: force = .* \[0, 12000\]"),
    ("dump_truck_8x4", "leaf_friction.velocity=0.001", r"leaf_friction: velocity = .* \[0.005, 0.1\]"),
    ("dump_truck_8x4", "frame_flex=0.01", r"frame_flex: stiffness_factor = .* outside"),
])
def test_refused_values_one_line_exit_2(tmp_path, capsys, vehicle, item, pattern):
    """Out-of-range effect values (static or per vehicle) stop ``eroad synth`` with one
    line on stderr naming the allowed range, exit code 2, and no dataset written."""
    from eroad.cli import main

    out = tmp_path / "d"
    rc = main(["synth", "--scenario", "null", "--seed", "1", "--duration", "2", "--vehicle",
               vehicle, "--effect", item, "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert "\n" not in err and err.startswith("eroad")
    import re
    assert re.search(pattern, err), err
    assert not out.exists() or not any(out.iterdir())


def test_vehicle_ranges_follow_the_payload():
    """payload.mass goes from the empty vehicle (-P) to 100 % overload (+P), P the
    vehicle's nominal payload; every other range is the parameter's own."""
    for vid in VEHICLES:
        vp = load_vehicle(vid)
        P = next(m.mass for m in vp.sprung if m.payload)
        for name, eff in EFFECTS.items():
            rng = eff.vehicle_ranges(vp)
            for p in eff.parameters:
                lo, hi, _ = rng[p.name]
                if (name, p.name) == ("payload", "mass"):
                    assert (lo, hi) == (-P, P)
                else:
                    assert (lo, hi) == tuple(p.range)
                assert p.range[0] <= lo <= hi <= p.range[1]


# ------------------------------------------------------------------ range ends simulate

def test_payload_range_ends_simulate_and_are_physical():
    """The empty vehicle (payload item removed) and the 100 % overload both run, and the
    static load moves as it must: outputs are zeroed on the nominal vehicle, so the
    springs' mean extra force sum_i k_i (mean travel_i - nominal mean travel_i) equals
    the payload's weight change dm g (vertical force balance of the sprung mass).
    Tolerance 5 %: the means are taken over a 2 s drive on class B roads, where the
    dynamic travel (about 1 mm sd) barely moves a 2 s mean against static shifts of
    1-5 cm."""
    for vid in VEHICLES:
        _, d = _drive(vid, seed=9, duration=2.0)       # class B roads: small dynamics
        vp = load_vehicle(vid)
        P = next(m.mass for m in vp.sprung if m.payload)
        nom = _sim(vid, d, None)
        for dm in (-P, P):
            res = _sim(vid, d, {"payload": {"mass": dm}})
            assert res.meta["effect_notes"]["payload_mass_kg"] == pytest.approx(P + dm)
            force = sum(vp.axles[int(c[10:-1]) - 1].spring_stiffness
                        * (np.mean(res.channels[c]) - np.mean(nom.channels[c]))
                        for c in res.channels if c.startswith("susp_disp_"))
            assert force == pytest.approx(dm * 9.81, rel=0.05), (vid, dm)


def test_leaf_friction_largest_force_simulates():
    """12 kN per spring (the range's end), alone and with the smallest smoothing velocity
    (the stiffest corner), runs on a class D/C road with a step halving to spare; friction lowers suspension travel
    against the nominal run (the spring sticks)."""
    _, d = _drive("dump_truck_8x4", seed=1, duration=3.0)
    nom = _sim("dump_truck_8x4", d, None)
    sd0 = max(np.std(nom.channels[c]) for c in nom.channels if c.startswith("susp_disp_"))
    for eff in ({"force": 12000.0}, {"force": 12000.0, "velocity": 0.005}):
        res = _sim("dump_truck_8x4", d, {"leaf_friction": eff})
        assert res.meta["dt_halvings"] < MAX_DT_HALVINGS      # one halving left as a margin
        sd = max(np.std(res.channels[c]) for c in res.channels if c.startswith("susp_disp_"))
        assert sd < 0.8 * sd0


def test_force_that_used_to_fail_runs_with_a_halved_step(monkeypatch):
    """Issue 15: 16.4 kN stopped with "no output stored at t = ..." -- Newton did not
    converge at dt = 2.5 ms (the friction slope F / v0 outweighs the axle's inertia
    term), Exudyn's own step reduction then left the output grid.  The simulator now
    repeats the run with the step halved: the same force (the range widened for this
    test only) runs at dt = 1.25 ms and says so in meta."""
    from vehicles.effects.base import Parameter

    eff = EFFECTS["leaf_friction"]
    wide = tuple(replace(p, range=(0.0, 20000.0)) if p.name == "force" else p
                 for p in eff.parameters)
    monkeypatch.setattr(type(eff), "parameters", wide)
    assert isinstance(wide[0], Parameter)
    _, d = _drive("dump_truck_8x4", seed=0, duration=8.0)   # the drive of the report
    res = _sim("dump_truck_8x4", d, {"leaf_friction": 16400.0})
    assert res.meta["dt_halvings"] == 1
    assert res.meta["dt"] == pytest.approx(0.5 * load_vehicle("dump_truck_8x4").solver.dt)
    assert np.all(np.isfinite(res.channels["body_acc_1L"]))


def test_out_of_range_value_refused_by_simulate():
    _, d = _drive("e_tractor", seed=1, duration=2.0)
    with pytest.raises(EroadInputError, match=r"range for vehicle e_tractor: \[-10000, 10000\]"):
        _sim("e_tractor", d, {"payload": -10500.0})


@pytest.mark.slow
@pytest.mark.parametrize("vehicle", VEHICLES)
def test_full_sweep_every_range_end_simulates(vehicle):
    """benchmarks/effect_ranges.py for one vehicle: every parameter at its range ends,
    three points inside and the stiff corners simulates (8 s record, null scenario seed 1)."""
    er, d = _drive(vehicle, seed=1, duration=8.0)
    failed = []
    for name, values, label in er.cases(vehicle):
        r = er.run_case(vehicle, d, name, values, 1)
        if not r["ok"]:
            failed.append(f"{name} {label}: {r['note']}")
    assert not failed, "\n".join(failed)
