"""`eroad road ...` smoke tests through eroad.cli.main with tmp_path."""
import json
from pathlib import Path

import numpy as np
import pytest

from eroad.cli import main
from roadlib.surface import RoadSurface

#: copy of ../shared/data/iri/profile_1.txt (provenance: tests/data/iri/PROVENANCE.md)
PROFILE = Path(__file__).resolve().parent / "data" / "iri" / "profile_1.txt"


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_generate_psd_plot_crg(tmp_path, capsys):
    """generate -> summary (json) -> psd -> plot -> crg export, the user's path in the issue.
    PSD class check: 500 m x 4 m class C, fitted level within its class bounds."""
    out = tmp_path / "c.npz"
    code, so, _ = _run(capsys, "road", "generate", "--class", "C", "--length", "500", "--width", "2",
                       "--seed", "3", "--out", str(out), "--json")
    assert code == 0
    summary = json.loads(so)
    assert summary["centre_track_psd"]["class"] == "C"
    assert json.loads((tmp_path / "c.npz.summary.json").read_text()) == summary
    s = RoadSurface.load(out)
    assert s.z.shape == (5001, 21) and s.meta["seed"] == 3

    code, so, _ = _run(capsys, "road", "psd", str(out), "--json")
    res = json.loads(so)
    assert code == 0 and res["class"] == "C" and 128e-6 <= res["Gd_n0"] < 512e-6

    code, so, _ = _run(capsys, "road", "plot", str(out))
    assert code == 0 and (tmp_path / "c.png").stat().st_size > 10_000

    crg = tmp_path / "c.crg"
    assert _run(capsys, "road", "generate", "--class", "C", "--length", "500", "--width", "2",
                "--seed", "3", "--out", str(crg))[0] == 0
    assert np.max(np.abs(RoadSurface.load(crg).z - s.z)) < 1e-6

    code, so, _ = _run(capsys, "road", "iri", str(crg), "--track", "0.5", "--segment", "100", "--json")
    rows = json.loads(so)
    assert code == 0 and len(rows) == 5 and all(r["iri"] > 0 for r in rows)


def test_iri_of_shared_profile(capsys):
    code, so, _ = _run(capsys, "road", "iri", str(PROFILE), "--segment", "100", "--json")
    rows = json.loads(so)
    assert code == 0
    assert [r["start"] for r in rows] == [478, 578, 678, 778, 878]
    assert rows[0]["iri"] == pytest.approx(3.2985, abs=1e-3)


def test_iri_comma_separated_with_header(tmp_path, capsys):
    d = np.loadtxt(PROFILE)
    f = tmp_path / "p.csv"
    f.write_text("x_m,z_m\n" + "\n".join(f"{a},{b}" for a, b in d))
    code, so, _ = _run(capsys, "road", "iri", str(f), "--segment", "100", "--json")
    assert code == 0 and json.loads(so)[3]["iri"] == pytest.approx(4.0855, abs=1e-3)


def test_segments_cli_and_toml(tmp_path, capsys):
    """Segments from the command line and from a TOML file.  Direction: the E segment
    has 4^4 = 256 times the displacement PSD level of the A
    segment (ISO 8608, same waviness), and the IRI is a linear filter of the profile, so
    its IRI is sqrt(256) = 16 times larger in expectation.  Asserted: between 8 and 32
    (a factor 2 either side covers the realisation scatter of a 100 m IRI, +-20 % per
    segment; measured 15.5-18.7 over seeds 0-3); a swapped or flattened class table
    fails."""
    out = tmp_path / "s.npz"
    code, so, _ = _run(capsys, "road", "generate", "--segment", "A:100", "--segment", "E:100", "--width", "0",
                       "--out", str(out), "--json")
    assert code == 0 and len(json.loads(so)["junctions"]) == 1
    code, so, _ = _run(capsys, "road", "iri", str(out), "--segment", "100", "--json")
    rows = json.loads(so)
    assert code == 0 and [r["start"] for r in rows] == [0, 100]
    assert 8.0 <= rows[1]["iri"] / rows[0]["iri"] <= 32.0, rows
    toml = tmp_path / "segs.toml"
    toml.write_text('[[segment]]\nclass = "B"\nlength = 60\n\n[[segment]]\nGq_n0 = 1e-3\nlength = 40\n'
                    'w = 2.5\nlambda = 2.0\n')
    code, so, _ = _run(capsys, "road", "generate", "--segments", str(toml), "--width", "1",
                       "--out", str(tmp_path / "t.crg"), "--json")
    segs = json.loads(so)["segments"]
    assert code == 0 and segs[1]["w"] == 2.5 and segs[1]["lam"] == 2.0


