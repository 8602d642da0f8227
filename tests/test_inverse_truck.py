"""The Exudyn truck as the inverse fit's simulator (inverse.truck) and common random
numbers in roadlib.synthesis (issue 5, items 1-2)."""
import pickle

import numpy as np
import pytest

from eroad.errors import EroadInputError
from inverse.sensitivity import check_common_random_numbers
from inverse.truck import TruckPredictRms, TruckSimulator, nmax_cap, road_from_params
from roadlib.synthesis import SpectralParams, harmonic_field

VEHICLE = "dump_truck_8x4"
P2 = np.array([[64e-6, 2.0, 0.05, 4.0], [256e-6, 1.8, 0.08, 5.0]])


def _band_corr(a, b, dx, lo=0.5, hi=2.0):
    fa, fb = np.fft.rfft(a), np.fft.rfft(b)
    n = np.fft.rfftfreq(a.size, dx)
    sel = (n >= lo) & (n <= hi)
    x, y = np.fft.irfft(np.where(sel, fa, 0), a.size), np.fft.irfft(np.where(sel, fb, 0), b.size)
    return float(np.corrcoef(x, y)[0, 1])


@pytest.mark.parametrize("field,value", [("nmin", 0.055), ("nmax", 4.0), ("w", 2.2), ("Gq_n0", 300e-6)])
def test_synthesis_keeps_phases_when_parameters_move(field, value):
    """Same seed, one parameter moved: the 0.5-2 cycles/m content of a 200 m profile keeps
    its phases (correlation > 0.999; before the fixed grid, nmin 0.05 -> 0.055 gave 0.004).
    Inside the band only the amplitudes change, by a smooth factor, so the correlation is
    near 1 whatever the move; a redraw of the phases would give about 0 +- 0.1."""
    import dataclasses
    p = SpectralParams(Gq_n0=256e-6, w=2.0, nmin=0.05, nmax=5.0, dx=0.05)
    q = dataclasses.replace(p, **{field: value})
    za = harmonic_field(p, 200.0, 0.0, seed=7).grid(0.0, 4001)[:, 0]
    zb = harmonic_field(q, 200.0, 0.0, seed=7).grid(0.0, 4001)[:, 0]
    assert _band_corr(za, zb, 0.05) > 0.999
    zc = harmonic_field(p, 200.0, 0.0, seed=8).grid(0.0, 4001)[:, 0]
    assert abs(_band_corr(za, zc, 0.05)) < 0.3          # another seed: other phases


def test_band_edge_is_continuous():
    """The band is a fractional amplitude mask: moving nmin by 1e-4 cycles/m (1/25 of a
    bin of 1/400 cycles/m) removes the PSD integral over the 1e-4 (Gd(0.05) 1e-4 =
    1.024e-7 m^2, 0.2 % of the variance) within 2 % (the edge bin carries Gd at its
    centre, 0.05 cycles/m: the PSD varies by 0.2 % over 1e-4), not a whole bin (25x)."""
    p = SpectralParams(Gq_n0=256e-6, w=2.0, nmin=0.05, nmax=5.0, dx=0.05)
    q = SpectralParams(Gq_n0=256e-6, w=2.0, nmin=0.0501, nmax=5.0, dx=0.05)
    fa, fb = harmonic_field(p, 200.0, seed=1), harmonic_field(q, 200.0, seed=1)
    assert fa.n_fft == fb.n_fft
    drop = fa.variance() - fb.variance()
    assert drop == pytest.approx(256e-6 * (0.05 / 0.1) ** -2.0 * 1e-4, rel=0.02)


def _sim(**kw):
    t = 460.0 + np.arange(1200) / 200.0             # 6 s at 200 Hz
    return TruckSimulator(VEHICLE, t, 10.0, [t[0], t[0] + 3.0, t[-1]],
                          ["susp_disp_3L", "susp_disp_3R", "axle_acc_3L"], **kw)


