"""Railway reference case (issue 18): the EN 50318-type 60 m catenary with slack droppers
and the two-mass reference pantograph against the EN 50318:2002 reference ranges
(:data:`studies.pantograph_contact.REFERENCE_RANGES`, sourced there).

Slow (about 5 min on 2 shared cores: two passes of 590 m at dt = 0.5 ms over 9 600 DOFs);
run with ``pytest -m slow tests/test_catenary_reference.py``.  What holds with the
parameters in ``catenary/data/line_en50318.toml`` and ``vehicles/data/
pantograph_en50318.toml`` is asserted; the contact-force standard deviation does not yet
fall inside the published ranges (see docs/pantograph_contact.md), so that check is a
strict expected failure: it turns into an error as soon as it passes, so the marker gets
removed then.

A fast check of the slack-dropper mechanics is in the same file (not slow).
"""
import numpy as np
import pytest

from catenary.contact import simulate_contact
from catenary.line import ContactLine, load_line
from vehicles.pantograph_model import collector, load_pantograph


@pytest.fixture(scope="module")
def reference():
    from studies.pantograph_contact import railway_reference

    return railway_reference()


@pytest.mark.slow
@pytest.mark.parametrize("kmh", ["250", "300"])
def test_reference_mean_and_no_loss(reference, kmh):
    case = reference["cases"][kmh]
    st, rg = case["stats"], case["ranges"]
    assert rg["mean"][0] <= st["mean"] <= rg["mean"][1]
    assert st["loss_percent"] == 0.0
    assert case["max_slack_droppers"] >= 1  # droppers near the pantograph do go slack


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="contact-force sd above the EN 50318:2002 range "
                   "(250 km/h: 34 N vs 26-31 N; 300 km/h: 46 N vs 32-40 N), see "
                   "docs/pantograph_contact.md")
@pytest.mark.parametrize("kmh", ["250", "300"])
def test_reference_sd_inside_published_range(reference, kmh):
    case = reference["cases"][kmh]
    lo, hi = case["ranges"]["sd"]
    assert lo <= case["stats"]["sd"] <= hi


def test_slack_dropper_static_tension_and_opening():
    """Droppers carry the contact wire's weight (tributary length times the weight per
    metre less the pre-sag share, plus clamp), sum over a span = wire weight between the
    first and last dropper's midpoints to the poles; a pantograph pushing the wire up makes
    the droppers next to it slack, and a slack dropper carries no force (the contact wire
    rises above the messenger by more than T0 / k_d there)."""
    from dataclasses import replace

    lp = replace(load_line("en50318"), n_spans=3, element_length=0.5)
    cl = ContactLine(lp)
    t0 = cl.dropper_static_tension()
    assert t0.size == 27 and np.all(t0 > 0)
    q = lp.contact.mass_per_length * lp.gravity - 8 * lp.contact.tension * lp.presag / lp.span ** 2
    covered = 0.5 * (lp.dropper_x[-1] + lp.span) - 0.5 * lp.dropper_x[0]
    clamps = 9 * lp.gravity * (lp.clamp_mass_contact + 0.5 * lp.dropper_mass)
    assert t0[:9].sum() == pytest.approx(q * covered + clamps, rel=1e-12)
    col = collector(load_pantograph("en50318"))
    r = simulate_contact(cl, col, speed=250 / 3.6, x_start=70.0, x_end=110.0, dt=5e-4)
    assert r["n_slack"].max() >= 1
    assert r.meta["active_set_unconverged_steps"] == 0
    lin = simulate_contact(ContactLine(replace(lp, dropper_slack=False)), col,
                           speed=250 / 3.6, x_start=70.0, x_end=110.0, dt=5e-4)
    assert lin["n_slack"].max() == 0
    # the slack line is softer under the pantograph: larger uplift where droppers open
    assert r["uplift"].max() > lin["uplift"].max()


def test_reference_takes_line_parameters_and_pre_sag_moves_the_uplift():
    """railway_reference runs the LineParams it is given (the pre-sag scan,
    benchmarks/catenary_presag_scan.py, relies on it): on a 6-span copy of the reference line
    at 250 km/h, dropping the pre-sag from 55 mm to 0 raises the support uplift and lowers
    the force sd, the direction the full scan measured (uplift 42.5 -> 53.2 mm, sd 34.2 ->
    31.2 N on 10 spans).  The thresholds are the signs plus margins (3 mm, 1 N) well inside
    the differences seen on 10 spans, so a run that ignored the parameters fails."""
    from dataclasses import replace

    from studies.pantograph_contact import railway_reference

    base = replace(load_line("en50318"), n_spans=6)
    r55 = railway_reference((250.0,), line=base)["cases"]["250"]
    r0 = railway_reference((250.0,), line=replace(base, presag=0.0))["cases"]["250"]
    assert r0["stats"]["max_support_uplift"] > r55["stats"]["max_support_uplift"] + 0.003
    assert r0["stats"]["sd"] < r55["stats"]["sd"] - 1.0


@pytest.mark.slow
@pytest.mark.parametrize("kmh", ["250", "300"])
def test_reference_with_little_pre_sag_meets_the_sd_and_uplift_ranges(kmh):
    """The scan's finding kept as a regression check: with 10 mm of pre-sag instead of the
    shipped 55 mm the sd and the support uplift fall inside the EN 50318:2002 ranges at both
    speeds (measured 30.4 / 34.3 N, 51.2 / 59.7 mm; results/pantograph_contact/
    20261128-presag-scan/).  Not the shipped value: see docs/pantograph_contact.md."""
    from dataclasses import replace

    from studies.pantograph_contact import railway_reference

    case = railway_reference((float(kmh),), line=replace(load_line("en50318"), presag=0.010))["cases"][kmh]
    assert case["inside"]["sd"] and case["inside"]["max_support_uplift"]
