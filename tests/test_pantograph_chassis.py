"""Chassis-stiffness study in contact-force terms (studies.pantograph_chassis).

A tiny study (frame factors 1 and rigid, nominal mounts, a 4 s drive at 80 km/h on a
class C road made by roadlib in the test, seed 2, serial) checks the table's columns, the
run folder and these physical properties, each of which can fail.  (Until 2026-11-24 it
drove the committed reference run's identified road; remade, that road starts with a
class A stretch whose base motion, 2 mm/s in 0.5-5 Hz, is too small for the checks below to
mean anything: a test should not hang on a result file that is regenerated.)

* the base excitation adds to the contact-force sd: sd(drive) > sd(base still), and the
  base-induced part ``F(drive) - F(base still)`` is not zero (it is zero for the still
  row by construction);
* the truck line has linear droppers and the contact does not open, so the contact
  problem is linear in the base motion: doubling the base motion doubles the
  base-induced force (tolerance 1e-6 relative: round-off of ~3000 HHT steps, each a
  banded solve, is ~1e-12; 1e-6 also leaves room for the float64 sums);
* below the pantograph's modes the base acts through the lower damper c3 (70 N s/m): the
  base-induced force per unit base velocity in 0.5-5 Hz lies between 0.5 c3 and 1.5 c3.
  Far more than the base spring k3 = 0.1 N/m could give, far less than a rigid coupling of
  the 22 kg pantograph (m omega = 280-690 N s/m at 2-5 Hz); above c3 by the inertia of the
  part of the frame that moves with the base (|c3 + i omega m_eff|: 79 N s/m measured here,
  m_eff of about 3 kg at 2 Hz; the bound allows up to about 4 kg at 3 Hz).
"""
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from eroad.cli import main
from studies.pantograph_chassis import (FORCE_BANDS, TABLE_COLUMNS, band_rms, contact_case,
                                        run_pantograph_chassis, study_cases)

@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("pc")
    road = out / "road.npz"
    assert main(["road", "generate", "--class", "C", "--length", "150", "--width", "4", "--seed", "2",
                 "--out", str(road)]) == 0
    s = run_pantograph_chassis(road, out, run_dir=out / "run", frames=(1.0, "rigid"),
                               mounts=(1.0,), duration=4.0, n_workers=0,
                               cache_dir=out / "cache", progress=False, command=["test"])
    return s, pd.read_csv(out / "run" / "data" / "table.csv", dtype={"frame": str}), out, road


def test_table_columns_and_run_folder(tiny):
    s, t, _, _ = tiny
    run = Path(s["path"])
    assert list(t.columns) == list(TABLE_COLUMNS)
    assert list(t["base"]) == ["drive", "drive", "still"]
    assert list(t["frame"]) == ["1.0", "rigid", "-"]
    md = (run / "data" / "table.md").read_text()
    assert md.count("| 1.0 | 1 |") == 2 and "| base still |" in md
    for name in ("run.json", "summary.json", "config.toml", "figures/contact_vs_stiffness.png",
                 "data/forces.npz"):
        assert (run / name).is_file(), name
    info = json.loads((run / "run.json").read_text())
    assert info["status"] == "complete" and info["run_id"] == "run"
    assert s["n_configurations"] == 2


def test_base_excitation_adds_to_the_sd(tiny):
    _, t, _, _ = tiny
    still = t[t["base"] == "still"].iloc[0]
    drive = t[t["base"] == "drive"]
    assert still["base_induced_sd_N"] == 0.0
    assert (drive["base_induced_sd_N"] > 0.05).all()
    assert (drive["sd_N"] > still["sd_N"]).all()
    # no loss, mean = static force (70 N) within 1 % (momentum balance, see
    # tests/test_pantograph_contact.py)
    assert (t["loss_percent"] == 0).all()
    assert np.allclose(t["mean_N"], 70.0, rtol=0.01)
    # the lateral offset stays on the head
    assert (drive["lateral_max_mm"] < drive["head_half_width_mm"]).all()