def test_truck_common_random_numbers_and_pickle():
    """check_common_random_numbers on the truck: every correlation > 0.9 (issue 5 asks
    > 0.9; measured >= 0.99 on the 30 s luliang drive).  The simulator pickles (process
    pools) and the unpickled copy gives the same bytes."""
    sim = _sim()
    out = sim(P2, 3)
    assert set(out) == {"susp_disp_3L", "susp_disp_3R", "axle_acc_3L"}
    assert all(v.shape == (1200,) and np.all(np.isfinite(v)) for v in out.values())
    crn = check_common_random_numbers(sim, P2, seed=3)
    assert min(crn.values()) > 0.9, crn
    again = pickle.loads(pickle.dumps(sim))(P2, 3)
    assert all(np.array_equal(out[c], again[c]) for c in out)
    other = sim(P2, 4)
    assert np.corrcoef(out["susp_disp_3L"], other["susp_disp_3L"])[0, 1] < 0.5


def test_layout_puts_boundaries_under_axle_3():
    """Segment lengths follow the speed: 3 s at 10 m/s is 30 m of road for the first
    segment after the reference axle's start position."""
    lay = _sim().layout()
    assert lay["x_bounds"][1] - (lay["x_front0"] + _axle_x(3) + 2.0 * 10.0) == pytest.approx(30.0, abs=1e-6)
    assert lay["road_length"] >= lay["x_bounds"][1] + 30.0


def _axle_x(i):
    from vehicles.params import load_vehicle
    return float(load_vehicle(VEHICLE).axles[i - 1].x)


def test_road_from_params_and_nmax_cap():
    """The global road: K segments of the given lengths, the simulator's grid, nmax capped
    at 1/(2 dx) when asked for more."""
    road = road_from_params(P2, [40.0, 60.0], seed=2, width=3.0)
    assert len(road.meta["segments"]) == 2 and len(road.meta["junctions"]) == 1
    assert road.meta["segments"][0]["end"] == pytest.approx(40.0, abs=0.05)
    assert nmax_cap() == pytest.approx(10.0)
    big = road_from_params(np.array([[64e-6, 2.0, 0.05, 30.0]]), [50.0], seed=2, width=3.0)
    assert big.meta["segments"][0]["nmax"] == pytest.approx(20.0)


def test_road_from_params_two_slope_columns():
    """Six columns: NaN in (w2, n_break) is the four-column road bit for bit; a two-slope
    row gives a segment whose track follows the two slopes.  The Whittle two-slope fit of
    the Welch PSD of a 3 km single track (1024-point segments: about 230 averages, each
    bin's log scatter about 0.07) recovers the exponents within 0.15 and the break within
    a factor 1.3 -- the tolerances of tests/test_road_model.py's synthesis check, which
    has fewer averages; the segment's meta carries w2 and n_break so the chassis study's
    equivalent realisations keep them."""
    from scipy.signal import welch

    from inverse.road_model import fit_two_slope_psd
    from studies.chassis_study import _equivalent_segments

    P6 = np.column_stack([P2, np.full((2, 2), np.nan)])
    a = road_from_params(P2, [40.0, 60.0], seed=2, width=3.0)
    b = road_from_params(P6, [40.0, 60.0], seed=2, width=3.0)
    assert np.array_equal(a.z, b.z) and "w2" not in b.meta["segments"][0]
    two = np.array([[256e-6, 3.0, 0.02, 4.0, 1.7, 0.25]])
    road = road_from_params(two, [3000.0], seed=5, width=0.0, dx=0.1)
    n, g = welch(road.z[:, 0], fs=10.0, nperseg=1024)
    r = fit_two_slope_psd(n, g, (0.04, 3.0))
    assert abs(r["w_low"] - 3.0) < 0.15 and abs(r["w_high"] - 1.7) < 0.15
    assert abs(np.log(r["n_break"] / 0.25)) < np.log(1.3)
    seg = road.meta["segments"][0]
    assert (seg["w2"], seg["n_break"]) == (1.7, 0.25)
    eq, _ = _equivalent_segments(road)
    assert (eq[0]["w2"], eq[0]["n_break"]) == (1.7, 0.25)
    with pytest.raises(EroadInputError, match="4 or 6 columns"):
        road_from_params(P2[:, :3], [40.0, 60.0], seed=2)


