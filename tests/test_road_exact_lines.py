"""Exact lines (roadlib.surface "Exact lines"): a synthesised road read at a tyre's own lateral
position is the harmonic field there, not the bilinear mix of the two grid lines beside it.

References: ``HarmonicField.evaluate``, the pointwise harmonic sum (it shares no code with the
FFT grid path the lines use); the grid itself on grid lines; numpy's uniform filter; the blend
formula of ``join_sides``.  Tolerances: 1e-10 of the road's height range where two exact
evaluations of one sum are compared (round-off of sums of ~1e4 harmonics is ~1e-13); 1e-6 where
a .crg file's float32 grid is involved.
"""
import numpy as np
import pytest
from scipy.ndimage import uniform_filter1d

from roadlib.segments import RoadSegment, segmented_surface
from roadlib.surface import RoadSurface
from roadlib.synthesis import SpectralParams, harmonic_field, synth_surface

#: off-grid lateral positions of the dump truck's tyres (grid lines every 0.1 m)
TYRES = [-1.02, -0.76, 0.76, 1.02]


def _field_road():
    params = SpectralParams(Gq_n0=64e-6, w=2.0, nmin=0.05, nmax=5.0, dx=0.05, dy=0.1)
    road = synth_surface(params, 60.0, 3.0, seed=11)
    field = harmonic_field(params, 60.0, 3.0, 11, lateral=True)
    return road, field


def test_an_off_grid_line_is_the_harmonic_field_there():
    road, field = _field_road()
    x = road.x[::7]
    scale = np.ptp(road.z)
    for y in TYRES:
        exact = road.height(x, np.full_like(x, y))
        ref = field.evaluate(x, y)
        assert np.max(np.abs(exact - ref)) < 1e-10 * scale
    # the bilinear reading the surface had before differs by far more (the test can fail)
    bare = RoadSurface(road.x, road.y, road.z, road.meta)
    mix = bare.height(x, np.full_like(x, 0.76))
    assert np.max(np.abs(mix - field.evaluate(x, 0.76))) > 1e-3 * scale


def test_between_grid_points_the_line_is_linear_in_x():
    road, _ = _field_road()
    xq = road.x[100:120] + 0.3 * road.dx
    line = road.lines(np.array([0.76]))[:, 0]
    assert np.allclose(road.height(xq, 0.76), np.interp(xq, road.x, line), rtol=0, atol=1e-15)


def test_segmented_lines_agree_with_the_grid_on_grid_lines_and_the_field_between():
    segs = [RoadSegment.from_class("C", 40), RoadSegment.from_class("A", 30), RoadSegment.from_class("D", 50)]
    road = segmented_surface(segs, 120.0, 3.0, 0.05, 0.1, seed=4)
    scale = np.ptp(road.z)
    on_grid = road.lines(road.y[[2, 15, 27]])
    assert np.max(np.abs(on_grid - road.z[:, [2, 15, 27]])) < 1e-10 * scale
    # inside segment 1, away from both junction patches, the line is that segment's own field
    j0, j1 = (j["x"] for j in road.meta["junctions"])
    reach = max(j["sx"] for j in road.meta["junctions"]) * 3.0 + 0.1
    inside = (road.x > j0 + reach) & (road.x < j1 - reach)
    a = int(np.flatnonzero(road.x > j0)[0])
    unit = SpectralParams(Gq_n0=1e-6, w=2.0, nmin=segs[1].nmin, nmax=segs[1].nmax, dx=0.05, dy=0.1)
    f = harmonic_field(unit, (int(np.flatnonzero(road.x < j1)[-1]) - a) * 0.05, 3.0,
                       np.random.SeedSequence(4, spawn_key=(1,)), lateral=True)
    g = np.sqrt(segs[1].Gq_n0 / 1e-6)
    line = road.lines(np.array([0.76]))[:, 0]
    assert np.max(np.abs(line[inside] - g * f.evaluate(road.x[inside], 0.76))) < 1e-10 * scale
    # every junction's step is removed on an off-grid line as on the grid (no step larger than
    # the line's own largest elsewhere)
    steps = np.abs(np.diff(line))
    for j in road.meta["junctions"]:
        c = int(np.argmin(np.abs(road.x - j["x"])))
        assert np.max(steps[c - 2:c + 2]) <= np.max(np.delete(steps, np.s_[c - 2:c + 2])) + 1e-15