def test_base_acts_through_the_lower_damper(tiny):
    _, t, _, _ = tiny
    drive = t[t["base"] == "drive"]
    ratio = drive["dF_rms_0.5-5Hz_N"] / (1e-3 * drive["vz_rms_0.5-5Hz_mm_s"])
    assert ((ratio > 0.5 * 70.0) & (ratio < 1.5 * 70.0)).all(), ratio.tolist()


def test_contact_force_linear_in_base_motion(tiny):
    from studies.chassis_study import road_specs
    from studies.pantograph_chassis import code_version
    from studies.sweep import run_cases

    out, road = tiny[2], tiny[3]
    spec = road_specs(road, n_seeds=0)[0][0]
    cases = study_cases(spec, frames=(1.0, "rigid"), mounts=(1.0,), duration=4.0)
    # the study's cases (frame 1 with base scale 1, and the still base) from its cache,
    # in float64; only the doubled base motion is computed here
    sw = run_cases(contact_case, cases, cache_dir=out / "cache", n_workers=0,
                   progress=False, code_version=code_version())
    assert sw.n_cached == len(cases)
    f = {1.0: sw.results[0]["force"], 0.0: sw.results[-1]["force"],
         2.0: contact_case({**cases[0], "base_scale": 2.0})["force"]}
    assert f[1.0].min() > 0 and f[2.0].min() > 0  # the contact never opens
    d1, d2 = f[1.0] - f[0.0], f[2.0] - f[0.0]
    assert np.max(np.abs(d1)) > 0.1
    assert np.max(np.abs(d2 - 2 * d1)) < 1e-6 * np.max(np.abs(d2))


def test_band_rms_parseval_and_derivative():
    fs, n = 1000.0, 4000
    t = np.arange(n) / fs
    rng = np.random.default_rng(1)
    x = 0.3 * np.sin(2 * math.pi * 3.0 * t) + 0.1 * rng.standard_normal(n)
    b = band_rms(x, fs)
    assert np.sum(b ** 2) == pytest.approx(np.var(x), rel=1e-12)
    s = 0.3 * np.sin(2 * math.pi * 3.0 * t)  # whole periods: one bin at 3 Hz
    bs = band_rms(s, fs)
    assert bs[1] == pytest.approx(0.3 / math.sqrt(2), rel=1e-9)
    assert np.sum(bs ** 2) - bs[1] ** 2 < 1e-20
    d = band_rms(s, fs, order=1)
    assert d[1] == pytest.approx(2 * math.pi * 3.0 * 0.3 / math.sqrt(2), rel=1e-9)
    assert len(b) == len(FORCE_BANDS)


def test_cli_grid_needs_a_road(capsys, tmp_path):
    rc = main(["pantograph-contact", "--out", str(tmp_path), "--chassis-grid"])
    err = capsys.readouterr().err
    assert rc != 0 and "--road" in err and "Traceback" not in err


def test_tractor_lift_off_reported_per_configuration(tiny):
    """The tractor's tyre lift-off share is a column (NaN for the still base, whose drive does
    not move the pantograph) and the summary's worst case; the drives run with unilateral
    tyres (a column), for which lift-off is modelled and the drive is within range."""
    s, t, _, _ = tiny
    drive = t[t["base"] == "drive"]
    assert drive["tyre_lift_off_percent"].notna().all()
    assert t[t["base"] == "still"]["tyre_lift_off_percent"].isna().all()
    assert (drive["tyres"] == "unilateral").all()
    assert s["max_tyre_lift_off_percent"] == pytest.approx(drive["tyre_lift_off_percent"].max())
    assert s["tractor_tyres"] == "unilateral" and s["tractor_within_model_range"] is True


def test_tractor_range_note_thresholds():
    """Bilateral tyres (older drives, or forced): the 1 % limit; unilateral tyres: lift-off is
    modelled, reported, never out of range; an unknown share is said to be unknown."""
    from studies.pantograph_contact import LIFT_OFF_LIMIT_PERCENT, tractor_range, tractor_range_note

    for tyres in ("bilateral", "unilateral"):
        assert tractor_range_note(0.0, tyres) is None
        assert "unknown" in tractor_range_note(float("nan"), tyres)
        assert tractor_range(float("nan"), tyres)["within_model_range"] is None
    assert "isolated peaks" in tractor_range_note(0.2, "bilateral")
    assert tractor_range_note(LIFT_OFF_LIMIT_PERCENT, "bilateral").startswith(
        "OUTSIDE THE TRACTOR MODEL'S RANGE")
    assert tractor_range(LIFT_OFF_LIMIT_PERCENT, "bilateral")["within_model_range"] is False
    assert tractor_range(0.5, "bilateral")["within_model_range"] is True
    assert tractor_range(30.0, "unilateral")["within_model_range"] is True
    assert "modelled" in tractor_range_note(30.0, "unilateral")


