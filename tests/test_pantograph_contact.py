"""Moving penalty contact with the lumped pantograph (catenary.contact,
vehicles.pantograph_model) and the ``eroad pantograph-contact`` command's input errors.

Physics checks: at the static start the contact force equals the static uplift
(statics of the chain: the force passes through every spring, less what the base spring
k3 takes; tolerance 1e-9 relative, round-off of one sparse solve); the run's mean contact force equals the static force
within 1 % (momentum balance of the pantograph: mean(Fc) = F0 - mean(sum m a) -
k3 mean(z3 - zb), the last term below 0.1 N/m x 0.1 m and the momentum change over a
run of seconds below 0.1 N); a base pulled down faster than the head can follow opens
the contact (force exactly zero, head below the wire) and the contact closes again.
"""
import math

import numpy as np
import pytest

from catenary.contact import simulate_contact
from catenary.line import ContactLine, load_line
from catenary.stats import contact_statistics
from eroad.cli import main
from eroad.errors import EroadInputError
from vehicles.pantograph_model import (collector, lateral_response, load_pantograph,
                                       pantograph_ids, vertical_modes)


@pytest.fixture(scope="module")
def short_line():
    from dataclasses import replace

    lp = load_line("truck_ohl")
    return ContactLine(replace(lp, n_spans=3, element_length=0.5))


@pytest.fixture(scope="module")
def pant():
    return load_pantograph("truck")


def test_static_start_force_equals_uplift(short_line, pant):
    r = simulate_contact(short_line, collector(pant), speed=20.0, x_start=50.0, x_end=52.0,
                         dt=1e-3)
    # statics of the chain: F0 minus what the base spring k3 takes at the lower frame
    z3 = r["collector"][0, 2]
    expected = pant.static_force - pant.lower_stiffness * z3
    assert expected != pant.static_force
    assert r["force"][0] == pytest.approx(expected, rel=1e-9)
    # penetration of the penalty = F0 / k_c
    pen = r["head_z"][0] - r["wire_z"][0]
    assert pen == pytest.approx(expected / r.meta["contact_stiffness"], rel=1e-9)


def test_mean_force_equals_static_force_and_no_loss(short_line, pant):
    r = simulate_contact(short_line, collector(pant), speed=80 / 3.6, x_start=50.0,
                         x_end=100.0, dt=1e-3)
    s = contact_statistics(r["force"], time=r.time, lowpass_hz=None)
    assert s.mean == pytest.approx(pant.static_force, rel=0.01)
    assert s.sd > 1.0  # the span stiffness variation does excite the pantograph
    assert s.loss_percent == 0.0


def test_base_pulled_down_loses_and_regains_contact(short_line, pant):
    """Base lowered by 0.1 m within 20 ms at t = 0.5 s: the head (spring-coupled, 18 kg
    over k3 = 0.1 N/m... pulled through c3 = 70 N s/m at 5 m/s = 350 N) falls away from
    the wire; the static force lifts it back later."""
    dt = 1e-3
    x0, x1, v = 40.0, 100.0, 20.0
    n = int(math.floor((x1 - x0) / v / dt + 1e-9)) + 1
    t = dt * np.arange(n)
    ramp = np.clip((t - 0.5) / 0.02, 0.0, 1.0)
    zb = -0.1 * ramp
    zbd = np.where((t >= 0.5) & (t < 0.52), -0.1 / 0.02, 0.0)
    r = simulate_contact(short_line, collector(pant), speed=v, x_start=x0, x_end=x1, dt=dt,
                         base_z=zb, base_zdot=zbd)
    F = r["force"]
    lost = F <= 0.0
    assert lost.any(), "contact never opened"
    assert np.all(F >= 0.0)
    gap = r["head_z"] - r["wire_z"]
    assert np.all(gap[lost] <= 1e-12)          # open contact: head at or below the wire
    assert np.all(gap[~lost] > 0.0)            # closed: penetration > 0
    first = int(np.argmax(lost))
    assert r.time[first] >= 0.5
    assert F[-1] > 0.0, "contact did not close again"


def test_no_contact_when_head_starts_below(short_line, pant):
    from dataclasses import replace

    down = replace(pant, static_force=0.0)
    r = simulate_contact(short_line, collector(down), speed=20.0, x_start=50.0, x_end=55.0,
                         dt=1e-3)
    assert np.all(r["force"] == 0.0)


def test_pantograph_files_load_with_sources():
    assert {"truck", "en50318", "dsa380"} <= set(pantograph_ids())
    for name in pantograph_ids():
        pp = load_pantograph(name)
        documented = {k for k, _ in pp.sources}
        numeric = {f for f in pp.__dataclass_fields__ if f not in ("name", "sources")}
        assert numeric <= documented, f"{name}: fields without a source: {numeric - documented}"
        f = vertical_modes(pp)
        assert f[0] < 0.5 and 3 < f[1] < 30  # free chain: soft frame mode + head/frame modes


