"""``eroad diagnose`` end to end on the Exudyn truck (issue 7, items 1, 2 and 4).

Fast tests use a 16 s synthetic drive, ``--quick`` and two candidate effects; the blind
check over synthetic cases is marked ``slow`` (``pytest -m slow``).
"""
import json
import subprocess
import sys

import pytest

from eroad.cli import main

#: summary fields that legitimately differ between two runs of the same diagnosis
RUN_FIELDS = ("timing", "dataset", "workers")


@pytest.fixture(scope="module")
def short_drive(tmp_path_factory):
    """A 16 s drive: nominal truck plus leaf-spring friction of 4 kN (seed 3)."""
    from drives.synth import synth_command

    out = tmp_path_factory.mktemp("diag") / "lf"
    synth_command(scenario="null", seed=3, effects=["leaf_friction=4000"], duration=16.0, out=out)
    return out


def _strip(summary):
    meta = dict(summary.get("meta", {}))
    for k in RUN_FIELDS:
        meta.pop(k, None)
    for k in ("band_refit", "joint_band"):      # second passes record their own run times
        if meta.get(k):
            rec = {f: v for f, v in meta[k].items() if f not in ("time_s", "first_pass_s")}
            for p in ("first_pass", "cut_pass"):
                if rec.get(p):
                    rec[p] = {f: v for f, v in rec[p].items() if f != "timing"}
            meta[k] = rec
    return dict(summary, meta=meta)