def test_rough_road_drive_lifts_off_with_unilateral_tyres(tmp_path):
    """ISO class E at 80 km/h: the e-tractor's rear tyres (16 kN static each) see dynamic
    loads of about 20 kN sd, so tyres leave the road in far more than 1 % of the samples
    (67 % over 21 s measured).  The drive runs with unilateral tyres, reports the share and
    says it is modelled."""
    from roadlib.surface import RoadSurface
    from studies.pantograph_contact import contact_drive

    road = tmp_path / "road.npz"
    assert main(["road", "generate", "--class", "E", "--length", "120", "--width", "4", "--seed", "2",
                 "--out", str(road)]) == 0
    # 30 s asked on a 120 m road: the drive is shortened to the whole seconds the road covers
    # (4 s), and says so; the statistics leave out the vehicle's run-in (1 s) and the
    # contact's settling (1 s), and their window is the samples they used
    out = contact_drive(RoadSurface.load(road), speed_kmh=80.0, duration=30.0, compare_static=False)
    cfg = out["config"]
    assert cfg["duration_requested_s"] == 30.0 and cfg["duration_s"] == 4.0
    w0, w1 = cfg["statistics_window_s"]
    assert w0 == 2.0 and w1 == pytest.approx(4.0, abs=0.01)
    assert out["stats"]["n_samples"] == pytest.approx((w1 - w0) / cfg["dt_s"] + 1, abs=1)
    tr = out["tractor"]
    assert tr["tyres"] == "unilateral"
    assert tr["tyre_lift_off_percent"] > 5.0 and tr["within_model_range"] is True
    assert "modelled" in tr["note"]


def test_grid_over_equivalent_roads(tiny, capsys):
    """``seeds=1``: every configuration is driven on the road file and on one statistically
    equivalent realisation (its own phases), the still base once. The road file's rows are
    the tiny study's (from the cache, bit for bit), so the figure and the top-level summary
    do not move; the realisation's rows differ (another road), and the summary pairs each
    configuration with the nominal one on the same road. Bad --seeds: one line, no run."""
    s1, t1, out, road = tiny
    s = run_pantograph_chassis(road, out, run_dir=out / "run2", frames=(1.0, "rigid"),
                               mounts=(1.0,), duration=4.0, seeds=1, n_workers=0,
                               cache_dir=out / "cache", progress=False, command=["test"])
    t = pd.read_csv(out / "run2" / "data" / "table.csv", dtype={"frame": str})
    assert list(t["road"]) == ["road file"] * 2 + ["realisation 1"] * 2 + ["road file"]
    assert list(t["base"]) == ["drive"] * 4 + ["still"]
    assert s["n_cached"] == 3 and s["n_computed"] == 2
    f = t[t["road"] == "road file"].reset_index(drop=True)
    assert f["sd_N"].tolist() == t1["sd_N"].tolist()
    assert s["sd_N_range"] == s1["sd_N_range"]
    real = t[t["road"] == "realisation 1"]
    # another road: its base motion and sd differ from the file's by more than round-off
    assert np.all(np.abs(real["base_z_rms_mm"].to_numpy() - f["base_z_rms_mm"][:2].to_numpy())
                  > 1e-3 * f["base_z_rms_mm"][:2].to_numpy())
    R = s["realisations"]
    assert R["n_roads"] == 2 and R["roads"] == ["road file", "realisation 1"]
    assert R["nominal_configuration"] == {"frame": "1.0", "mount": 1.0}
    cfg = {c["frame"]: c for c in R["per_configuration"]}
    assert cfg["1.0"]["paired_sd_N"] == [0.0, 0.0]
    for k, rd in enumerate(R["roads"]):
        g = t[(t["road"] == rd) & (t["base"] == "drive")].set_index("frame")
        # table.csv keeps 6 significant digits (float_format %.6g): ~1e-5 N at 10-20 N
        assert cfg["rigid"]["paired_sd_N"][k] == pytest.approx(
            g.loc["rigid", "sd_N"] - g.loc["1.0", "sd_N"], abs=1e-4)
        assert R["per_road"][rd]["sd_N_range"] == pytest.approx(
            [g["sd_N"].min(), g["sd_N"].max()], abs=1e-4)
    assert R["road_span_N"][1] == pytest.approx(max(
        abs(g["sd_N"].iloc[0] - g["sd_N"].iloc[1])
        for _, g in t[t["base"] == "drive"].groupby("frame")), abs=1e-4)
    run = Path(s["path"])
    assert (run / "figures" / "realisations.png").is_file()
    assert "| rigid | 1 |" in (run / "data" / "table.md").read_text().split("Every road")[1]
    with pytest.raises(SystemExit) as ex:   # argparse: usage line, one error line, exit 2
        main(["pantograph-contact", "--road", str(road), "--out", str(out / "x"),
              "--chassis-grid", "--seeds", "-1"])
    err = capsys.readouterr().err
    assert ex.value.code == 2 and "--seeds: '-1' must be >= 0" in err and "Traceback" not in err
    assert not (out / "x").exists()


