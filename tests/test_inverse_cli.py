"""``eroad invert`` (inverse.cli): run folder contents, blindness to truth/, bad input."""
import json
import shutil

import pytest

from drives.synth import copy_without_truth, synth_command
from eroad.cli import main
from inverse.cli import run_inversion


@pytest.fixture(scope="module")
def short_drive(tmp_path_factory):
    """An 8 s random drive (seed 5) and its copy without truth/."""
    root = tmp_path_factory.mktemp("invert")
    ds = root / "ds"
    synth_command(scenario="random", seed=5, duration=8.0, out=ds)
    blind = copy_without_truth(ds, root / "blind")
    return ds, blind, root


def _run(ds, out):
    # K fixed, 2 iterations, 2 candidate realisations, serial: a smoke-size inversion
    return run_inversion(ds, out, segments=2, workers=1, seed=0, max_iter=2, candidates=2)


def test_invert_writes_the_run_and_ignores_truth(short_drive):
    """The run folder holds summary/config/provenance, Tables 1-2, Figures 6/8/9 and the
    road; the copy without truth/ gives the same segments, Table 2 and selection
    (nothing is read from truth/; timings excluded)."""
    ds, blind, root = short_drive
    a = _run(ds, root / "run_a")
    b = _run(blind, root / "run_b")
    for key in ("segments", "table2", "errors", "road"):
        assert a[key] == b[key], key
    assert a["selection"]["candidates"] == b["selection"]["candidates"]
    run = root / "run_a"
    for f in ("summary.json", "config.toml", "run.json", "history.json", "road.npz", "road.crg",
              "tables/table1.csv", "tables/table1.md", "tables/table2.csv", "tables/table2.md",
              "figures/figure6_segmentation.png", "figures/figure8_time_compare.pdf",
              "figures/figure9_amplitude_distributions.png"):
        assert (run / f).is_file(), f
    s = json.loads((run / "summary.json").read_text())
    assert len(s["segments"]) == 2
    keys = {"t_start", "t_end", "proportion", "Gq_n0", "w", "nmin", "nmax", "dx", "dy", "class"}
    assert all(keys <= set(seg) for seg in s["segments"])
    # a class is a result only where Gq(n0) is identifiable (stop 71: Table 1 brackets the others)
    assert all(seg["class_identified"] == seg["identifiable"]["Gq_n0"] for seg in s["segments"])
    assert sum(seg["proportion"] for seg in s["segments"]) == pytest.approx(1.0)
    assert {"axle_acc_3L", "axle_acc_3R"} <= set(s["errors"])
    assert s["selection"]["n_candidates"] == 3 and len(s["history"]) >= 2
    # the lateral structure is a stated assumption with its sensitivity (inverse/lateral.py)
    assert len(s["lateral"]["segments"]) == 2 and "lam=2" in s["lateral"]["factor_range"]
    assert "Lateral road structure assumed" in (run / "tables" / "table1.md").read_text()
    assert s["segmentation"]["boundaries_from"].startswith("susp_disp_3L, susp_disp_3R in 3-20 Hz")
    rj = json.loads((run / "run.json").read_text())
    assert rj["status"] == "complete"
    assert rj["start_utc"] and rj["end_utc"] and rj["host"]["hostname"] and rj["seed"] == 0