def test_same_summary_without_truth(short_drive, tmp_path):
    """The diagnosis reads nothing from truth/: a copy without it gives the same summary.json
    (all fields but the run's own timing, dataset path and worker count)."""
    from drives.synth import copy_without_truth

    blind = copy_without_truth(short_drive, tmp_path / "blind")
    assert not (blind / "truth").exists()
    args = ["diagnose", "--quick", "--effects", "leaf_friction,sensor", "--workers", "1"]
    assert main(args + [str(short_drive), "--out", str(tmp_path / "a")]) == 0
    assert main(args + [str(blind), "--out", str(tmp_path / "b")]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    b = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert _strip(a) == _strip(b)
    # the report is complete and names the friction the truth carries
    for key in ("localization", "ranking", "verdict", "how_far", "transmissibility"):
        assert key in a
    assert a["verdict"] == "leaf_friction"
    # what a correct model's signature reaches on this drive: the winner (leaf friction)
    # against its own records on 4 other road phases.  The two-input estimate, which the road does not
    # enter, stays within the fixed threshold 2 for a correct model (0.3-0.5 measured here);
    # the single-input one moves with the road (1.2-1.8 here, 4-13 on other drives)
    cm2 = a["signature_two_input"]["chi2_correct_model"]
    assert len(cm2) == 4 and all(0.0 < v < 2.0 for v in cm2)
    cm1 = a["signature"]["chi2_correct_model"]
    assert len(cm1) == 4 and all(v > 0.0 for v in cm1)
    assert (tmp_path / "a" / "report.md").is_file()
    assert (tmp_path / "a" / "figures" / "heatmap.png").is_file()
    # an existing run is not overwritten without --force
    proc = subprocess.run([sys.executable, "-m", "eroad.cli"] + args
                          + [str(blind), "--out", str(tmp_path / "b")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "--force" in proc.stderr


def test_missing_dataset_is_one_line(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "eroad.cli", "diagnose", str(tmp_path / "nope"),
                           "--out", str(tmp_path / "run")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "run").exists()


def test_road_fit_recovers_waviness(tmp_path):
    """On a null drive (truth = nominal model) the cheap road fit recovers level and waviness
    of a segment it finds whole.

    Drive: null scenario, seed 2, 20 s (truth: 4271e-6 m^3, w 2.29 for 0-5.4 s, then two
    smooth segments).  Checked: fitted segments of >= 4 s that lie >= 80 % inside one truth
    segment.  Tolerance: w within 0.35, level within a factor 1.5 (calibration half of the
    record, band powers of 1-12 Hz from about 2.5 s; measured on seeds 1-3: w errors
    0.1-0.3).  Known limitation: smooth segments after a rough one came out up to 4x low
    (seed 2, 26e-6 fitted as 7e-6); the per-window re-levelling of the ranking corrects
    the level, not the localisation."""
    from diagnosis.pipeline import load_measured, prepare
    from drives.synth import read_truth, synth_command

    ds = tmp_path / "null"
    synth_command(scenario="null", seed=2, duration=20.0, out=ds)
    drive, sig = load_measured(ds)
    ctx = prepare(sig, drive.vehicle)
    truth = read_truth(ds)["segments"]
    checked = 0
    for k in range(len(ctx.bounds) - 1):
        a, b = ctx.bounds[k], ctx.bounds[k + 1]
        for seg in truth:
            inside = min(b, seg["t_end"]) - max(a, seg["t_start"])
            if b - a >= 4.0 and inside >= 0.8 * (b - a):
                assert abs(ctx.model.w[k] - seg["w"]) < 0.35
                assert 1 / 1.5 < ctx.model.gq[k] / seg["Gq_n0"] < 1.5
                checked += 1
    assert checked >= 1


@pytest.mark.slow
def test_blind_cases(tmp_path):
    """Blind check (issue 7, item 2) on a small set: 6 cases (null, frame flexibility,
    leaf friction, bump stops, damper asymmetry, payload), diagnosed from copies without
    truth/.  Scored over ALL six cases against the truth, with a fixed minimum: at least
    5 of the 6 verdicts right, the null case "none", no confident wrong attribution.  (The
    earlier form scored only the cases the pipeline itself judged "detectable", a
    denominator of its own choosing that could shrink to one case.)  Why 5: these are
    cases 0-5 of the 30-case reference run (results/diagnosis_blind/20261121-30cases-v4,
    same seeds, strengths and settings), which had 5 of 6 right (case 3, a 10.3 mm bump
    stop, was named damper_asymmetry "ambiguous"); the run is seeded, so fewer is a
    regression, not chance; the documented target is top-1 >= 90 %.  The full 30-case
    run is ``benchmarks/bench_diagnosis.py``."""
    from diagnosis.blind import run_blind

    out = run_blind(tmp_path, 6, seed=0, workers=2, progress=lambda m: None)
    res = out["results"]
    assert len(res) == 6
    assert [r["effect"] for r in res] == ["none", "frame_flex", "leaf_friction", "bump_stop",
                                          "damper_asymmetry", "payload"]
    assert sum(r["verdict"] == r["effect"] for r in res) >= 5
    assert res[0]["verdict"] == "none"
    assert not any(r["verdict"] not in (r["effect"], "none")
                   and r["confidence"] == "clear" for r in res)


def test_per_model_nuisances_tilt_and_noise():
    """The nuisances profiled per model and window (nuisance.window_tilt, apply_tilt,
    window_noise), on 7.5 s of coloured noise at 200 Hz: a waviness change dw = 0.4 applied
    as a PSD tilt is recovered within 0.05 (third-octave regression 1-12 Hz over 8 channels
    of independent noise; the slope's sd is about 0.02); white noise of sd 0.05 added to a
    channel is recovered within 15 % (60-95 Hz of 7.5 s: the amplitude estimate scatters by
    about 4 % between channels, so 15 % is over 3 sd)."""
    import numpy as np
    from scipy import signal

    from diagnosis.nuisance import apply_tilt, window_noise, window_tilt

    fs, n = 200.0, 1500
    rng = np.random.default_rng(3)
    b, a = signal.butter(2, 20.0, fs=fs)
    sim = {f"{q}_{k}L": signal.lfilter(b, a, rng.standard_normal(n))
           for q in ("susp_disp", "axle_acc") for k in (1, 2, 3, 4)}
    meas = apply_tilt(sim, fs, 0.4)
    assert window_tilt(meas, sim, fs, {}) == pytest.approx(0.4, abs=0.05)
    assert window_tilt(sim, sim, fs, {}) == pytest.approx(0.0, abs=1e-9)
    noisy = {c: x + 0.05 * rng.standard_normal(n) for c, x in sim.items()}
    est = window_noise(noisy, sim, fs)
    assert all(v == pytest.approx(0.05, rel=0.15) for v in est.values())


def test_prelevel_gives_linear_models_the_nominal_level_and_nonlinear_ones_their_own(short_drive):
    """``PRE_LEVEL = "nested"``: the nominal model and a linear candidate drive the road level
    the nominal model needs in that window; a nonlinear candidate the level its own run
    needs.  Measured here = 2 x the nominal run on the same road phases, so the nominal
    model's pre-levelled Gq must be 4 x the fitted Gq in every segment the window crosses
    (the model is linear and the phases identical: only the multibody model's geometric
    nonlinearity, ~1e-4, and the tilt refit, exactly 0 for a scaled copy, separate them;
    tolerance 1 %; noise floor set to 0, else the level is that of measured power less
    the noise power).  The nominal run that sets the level is made once per window and
    road seed (then cached): the payload runs once, on it; the bump stop twice, on the
    fitted road, then on its own level."""
    import dataclasses

    import numpy as np

    from diagnosis.pipeline import load_measured, prepare
    from diagnosis.truck_model import Simulate, State
    from diagnosis.signals import Signals

    drive, sig = load_measured(short_drive)
    ctx = prepare(sig, drive.vehicle, workers=1)
    m = dataclasses.replace(ctx.model, noise={})   # 'measured' below is noise-free
    t0, t1 = 4.0, 12.0
    nom = m.run({}, t0, t1, seed=5)
    n = next(iter(nom.values())).size
    w = Signals(np.arange(n) / m.fs + t0, {c: 2.0 * x for c, x in nom.items()}, {},
                np.interp(np.arange(n) / m.fs + t0, sig.time, sig.speed), {"t0": t0})
    sim = Simulate(m)
    gq = sim.prelevel_gq(w, t0, t1, 5, {})
    for k, a, b in m.pieces(t0, t1):
        assert gq[k] / m.gq[k] == pytest.approx(4.0, rel=0.01)
    calls = []
    real_run = m.run

    def spy(effects, a, b, seed, gq=None):
        calls.append((dict(effects), gq))
        return real_run(effects, a, b, seed, gq=gq)

    m.run = spy
    stop = {"bump_stop": {"gap": 0.03}}
    sim(State({}), w, 5)
    sim(State({"payload": {"mass": 1000.0}}), w, 5)
    sim(State(stop), w, 5)
    assert [e for e, _ in calls] == [{}, {}, {"payload": {"mass": 1000.0}}, stop, stop]
    assert calls[0][1] is None and calls[3][1] is None          # the runs on the fitted road
    for _, g in calls[1:3]:
        np.testing.assert_allclose(g, gq, rtol=1e-12)             # nominal and payload
    np.testing.assert_allclose(calls[4][1], sim.prelevel_gq(w, t0, t1, 5, stop), rtol=1e-12)


def test_nominal_levels_travel_to_the_workers(short_drive):
    """The nominal model's per-window levels go with a pickled ``Simulate`` (the ranking's
    workers get the held-out levels the parent made for the nominal simulations instead of
    one extra run per window and seed per task), and a level made in another process is the
    one this process would make (exactly: same model, window and seed)."""
    import pickle

    import numpy as np

    from diagnosis.pipeline import load_measured, prepare
    from diagnosis.truck_model import Simulate

    drive, sig = load_measured(short_drive)
    ctx = prepare(sig, drive.vehicle, workers=1)
    sim = Simulate(ctx.model)
    w = ctx.calib[0]
    t0 = float(w.meta["t0"])
    t1 = t0 + w.time.size / ctx.model.fs
    g = sim.road_level(w, t0, t1, 11, {})
    copy = pickle.loads(pickle.dumps(sim))

    def no_run(*a, **k):
        raise AssertionError("the level was made again")

    copy.model.run = no_run
    np.testing.assert_array_equal(copy.road_level(w, t0, t1, 11, {}), g)
    fresh = Simulate(pickle.loads(pickle.dumps(ctx.model)))
    np.testing.assert_array_equal(fresh.road_level(w, t0, t1, 11, {}), g)


def test_a_candidate_at_its_neutral_value_is_the_nominal_model(short_drive):
    """The ranking compares each candidate with the nominal model, so the nominal model must
    be in every candidate's family: a bump stop 0.3 m away (it never engages) scores the
    nominal model's simulation, window by window, including the road level and the
    re-levelling; a payload of 0 kg is the nominal model exactly.  Until stop 42
    (2026-11-27) only nonlinear candidates were pre-levelled and such a bump stop scored
    0.34 against the nominal model's 0.23 (docs/diagnosis.md); its run differed by ~10 %
    of the rms.  Tolerance 1e-9 of the channel's rms: both run on the linear integrator
    (``SIM_SOLVER = "linear"``; the bump stop's force, e^-150 of its scale here, solved per
    step by vehicles.suspension_forces), so only rounding separates them (one step at a time
    against two): measured 1.2e-13 (stop 59).  Before, the bump stop ran in Exudyn with Newton
    iterations and its geometric nonlinearity: 5.7e-3 (stop 58), 1.2e-3 when both ran in
    Exudyn."""
    import numpy as np

    from diagnosis.pipeline import load_measured, prepare
    from diagnosis.truck_model import Simulate, State

    drive, sig = load_measured(short_drive)
    ctx = prepare(sig, drive.vehicle, workers=1)
    sim = Simulate(ctx.model)
    w = ctx.calib[0]
    a = sim(State({}), w, 7)
    b = sim(State({"bump_stop": {"gap": 0.3}}), w, 7)
    p = sim(State({"payload": {"mass": 0.0}}), w, 7)
    for c, x in a.channels.items():
        assert np.max(np.abs(x - b.channels[c])) <= 1e-9 * np.sqrt(np.mean(x ** 2)), c
        np.testing.assert_array_equal(p.channels[c], x)     # linear: the very same path


def test_window_road_has_no_segment_the_truck_does_not_reach(short_drive):
    """``TruckModel._road``: a boundary after the window lies where the truck would meet it,
    not at the window's end.  Before the fix it was clamped to the end of the drive, so the
    front axles ran onto the next segment for the last ~0.4 s of the window (null drive
    1106: a class-F segment 19 s later made the class-A windows' simulated power 5x too
    high).  Here: segments 1e-6 and 1e-2 m^3 (factor 1e4 in power, 100 in height), the
    boundary 10 s after a 0-6 s window: the window's road is all smooth (rms below 3x
    that of the smooth class alone: its realisation scatters, the rough one would be
    ~100x); a boundary 0.3 s after the window end is still on the road."""
    import dataclasses

    import numpy as np

    from diagnosis.pipeline import load_measured, prepare

    drive, sig = load_measured(short_drive)
    ctx = prepare(sig, drive.vehicle, workers=1)
    m = dataclasses.replace(ctx.model, bounds=np.array([0.0, 16.0, sig.duration]),
                            gq=np.array([1e-6, 1e-2]), w=np.array([2.0, 2.0]), _roads={})
    smooth = dataclasses.replace(m, bounds=np.array([0.0, sig.duration]), gq=np.array([1e-6]),
                                 w=np.array([2.0]), _roads={})
    r = m._road(0.0, 6.0, 3, m.gq)
    r0 = smooth._road(0.0, 6.0, 3, smooth.gq)
    assert np.std(r.z) < 3.0 * np.std(r0.z)
    m2 = dataclasses.replace(m, bounds=np.array([0.0, 6.3, sig.duration]), _roads={})
    assert np.std(m2._road(0.0, 6.0, 3, m2.gq).z) > 10.0 * np.std(r0.z)


def test_unknown_integrator_setting_refused_before_any_work(short_drive, tmp_path):
    """``settings={"solver": ...}`` takes "linear" or "exudyn"; anything else is one clear line
    (EroadInputError), raised before a worker pool is started or a run folder written."""
    from diagnosis.pipeline import diagnose
    from eroad.errors import EroadInputError

    with pytest.raises(EroadInputError, match="solver must be 'exudyn' or 'linear'"):
        diagnose(short_drive, tmp_path / "out", settings={"solver": "fast"}, workers=2)
    assert not (tmp_path / "out").exists()


def test_a_drive_without_body_accelerometers_is_diagnosed_without_the_transmissibility(short_drive, tmp_path):
    """A logger with no body accelerometer (the 16 s friction drive, every body_acc column
    dropped): `eroad diagnose` runs to the end (it stopped with "transmissibility: no
    axle_acc/body_acc pair in both records" before), writes no transmissibility and no
    signature, says so in the report, and the verdict is never 'clear'."""
    import pandas as pd

    from drives.format import read_drive, write_drive

    d = read_drive(short_drive)
    frame = pd.DataFrame({"time": d.time, "speed": d.speed,
                          **{c: d.channels[c] for c in d.channel_names if not c.startswith("body_acc")}})
    ds = write_drive(tmp_path / "nobody", frame, dict(d.meta, vehicle=d.vehicle))
    args = ["diagnose", "--quick", "--effects", "leaf_friction,sensor", "--workers", "1"]
    assert main(args + [str(ds), "--out", str(tmp_path / "run")]) == 0
    s = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert s["transmissibility"] is None and not s.get("signature")
    assert s["verdict_confidence"] != "clear"
    if s["verdict"] not in ("none", "unexplained"):
        assert s["verdict_detail"]["named_on"] in ("gap_alone", "vehicle_share")
    assert "not measured" in (tmp_path / "run" / "report.md").read_text()