def test_an_off_grid_line_keeps_the_roads_short_waves():
    """The reason for exact lines: midway between two grid lines the bilinear mix has less
    power at short waves than the road; the exact line has the grid line's.  Long road,
    periodogram averaged over 2-3 cycles/m (about 800 bins: scatter ~4 %)."""
    params = SpectralParams(Gq_n0=64e-6, w=2.0, nmin=0.05, nmax=8.0, dx=0.05, dy=0.1)
    road = synth_surface(params, 2000.0, 2.0, seed=5)
    bare = RoadSurface(road.x, road.y, road.z, road.meta)

    def power(z):
        f = np.fft.rfftfreq(z.size, road.dx)
        p = np.abs(np.fft.rfft(z - z.mean())) ** 2
        return p[(f > 2) & (f < 3)].mean()

    ref = power(road.z[:, np.argmin(np.abs(road.y - 0.7))])
    exact = power(road.track(0.75))
    mixed = power(bare.track(0.75))
    assert abs(np.log(exact / ref)) < 0.15
    assert mixed / ref < 0.85


@pytest.mark.parametrize("suffix", [".npz", ".crg"])
def test_a_saved_road_gets_its_lines_back(tmp_path, suffix):
    segs = [RoadSegment.from_class("B", 30), RoadSegment.from_class("C", 30)]
    road = segmented_surface(segs, 60.0, 3.0, 0.05, 0.1, seed=9)
    path = road.save(tmp_path / f"road{suffix}")
    back = RoadSurface.load(path)
    tol = (1e-10 if suffix == ".npz" else 1e-6) * np.ptp(road.z)
    assert np.max(np.abs(back.tracks(TYRES) - road.tracks(TYRES))) < tol
    # a grid that is not what its metadata makes (edited after generation) is read bilinearly
    edited = RoadSurface(road.x, road.y, road.z + 1e-3 * (road.x[:, None] > 30), road.meta)
    p2 = edited.save(tmp_path / f"edited{suffix}")
    back2 = RoadSurface.load(p2)
    bare = RoadSurface(edited.x, edited.y, edited.z, edited.meta)
    assert np.max(np.abs(back2.tracks(TYRES) - bare.tracks(TYRES))) < tol
    assert back2.lines is None


def test_footprint_and_side_join_carry_the_lines():
    from inverse.truck import join_sides

    road, _ = _field_road()
    other = synth_surface(SpectralParams(Gq_n0=16e-6, w=2.5, nmin=0.05, nmax=5.0, dx=0.05, dy=0.1),
                          60.0, 3.0, seed=12)
    ys = np.array(TYRES + [0.1])
    filt = road.footprint_filtered(0.25)
    n = int(round(0.25 / road.dx)) | 1
    assert np.allclose(filt.lines(ys), uniform_filter1d(road.lines(ys), n, axis=0, mode="nearest"),
                       rtol=0, atol=1e-15)
    both = join_sides(road, other)
    u = np.clip((ys + 0.3) / 0.6, 0, 1)
    s = 0.5 - 0.5 * np.cos(np.pi * u)
    assert np.allclose(both.lines(ys), road.lines(ys) * s + other.lines(ys) * (1 - s), rtol=0, atol=1e-15)
    # a tyre outside the join strip reads exactly one side's line
    assert np.array_equal(both.track(0.76), road.track(0.76))


def test_the_simulator_reads_each_tyres_own_line():
    from vehicles.builder import build_model
    from vehicles.params import load_vehicle
    from vehicles.simulate import road_under_tyres

    segs = [RoadSegment.from_class("C", 80)]
    road = segmented_surface(segs, 80.0, 3.0, 0.05, 0.1, seed=2)
    model = build_model(load_vehicle("dump_truck_8x4"), "rigid")
    s = np.linspace(0.0, 40.0, 801)
    v = np.full_like(s, 10.0)
    z, _ = road_under_tyres(road, model, 20.0, 0.0, s, v)
    for c, ct in enumerate(model.contacts):
        xq = 20.0 + model.vp.axles[ct.axle].x + s
        line = road.lines(np.array([ct.y]))[:, 0]
        assert np.allclose(z[:, c], np.interp(xq, road.x, line), rtol=0, atol=1e-12)


def test_a_pickled_road_keeps_its_lines():
    """Process pools and Dask move roads by pickle; the closure is not pickled, the lines come back
    from the metadata as for a loaded file."""
    import pickle

    segs = [RoadSegment.from_class("C", 30), RoadSegment.from_class("B", 30)]
    road = segmented_surface(segs, 60.0, 3.0, 0.05, 0.1, seed=6)
    back = pickle.loads(pickle.dumps(road))
    assert np.max(np.abs(back.tracks(TYRES) - road.tracks(TYRES))) < 1e-10 * np.ptp(road.z)
    assert np.array_equal(back.z, road.z)