def test_pantograph_file_errors(tmp_path):
    p = tmp_path / "p.toml"
    p.write_text('name = "x"\nhead_mas = 1.0\n')
    with pytest.raises(EroadInputError, match="unknown key 'head_mas'"):
        load_pantograph(p)
    with pytest.raises(EroadInputError, match="unknown pantograph"):
        load_pantograph("nope")


def test_lateral_head_follows_slow_base_and_resonates(pant):
    """Static gain 1 (a slow ramp is followed within 1 %); at the lateral natural
    frequency the head's amplitude exceeds the base's (damping ratio ~0.17 gives ~3x)."""
    t = np.arange(0, 20, 1e-3)
    yb = 0.01 * np.clip(t / 10, 0, 1)
    yh = lateral_response(pant, t, yb)
    assert yh[-1] == pytest.approx(0.01, rel=0.01)
    fn = math.sqrt(pant.lateral_stiffness / pant.lateral_mass) / (2 * math.pi)
    yb = 0.001 * np.sin(2 * math.pi * fn * t)
    yh = lateral_response(pant, t, yb)
    assert np.max(np.abs(yh[t > 10])) > 2.0 * 0.001


def test_cli_needs_a_road_or_reference(tmp_path, capsys):
    code = main(["pantograph-contact", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "road" in err
    code = main(["pantograph-contact", "--out", str(tmp_path), "--road",
                 str(tmp_path / "missing.npz")])
    err = capsys.readouterr().err
    assert code == 2 and "not found" in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())  # nothing written for a refused input


def test_speed_at_or_above_the_wave_speed_is_refused(short_line, pant):
    """At and above the contact wire's wave speed sqrt(T / rho_A) the moving load has no
    steady response: refused with one line that gives the wave speed and the 70 % design
    limit; just below it the integrator is entered (a 2-step travel)."""
    c = short_line.params.contact.wave_speed
    for v in (c, 1.5 * c):
        with pytest.raises(EroadInputError, match=rf"at or above the contact wire's wave speed "
                                                  rf"sqrt\(T / rho_A\) = {c * 3.6:.0f} km/h"):
            simulate_contact(short_line, collector(pant), speed=v, x_start=50.0, x_end=60.0)
    r = simulate_contact(short_line, collector(pant), speed=0.99 * c, x_start=50.0,
                         x_end=50.0 + 2.5 * 0.99 * c * 1e-3, dt=1e-3)
    assert r["force"].size == 3


def test_cli_drive_options_without_a_road_are_refused(tmp_path, capsys):
    """``--speed-kmh`` and the other drive options shape a drive (``--road``); with the railway
    reference alone they would be silently ignored (900 km/h ran the reference at 250 and 300):
    refused in one line naming them, nothing written."""
    code = main(["pantograph-contact", "--out", str(tmp_path / "o"), "--railway-reference",
                 "--speed-kmh", "900", "--dt", "0.002"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert "--speed-kmh, --dt: options of a drive (--road FILE)" in err
    assert not (tmp_path / "o").exists()


def test_cli_unknown_line_refused_before_any_run_folder(tmp_path, capsys):
    road = tmp_path / "road.npz"
    road.write_bytes(b"")  # never read: the line id is checked first
    code = main(["pantograph-contact", "--out", str(tmp_path / "out"), "--road", str(road),
                 "--line", "no_such_line"])
    err = capsys.readouterr().err
    assert code == 2 and "unknown contact line" in err
    assert not (tmp_path / "out").exists()


def test_reference_printout_names_what_is_outside_with_its_range():
    """The railway reference's printout says in words what lies inside the EN 50318 ranges and
    gives each value outside with its range (uplift in mm), not a Python dict."""
    from studies.cli_pantograph_contact import _ref_lines

    case = {"stats": {"mean": 117.9, "sd": 34.2, "stat_max": 220.4, "stat_min": -22.0, "actual_max": 200.0,
                      "actual_min": 58.3, "max_support_uplift": 0.0425, "loss_percent": 0.0},
            "ranges": {"mean": [110, 120], "sd": [26, 31], "stat_min": [-5, 20], "max_support_uplift": [0.048, 0.055],
                       "loss_percent": [0, 0]},
            "inside": {"mean": True, "sd": False, "stat_min": False, "max_support_uplift": False, "loss_percent": True}}
    head, line = _ref_lines("250", case)
    assert head.startswith("reference 250 km/h: mean 117.9 N, sd 34.2 N")
    assert "2 of 5 (mean, loss)" in line
    assert "sd 34.2 N (range 26 to 31)" in line
    assert "Fm-3sd -22.0 N (range -5 to 20)" in line
    assert "support uplift 42.5 mm (range 48 to 55)" in line
    assert "{" not in line
