"""IRI by the golden quarter car (roadlib.iri) against the shared reference profile.

Reference: ../shared/data/iri/profile_1.txt and PROVENANCE.md (measured profile, 0.25 m,
IRI of five 100 m segments by the peer implementation michalsorel/iri, quoted to 1e-4
m/km).  Our values come from our own exact-discretisation code.
"""
from pathlib import Path

import numpy as np
import pytest

from eroad.errors import EroadInputError
from roadlib.iri import iri, iri_segments

#: copy of ../shared/data/iri/profile_1.txt kept beside the tests (provenance: tests/data/iri/PROVENANCE.md)
DATA = Path(__file__).resolve().parent / "data" / "iri" / "profile_1.txt"
REFERENCE = [(478, 578, 3.2985), (578, 678, 2.4421), (678, 778, 3.5551), (778, 878, 4.0855),
             (878, 978, 2.7079)]


def test_iri_matches_reference_within_1e3():
    """Each 100 m segment within 1e-3 m/km (issue requirement; the reference is rounded to
    1e-4, we agree to ~4e-5)."""
    d = np.loadtxt(DATA)
    segs = iri_segments(d[:, 0], d[:, 1], 100.0)
    assert [(s.start, s.end) for s in segs] == [(a, b) for a, b, _ in REFERENCE]
    for s, (_, _, ref) in zip(segs, REFERENCE):
        assert abs(s.iri - ref) < 1e-3


def test_iri_of_a_straight_grade_is_zero():
    """A constant slope is the initial steady state (slope initialised over 11 m): IRI 0."""
    x = np.arange(0, 200.001, 0.25)
    assert iri(x, 0.03 * x + 5.0) < 1e-12


def test_iri_scales_linearly():
    """The golden car is linear: k z gives k IRI (round-off 1e-12)."""
    d = np.loadtxt(DATA)
    z = d[:, 1] - d[0, 1]
    assert iri(d[:, 0], 3.0 * z) == pytest.approx(3.0 * iri(d[:, 0], z), rel=1e-12)


def test_moving_average_only_below_0_25_m():
    """dx = 0.05 m: the 250 mm moving average removes a 0.25 m wavelength exactly (IRI 0);
    at dx = 0.25 m there is no averaging and the same kind of short wave is seen."""
    x = np.arange(0, 100.0001, 0.05)
    assert iri(x, 0.005 * np.sin(2 * np.pi * x / 0.25)) < 1e-12
    x = np.arange(0, 100.0001, 0.25)
    assert iri(x, 0.005 * np.sin(2 * np.pi * x / 1.0)) > 1.0


def test_partial_and_start():
    d = np.loadtxt(DATA)
    segs = iri_segments(d[:, 0], d[:, 1], 100.0, start=500.0, partial=True)
    assert segs[0].start == 500.0 and segs[-1].end == pytest.approx(1022.0)


@pytest.mark.parametrize("x, z, kw, msg", [
    (np.array([0, 1, 1, 2.0]), np.zeros(4), {}, "x must increase strictly; row 3"),
    (np.r_[np.arange(0, 20, 0.25), 20.3], np.zeros(81), {}, "uniformly sampled"),
    (np.arange(0, 5, 0.25), np.zeros(20), {}, "shorter than the 11 m"),
    (np.arange(0, 50, 0.25), np.zeros(200), {"segment_length": 0.0}, "segment length must be a positive number"),
    (np.arange(0, 50, 0.25), np.zeros(200), {"segment_length": 100.0}, "no complete 100 m segment"),
    (np.arange(0, 50, 0.25), np.r_[np.zeros(199), np.nan], {}, "NaN/inf at row 200"),
])
def test_bad_profiles_refused(x, z, kw, msg):
    kw.setdefault("segment_length", 10.0)
    with pytest.raises(EroadInputError, match=msg):
        iri_segments(x, z, **kw)
