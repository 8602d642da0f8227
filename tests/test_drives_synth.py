"""The virtual test drive: scenario resolution, the dataset and its truth, seeds and
bytes, effects, blind use without truth/, Figures 4-5.

Simulations here are short (3 s records, 0.5 s run-in, the nominal 5 ms step) so the
file runs in seconds; the full 30 s luliang run is the slow test at the end.
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from drives import synth
from drives.format import check_drive, read_drive
from eroad.cli import main
from eroad.errors import EroadInputError

SHORT = """
[scenario]
name = "short"
dataset_name = "short-{seed}"
vehicle = "dump_truck_8x4"
duration_s = 3.0
sample_rate_hz = 200.0
start_time_s = 100.0
runin_s = 0.5
reference_axle = 3

[speed]
kind = "smooth_random"
min_mps = 8.0
max_mps = 11.0
knot_spacing_s = 1.5
exact_range = true

[road]
dx_m = 0.05
dy_m = 0.1
width_m = 3.0
segments = [
  { proportion = 0.6, Gq_n0 = 64e-6, w = 2.0, nmin = 0.1, nmax = 5.0 },
  { proportion = 0.4, Gq_n0 = 256e-6, w = 1.8, nmin = 0.1, nmax = 5.0 },
]

[truth]
chassis = "nominal"
frame_segments = 0
dt_s = 0.0

[truth.effects]

