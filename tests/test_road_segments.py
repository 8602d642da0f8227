"""Segments and junction patches (roadlib.segments, eq (8))."""
import numpy as np
import pytest

from eroad.errors import EroadInputError
from roadlib.segments import RoadSegment, segmented_surface


def _road(seed=0, width=4.0):
    segs = [RoadSegment.from_class("A", share=200), RoadSegment.from_class("E", share=200),
            RoadSegment.from_class("B", share=100)]
    return segmented_surface(segs, 500.0, width, 0.1, 0.1, seed=seed)


@pytest.mark.parametrize("width", [0.0, 4.0])
def test_junction_steps_bounded(width):
    """No step across a junction larger than 3x the median step of the field next to it.

    'The field' is the rougher of the two neighbouring segments (outside all patch
    supports): a step across a junction is the sum of the two fields' own half-steps
    (docs/roadlib.md), i.e. ordinary roughness of the rougher side (its std is ~0.75x that
    side's median step, against 1.46x for a full step), so it can only be compared with
    the roughness that is there.  Measured over 30 seeds x 2 junctions of this A-E-B road
    (41 lines each): largest ratio 2.94, mean 1.8; seed 0 is not the worst case.  The
    unpatched concatenation would jump by the offset the patches removed, asserted to be
    > 3x the bound, so the test can fail.

    Seed changed 0 -> 3 on 2026-11-21: the synthesis now draws one phase per bin of a
    fixed grid (common random numbers, issue 5), which changed every realisation; with
    the new phases seed 0 removes an offset of only 1.8x the bound at one junction (the
    patch still holds: step ratio 0.27), so it no longer shows what an unpatched
    junction would do.  Seed 3: step ratios 0.29/0.05 (width 0) and 0.76/0.66 (4 m),
    offsets 5.7/4.5 and 3.9/11.8 x the bound."""
    s = _road(seed=3, width=width)
    steps = np.abs(np.diff(s.z, axis=0))
    x_mid = s.x[:-1] + 0.5 * s.dx
    segs, juncs = s.meta["segments"], s.meta["junctions"]
    away = np.ones(x_mid.size, bool)
    for jc in juncs:
        away &= np.abs(x_mid - jc["x"]) > 3 * jc["sx"]
    for j, jc in enumerate(juncs):
        k = int(np.argmin(np.abs(x_mid - jc["x"])))
        assert abs(x_mid[k] - jc["x"]) < 1e-9
        meds = [np.median(steps[away & (x_mid > g["start"]) & (x_mid < g["end"])])
                for g in (segs[j], segs[j + 1])]
        bound = 3 * max(meds)
        assert np.max(steps[k]) <= bound
        assert jc["max_offset_removed"] > 3 * bound     # what an unpatched junction would do
        assert not jc["sx_capped"]


def test_segment_lengths_follow_shares():
    """Segment edges at the requested proportions, to half a grid step (junctions sit
    half-way between samples)."""
    s = _road(seed=2, width=0.0)
    edges = [seg["start"] for seg in s.meta["segments"]] + [s.meta["segments"][-1]["end"]]
    assert edges == pytest.approx([0.0, 200.0, 400.0, 500.0], abs=0.5 * 0.1 + 1e-9)
    # each segment keeps its own roughness away from the junctions (A << E)
    zA = s.z[(s.x > 20) & (s.x < 180), 0]
    zE = s.z[(s.x > 220) & (s.x < 380), 0]
    assert np.std(np.diff(zE)) / np.std(np.diff(zA)) == pytest.approx(16.0, rel=0.25)


def test_segmented_same_seed_same_bytes():
    a, b, c = _road(seed=3), _road(seed=3), _road(seed=4)
    assert a.z.tobytes() == b.z.tobytes() and a.meta == b.meta
    assert not np.array_equal(a.z, c.z)


def test_level_scaling_and_the_unit_cache():
    """A segment is its unit-level synthesis scaled by sqrt(Gq_n0 / UNIT_GQ) (the synthesis
    is linear in the amplitudes), cached per process.  A road with every level times 4 is
    the same road times 2 (the junction patches scale too: their width depends on the
    ratio of step to median step); tolerance 1e-12 of the road's range, rounding only.  A
    cache miss and a hit give the same bytes, and a fresh harmonic field of the segment's own
    level (no cache) agrees to rounding."""
    import roadlib.segments as seg
    from roadlib.synthesis import harmonic_field

    segs = [RoadSegment.from_class("B", share=2), RoadSegment.from_class("D", share=1, w=2.4)]
    a = segmented_surface(segs, 80.0, 1.0, 0.05, 0.1, seed=5)
    b = segmented_surface([RoadSegment(Gq_n0=4 * sg.Gq_n0, share=sg.share, w=sg.w) for sg in segs],
                          80.0, 1.0, 0.05, 0.1, seed=5)
    tol = 1e-12 * np.ptp(a.z)
    np.testing.assert_allclose(b.z, 2.0 * a.z, rtol=0, atol=2 * tol)
    seg._unit_cache.clear()
    c = segmented_surface(segs, 80.0, 1.0, 0.05, 0.1, seed=5)
    assert c.z.tobytes() == a.z.tobytes()
    p0 = segs[0].params(0.05, 0.1)
    n0 = int(round(a.meta["junctions"][0]["x"] / 0.05 - 0.5)) + 1
    f = harmonic_field(p0, (n0 - 1) * 0.05, 1.0, np.random.SeedSequence(5, spawn_key=(0,)))
    np.testing.assert_allclose(f.grid(0.0, 10, a.y), a.z[:10], rtol=0, atol=tol)


def test_single_segment_is_a_plain_surface():
    s = segmented_surface([RoadSegment.from_class("C")], 50.0, 1.0, 0.1, 0.1, seed=9)
    assert s.meta["junctions"] == [] and s.z.shape == (501, 11)


@pytest.mark.parametrize("segs, kw, msg", [
    ([], {}, "no segments"),
    (["C"], {}, "segment 0 is a str, not a RoadSegment"),
    ([RoadSegment.from_class("C", share=1), RoadSegment.from_class("D", share=1e-6)], {},
     "segment 1 \\(D\\) gets fewer than 2 samples"),
    ([RoadSegment.from_class("C")], {"seed": -1}, "seed must be a non-negative integer"),
    ([RoadSegment.from_class("C")], {"dx": 0.0}, "grid spacing dx"),
    ([RoadSegment.from_class("C", nmax=6.0)], {}, "segment C: SpectralParams: nmax = 6"),
])
def test_bad_segments_refused(segs, kw, msg):
    args = dict(length=100.0, width=0.0, dx=0.1, dy=0.1, seed=0)
    args.update(kw)
    with pytest.raises(EroadInputError, match=msg):
        segmented_surface(segs, **args)


def test_bad_segment_share_refused():
    with pytest.raises(EroadInputError, match="share must be positive"):
        RoadSegment.from_class("C", share=0)
    with pytest.raises(EroadInputError, match="unknown ISO 8608 road class"):
        RoadSegment.from_class("Q")


def test_unit_cache_bounded_in_bytes(monkeypatch):
    """The unit cache keeps at most UNIT_CACHE_BYTES of grids (the newest entry always)."""
    import roadlib.segments as seg

    seg._unit_cache.clear()
    monkeypatch.setattr(seg, "UNIT_CACHE_BYTES", 1)
    for sd in range(3):
        segmented_surface([RoadSegment.from_class("C")], 30.0, 1.0, 0.1, 0.1, seed=sd)
    assert len(seg._unit_cache) == 1
    seg._unit_cache.clear()
