"""Coulomb friction in the collector (catenary.contact.Collector.friction,
vehicles.pantograph_model PantographParams.frame_friction) against closed forms.

1. Free decay of a mass on a spring with Coulomb friction to the base (Den Hartog's
   closed form): the extremes fall by 2 F_c / k per half period pi sqrt(m/k), the mass
   stops for good at the first extreme with |x| <= F_c / k.  The collector is held far
   below the wire, so the line plays no part.  Tolerance: extremes within 1 % of the
   decrement 2 F_c / k (HHT with alpha = 0 at 1e-4 s has a period error of
   (omega dt)^2 / 12 ~ 3e-7 and no amplitude error; the stick/slip switch is resolved to
   one step, omega dt = 0.002, a displacement error of order (omega dt)^2 A ~ 2e-7 m);
   half periods within two steps.
2. Hysteresis of the pantograph pressed against the line under a slow base motion (what
   EN 50206-1 measures as the static force raising against lowering): with the lower
   frame's spring and damper removed, the quasi-static contact force is F0 + F_c while
   the base rises and F0 - F_c while it falls, so the two strokes differ by 2 F_c.
   Tolerance 4 %: the slipping frame's inertia at 0.1 Hz and 0.1 m is below
   6 kg x A omega^2 = 0.24 N, under 1 % of 2 F_c = 40 N; the line's own motion under the
   moving head adds the rest.
3. Friction zero leaves the run identical to a collector without the field (the code
   path is skipped), and a negative or non-finite friction is refused with one line.
4. Friction no load overcomes welds the DOF to the base: the three-mass pantograph then
   is the two-mass chain on the base (another model, same line), and a contact DOF held
   by friction pushes the line as one held by a stiff spring does (this one checks the
   contact's column in the friction solve; tolerances in each test).
"""
import math
from dataclasses import replace

import numpy as np
import pytest

from catenary.contact import Collector, simulate_contact
from catenary.line import ContactLine, load_line
from eroad.errors import EroadInputError
from vehicles.pantograph_model import collector, load_pantograph


@pytest.fixture(scope="module")
def short_line():
    lp = load_line("truck_ohl")
    return ContactLine(replace(lp, n_spans=3, element_length=0.5))


def _den_hartog(x0: float, fk: float, n_max: int = 50) -> list:
    """Extremes of the free decay with Coulomb friction, from rest at x0 (relative to
    the spring's rest position); fk = F_c / k."""
    xs = [x0]
    while abs(xs[-1]) > fk and len(xs) < n_max:
        xs.append(-xs[-1] + math.copysign(2.0 * fk, xs[-1]))
    return xs


@pytest.mark.parametrize("alpha", [0.0, -0.05])
def test_free_decay_matches_coulomb_closed_form(short_line, alpha):
    m, k, fc, step = 10.0, 4000.0, 20.0, 0.047
    col = Collector(M=np.array([[m]]), C=np.zeros((1, 1)), K=np.array([[k]]), head=0,
                    f_static=np.array([-2000.0]), base_k=np.array([k]),
                    base_c=np.zeros(1), labels=("mass",), friction=fc)
    dt, v, dur = 1e-4, 20.0, 1.6
    n = int(math.floor(dur / dt + 1e-9)) + 1
    zb = np.full(n, step)
    zb[0] = 0.0  # the base jumps up by `step` after the static start
    r = simulate_contact(short_line, col, speed=v, x_start=10.0, x_end=10.0 + v * dur,
                         dt=dt, alpha=alpha, base_z=zb, base_zdot=np.zeros(n))
    assert np.all(r["force"] == 0.0)  # never touches the wire
    z0 = r["collector"][0, 0]
    x = r["collector"][:, 0] - (z0 + step)  # about the spring's new rest position
    expect = _den_hartog(x[0], fc / k)
    assert len(expect) == 6  # -0.047, 0.037, -0.027, 0.017, -0.007, -0.003 (stuck)
    half = math.pi * math.sqrt(m / k)
    dec = 2.0 * fc / k
    for i, xe in enumerate(expect[1:], start=1):
        j = int(round(i * half / dt))
        window = x[max(j - 50, 0): j + 51]
        got = window[np.argmax(np.abs(window))] if i < len(expect) - 1 else x[j + 100]
        assert got == pytest.approx(xe, abs=0.01 * dec), (i, got, xe)
    # stuck for good after the last motion: no drift, friction holds the spring force
    last = int(round((len(expect) - 1) * half / dt)) + 20
    assert np.ptp(x[last:]) < 1e-9
    assert np.abs(r["friction"][last:]).max() <= fc
    # the friction force holds the spring: with alpha = 0 (trapezoidal rule) a velocity
    # held at zero makes the acceleration, so the force, alternate about the true value
    # step by step (a1 = -a0); the average of two steps is exact.  HHT's alpha < 0 damps
    # the alternation (a1 = -(1 - gamma) / gamma a0, 0.82 per step at -0.05)
    fr = r["friction"][last:]
    if alpha == 0.0:
        pair = 0.5 * (fr[1:] + fr[:-1])
        assert pair == pytest.approx(k * x[last + 1:], abs=1e-6)
    else:
        assert fr[200:] == pytest.approx(k * x[last + 200:], abs=1e-6)
    # half periods: sign changes of the velocity at multiples of pi sqrt(m/k)
    vel = np.diff(x)
    turns = np.flatnonzero((vel[1:] * vel[:-1] < 0) | ((vel[:-1] != 0) & (vel[1:] == 0)))
    for i, tt in enumerate(turns[:4], start=1):
        assert abs((tt + 1) * dt - i * half) <= 2 * dt, (i, (tt + 1) * dt, i * half)