@pytest.mark.parametrize("argv, msg", [
    (["--class", "C", "--dx", "0.2", "--nmax", "5"], "exceeds the Nyquist frequency"),
    (["--class", "Q"], "unknown ISO 8608 road class 'Q'"),
    ([], "give the road: --class C"),
    (["--class", "C", "--gd0", "1e-4"], "give only one of"),
    (["--segment", "C300"], "expected CLASS:LENGTH"),
    (["--segment", "C:abc"], "is not a number of metres"),
    (["--segment", "C:100", "--length", "50"], "differs from the sum of the segment lengths"),
    (["--class", "C", "--seed", "-3"], "--seed must be a non-negative integer"),
    (["--gd0", "256"], "implausible"),
])
def test_generate_bad_parameters(tmp_path, capsys, argv, msg):
    code, _, err = _run(capsys, "road", "generate", *argv, "--length" if "--segment" not in argv[:1] and
                        "--length" not in argv else "--width", "50" if "--length" not in argv else "0",
                        "--out", str(tmp_path / "x.npz"))
    assert code == 2
    assert msg in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "x.npz").exists()


def test_argparse_refuses_nonpositive_numbers(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["road", "generate", "--class", "C", "--dx", "-1", "--out", str(tmp_path / "x.npz")])
    assert exc.value.code == 2
    assert "'-1' must be positive" in capsys.readouterr().err


def test_never_overwrites_without_force(tmp_path, capsys):
    out = tmp_path / "r.npz"
    out.write_bytes(b"user data")
    code, _, err = _run(capsys, "road", "generate", "--class", "C", "--length", "20", "--out", str(out))
    assert code == 2 and "exists; refusing to overwrite it (use --force)" in err
    assert out.read_bytes() == b"user data"
    code, _, _ = _run(capsys, "road", "generate", "--class", "C", "--length", "20", "--out", str(out), "--force")
    assert code == 0 and RoadSurface.load(out).length == pytest.approx(20.0)
    png = tmp_path / "r.png"
    png.write_bytes(b"mine")
    code, _, err = _run(capsys, "road", "plot", str(out))
    assert code == 2 and png.read_bytes() == b"mine"


def test_bad_toml_and_profiles(tmp_path, capsys):
    toml = tmp_path / "segs.toml"
    toml.write_text('[[segment]]\nclass = "B"\nlength = 60\ncolour = "red"\n')
    code, _, err = _run(capsys, "road", "generate", "--segments", str(toml), "--out", str(tmp_path / "a.npz"))
    assert code == 2 and "segs.toml, segment 1: unknown key 'colour'" in err
    prof = tmp_path / "p.txt"
    prof.write_text("0 0\n0.25 0.1\n0.5 x\n")
    code, _, err = _run(capsys, "road", "iri", str(prof), "--segment", "10")
    assert code == 2 and "p.txt, row 3: not numeric" in err
    prof.write_text("0 0 1\n")
    code, _, err = _run(capsys, "road", "iri", str(prof), "--segment", "10")
    assert code == 2 and "row 1: expected 2 columns" in err
    out = tmp_path / "w.npz"
    assert _run(capsys, "road", "generate", "--class", "C", "--length", "30", "--out", str(out))[0] == 0
    code, _, err = _run(capsys, "road", "iri", str(out), "--segment", "10")
    assert code == 2 and "choose a track with --track Y" in err
    code, _, err = _run(capsys, "road", "iri", str(out), "--segment", "10", "--track", "9")
    assert code == 2 and "--track 9 m is outside the road" in err
    code, _, err = _run(capsys, "road", "generate", "--class", "C", "--out", str(tmp_path / "a.txt"))
    assert code == 2 and "use a .npz or .crg file name" in err


def test_gd0_above_class_h_is_refused(tmp_path, capsys):
    """--gd0 1 (a value in 1e-6 m^3 given as m^3, say) lies above class H's range
    (H: 0.131-0.524 m^3): one line, exit 2, nothing written; class H's own level passes."""
    from eroad.cli import main

    out = tmp_path / "r.npz"
    assert main(["road", "generate", "--gd0", "1", "--length", "20", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "above the range" in err and "\n" not in err and not out.exists()
    assert main(["road", "generate", "--gd0", "0.262144", "--length", "20", "--out", str(out)]) == 0