def test_pantograph_file_and_friction_enter_the_cache_key(tiny, tmp_path):
    """A pantograph given as a file carries its sha256 in every case (the built-in files are in
    the cache's code version, a user's file is not): editing the file must not reuse a cached
    case.  ``frame_friction`` enters the case only when given, so cases cached before it
    existed stay valid; a negative value is refused in one line."""
    from eroad.errors import EroadInputError
    from studies.chassis_study import road_specs
    from vehicles.pantograph_model import DATA_DIR

    spec = road_specs(tiny[3], n_seeds=0)[0][0]
    plain = study_cases(spec, frames=(1.0,), mounts=(1.0,))
    assert all("frame_friction" not in c and "pantograph_sha256" not in c for c in plain)
    f = tmp_path / "p.toml"
    f.write_text((DATA_DIR / "pantograph_truck.toml").read_text())
    a = study_cases(spec, frames=(1.0,), mounts=(1.0,), pantograph=str(f), frame_friction=5.0)
    assert all(c["frame_friction"] == 5.0 for c in a)
    f.write_text(f.read_text().replace("static_force = 70.0", "static_force = 80.0"))
    b = study_cases(spec, frames=(1.0,), mounts=(1.0,), pantograph=str(f), frame_friction=5.0)
    assert a[0]["pantograph_sha256"] != b[0]["pantograph_sha256"]
    with pytest.raises(EroadInputError, match="frame friction must be a finite force >= 0"):
        study_cases(spec, frames=(1.0,), mounts=(1.0,), frame_friction=-1.0)


def test_frame_friction_passes_the_base_motion_on_and_is_not_linear(tiny):
    """With 20 N of frame friction the frame is dragged by the base (up to the friction
    force) instead of through the 70 N s/m damper alone: the base-induced force grows, and
    doubling the base motion no longer doubles it (Coulomb friction is not linear; the
    friction-free contact is, see test_contact_force_linear_in_base_motion)."""
    from studies.chassis_study import road_specs

    spec = road_specs(tiny[3], n_seeds=0)[0][0]
    plain = study_cases(spec, frames=(1.0,), mounts=(1.0,), duration=4.0)
    fric = study_cases(spec, frames=(1.0,), mounts=(1.0,), duration=4.0, frame_friction=20.0)
    f0 = {s: contact_case({**plain[0], "base_scale": s})["force"] for s in (0.0, 1.0)}
    f = {s: contact_case({**fric[0], "base_scale": s})["force"] for s in (0.0, 1.0, 2.0)}
    d_plain = np.std(f0[1.0] - f0[0.0])
    d1, d2 = f[1.0] - f[0.0], f[2.0] - f[0.0]
    assert np.std(d1) > 1.5 * d_plain
    assert np.max(np.abs(d2 - 2 * d1)) > 0.05 * np.max(np.abs(d2))