[noise]
susp_disp_m = 1e-4
axle_acc_mps2 = 0.03
body_acc_mps2 = 0.03
dcdc_m = 1e-4
speed_mps = 0.01
"""

TRUTH_FILES = ["channels_clean.csv", "road.npz", "scenario.toml", "summary.json", "truth.json"]


def files_digest(folder: Path) -> dict:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def short_cfg(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("cfg") / "short.toml"
    p.write_text(SHORT)
    return p


@pytest.fixture(scope="module")
def short_ds(tmp_path_factory, short_cfg) -> Path:
    out = tmp_path_factory.mktemp("ds") / "short"
    assert main(["synth", "--config", str(short_cfg), "--seed", "3", "--out", str(out)]) == 0
    return out


# ----------------------------------------------------------------- scenarios (no simulation)

PAPER_TABLE1 = [0.4208, 0.0470, 0.3728, 0.0292, 0.1302]


def test_luliang_is_the_papers_window_in_a_longer_record():
    """Issue 4 item 3 and issue 16 item 4: a 180 s record (400-580 s) at 200 Hz whose
    460-490 s window holds five segments in Table 1's time proportions, with Gq(n0) inside
    the issue's ranges and the paper's nmin, nmax, w; the record has an asphalt part (A)
    before the window and another (A or B) after the loess part (C, D); speed spans exactly
    7.86-11.28 m/s in the window (knots at the extremes) and more outside it."""
    from roadlib.psd import class_of

    cfg, _ = synth.load_scenario("luliang")
    r = synth.resolve_scenario(cfg, 0)
    sc = r["scenario"]
    assert (sc["duration_s"], sc["start_time_s"], sc["window_s"]) == (180.0, 400.0, [460.0, 490.0])
    assert (sc["sample_rate_hz"], sc["vehicle"]) == (200.0, "dump_truck_8x4")
    segs = r["road"]["segments"]
    # record segment boundaries on the record's time axis, clipped to the window
    bounds = 400.0 + 180.0 * np.concatenate([[0.0], np.cumsum([s["proportion"] for s in segs])])
    clipped = np.clip(bounds, 460.0, 490.0)
    share = np.diff(clipped) / 30.0
    inside = share > 0
    np.testing.assert_allclose(share[inside], PAPER_TABLE1, atol=1e-9)
    win = [s for s, k in zip(segs, inside) if k]
    ranges = [(8, 32), (128, 512), (128, 512), (512, 2048), (512, 2048)]
    for s, (lo, hi) in zip(win, ranges):
        assert lo * 1e-6 <= s["Gq_n0"] <= hi * 1e-6
    assert [s["nmin"] for s in win] == [0.1, 0.01, 0.1, 0.05, 0.1]
    assert [s["nmax"] for s in win] == [5.0] * 5
    assert [s["w"] for s in win] == [2.0, 2.0, 1.8, 1.8, 1.6]
    # asphalt before the window (the window's A segment reaches back), loess, asphalt again
    classes = [class_of(s["Gq_n0"]) for s in segs]
    assert classes[0] == "A" and bounds[1] - bounds[0] > 60.0
    assert classes[-1] in ("A", "B") and bounds[-1] - bounds[-2] > 30.0
    assert set(classes[1:-1]) <= {"C", "D"} and bounds[-2] > 500.0
    assert r["truth"]["chassis"] == "flexible" and "leaf_friction" in r["truth"]["effects"]
    v = synth._speed_samples(r, np.arange(60 * 200, 90 * 200) / 200.0)
    assert abs(v.min() - 7.86) < 1e-9 and abs(v.max() - 11.28) < 1e-9
    v_all = synth._speed_samples(r, np.arange(-400, 180 * 200) / 200.0)
    assert v_all.max() > 12.0 and v_all.min() >= 7.86 - 1e-9


def test_window_is_cut_from_the_record(tmp_path, short_cfg):
    """A windowed scenario: the dataset is the window's rows of record/ (same samples, same
    noise), record/ is a valid dataset of its own, the truth's segments are the record's
    clipped to the window with proportions of the window, and --duration sets the
    window's length (the same drive: its rows equal the longer window's first rows)."""
    cfg = tmp_path / "win.toml"
    cfg.write_text(short_cfg.read_text().replace("start_time_s = 100.0",
                                                 "start_time_s = 100.0\nwindow_s = [101.0, 102.5]"))
    out = tmp_path / "d"
    assert main(["synth", "--config", str(cfg), "--seed", "3", "--out", str(out)]) == 0
    w, rec = read_drive(out), read_drive(out / synth.RECORD_DIR)
    assert check_drive(out / synth.RECORD_DIR) == []
    assert (w.n_samples, rec.n_samples) == (300, 600)
    assert w.time[0] == 101.0 and rec.time[0] == 100.0
    cut = rec.window(101.0, 102.5)
    np.testing.assert_array_equal(w.channels.to_numpy(), cut.channels.to_numpy())
    np.testing.assert_array_equal(w.speed, cut.speed)
    np.testing.assert_allclose(w.time, cut.time, rtol=0, atol=1e-9)
    truth = synth.read_truth(out)
    whole = truth["whole_record"]
    assert (whole["start_time_s"], whole["duration_s"], whole["window_s"]) == (100.0, 3.0, [101.0, 102.5])
    segs = truth["segments"]
    assert segs[0]["t_start"] == 101.0 and segs[-1]["t_end"] == 102.5
    assert sum(s["proportion"] for s in segs) == pytest.approx(1.0)
    for s in segs:
        r = whole["segments"][s["record_segment"] - 1]
        assert r["t_start"] <= s["t_start"] < s["t_end"] <= r["t_end"]
        assert s["duration_s"] == pytest.approx(s["t_end"] - s["t_start"])
    assert truth["record"]["start_time_s"] == 101.0 and truth["record"]["duration_s"] == 1.5
    clean = pd.read_csv(out / "truth" / "channels_clean.csv")
    assert len(clean) == 300 and clean["time"].iloc[0] == 101.0
    short = tmp_path / "d1"
    assert main(["synth", "--config", str(cfg), "--seed", "3", "--duration", "0.5",
                 "--out", str(short)]) == 0
    s1 = read_drive(short)
    assert s1.n_samples == 100 and read_drive(short / synth.RECORD_DIR).n_samples == 600
    np.testing.assert_array_equal(s1.channels.to_numpy(), w.channels.to_numpy()[:100])


@pytest.mark.parametrize("window, msg", [("[99.0, 101.0]", "inside the record"),
                                         ("[101.0, 104.0]", "inside the record"),
                                         ("[101.001, 102.0]", "sample grid"),
                                         ("[102.0, 101.0]", "inside the record"),
                                         ('"x"', "two numbers")])
def test_bad_window_refused(tmp_path, short_cfg, window, msg):
    cfg = tmp_path / "win.toml"
    cfg.write_text(short_cfg.read_text().replace("start_time_s = 100.0",
                                                 f"start_time_s = 100.0\nwindow_s = {window}"))
    c, path = synth.load_scenario(cfg)
    with pytest.raises(EroadInputError, match=msg):
        synth.resolve_scenario(c, 0, src=path)


def test_default_dataset_cache_is_keyed_by_the_scenario(tmp_path, monkeypatch, short_cfg):
    """The cache folder's name carries a hash of the resolved default scenario, so an edited
    scenario file is not served from the folder the old one made."""
    monkeypatch.setattr(synth, "DEFAULT_SCENARIO", str(short_cfg))
    k1 = synth._scenario_key()
    other = tmp_path / "other.toml"
    other.write_text(short_cfg.read_text().replace("Gq_n0 = 64e-6", "Gq_n0 = 65e-6"))
    monkeypatch.setattr(synth, "DEFAULT_SCENARIO", str(other))
    assert synth._scenario_key() != k1
    monkeypatch.setattr(synth, "DEFAULT_SCENARIO", str(short_cfg))
    assert synth._scenario_key() == k1
    # and a new truth model (its output changed) is a new key too
    monkeypatch.setattr(synth, "TRUTH_MODEL_VERSION", synth.TRUTH_MODEL_VERSION + " changed")
    assert synth._scenario_key() != k1


def test_time_proportions_become_road_lengths():
    """The reference axle (3) spends proportion * T on each segment: checked with the
    vehicles package's own distance integral of the speed profile, independently of
    drives.synth.plan_drive's."""
    from vehicles.params import load_vehicle
    from vehicles.simulate import SpeedProfile

    cfg, _ = synth.load_scenario("luliang")
    r = synth.resolve_scenario(cfg, 5)
    axle_x = [a.x for a in load_vehicle("dump_truck_8x4").axles]
    plan = synth.plan_drive(r, axle_x)
    prof = SpeedProfile(plan["t_sim"], plan["v_sim"])
    tt = np.linspace(0, plan["t_sim"][-1], 200001)
    x3 = plan["x_front0"] + axle_x[2] + prof.distance(tt)
    runin = r["scenario"]["runin_s"]
    for s in plan["segments"][:-1]:
        t_cross = np.interp(s["x_end"], x3, tt) - runin
        assert t_cross == pytest.approx(s["t_end"], abs=1e-4)
    assert plan["segments"][0]["x_start"] == 0.0
    # the road covers the rearmost axle at the start and the first axle at the end
    assert plan["x_front0"] + min(axle_x) >= synth.ROAD_MARGIN_M - 1e-9
    assert plan["road_length"] >= plan["x_front0"] + prof.distance(plan["t_sim"][-1]) + 1.0