def test_hysteresis_is_twice_the_friction(short_line):
    pp = replace(load_pantograph("truck"), lower_stiffness=0.0, lower_damping=0.0,
                 frame_friction=20.0)
    col = collector(pp)
    assert col.friction == 20.0 and col.friction_dof == -1
    dt, v, f_hz, amp = 1e-3, 2.0, 0.1, 0.1
    dur = 12.0
    n = int(math.floor(dur / dt + 1e-9)) + 1
    t = dt * np.arange(n)
    w = 2 * math.pi * f_hz
    zb = amp * np.sin(w * t)
    zbd = amp * w * np.cos(w * t)
    r = simulate_contact(short_line, col, speed=v, x_start=40.0, x_end=40.0 + v * dur,
                         dt=dt, base_z=zb, base_zdot=zbd)
    F = r["force"]
    assert F.min() > 0.0
    # the frame sticks after each reversal until the chain's springs take 2 F_c (about
    # 3 cm of base travel); around mid-stroke it slips
    rising = (t > 2.0) & (np.cos(w * t) > 0.9)
    falling = (t > 2.0) & (np.cos(w * t) < -0.9)
    assert np.all(r["friction"][rising] == pytest.approx(20.0))
    assert np.all(r["friction"][falling] == pytest.approx(-20.0))
    width = F[rising].mean() - F[falling].mean()
    assert width == pytest.approx(2 * 20.0, rel=0.04)
    assert F[rising].mean() == pytest.approx(pp.static_force + 20.0, rel=0.02)


def test_zero_friction_is_the_run_without_it_and_bad_values_refused(short_line):
    pp = load_pantograph("truck")
    assert pp.frame_friction == 0.0
    base = collector(pp)
    kw = dict(speed=20.0, x_start=50.0, x_end=60.0, dt=1e-3)
    a = simulate_contact(short_line, base, **kw)
    b = simulate_contact(short_line, replace(base, friction=0.0, friction_dof=1), **kw)
    assert np.array_equal(a["force"], b["force"])
    assert np.all(a["friction"] == 0.0)
    with_f = simulate_contact(short_line, replace(base, friction=5.0), **kw)
    assert not np.array_equal(a["force"], with_f["force"])
    for bad in (-1.0, float("nan")):
        with pytest.raises(EroadInputError, match="friction"):
            simulate_contact(short_line, replace(base, friction=bad), **kw)
    with pytest.raises(EroadInputError, match="friction_dof"):
        simulate_contact(short_line, replace(base, friction=5.0, friction_dof=3), **kw)


def test_pantograph_file_friction_optional_and_checked(tmp_path):
    from vehicles.pantograph_model import DATA_DIR

    text = (DATA_DIR / "pantograph_truck.toml").read_text().splitlines()
    no_f = [ln for ln in text if not ln.startswith("frame_friction")]
    p = tmp_path / "p.toml"
    p.write_text("\n".join(no_f) + "\n")
    assert load_pantograph(p).frame_friction == 0.0  # files written before it still load
    bad = [ln if not ln.startswith("frame_friction =") or "assumed" in ln
           else "frame_friction = -3.0" for ln in text]
    p.write_text("\n".join(bad) + "\n")
    with pytest.raises(EroadInputError, match="frame_friction must be a finite number >= 0"):
        load_pantograph(p)


def test_cli_refuses_negative_friction_in_one_line(tmp_path, capsys):
    from eroad.cli import main

    with pytest.raises(SystemExit) as e:
        main(["pantograph-contact", "--road", "x.npz", "--out", str(tmp_path),
              "--frame-friction", "-2"])
    assert e.value.code != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert "--frame-friction" in err[-1] and "must be >= 0" in err[-1]
    assert not any(tmp_path.iterdir())