def test_bad_input_is_one_line(short_drive, tmp_path, capsys):
    """Missing dataset, existing non-empty --out and a bad --segments: exit 2, one line,
    nothing overwritten."""
    ds, _, _ = short_drive
    assert main(["invert", str(tmp_path / "nope"), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("eroad: error:") and "\n" not in err
    out = tmp_path / "taken"
    out.mkdir()
    (out / "mine.txt").write_text("keep")
    assert main(["invert", str(ds), "--out", str(out)]) == 2
    assert "not empty" in capsys.readouterr().err and (out / "mine.txt").read_text() == "keep"
    assert main(["invert", str(ds), "--out", str(tmp_path / "r2"), "--segments", "0"]) == 2
    assert "--segments" in capsys.readouterr().err
    assert main(["invert", str(ds), "--out", str(tmp_path / "r3"), "--channels", "nope_1L"]) == 2
    assert "--channels" in capsys.readouterr().err
    assert not (tmp_path / "r2").exists() and not (tmp_path / "r3").exists()


@pytest.mark.slow
def test_blind_benchmark_no_model_gap(tmp_path, capsys):
    """Accuracy against truth (benchmarks/bench_inverse.py) on 3 blind random drives whose
    truth vehicle has no leaf friction (no model gap; still the flexible frame, 1 ms step,
    sensor noise).  About 3-5 min.  Bounds (docs/inverse.md, section 10): the level within a
    factor 2 (|ln| < ln 2) and w within 0.3 at the median, for the segments >= 8 s and for
    those >= 3 s: loose on purpose, the Cramer-Rao floor of ln Gq for 80-100 m is 0.11-0.14
    and 3 drives give only a handful of long segments (null benchmark: median 0.109 for
    >= 8 s, 0.242 for >= 3 s).

    Every case must have been inverted and scored (no skip), and the segments must be there
    to judge: seeds 1-3 hold 3 true segments >= 8 s (26.5, 14.2, 8.5 s) and 10 >= 3 s; should
    a seed be refused by the format (then 4 replaces it) there are still >= 3 and >= 8, so
    fewer than that fails the test instead of letting it pass on nothing."""
    import importlib.util
    import math
    from pathlib import Path

    import numpy as np

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_inverse.py"
    spec = importlib.util.spec_from_file_location("bench_inverse", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    assert bench.main(["--cases", "3", "--no-default-effects", "--root", str(tmp_path), "--max-iter", "8"]) == 0
    out = capsys.readouterr().out
    assert "| >= 3 s |" in out and "| >= 8 s |" in out
    lines = [json.loads(x) for x in (tmp_path / "results.jsonl").read_text().splitlines()]
    cases = [c for c in lines if "skipped" not in c]
    assert len(cases) == 3, [c.get("seed") for c in lines]
    assert all(c["segments"] for c in cases)
    for min_s, min_count in ((8.0, 3), (3.0, 8)):
        segs = [r for c in cases for r in c["segments"] if r["duration_s"] >= min_s]
        assert len(segs) >= min_count, (min_s, len(segs))
        assert np.median([r["dlnGq"] for r in segs]) < math.log(2.0), min_s
        assert np.median([r["dw"] for r in segs]) < 0.3, min_s


def test_noise_option_parsing_and_psd():
    """--noise NAME=SD: sd in SI units -> white PSD sd^2 / (fs/2) per matching channel;
    a bad value or a name matching no channel is one clear error."""
    from eroad.errors import EroadInputError
    from inverse.cli import _noise, noise_psd_from_sd

    sd = _noise(["axle_acc=0.03", "susp_disp_3L=1e-4"])
    psd = noise_psd_from_sd(sd, ["axle_acc_3L", "axle_acc_3R", "susp_disp_3L", "susp_disp_3R"], fs=200.0)
    assert psd == pytest.approx({"axle_acc_3L": 9e-6, "axle_acc_3R": 9e-6, "susp_disp_3L": 1e-10})
    for bad in (["axle_acc=abc"], ["axle_acc=-1"], ["=0.1"], ["axle_acc"]):
        with pytest.raises(EroadInputError, match="NAME=SD"):
            _noise(bad)
    with pytest.raises(EroadInputError, match="matches no channel"):
        noise_psd_from_sd({"wheel": 0.1}, ["axle_acc_3L"], fs=200.0)


# --------------------------------------------------------------------------- accuracy of the truck inversion

#: the single-segment drive: class C at its geometric mean, w = 2
TRUTH_GQ, TRUTH_W = 256e-6, 2.0


@pytest.fixture(scope="module")
def single_class_drive(tmp_path_factory):
    """A 15 s ``null`` drive (truth vehicle = the nominal rigid model; its own road grid,
    phases, smooth random speed 6-14 m/s and sensor noise) over ONE class C segment
    (Gq_n0 = 256e-6 m^3, w = 2, band 0.1-5 cycles/m), seed 3; and its copy without truth/."""
    from drives.synth import load_scenario, resolve_scenario, synthesize

    root = tmp_path_factory.mktemp("invert_single")
    cfg, src = load_scenario("null")
    cfg["road"]["segments"] = [{"proportion": 1.0, "Gq_n0": TRUTH_GQ, "w": TRUTH_W, "nmin": 0.1, "nmax": 5.0}]
    cfg = resolve_scenario(cfg, 3, duration=15.0, src=src)
    ds = root / "ds"
    synthesize(cfg, ds)
    return ds, copy_without_truth(ds, root / "blind"), root


def test_truck_inversion_recovers_a_single_class_road(single_class_drive):
    """``run_inversion`` with the Exudyn truck on a blind 15 s single-segment drive (K = 1
    given, default iterations, fit phases only): class C and |ln(Gq_fit / Gq_true)| < ln 2,
    |w - 2| < 0.3.

    Bounds from docs/inverse.md section 10 (null scenario, no model gap): on segments >= 8 s
    the median |ln Gq| is 0.109, the worst 0.78, the class right in 95 % and w within 0.15 in
    86 % (worst 0.45).  The truth sits at the centre of class C, so |ln Gq| < ln 2 = 0.69 is
    the same as the class being right; 0.3 in w is twice the largest error measured on this
    set-up.  Measured by hand on this drive with seeds 1-5 (seed 3 is the test's):
    ln Gq error -0.004, -0.046, -0.107, -0.353, -0.334; w error +0.007, -0.037, -0.029,
    -0.148, -0.115 (ln Gq follows w with the lever ln(n_data / n0) ~ 2.3).  About 30 s
    (60 simulations of 17 s of truck, serial)."""
    import math

    from drives.synth import read_truth

    ds, blind, root = single_class_drive
    truth = read_truth(ds)["segments"]
    assert len(truth) == 1 and truth[0]["Gq_n0"] == pytest.approx(TRUTH_GQ)
    s = run_inversion(blind, root / "run", segments=1, workers=1, seed=0, candidates=0)
    (seg,) = s["segments"]
    assert seg["class"] == "C"
    assert abs(math.log(seg["Gq_n0"] / TRUTH_GQ)) < math.log(2.0), seg["Gq_n0"]
    assert abs(seg["w"] - TRUTH_W) < 0.3, seg["w"]
    assert s["fit"]["iterations"] >= 2   # a real fit, not the start point


def test_effect_option_reaches_the_simulation(short_drive, tmp_path):
    """``eroad invert --effect payload=15000``: the effect is in config.toml, and Table 2 of
    the run is the response of the model WITH it: a TruckSimulator built here with
    effects={'payload': 15000} on the run's fitted segments and the fit's phase seed
    (SeedSequence(0, (5, 1)); --candidates 0 keeps the fit's phases) reproduces every
    rms_sim to 1e-9 (deterministic: the same simulation), while the nominal model on the same
    road must differ by more than 1 % in some channel (15 t of payload: measured +11 % and
    +18 % in suspension RMS, 0.3-0.4 % in axle acceleration).  Smoke-size: K = 1, one
    iteration, serial; about 15 s."""
    import math

    import numpy as np

    from drives.format import read_drive
    from inverse.truck import TruckSimulator

    ds, _, _ = short_drive
    out = tmp_path / "run_payload"
    assert main(["invert", str(ds), "--out", str(out), "--effect", "payload=15000", "--segments", "1",
                 "--workers", "1", "--max-iter", "1", "--candidates", "0"]) == 0
    import tomllib
    cfg = tomllib.loads((out / "config.toml").read_text())
    assert json.loads(cfg["effects"]) == {"payload": {"mass": 15000.0}}
    s = json.loads((out / "summary.json").read_text())
    segs = s["segments"]
    params = np.array([[r["Gq_n0"], r["w"], r["nmin"], r["nmax"]] for r in segs])
    t_bounds = [segs[0]["t_start"]] + [r["t_end"] for r in segs]
    drive = read_drive(ds)
    rows = {r["channel"]: r for r in s["table2"]}
    chans = sorted(rows)
    fit_seed = int(np.random.SeedSequence(0, spawn_key=(5, 1)).generate_state(1)[0])
    kw = dict(time=np.asarray(drive.time, float), speed=np.asarray(drive.speed, float), t_bounds=t_bounds,
              channels=chans)
    with_effect = TruckSimulator(drive.vehicle, effects={"payload": 15000.0}, **kw)(params, fit_seed)
    nominal = TruckSimulator(drive.vehicle, **kw)(params, fit_seed)
    for c in chans:
        assert rows[c]["rms_sim"] == pytest.approx(float(np.std(with_effect[c])), rel=1e-9), c
    assert max(abs(math.log(np.std(nominal[c]) / rows[c]["rms_sim"])) for c in chans) > 0.01


def test_segment_on_option_reaches_the_segmentation(short_drive, tmp_path):
    """``eroad invert --segment-on axle_acc``: the boundaries are located on the octave bands of
    axle 3's accelerations, and summary.json says so (the default run in
    ``test_invert_writes_the_run_and_ignores_truth`` names the displacements); smoke-size:
    K = 2, one iteration, serial."""
    ds, _, _ = short_drive
    out = tmp_path / "run_axle_acc"
    assert main(["invert", str(ds), "--out", str(out), "--segment-on", "axle_acc", "--segments", "2",
                 "--workers", "1", "--max-iter", "1", "--candidates", "0", "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["segmentation"]["boundaries_from"].startswith("axle_acc_3L, axle_acc_3R in 6-12")
    assert len(s["segments"]) == 2


def test_acceleration_only_fit_simulates_the_displacements_but_does_not_fit_them(short_drive, tmp_path):
    """``eroad invert --channels axle3_acc``: the fit compares the axle accelerations alone
    (summary fit.channels and config.toml), the displacements are still simulated (they segment
    the drive and fill Table 2), the features are fewer than the default fit's on the same
    segments (the displacements' bands are gone), and the intervals name their own calibration;
    smoke-size: K = 2, one iteration, serial."""
    ds, _, _ = short_drive
    runs = {}
    for name, extra in (("default", []), ("acc", ["--channels", "axle3_acc"])):
        out = tmp_path / name
        assert main(["invert", str(ds), "--out", str(out), "--segments", "2", "--workers", "1",
                     "--max-iter", "1", "--candidates", "0", "--quiet"] + extra) == 0
        runs[name] = json.loads((out / "summary.json").read_text())
    fit = runs["acc"]["fit"]
    assert fit["channels"] == ["axle_acc_3L", "axle_acc_3R"]
    assert {"susp_disp_3L", "susp_disp_3R"} <= set(fit["simulated_channels"])
    assert fit["channel_set"] == "axle3_acc" and fit["uncertainty_calibration"] == "linear/axle3_acc"
    assert {"susp_disp_3L", "susp_disp_3R"} <= {r["channel"] for r in runs["acc"]["table2"]}
    assert 0 < fit["n_features"] < runs["default"]["fit"]["n_features"]
    import tomllib
    cfg = tomllib.loads((tmp_path / "acc" / "config.toml").read_text())
    assert cfg["channels"] == ["axle_acc_3L", "axle_acc_3R"]