def test_random_scenario_draws_within_the_issue_ranges():
    """30 seeds: 2-6 segments, each >= min_segment_s (2 s), classes A-E with Gq(n0) inside
    the class's nominal bounds, w in 1.5-2.5, speed within 6-14 m/s; seeds differ."""
    from roadlib.psd import ISO_CLASSES

    cfg, _ = synth.load_scenario("random")
    counts = set()
    for seed in range(30):
        r = synth.resolve_scenario(cfg, seed)
        segs = r["road"]["segments"]
        counts.add(len(segs))
        assert 2 <= len(segs) <= 6
        assert sum(s["proportion"] for s in segs) == pytest.approx(1.0)
        for s in segs:
            assert s["proportion"] * 30.0 >= 2.0 - 1e-9
            lo, hi = ISO_CLASSES[s["label"]].nominal_bounds
            assert s["label"] in "ABCDE" and lo <= s["Gq_n0"] <= hi
            assert 1.5 <= s["w"] <= 2.5
        v = synth._speed_samples(r, np.linspace(-2, 30, 3000))
        assert v.min() >= 6.0 and v.max() <= 14.0
    assert len(counts) >= 4


def test_null_truth_is_the_nominal_model():
    cfg, _ = synth.load_scenario("null")
    r = synth.resolve_scenario(cfg, 1)
    assert synth._sim_kwargs(r) == {"effects": {}}
    # null and random with one seed share road and speed: paired blind cases
    rr = synth.resolve_scenario(synth.load_scenario("random")[0], 1)
    assert r["road"]["segments"] == rr["road"]["segments"] and r["speed"] == rr["speed"]
    assert r["scenario"]["dataset_name"] == rr["scenario"]["dataset_name"]  # name gives nothing away


