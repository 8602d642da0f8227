"""What the command line prints around the work: --json errors as one JSON object on
stdout, a closed pipe without a traceback, progress bars only where a person watches,
road psd's interval for correlated tracks, a broken travel not called a unit error."""
from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from argparse import Namespace
from pathlib import Path

import numpy as np
import pytest

from eroad.cli import main
from eroad.errors import EroadInputError
from eroad.progress import MessageCounter, progress_bar, wants_progress

REPO = Path(__file__).resolve().parents[1]


def _eroad(*args, cwd=REPO, **kw):
    return subprocess.run([sys.executable, "-m", "eroad.cli", *args], capture_output=True, text=True,
                          cwd=cwd, **kw)


def test_json_input_error_is_one_json_object_on_stdout(tmp_path, capsys):
    code = main(["road", "psd", str(tmp_path / "missing.npz"), "--json"])
    out, err = capsys.readouterr()
    assert code == 2 and err == ""
    obj = json.loads(out)
    assert obj["error"]["kind"] == "input" and obj["error"]["exit_code"] == 2
    assert "missing.npz" in obj["error"]["message"]
    # without --json: one line on stderr, nothing on stdout
    assert main(["road", "psd", str(tmp_path / "missing.npz")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("eroad: error:") and err.count("\n") == 1


def test_json_usage_error_is_json_too():
    r = _eroad("runs", "show", "--json")
    assert r.returncode == 2 and "Traceback" not in r.stderr
    obj = json.loads(r.stdout)
    assert obj["error"]["kind"] == "usage" and "RUN" in obj["error"]["message"]


def test_closed_pipe_ends_quietly(tmp_path):
    """`eroad runs list --json | head -1`: enough output to fill the pipe, the reader
    leaves after one line, and no BrokenPipeError traceback follows."""
    for k in range(600):
        d = tmp_path / "study" / f"run-{k:04d}"
        d.mkdir(parents=True)
        (d / "table.txt").write_text("x")
    p = subprocess.Popen([sys.executable, "-m", "eroad.cli", "runs", "list", "--json", "--root",
                          str(tmp_path)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=REPO)
    with p:
        p.stdout.readline()
        p.stdout.close()
        err = p.stderr.read().decode()
        p.wait(timeout=60)
    assert "Traceback" not in err and "BrokenPipe" not in err, err
    assert p.returncode in (0, 141)


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_progress_only_on_a_terminal_without_json_or_quiet():
    assert wants_progress(Namespace(json=False, quiet=False), _Tty())
    assert not wants_progress(Namespace(json=True, quiet=False), _Tty())
    assert not wants_progress(Namespace(json=False, quiet=True), _Tty())
    assert not wants_progress(Namespace(json=False, quiet=False), io.StringIO())


def test_progress_bar_draws_on_stderr_only_when_shown(capsys):
    with progress_bar(False, desc="x", total=2) as bar:
        bar.update(2)
    assert capsys.readouterr() == ("", "")
    with progress_bar(True, desc="x", total=2) as bar:
        bar.update(2)
    out, err = capsys.readouterr()
    assert out == "" and "x" in err


class _Bar:
    n, total, desc = 0, None, ""

    def update(self, k=1):
        self.n += k

    def refresh(self):
        pass

    def set_description(self, text):
        self.desc = text

    def write(self, line):
        pass


def test_message_counter_counts_the_announced_steps():
    bar = _Bar()
    say = MessageCounter(bar, r"calibrating (\d+) candidates", r"^\s+\S+: held-out gap")
    say("nominal model on held-out data")
    say("calibrating 3 candidates")
    for name in ("a", "b"):
        say(f"  {name}: held-out gap 0.1 (nominal 0.2)")
    assert (bar.n, bar.total, bar.desc) == (2, 3, "calibrating 3 candidates")
    say("calibrating 3 candidates")      # the second fold
    assert bar.total == 6


def _dataset(tmp_path, peak):
    d = tmp_path / "ds"
    d.mkdir(parents=True)
    t = np.arange(40) / 200.0
    z = 0.01 * np.sin(np.arange(40) / 3.0)
    z[20] = peak
    rows = ["time,susp_disp_3L,speed"] + [f"{float(a)!r},{float(b)!r},10.0" for a, b in zip(t, z)]
    (d / "channels.csv").write_text("\n".join(rows) + "\n")
    (d / "meta.toml").write_text('[dataset]\nname = "h"\nsample_rate_hz = 200.0\n'
                                 'vehicle = "dump_truck_8x4"\n')
    return d


def test_a_broken_suspension_travel_is_not_called_millimetres(tmp_path):
    """0.84 m of suspension travel (a diverged simulation) is impossible, not a unit
    error; 12.5 (a millimetre record) still is one."""
    from drives.format import read_drive

    with pytest.raises(EroadInputError) as ei:
        read_drive(_dataset(tmp_path / "a", 0.84))
    assert "diverged simulation" in str(ei.value) and "millimetres" not in str(ei.value)
    with pytest.raises(EroadInputError, match="looks like millimetres"):
        read_drive(_dataset(tmp_path / "b", 12.5))


def test_effective_tracks_between_one_and_all():
    """Identical tracks are worth one; independent ones (white noise) about all of them
    (the coherence bias of 8 Welch segments removed: 20 tracks count 17-21)."""
    from roadlib.tracks import effective_tracks, fit_weights

    rng = np.random.default_rng(0)
    z1 = rng.standard_normal(10001)
    band = (0.05, 2.7)
    assert effective_tracks(np.repeat(z1[:, None], 5, axis=1), 0.1, 2048, band) == pytest.approx(1.0)
    zi = rng.standard_normal((10001, 20))
    assert 17.0 <= effective_tracks(zi, 0.1, 2048, band) <= 20.0
    assert 17.0 <= effective_tracks(zi, 0.1, 2048, band, weights=lambda n: fit_weights(n)[0]) <= 20.0


def test_road_psd_interval_of_neighbouring_tracks_and_the_centre_track(tmp_path, capsys):
    """A 4 m wide road of 41 tracks 0.1 m apart: the +- of Gd(n0) from their average is
    wider than the 41-independent-tracks value (the tracks are nearly one profile at long
    wavelengths) and narrower than one track's; the centre track psd reports is the
    fit road plot reports."""
    road = tmp_path / "c.npz"
    assert main(["road", "generate", "--class", "C", "--length", "1000", "--out", str(road)]) == 0
    capsys.readouterr()
    assert main(["road", "psd", str(road), "--json"]) == 0
    allt = json.loads(capsys.readouterr().out)
    assert main(["road", "psd", str(road), "--track", "0", "--json"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert main(["road", "plot", str(road), "--out", str(tmp_path / "c.png"), "--json"]) == 0
    plot = json.loads(capsys.readouterr().out)
    naive = one["Gd_n0_rel_se"] / np.sqrt(41)
    assert naive * 2 < allt["Gd_n0_rel_se"] < one["Gd_n0_rel_se"]
    # 41 tracks 0.1 m apart on a class C road are worth about 3 independent ones for Gd(n0)
    # (3.06 here; over 16 seeds the interval this gives is within 25 % of the seed spread):
    # 2-5 fails both "all independent" (41) and "all one track" (1)
    assert 2.0 <= allt["effective_tracks"]["Gd_n0"] <= 5.0
    assert allt["centre_track"]["Gd_n0"] == pytest.approx(plot["Gd_n0"], rel=1e-12)
    assert allt["centre_track"]["Gd_n0"] == pytest.approx(one["Gd_n0"], rel=1e-12)


def test_road_files_follow_the_umask(tmp_path):
    old = os.umask(0o027)
    try:
        assert main(["road", "generate", "--class", "B", "--length", "50", "--width", "0",
                     "--out", str(tmp_path / "r.npz")]) == 0
    finally:
        os.umask(old)
    for f in (tmp_path / "r.npz", tmp_path / "r.npz.summary.json"):
        assert f.stat().st_mode & 0o777 == 0o640, f