def test_predict_rms_scales_with_sqrt_gq():
    """Linear model: the displacement RMS scales with sqrt(Gq_n0) exactly (linearity),
    and a truck on class C at 10 m/s has suspension travel of a few mm."""
    pr = TruckPredictRms(VEHICLE)
    a, b = pr(256e-6, 2.0, 10.0), pr(1024e-6, 2.0, 10.0)
    assert b / a == pytest.approx(2.0, rel=1e-9)
    assert 1e-3 < a < 2e-2
    pickle.dumps(pr)


def test_join_sides_keeps_each_track():
    """The per-side road: tracks outside the 0.3 m centre strip are exactly the left
    road's (y > 0) and the right road's (y < 0); the seed pair reaches the simulator's road."""
    from inverse.truck import join_sides
    a = road_from_params(P2, [40.0, 60.0], seed=1, width=3.0)
    b = road_from_params(P2, [40.0, 60.0], seed=2, width=3.0)
    j = join_sides(a, b)
    left, right = np.flatnonzero(a.y >= 0.3), np.flatnonzero(a.y <= -0.3)
    assert np.array_equal(j.z[:, left], a.z[:, left]) and np.array_equal(j.z[:, right], b.z[:, right])
    sim = _sim()
    r = sim.road(P2, (1, 2))
    assert r.meta["seed_left"] != r.meta["seed_right"]


def test_truck_simulator_equals_vehicles_simulate_on_one_road():
    """TruckSimulator against a direct ``vehicles.simulate`` run laid out by hand from the
    documented geometry (docs/inverse.md section 7): the simulation starts 2 s before the
    record (a 4 s record at 200 Hz starting at t = 100 s) at the record's speed, the
    rearmost axle 10 m into the road (drives.synth.ROAD_MARGIN_M); the boundary at record
    time 102 s is where axle 3 is then; the road ends 10 m past axle 1's last position,
    rounded up to the 0.025 m grid; the road is built here with roadlib.segments from the
    hand lengths and the same seed.  The record is the simulation's samples 400..1199.

    Same road, model, integrator and step, so only round-off separates the two (the simulator's
    fs = 1/mean(diff(t)) is 199.9999999999998 Hz for this time axis): agreement within
    1e-8 of each channel's sd (measured 3e-11).  The speed 9.137 m/s is deliberately not
    commensurate with the road grid: at 9 m/s the step (22.5 mm) puts tyres exactly on
    grid nodes every 9 steps, where the road slope fed to the tyre damper flips between the
    two cells on a round-off, and the two runs then differ by 0.1-0.5 % (displacement) and
    up to 12 % of the sd at axle-acceleration peaks."""
    import math

    from roadlib.segments import RoadSegment, segmented_surface
    from vehicles.params import load_vehicle
    from vehicles.simulate import simulate

    fs, n, v = 200.0, 800, 9.137
    t = 100.0 + np.arange(n) / fs
    channels = ["susp_disp_3L", "axle_acc_3R", "body_acc_3L", "susp_disp_1R"]
    sim = TruckSimulator(VEHICLE, t, v, [t[0], 102.0, t[-1]], channels)
    got = sim(P2, 5)

    axle_x = [float(a.x) for a in load_vehicle(VEHICLE).axles]
    x_front0 = 10.0 - min(axle_x)
    runin = 2.0
    duration = runin + (n - 1) / fs
    x_b = x_front0 + axle_x[2] + v * (runin + 2.0)
    length = math.ceil((x_front0 + v * duration + 10.0) / 0.025) * 0.025
    lay = sim.layout()
    np.testing.assert_allclose(lay["x_bounds"], [0.0, x_b, length], rtol=0, atol=1e-9)
    road = segmented_surface([RoadSegment(Gq_n0=p[0], share=s, w=p[1], nmin=p[2], nmax=p[3], lam=1.0)
                              for p, s in zip(P2, (x_b, length - x_b))], length, 3.0, 0.025, 0.1, seed=5)
    # the same integrator as the simulator's (inverse.truck.SIM_SOLVER unless given)
    ref = simulate(VEHICLE, road, speed=v, duration=duration, fs_out=fs, x_start=x_front0, seed=0,
                   solver=sim.solver)
    first = int(round(runin * fs))
    for c in channels:
        r = np.asarray(ref.channels[c])[first:first + n]
        assert got[c].shape == (n,)
        assert np.max(np.abs(got[c] - r)) < 1e-8 * np.std(r), c