def test_scenario_file_errors_name_key_and_file(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(SHORT.replace("runin_s = 0.5", "runin = 0.5"))
    with pytest.raises(EroadInputError, match=r"bad.toml: unknown key 'runin' in \[scenario\]"):
        synth.load_scenario(p)
    with pytest.raises(EroadInputError, match="unknown scenario 'nope'"):
        synth.load_scenario("nope")
    assert main(["synth", "--scenario", "nope", "--out", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()


# ----------------------------------------------------------------- the dataset

def test_dataset_is_valid_and_truth_complete(short_ds):
    assert check_drive(short_ds) == []
    d = read_drive(short_ds)
    assert d.n_samples == 600 and d.time[0] == 100.0 and d.sample_rate_hz == 200.0
    assert {"susp_disp_3L", "axle_acc_3R", "body_acc_1L"} <= set(d.channel_names)
    assert sorted(p.name for p in (short_ds / "truth").iterdir()) == TRUTH_FILES
    truth = synth.read_truth(short_ds)
    for key in ("segments", "junctions", "road", "speed", "vehicle", "noise", "seed", "streams",
                "record"):
        assert key in truth
    assert truth["seed"] == 3
    segs = truth["segments"]
    assert [s["Gq_n0"] for s in segs] == [64e-6, 256e-6]
    assert segs[0]["t_start"] == 100.0 and segs[-1]["t_end"] == pytest.approx(103.0)
    from roadlib.surface import RoadSurface

    road = RoadSurface.load(truth["road_file"])
    assert road.x_max == pytest.approx(truth["road"]["length_m"], abs=0.05)
    assert len(truth["junctions"]) == 1
    # the truth says which model made it and how its tyres behaved
    import json

    tm = json.loads((short_ds / "truth" / "summary.json").read_text())["truth_model"]
    assert tm["model"] == "exudyn" and tm["tyres"] == "unilateral"
    assert tm["version"] == synth.TRUTH_MODEL_VERSION and 0.0 <= tm["tyre_lift_off_fraction"] <= 1.0
    # meta.toml gives nothing of the truth away
    meta = (short_ds / "meta.toml").read_text()
    assert "Gq" not in meta and "effect" not in meta
    # it says where the displacements read 0 (the nominal vehicle at rest: a payload error's
    # sag shows in their mean), which is a property of the generator, not of the truth
    assert read_drive(short_ds).meta["susp_disp_zero"] == "nominal_static"


def test_sensor_noise_is_what_truth_says(short_ds):
    """Noisy minus clean is white noise of the stated standard deviation: 600 samples give
    a relative standard error of 1/sqrt(2*600) = 2.9 %; tolerance 5 sigma = 15 %."""
    d = read_drive(short_ds)
    clean = pd.read_csv(short_ds / "truth" / "channels_clean.csv")
    truth = synth.read_truth(short_ds)
    for c, key in (("susp_disp_3L", "susp_disp_m"), ("axle_acc_2R", "axle_acc_mps2"),
                   ("body_acc_4L", "body_acc_mps2")):
        sd = np.std(d.channels[c].to_numpy() - clean[c].to_numpy())
        assert sd == pytest.approx(truth["noise"][key], rel=0.15)
    assert np.std(d.speed - clean["speed"].to_numpy()) == pytest.approx(0.01, rel=0.15)


def test_same_seed_same_bytes_and_config_round_trip(short_ds, short_cfg, tmp_path):
    """Same seed, same bytes (every file, truth included); the explicit truth/scenario.toml
    given back with --config regenerates them too; another seed differs."""
    ref = files_digest(short_ds)
    again = tmp_path / "again"
    assert main(["synth", "--config", str(short_cfg), "--seed", "3", "--out", str(again)]) == 0
    assert files_digest(again) == ref
    explicit = tmp_path / "explicit"
    assert main(["synth", "--config", str(short_ds / "truth" / "scenario.toml"),
                 "--out", str(explicit)]) == 0
    d1, d2 = files_digest(explicit), dict(ref)
    assert d1["channels.csv"] == d2["channels.csv"] and d1["truth/road.npz"] == d2["truth/road.npz"]
    other = tmp_path / "other"
    assert main(["synth", "--config", str(short_cfg), "--seed", "4", "--out", str(other)]) == 0
    assert files_digest(other)["channels.csv"] != ref["channels.csv"]


def test_refuses_non_empty_out(short_cfg, short_ds):
    before = files_digest(short_ds)
    assert main(["synth", "--config", str(short_cfg), "--seed", "9", "--out", str(short_ds)]) == 2
    assert files_digest(short_ds) == before


def test_without_truth_commands_behave_the_same(short_ds, tmp_path, capsys):
    """`eroad data check` and `eroad data figures` give the same output on a copy without
    truth/ (byte for byte for the JSON summaries)."""
    blind = synth.copy_without_truth(short_ds, tmp_path / "blind")
    assert not (blind / "truth").exists()
    outs = []
    for ds in (short_ds, blind):
        capsys.readouterr()
        assert main(["data", "check", str(ds), "--json"]) == 0
        outs.append(capsys.readouterr().out)
    assert outs[0] == outs[1] and json.loads(outs[0])["valid"]
    sums = []
    for i, ds in enumerate((short_ds, blind)):
        out = tmp_path / f"fig{i}"
        assert main(["data", "figures", str(ds), "--out", str(out), "--window", "101", "102.5"]) == 0
        sums.append((out / "summary.json").read_text())
    assert sums[0] == sums[1]


def test_figures_4_and_5(short_ds, tmp_path):
    from drives.figures import figures_command

    s = figures_command(short_ds, tmp_path / "f", window=(101.0, 102.5))
    names = sorted(Path(f).name for f in s["files"])
    assert names == ["figure4_displacement.pdf", "figure4_displacement.png",
                     "figure5_spectrum.pdf", "figure5_spectrum.png"]
    d = read_drive(short_ds)
    w = d.window(101.0, 102.5)
    assert s["rms_window"] == pytest.approx(np.std(w.channels["susp_disp_3L"]))
    with pytest.raises(EroadInputError, match="T1 must be greater"):
        figures_command(short_ds, tmp_path / "g", window=(102.0, 101.0))


#: strengths that act on the short scenario's road (3 s, classes B and C: suspension travel
#: of about +-15 mm, so a bump stop needs a small gap to engage); the rest at their defaults
EFFECT_ARGS = {"bump_stop": "bump_stop.gap=0.005"}


def _effects():
    from vehicles.effects import EFFECTS

    return sorted(EFFECTS)


def _cols(df, prefix):
    return [c for c in df.columns if c.startswith(prefix)]


def _band_power(x, lo, hi, fs=200.0):
    """Welch power of ``x`` in [lo, hi) Hz (Hann, 256 samples: 0.78 Hz bins)."""
    from scipy import signal

    f, p = signal.welch(np.asarray(x, float), fs, nperseg=256)
    return float(p[(f >= lo) & (f < hi)].sum())


def _bump_stop(a, b):
    # one-sided contact force (only in compression beyond the gap): its mean is > 0, so
    # the springs carry less of the weight and the mean compression drops on every
    # spring; the stiff stop transmits harsh forces: more body acceleration
    for c in _cols(a, "susp_disp_"):
        assert b[c].mean() < a[c].mean(), c
    for c in _cols(a, "body_acc_"):
        assert b[c].std() > a[c].std(), c


def _damper_asymmetry(a, b):
    # rebound damping 3x compression with the mean kept: the damper pulls harder in
    # rebound than it pushes in compression, a net downward force on a rough road, so
    # the vehicle sits lower ("jacking down"): mean compression grows on every spring
    for c in _cols(a, "susp_disp_"):
        assert b[c].mean() > a[c].mean(), c


def _frame_flex(a, b):
    # the rigid chassis cannot twist; the flexible frame's torsion modes (6, 7.8 Hz) let
    # front and rear roll against each other, which the left-right road difference
    # excites: the left-right difference of the body accelerations grows at every axle
    for ax in sorted({c[len("body_acc_"):-1] for c in _cols(a, "body_acc_")}):
        da = a[f"body_acc_{ax}L"] - a[f"body_acc_{ax}R"]
        db = b[f"body_acc_{ax}L"] - b[f"body_acc_{ax}R"]
        assert db.std() > da.std(), ax


def _leaf_friction(a, b):
    # inter-leaf friction holds the spring until the force exceeds it: less travel on
    # every spring
    for c in _cols(a, "susp_disp_"):
        assert b[c].std() < a[c].std(), c


def _payload(a, b):
    # 2 t more on the frame, outputs zeroed at the nominal vehicle's static state: every
    # spring is compressed further on average
    for c in _cols(a, "susp_disp_"):
        assert b[c].mean() > a[c].mean(), c


def _sensor(a, b):
    # causal 2nd-order Butterworth at 40 Hz: |H|^2 = 1 / (1 + (f/40)^4) = 0.5-0.87 in
    # 25-40 Hz, where the road's axle acceleration (not the 0.05 m/s^2 noise, whose
    # PSD is 2.5e-5 (m/s^2)^2/Hz) dominates: less axle-acceleration power there.  The
    # added 0.2 mm displacement noise raises the floor of susp_disp above 60 Hz, where
    # the suspension motion itself is negligible
    for c in _cols(a, "axle_acc_"):
        assert _band_power(b[c], 25.0, 40.0) < _band_power(a[c], 25.0, 40.0), c
    for c in _cols(a, "susp_disp_"):
        assert _band_power(b[c], 60.0, 100.0) > _band_power(a[c], 60.0, 100.0), c


def _speed_scale(a, b):
    # the recorded speed is factor (1.02) x the true speed; nothing else changes (the
    # speed noise stream is the same, so the mean ratio is the factor to ~1e-6)
    assert b["speed"].mean() / a["speed"].mean() == pytest.approx(1.02, abs=1e-4)
    others = [c for c in a.columns if c != "speed"]
    assert np.array_equal(a[others].to_numpy(), b[others].to_numpy())


def _tyre_enveloping(a, b):
    # the footprint averages the road over its length L (0.22-0.25 m): sinc(n L)^2 halves
    # the road power at n = 0.44 / L ~ 2 cycles/m (about 20 Hz at 8-11 m/s) and removes
    # it at 1 / L, so the axles, which see the road through the tyres alone, accelerate
    # less
    for c in _cols(a, "axle_acc_"):
        assert b[c].std() < a[c].std(), c


#: effect -> the direction its physics predicts on the short dataset (see each function)
DIRECTIONS = {"bump_stop": _bump_stop, "damper_asymmetry": _damper_asymmetry,
              "frame_flex": _frame_flex, "leaf_friction": _leaf_friction, "payload": _payload,
              "sensor": _sensor, "speed_scale": _speed_scale, "tyre_enveloping": _tyre_enveloping}


@pytest.mark.parametrize("effect", _effects())
def test_each_effect_changes_the_data_in_its_physical_direction(short_cfg, short_ds, tmp_path, effect):
    """Every effect of the library, switched on in the truth vehicle, changes the dataset
    (same seed, so road, speed and noise streams are identical and any difference is the
    effect's), and in the direction its physics predicts (``DIRECTIONS``: a bump stop
    lowers the mean compression and raises the body acceleration, asymmetric dampers
    and payload raise the mean compression, leaf friction lowers the travel, the
    flexible frame raises the left-right body difference, the sensor low-pass lowers
    the axle acceleration below its cutoff, speed_scale raises the recorded speed by
    its factor, tyre enveloping lowers the axle acceleration).  Every effect needs a
    direction here.  Size threshold: the largest relative RMS change over the channels
    (speed included, which speed_scale acts on) exceeds 1e-3, far above round-off
    (1e-15) and far below the effects' sizes."""
    assert effect in DIRECTIONS, f"effect {effect!r} has no physical direction in this test"
    out = tmp_path / effect
    assert main(["synth", "--config", str(short_cfg), "--seed", "3", "--effect",
                 EFFECT_ARGS.get(effect, effect), "--out", str(out)]) == 0
    a = read_drive(short_ds).to_dataframe().drop(columns="time")
    b = read_drive(out).to_dataframe().drop(columns="time")
    rel = np.sqrt(((a - b) ** 2).mean()) / np.sqrt((a ** 2).mean())
    assert rel.max() > 1e-3, rel.sort_values().tail(3)
    DIRECTIONS[effect](a, b)
    truth = synth.read_truth(out)
    assert effect in truth["vehicle"]["truth"]["effects"]


def test_default_dataset_is_generated_once_and_reused(tmp_path, monkeypatch, short_cfg):
    """default_dataset() generates the default scenario into its folder on first use,
    reuses it afterwards (no rewrite), and refuses a damaged cache with one line. The
    default scenario is swapped for the short one to keep the test fast."""
    monkeypatch.setattr(synth, "DEFAULT_SCENARIO", str(short_cfg))
    monkeypatch.setenv("EROAD_CACHE", str(tmp_path / "cache"))
    p = synth.default_dataset()
    assert p.parent == tmp_path / "cache" / "datasets" and check_drive(p) == []
    stamp = (p / "channels.csv").stat().st_mtime_ns
    assert synth.default_dataset() == p
    assert (p / "channels.csv").stat().st_mtime_ns == stamp
    (p / "channels.csv").write_text("time;x\n")
    with pytest.raises(EroadInputError, match="semicolon-delimited"):
        synth.default_dataset()


def test_vehicle_file_becomes_the_nominal_vehicle(short_cfg, tmp_path):
    from vehicles.params import load_vehicle

    vf = tmp_path / "my_truck.toml"
    vf.write_bytes(Path(load_vehicle("dump_truck_8x4").source).read_bytes())
    out = tmp_path / "d"
    assert main(["synth", "--config", str(short_cfg), "--vehicle", str(vf), "--duration", "1",
                 "--out", str(out)]) == 0
    d = read_drive(out)
    assert d.vehicle == (out / "vehicle.toml").resolve() and d.duration_s == 1.0
    assert (out / "vehicle.toml").read_bytes() == vf.read_bytes()


@pytest.mark.slow
def test_luliang_default_regenerates_bit_for_bit(tmp_path):
    """`eroad synth --scenario luliang --seed 0` twice gives the same bytes, and
    default_dataset() builds that dataset in its cache."""
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["synth", "--scenario", "luliang", "--seed", "0", "--out", str(a)]) == 0
    p = synth.default_dataset(b)
    assert p == b
    assert files_digest(a) == files_digest(b)
    d = read_drive(a)
    assert d.n_samples == 6000 and d.duration_s == pytest.approx(30.0) and d.time[0] == 460.0
    rec = read_drive(a / synth.RECORD_DIR)
    assert rec.n_samples == 36000 and rec.time[0] == 400.0
    np.testing.assert_array_equal(d.channels.to_numpy(), rec.window(460.0, 490.0).channels.to_numpy())
    truth = synth.read_truth(a)
    assert math.isclose(truth["speed"]["min_mps"], 7.86, abs_tol=1e-6)
    assert [s["label"] for s in truth["segments"]] == ["A", "C", "C", "D", "D"]
    np.testing.assert_allclose([s["proportion"] for s in truth["segments"]], PAPER_TABLE1,
                               atol=0.002)   # junctions sit half-way between road grid points
