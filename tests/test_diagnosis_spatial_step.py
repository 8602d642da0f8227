"""road_fit.NMAX_SPATIAL_STEP: a fitted cut that the spatial spectrum does not show is not the road's.

A sensor low-pass far below 20 Hz leaves only noise above the trial cuts of ``fit_nmax`` on a smooth
road, so every segment looks cut and the roll-off veto (which needs one segment showing a roll-off)
cannot act; cut, the road takes the low-pass up and no candidate has anything left to explain.  A
road that stops at n_c steps down there in spatial frequency at every speed
(``diagnosis.band_edge``); a low-pass fixed in Hz does not.  The records are made by the diagnosis's
own nominal model (``TruckModel``) on a smooth one-segment road (Gq(n0) 16e-6 m^3, class A/B) at a
speed rising from 8 to 15 m/s, with a noise floor added (the spatial step statistic read 0.83 at most
on the sensor record, 1.0 asked), so the test checks the choice,
not the model.
"""
import numpy as np
import pytest

DUR, FS = 16.0, 200.0
# a logger noise floor of 0.1 m/s^2: with 0.03 the attenuated road stays above it and the
# segment shows as a roll-off (the veto's case); with 0.1 it looks cut (nmax 1.5 when written)
ACC_NOISE, DISP_NOISE = 0.1, 1.0e-4
GQ = 16e-6


def _model(nmax=None, gq=GQ, rising=True):
    from diagnosis.truck_model import TruckModel

    t = np.arange(int(DUR * FS)) / FS
    v = 8.0 + 7.0 * t / DUR if rising else np.full(t.size, 10.0)
    names = [f"{q}{i}{s}" for q in ("susp_disp_", "axle_acc_", "body_acc_")
             for i in (1, 2, 3, 4) for s in "LR"]
    noise = {c: DISP_NOISE if c.startswith("susp") else ACC_NOISE for c in names}
    return TruckModel("dump_truck_8x4", t, v, np.array([0.0, DUR]), np.array([gq]), noise, names,
                      w=np.array([2.0]), nmax=None if nmax is None else np.array([nmax]))


def _measured(nmax, seed, effects=None, gq=GQ, rising=True):
    from diagnosis.signals import Signals

    m = _model(nmax, gq, rising)
    ch = m.add_noise(m.run(effects or {}, 0.0, DUR, 1000 + seed), 2000 + seed)
    return Signals(m.time, ch, speed=m.speed.copy())


def _fit(sig, gq=GQ, rising=True):
    from diagnosis import road_fit as P

    m = _model(gq=gq, rising=rising)
    return float(P.fit_nmax(m, sig, m.gq, seed=3)[0]), m.high_band


SENSOR = {"sensor": {"cutoff": 6.5}}


@pytest.fixture(scope="module")
def sensor_record():
    return _measured(5.0, 1, SENSOR)


def test_a_steep_sensor_low_pass_looks_cut_without_the_rule(sensor_record, monkeypatch):
    from diagnosis import road_fit as P

    monkeypatch.setattr(P, "NMAX_SPATIAL_STEP", False)
    nmax, hb = _fit(sensor_record)
    assert nmax < P.ROAD_NMAX, hb
    assert not hb["vetoed"]


def test_with_the_rule_the_unstepped_cut_is_not_taken(sensor_record, monkeypatch):
    from diagnosis import road_fit as P
    from diagnosis.band_edge import trial_cut

    tc = trial_cut(sensor_record, P.NMAX_GRID, P.ROAD_NMAX)
    assert tc["cut"] is None and tc["windows"] >= 20, tc
    monkeypatch.setattr(P, "NMAX_SPATIAL_STEP", True)
    nmax, hb = _fit(sensor_record)
    assert nmax == P.ROAD_NMAX and hb["unstepped"] and hb["cut"] == [], hb


def test_with_the_rule_a_road_cut_that_steps_is_kept(monkeypatch):
    """A class C road (256e-6 m^3) cut at 2 cycles/m, at a steady 10 m/s (as test_diagnosis_nmax's cut
    road; on the smooth road the band above the cut is noise whatever the road does, and on the
    rising speed fit_nmax does not cut it): the step in spatial frequency is there, the cut stays."""
    from diagnosis import road_fit as P

    monkeypatch.setattr(P, "NMAX_SPATIAL_STEP", True)
    nmax, hb = _fit(_measured(2.0, 2, gq=256e-6, rising=False), gq=256e-6, rising=False)
    assert nmax == 2.0 and not hb["unstepped"], hb


def test_the_report_says_why_no_segment_is_cut():
    """The saved blind drive the rule was found on (our truck, sensor 6.84 Hz, seed 647 case 18: both
    segments cut without a spatial step), its road record as the rule writes it."""
    import json
    from pathlib import Path

    from diagnosis.report import render_markdown

    p = (Path(__file__).resolve().parents[1]
         / "results/diagnosis_blind/20261130-frozen-rules-stop69/nominal/case018-summary.json")
    s = json.loads(p.read_text())
    assert s["meta"]["road_high_band"]["cut"] and not s["meta"]["road_high_band"].get("unstepped")
    assert "Cut road" in render_markdown(s, {})
    s["meta"]["road_high_band"] = {"cut": [], "rolloff": [], "vetoed": False, "unstepped": True}
    md = render_markdown(s, {})
    assert "step down nowhere" in md and "Cut road" not in md
