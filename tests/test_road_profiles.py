"""Measured profiles as road surfaces (roadlib.profiles, ``eroad road from-profile``).

Reference: the measured profile of ../shared/data/iri (a copy in tests/data/iri, provenance
there: 0.25 m steps, 544 m) -- data our code did not make.

Tolerances
----------
* Read-back at the profile's own samples: 1e-6 m.  The band-limited upsampling (spectrum
  zero-padding of the even extension) passes through the samples up to round-off (1e-12 m
  observed); the road grid is an integer multiple of the fine grid here, and 1e-6 m is
  a thousandth of the profile's 1-mm-scale heights.
* PSD kept: within 2 % over 0.3-1.8 cycles/m (the fine grid's linear read-out loses
  under 1 % below half the profile's Nyquist wavenumber and 10 % at it; 0.3-1.8 stays
  below 0.9 of it).
* Where the content ends: the profile's Nyquist wavenumber 2 cycles/m to two Welch bins.
"""
import json
from pathlib import Path

import numpy as np
import pytest

from eroad.cli import main
from eroad.errors import EroadInputError
from roadlib.metrics import content_top, fit_iso_psd, profile_psd, surface_content_top
from roadlib.profiles import detrend_profile, surface_from_profiles

PROFILE = Path(__file__).resolve().parent / "data" / "iri" / "profile_1.txt"


@pytest.fixture(scope="module")
def measured():
    d = np.loadtxt(PROFILE)
    return d[:, 0], d[:, 1]


def test_one_profile_is_read_back_on_every_track_with_its_grade_removed(measured):
    x, z = measured
    surf = surface_from_profiles((x, z), dx=0.05, dy=0.05)
    x0, zd, grade = detrend_profile(x, z)
    assert grade == pytest.approx(np.polyfit(x - x[0], z, 1)[0])
    assert surf.meta["grades"] == [grade] and surf.meta["source_x_start_m"] == x[0]
    # x = 0 at the profile's first chainage; every 5th grid point is a profile sample
    assert surf.x[0] == 0.0 and surf.x[-1] == pytest.approx(x[-1] - x[0])
    np.testing.assert_allclose(surf.z[::5, 0], zd, atol=1e-6)
    # one profile: every track alike (no roll input), and said so
    assert np.all(surf.z == surf.z[:, :1])
    assert "no roll input" in surf.meta["lateral"]


def test_two_profiles_are_the_wheel_tracks_linear_between_and_held_beyond(measured):
    x, z = measured
    zr = z[::-1].copy()                       # another track on the same chainage
    surf = surface_from_profiles((x, z), (x, zr), track_width=1.8, width=3.0, dx=0.05, dy=0.05)
    zl_d, zr_d = detrend_profile(x, z)[1], detrend_profile(x, zr)[1]
    j = {round(float(v), 3): k for k, v in enumerate(surf.y)}
    np.testing.assert_allclose(surf.z[::5, j[0.9]], zl_d, atol=1e-6)
    np.testing.assert_allclose(surf.z[::5, j[-0.9]], zr_d, atol=1e-6)
    np.testing.assert_allclose(surf.z[::5, j[0.0]], 0.5 * (zl_d + zr_d), atol=1e-6)
    np.testing.assert_allclose(surf.z[:, j[1.5]], surf.z[:, j[0.9]], atol=0)
    np.testing.assert_allclose(surf.z[:, j[-1.5]], surf.z[:, j[-0.9]], atol=0)


def test_the_profiles_spectrum_is_kept_and_ends_at_its_nyquist_wavenumber(measured):
    """The road the vehicle reads (the grid's tracks) has the profile's PSD within 2 % in
    0.3-1.8 cycles/m and nothing above 2 cycles/m; the ISO fit of the road with the default
    band stays inside that content (it fitted the empty bins up to 2.83 before: w 4.06, class
    D; the profile's own fit: w 3.24, class C)."""
    from scipy.signal import welch

    x, z = measured
    surf = surface_from_profiles((x, z), dx=0.025, dy=0.1)
    n0, g0 = welch(detrend_profile(x, z)[1], fs=4.0, nperseg=512, detrend="linear")
    n1, g1 = welch(surf.z[:, 0], fs=1 / 0.025, nperseg=5120, detrend="linear")
    band = (n0 >= 0.3) & (n0 <= 1.8)
    ratio = np.interp(n0[band], n1, g1) / g0[band]
    assert np.all(np.abs(ratio - 1) < 0.02), ratio
    est = profile_psd(surf.z[:, :1], surf.dx)
    assert content_top(est) == pytest.approx(2.0, abs=2 * est.n[1])
    assert surface_content_top(surf) == pytest.approx(2.0, abs=2 * est.n[1])
    fit = fit_iso_psd(profile_psd(surf.z, surf.dx))
    assert fit.band[1] < 2.0 and fit.iso_class == "C"


def test_bad_profiles_are_refused_in_one_line(measured, tmp_path):
    x, z = measured
    xb = x.copy()
    xb[100] += 0.1
    with pytest.raises(EroadInputError, match=r"left profile: chainage step varies .*row 10[12]"):
        surface_from_profiles((xb, z))
    with pytest.raises(EroadInputError, match="share no stretch of chainage"):
        surface_from_profiles((x, z), (x + 1000.0, z))
    with pytest.raises(EroadInputError, match="narrower than the track width"):
        surface_from_profiles((x, z), (x, z), track_width=2.0, width=1.5)
    with pytest.raises(EroadInputError, match="must increase"):
        surface_from_profiles((x[::-1], z))


def test_eroad_road_from_profile_then_simulate(tmp_path, capsys):
    """End to end as a user: a road file of the measured profile, a truck driven over it, the
    dataset valid; the command says the road ends at 2.01 cycles/m and that one profile gives
    no roll input; refused inputs write nothing."""
    road = tmp_path / "measured.npz"
    assert main(["road", "from-profile", str(PROFILE), "--out", str(road)]) == 0
    out = capsys.readouterr().out
    assert "content up to 2.0" in out and "no roll input" in out and "grade removed" in out
    summary = json.loads((tmp_path / "measured.npz.summary.json").read_text())
    assert summary["no_roll_input"] is True and summary["content_top_cpm"] == pytest.approx(2.0, abs=0.05)
    # an existing output is not overwritten without --force
    assert main(["road", "from-profile", str(PROFILE), "--out", str(road)]) == 2
    assert "exists" in capsys.readouterr().err
    drive = tmp_path / "drive"
    assert main(["simulate", "--vehicle", "dump_truck_8x4", "--road", str(road), "--speed", "15",
                 "--duration", "5", "--out", str(drive)]) == 0
    capsys.readouterr()
    assert main(["data", "check", str(drive)]) == 0
    assert "valid" in capsys.readouterr().out
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0\n0.25 0.001\n0.6 0.002\n" + "".join(f"{0.6 + 0.25 * k} 0\n" for k in range(1, 20)))
    assert main(["road", "from-profile", str(bad), "--out", str(tmp_path / "b.npz")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "bad.txt: chainage step varies" in err
    assert not (tmp_path / "b.npz").exists()