def test_friction_beyond_any_load_welds_the_frame_to_the_base(short_line):
    """A friction no force in the run can overcome holds the lower frame on the base: the
    three-mass pantograph then is the two-mass chain (head, upper frame) whose upper frame
    stands on the base through k2, c2 with the lower frame's start height as preload.
    Both run on the same line under the same base motion (5 mm at 3 Hz, from rest); their contact
    forces agree to 1e-3 of the force's own sd (the stuck frame follows the trapezoidal
    integral of the base velocity, which differs from the base height by O(dt^2))."""
    pp = replace(load_pantograph("truck"), frame_friction=1.0e7)
    dt, v, dur = 1e-3, 20.0, 3.0
    n = int(math.floor(dur / dt + 1e-9)) + 1
    t = dt * np.arange(n)
    w = 2 * math.pi * 3.0
    # from rest: the start is static, so a base already moving at t = 0 would offset the
    # frame by dt/2 times that velocity in the first step
    zb, zbd = 0.005 * (1.0 - np.cos(w * t)), 0.005 * w * np.sin(w * t)
    kw = dict(speed=v, x_start=40.0, x_end=40.0 + v * dur, dt=dt, base_z=zb, base_zdot=zbd)
    stuck = simulate_contact(short_line, collector(pp), **kw)
    assert np.all(np.abs(stuck["friction"]) < 1.0e7)  # never slipped
    z3 = stuck["collector"][:, 2]
    assert np.ptp(z3 - zb) < 1e-6
    k1, k2, c1, c2 = pp.head_stiffness, pp.upper_stiffness, pp.head_damping, pp.upper_damping
    two = Collector(M=np.diag([pp.head_mass, pp.upper_mass]),
                    C=np.array([[c1, -c1], [-c1, c1 + c2]]),
                    K=np.array([[k1, -k1], [-k1, k1 + k2]]), head=0,
                    f_static=np.array([0.0, k2 * z3[0]]), base_k=np.array([0.0, k2]),
                    base_c=np.array([0.0, c2]))
    ref = simulate_contact(short_line, two, **kw)
    assert np.std(ref["force"]) > 5.0  # the base motion does drive the chain
    assert np.max(np.abs(stuck["force"] - ref["force"])) < 1e-3 * np.std(ref["force"])


def test_welded_contact_dof_matches_a_stiff_spring_weld(short_line):
    """Friction on the contact DOF itself, beyond any load, holds the head on the base
    while it pushes the line (a stiff 1e6 N/m contact, so the contact's own column
    matters in the friction solve).  Reference: the same head held on the base by a
    1e9 N/m spring with the preload that starts it at the same height, no friction.  The
    spring lets the head move by (force change) / 1e9 ~ 2e-7 m, which the contact turns
    into ~0.2 N, and contact opens and closes in this run (min force 0); tolerance 3 %
    of the force's sd (40 N)."""
    dt, v, dur = 1e-3, 20.0, 3.0
    n = int(math.floor(dur / dt + 1e-9)) + 1
    t = dt * np.arange(n)
    w = 2 * math.pi * 3.0
    zb, zbd = 0.005 * (1.0 - np.cos(w * t)), 0.005 * w * np.sin(w * t)
    kw = dict(speed=v, x_start=40.0, x_end=40.0 + v * dur, dt=dt, base_z=zb, base_zdot=zbd,
              contact_stiffness=1.0e6)
    held = Collector(M=np.array([[1.0]]), C=np.zeros((1, 1)), K=np.array([[100.0]]), head=0,
                     f_static=np.array([70.0]), base_k=np.array([100.0]), base_c=np.zeros(1),
                     friction=1.0e6, friction_dof=0)
    r = simulate_contact(short_line, held, **kw)
    z = r["collector"][:, 0]
    assert np.ptp(z - zb) < 1e-6
    kw_ = 1.0e9
    spring = Collector(M=np.array([[1.0]]), C=np.zeros((1, 1)), K=np.array([[100.0 + kw_]]),
                       head=0, f_static=np.array([70.0 + kw_ * z[0]]),
                       base_k=np.array([100.0 + kw_]), base_c=np.zeros(1))
    ref = simulate_contact(short_line, spring, **kw)
    sd = np.std(ref["force"])
    assert sd > 20.0 and ref["force"].min() == 0.0
    assert np.max(np.abs(r["force"] - ref["force"])) < 0.03 * sd


def test_drive_with_friction_archives_the_friction_force(tmp_path, capsys):
    """``eroad pantograph-contact --frame-friction 20`` on a short class D drive: the run's
    ``contact.npz`` carries the friction force, bounded by 20 N and at 20 N while the frame
    slips; the summary and the printout name the friction."""
    import json

    from eroad.cli import main

    road = tmp_path / "road.npz"
    assert main(["road", "generate", "--class", "D", "--length", "150", "--width", "4",
                 "--seed", "3", "--out", str(road)]) == 0
    assert main(["pantograph-contact", "--road", str(road), "--out", str(tmp_path / "o"),
                 "--duration", "4", "--no-compare", "--frame-friction", "20"]) == 0
    out = capsys.readouterr().out
    assert "frame friction 20 N" in out
    run = next((tmp_path / "o" / "pantograph_contact").iterdir())
    d = np.load(run / "data" / "contact.npz")
    fr = d["friction"]
    assert np.abs(fr).max() <= 20.0 + 1e-9
    assert np.mean(np.isclose(np.abs(fr), 20.0)) > 0.1  # slips some of the time
    s = json.loads((run / "summary.json").read_text())
    assert s["config"]["frame_friction_N"] == 20.0
    assert (run / "figures" / "contact.png").is_file()
