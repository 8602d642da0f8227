"""Effect ranking on held-out data (diagnosis.which) with the toy model's candidate effects."""
import re

import numpy as np
import pytest

from diagnosis import toy
from diagnosis.which import Candidate, Param, calibrate, candidates_from_library, rank_effects


def _windows(effects, seed, n=4, length=20.0):
    meas = toy.simulate_drive(toy.make_state(effects), n * length, 10.0, seed)
    w = [meas.window(i * length, (i + 1) * length) for i in range(n)]
    return w[0::2], w[1::2]


def test_calibrate_finds_the_minimum():
    """Grid + golden section: 1-D quadratic minimum at u = 0.37; after a 5-point grid the
    bracket is 0.5 wide and 8 golden evaluations shrink it to 0.5 * 0.618^7 = 0.017, so the
    best point is within 0.01, in at most 13 evaluations.  2-D: a 4x4 grid (step 1/3) then one
    golden pass of 5 evaluations per axis over 2/3: bracket 0.67 * 0.618^4 = 0.1, tolerance 0.05
    per axis in unit coordinates (0.05 in a, 0.1 decades in b)."""
    c1 = Candidate("e", (Param("a", 0.0, 1.0),))
    cal = calibrate([c1], lambda e: (e["e"]["a"] - 0.37) ** 2, grid=5, refine=8)
    assert cal.effects["e"]["a"] == pytest.approx(0.37, abs=0.01)
    assert cal.n_evals <= 13
    c2 = Candidate("e", (Param("a", 0.0, 1.0), Param("b", 1.0, 100.0, log=True)))
    cal = calibrate([c2], lambda e: (e["e"]["a"] - 0.6) ** 2 + (np.log10(e["e"]["b"]) - 1.3) ** 2)
    assert cal.effects["e"]["a"] == pytest.approx(0.6, abs=0.05)
    assert np.log10(cal.effects["e"]["b"]) == pytest.approx(1.3, abs=0.1)


def test_calibrate_refines_the_second_basin_of_a_two_basin_grid(monkeypatch):
    """An objective with two basins, as a damper asymmetry's (rebound- or compression-heavy
    fit the band powers alike): a basin at the lower edge (value 0.2145 at u = 0, the grid's
    best point) and a deeper one at u = 0.85 (0.205) between the last two grid points of a
    4-point grid (0.2218 at 2/3, 0.2162 at 1).  The values are shaped on blind case 005's
    second fold (0.2145, 0.3275, 0.2291, 0.2239 on the grid) (results/diagnosis_blind/20261127-fresh-40; damper ratio 0.3 ... 6, log).
    Refining only the grid's best point stays at the edge; refining every grid basin finds
    the deeper one within the golden bracket's tolerance (2/3 * 0.618^2 = 0.25 after 3
    evaluations; 0.85 +- 0.15 asked)."""
    import diagnosis.which as which

    def obj(e):
        u = e["e"]["a"]
        return min(0.2145 + 0.3 * u, 0.205 + 0.5 * (u - 0.85) ** 2 + (0.3 if u < 0.55 else 0.0))

    c = Candidate("e", (Param("a", 0.0, 1.0),))
    vals = [obj({"e": {"a": u}}) for u in np.linspace(0, 1, 4)]
    assert int(np.argmin(vals)) == 0                   # the grid's best is the edge basin
    cal = calibrate([c], obj, grid=4, refine=3)
    assert cal.effects["e"]["a"] == pytest.approx(0.85, abs=0.15)
    assert cal.calib_gap < 0.2145
    assert cal.n_evals <= 4 + 3 + 3
    monkeypatch.setattr(which, "BASINS", 1)            # the old search: best grid point only
    assert calibrate([c], obj, grid=4, refine=3).effects["e"]["a"] < 0.34


def test_a_wide_log_range_gets_a_finer_grid(monkeypatch):
    """A one-parameter search over 3 decades (the frame's stiffness factor 0.1-100) with the
    budget's 4 grid points would step a decade at a time; ``grid_points`` gives it 6 (0.6
    decade a step, GRID_MAX_DECADES 0.65), ranges of up to 1.95 decades keep 4 and a linear
    range keeps 4.  The objective: a slope rising with log10 x and a well 0.3 decade wide at
    x = 3 (the weak-frame drives' truths were 1.8-7.6), whose depth the 1-decade grid does not
    see (grid values 0.30, 0.33, 0.39, 0.45: best at the 0.1 edge, which the golden section
    within a decade of it cannot leave).  With 6 points the grid's best is 10^0.2 and 3 golden
    evaluations between 10^-0.4 and 10^0.8 reach 10^0.52 (0.15 decade asked)."""
    import diagnosis.which as which
    from diagnosis.which import grid_points

    assert grid_points(Param("k", 0.1, 100.0, log=True), 4) == 6
    assert grid_points(Param("gap", 0.001, 0.08, log=True), 4) == 4
    assert grid_points(Param("ratio", 0.2, 8.0, log=True), 4) == 4
    assert grid_points(Param("mass", -14000.0, 14000.0), 4) == 4

    def obj(e):
        lg = np.log10(e["e"]["k"])
        return 0.30 + 0.05 * (lg + 1.0) - 0.25 * np.exp(-((lg - np.log10(3.0)) / 0.3) ** 2)

    c = Candidate("e", (Param("k", 0.1, 100.0, log=True),))
    cal = calibrate([c], obj, grid=4, refine=3)
    assert np.log10(cal.effects["e"]["k"]) == pytest.approx(np.log10(3.0), abs=0.15)
    assert cal.n_evals <= 6 + 3 + 3
    monkeypatch.setattr(which, "GRID_MAX_DECADES", 10.0)     # the old grid: 4 points
    assert calibrate([c], obj, grid=4, refine=3).effects["e"]["k"] < 0.2


def test_candidates_from_library_reads_an_effect_registry():
    """Duck-typed registry (objects with .parameters of name/default/range): up to two
    calibrated parameters, log search for wide positive ranges, the rest fixed at defaults."""
    class P:
        def __init__(self, name, default, rng):
            self.name, self.default, self.range = name, default, rng

    class Bump:
        parameters = [P("gap", 0.02, (0.01, 0.05)), P("stiffness", 1e6, (1e5, 1e7)), P("c", 0.0, None)]

    cands = candidates_from_library({"bump_stop": Bump(), "x": {"parameters": []}})
    assert [c.name for c in cands] == ["bump_stop"]
    c = cands[0]
    assert [p.name for p in c.params] == ["gap", "stiffness"] and c.params[1].log and not c.params[0].log
    assert c.fixed == {"c": 0.0}
    assert c.effects([0.0, 1.0]) == {"bump_stop": {"c": 0.0, "gap": 0.01, "stiffness": pytest.approx(1e7)}}


def test_ranking_picks_the_true_effect():
    """Truth: tyre stiffness x1.5 (axle hop 11.6 -> 13.9 Hz), nominal model without it.
    Calibrated on windows 1 and 3, scored on 2 and 4 (20 s each), 4 road-phase seeds: the
    verdict is tyre_stiffness, its calibrated scale within 10 % of 1.5, the held-out gap
    shrinks on every seed, and no pair is accepted over it."""
    calib, held = _windows({"tyre_stiffness": {"scale": 1.5}}, 11)
    r = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held, seed=5, n_seeds=4,
                     n_null=6, grid=4, refine=5)
    assert r.gap_present
    assert r.verdict == "tyre_stiffness"
    w = r.winner
    assert w.effects["tyre_stiffness"]["scale"] == pytest.approx(1.5, rel=0.10)
    assert np.all(w.shrink_per_seed > 0) and w.accepted
    assert sum(e.accepted for e in r.entries) >= 1
    assert all(not e.accepted for e in r.entries if "+" in e.effect)
    rec = r.records()[0]
    assert {"effect", "parameters", "heldout_gap_before", "heldout_gap_after", "shrink_fraction",
            "shrink_spread"} <= set(rec)


def test_ranking_picks_sensor_dynamics():
    """Truth: 2nd-order sensor low-pass at 15 Hz on every channel: verdict sensor, cutoff
    within 20 % (the band-power gap only sees the cutoff through a few bands above it)."""
    calib, held = _windows({"sensor": {"cutoff_hz": 15.0}}, 12)
    r = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held, seed=6, n_seeds=4,
                     n_null=6, grid=4, refine=5, pairs=False)
    assert r.verdict == "sensor"
    assert r.winner.effects["sensor"]["cutoff_hz"] == pytest.approx(15.0, rel=0.2)


def test_calibrations_are_submitted_longest_first_and_come_back_in_candidate_order():
    """The worker pool gets the single-candidate calibrations in ``task_order`` (longest first)
    and the ranking's entries come back in the candidates' order with the same values as
    without a pool.  An executor that records what it is handed stands in for the pool; the
    toy's candidates are given a task order that reverses theirs."""
    from diagnosis.which import submission_order

    order = ("leaf_friction", "bump_stop", "speed_scale")
    assert submission_order(["speed_scale", "leaf_friction", "x", "bump_stop"], order) == [1, 3, 0, 2]
    names = [c.name for c in toy.TOY_CANDIDATES]

    class Recording:
        handed = []

        def map(self, fn, tasks):
            tasks = list(tasks)
            if fn.__name__ == "_score_task":          # (the nominal simulations come first)
                Recording.handed.append([t[1][0].name for t in tasks])
            return map(fn, tasks)

    calib, held = _windows({"sensor": {"cutoff_hz": 15.0}}, 12)
    kw = dict(seed=6, n_seeds=2, n_null=4, grid=3, refine=2, pairs=False)
    a = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held,
                     task_order=tuple(names), **kw)                      # the candidates' order
    b = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held, executor=Recording(),
                     task_order=tuple(reversed(names)), **kw)            # reversed
    assert Recording.handed[0] == list(reversed(names))
    assert [e.effect for e in b.entries] == [e.effect for e in a.entries]
    assert [e.heldout_gap_after for e in b.entries] == [e.heldout_gap_after for e in a.entries]
    assert [e.effects for e in b.entries] == [e.effects for e in a.entries]
    assert b.verdict == a.verdict


class _CachingSimulate:
    """The toy's simulator with a cache, as the pipeline's ``Simulate`` keeps its road levels:
    it learns one entry per (window start, seed) it simulates."""

    def __init__(self):
        self.cache = {}

    def __call__(self, state, window, seed):
        self.cache.setdefault((float(window.time[0]), int(seed)), float(seed % 97))
        return toy.simulate(state, window, seed)

    def export_cache(self):
        return dict(self.cache)

    def import_cache(self, cache):
        self.cache.update(cache)


def test_nominal_simulations_run_on_the_pool_and_their_cache_comes_back():
    """The nominal model's held-out, surrogate and calibration simulations of a ranking go to
    the executor (``nominal_sim_sets``): the sets are those of the serial run (same seeds, in
    the jobs' order), and what the workers' simulators learnt reaches the parent's, so the
    calibrations handed out afterwards carry it.  The executor pickles every task (a worker
    process sees a copy), so nothing comes back by shared state."""
    import pickle

    from diagnosis.which import _Scorer, nominal_sim_sets

    class Pickling:
        calls = []

        def map(self, fn, tasks):
            tasks = [pickle.loads(pickle.dumps(t)) for t in tasks]
            Pickling.calls.append((fn.__name__, len(tasks)))
            return map(fn, tasks)

    calib, held = _windows({"sensor": {"cutoff_hz": 15.0}}, 12)
    jobs = [("held", 1, 0), ("held", 2, 3), ("calib", 3, 1)]
    sc_pool = _Scorer(toy.fit, _CachingSimulate(), calib, held, 4, 1, 2, None, None)
    sc_here = _Scorer(toy.fit, _CachingSimulate(), calib, held, 4, 1, 2, None, None)
    a = nominal_sim_sets(sc_pool, jobs, Pickling().map)
    # the serial sets, made directly (not through nominal_sim_sets)
    b = []
    for which, stream, i in jobs:
        ws = sc_here.heldout if which == "held" else sc_here.calib
        b.append(sc_here.sims(toy.fit({}, ws), ws, stream, i))
    assert Pickling.calls == [("_sims_task", 3)]
    assert len(a) == 3 and all(len(s) == 2 for s in a)
    for sa, sb in zip(a, b):
        for wa, wb in zip(sa, sb):
            for c in wb.channels:
                np.testing.assert_array_equal(wa.channels[c], wb.channels[c])
    assert sc_pool.simulate.cache == sc_here.simulate.cache and len(sc_pool.simulate.cache) == 6
    # and the ranking with a pool: the same values as without one
    kw = dict(seed=6, n_seeds=2, n_null=3, grid=3, refine=2, pairs=False)
    r1 = rank_effects(toy.TOY_CANDIDATES[:2], toy.fit, _CachingSimulate(), calib, held, **kw)
    r2 = rank_effects(toy.TOY_CANDIDATES[:2], toy.fit, _CachingSimulate(), calib, held,
                      executor=Pickling(), **kw)
    assert [e.heldout_gap_after for e in r2.entries] == [e.heldout_gap_after for e in r1.entries]
    assert Pickling.calls[1] == ("_sims_task", 3 + 3)          # max(n_seeds, n_null) + n_null


def test_ranking_says_none_on_null_data():
    """Truth = nominal model: no candidate may be accepted and the verdict is "none"."""
    calib, held = _windows({}, 13)
    r = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held, seed=7, n_seeds=4,
                     n_null=6, grid=4, refine=5)
    assert r.verdict == "none" and r.confidence == "none"
    assert not any(e.accepted for e in r.entries)


def test_delay_term_names_a_speed_scale_and_stays_quiet_on_null_data():
    """Speed-signal scale error (toy: true speed 1.06 x the recorded one, i.e. the recorded
    speed reads 6 % low): the band powers barely change (the road fit absorbs the level), but
    the front-to-rear delay is 6 % shorter than the simulation's; with the delay term
    (:class:`diagnosis.which.DelayTerm`, axle 1 -> 3 at the toy's 4 m wheelbase) the verdict
    is speed_scale and the calibrated scale is within 1 % of 1.06 (the delay's standard
    error on 20 s windows is about 0.2 %).  On null data the same ranking says "none"."""
    from diagnosis.which import DelayTerm

    cands = [Candidate("speed_scale", (Param("scale", 0.85, 1.15),)),
             Candidate("damper", (Param("scale", 0.5, 2.0, log=True),))]
    for truth, want in (({"speed_scale": {"scale": 1.06}}, "speed_scale"), ({}, "none")):
        calib, held = _windows(truth, 14)
        r = rank_effects(cands, toy.fit, toy.simulate, calib, held, seed=8, n_seeds=3, n_null=6,
                         grid=4, refine=6, pairs=False,
                         delay=DelayTerm([("axle_acc_1L", "axle_acc_3L")], [4.0]))
        assert r.verdict == want
        assert r.settings["delay"]["weight"] > 0
        if want == "speed_scale":
            assert r.winner.effects["speed_scale"]["scale"] == pytest.approx(1.06, rel=0.01)


def test_delay_is_measured_in_recorded_distance_while_the_speed_changes():
    """A road profile r(x) under a front and a rear axle d = 5 m apart, the truck speeding
    up from 7 to 12 m/s in 7.5 s (blind case 26's window), the speed signal reading
    ``factor`` x the true speed: the lag of :meth:`DelayTerm.log_delays` is ``factor * d``
    within 1 % (about 1.5 grid steps of 0.035 m), where a delay in time would run from
    0.71 s to 0.42 s through the window.  Exact kinematics: the tolerance is the GCC peak
    interpolation on a band-limited random road."""
    from diagnosis.signals import Signals
    from diagnosis.which import DelayTerm

    fs, T, d = 200.0, 7.5, 5.0
    t = np.arange(int(T * fs)) / fs
    v_true = 7.0 + 5.0 * t / T
    x = 10.0 + 7.0 * t + 2.5 * t ** 2 / T                    # integral of v_true
    rng = np.random.default_rng(3)
    n = np.linspace(0.1, 3.0, 300)                            # cycles/m, road harmonics
    amp, ph = n ** -1.0, rng.uniform(0, 2 * np.pi, n.size)

    def road(xx):
        return np.sin(2 * np.pi * np.outer(xx, n) + ph) @ amp

    term = DelayTerm([("axle_acc_1L", "axle_acc_3L")], [d])
    for factor in (0.93, 1.0, 1.07):
        sig = Signals(t, {"axle_acc_1L": road(x), "axle_acc_3L": road(x - d)},
                      speed=factor * v_true)
        lag = float(np.exp(term.log_delays([sig])[0, 0]))
        assert lag == pytest.approx(factor * d, rel=0.01)


def test_paired_null_names_an_effect_the_whole_gap_noise_hides():
    """Truth: tyre stiffness x1.4.  The held-out improvement of the calibrated candidate
    (about 0.01) is below 2 sd of the nominal-vs-nominal gap (the old gate, sd0 about 0.009:
    mostly road-phase scatter common to every model), but far beyond the scatter of the
    improvement this candidate reaches on nominal surrogate measurements with the same seeds
    (paired null, sd about 0.01 around a mean of -0.06), so the verdict is tyre_stiffness.
    The null-data test above checks the same gate says "none" when nothing is wrong."""
    calib, held = _windows({"tyre_stiffness": {"scale": 1.4}}, 11)
    r = rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, calib, held, seed=5, n_seeds=4,
                     n_null=8, grid=4, refine=5, pairs=False)
    assert r.verdict == "tyre_stiffness"
    w = r.winner
    assert 0 < w.improvement < 2 * r.null.std                      # the old gate would say "none"
    assert w.improvement - w.null_improvement.mean() > 3 * w.null_sd
    assert w.null_improvement.size == 8
    rec = w.record()
    assert rec["null_improvement_sd"] == pytest.approx(w.null_sd)


def test_two_folds_combine_the_held_out_evidence():
    """Cross-fitting: rank with windows (1, 3) calibrating and (2, 4) held out, then the other
    way round, and combine.  The combined improvement and paired null are the means of the
    folds' (so the null spread of independent folds shrinks), BIC adds the folds' terms; the
    true tyre stiffness x1.5 is named and null data stay "none"."""
    from diagnosis.which import combine_folds

    for truth, want in (({"tyre_stiffness": {"scale": 1.5}}, "tyre_stiffness"), ({}, "none")):
        calib, held = _windows(truth, 11)
        rs = [rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, c, h, seed=sd, n_seeds=4,
                           n_null=8, grid=4, refine=5, pairs=False)
              for c, h, sd in ((calib, held, 5), (held, calib, 6))]
        r = combine_folds(rs)
        assert r.verdict == want
        assert r.settings["folds"] == 2
        for e in r.entries:
            es = [next(f for f in x.entries if f.effect == e.effect) for x in rs]
            assert e.improvement == pytest.approx(np.mean([f.improvement for f in es]))
            assert e.null_improvement == pytest.approx(np.mean([f.null_improvement for f in es], axis=0))
            assert len(e.fold_effects) == 2
        if want != "none":
            w = r.winner
            assert w.null_sd < max(f.null_sd for x in rs for f in x.entries if f.effect == want)
            # the rivals that make a winner "ambiguous" are the ones the reason names, and
            # pipeline.close_rival (whose signature breaks a tie) is the best accepted one
            from diagnosis.pipeline import close_rival
            from diagnosis.which import close_rivals
            close = close_rivals(r.entries, w, r.null.std)
            assert (r.confidence == "ambiguous") == bool(close)
            assert all(e.effect in r.reason for e in close)
            acc = [e for e in close if e.accepted]
            assert close_rival(r) is (acc[0] if acc else None)
        # given the candidates, the reported calibration is the folds' mean in the search's
        # unit coordinates: the geometric mean for a log-searched parameter, the arithmetic
        # mean for a linear one; without them, the first fold's (as before)
        rc = combine_folds(rs, candidates=toy.TOY_CANDIDATES)
        assert any(len({str(fe) for fe in e.fold_effects}) > 1 for e in rc.entries)
        assert [e.effect for e in rc.entries] == [e.effect for e in r.entries]
        for e, e0 in zip(rc.entries, r.entries):
            (pname, val), = e.effects[e.effect].items()
            vals = [fe[e.effect][pname] for fe in e.fold_effects]
            mean = (float(np.mean(vals)) if e.effect == "payload"
                    else float(np.exp(np.mean(np.log(vals)))))
            ch = e.fold_choice or {}
            if ch.get("edge_discarded"):   # one fold at an edge, set aside (fold_edge_choice)
                mean = vals[1 - ch["edge_fold"]]
            assert val == pytest.approx(mean, rel=1e-12)
            assert [g["calib_gap"] for g in e.fold_gaps] == pytest.approx(
                [next(f for f in x.entries if f.effect == e.effect).calib_gap for x in rs])
            assert e0.effects == e.fold_effects[0]
            assert e.improvement == e0.improvement   # the held-out evidence is the folds'


def test_shape_term_skewness_and_its_noise():
    """:class:`diagnosis.which.ShapeTerm`: the sample skewness per window and channel (exact
    on a hand example: [0, 0, 0, 1] has g1 = 2/sqrt(3)), and ``z`` standardised by the
    road-phase spread of nominal simulations: for 40 Gaussian "simulations" against a
    Gaussian "measurement" z has sd within 0.6-1.6 (chi-square of 40: sd of the sd estimate
    about 11 %, plus the 8-seed sigma), while a response stiffened on one side above half
    its sd (a bump stop: x - 0.9 max(x - 0.5 sd, 0); skewness about -0.9 against a
    window's sampling sd of about 0.1 for 10 Hz-wide noise over 7.5 s) gives |z| > 5 (13-16 measured) over
    four windows and two channels."""
    from scipy import signal as sps

    from diagnosis.signals import Signals
    from diagnosis.which import ShapeTerm

    t = ShapeTerm(["a"])
    hand = Signals(np.arange(4) / 4.0, {"a": np.array([0.0, 0.0, 0.0, 1.0])})
    assert t.stats([hand])[0, 0] == pytest.approx(2.0 / np.sqrt(3.0), rel=1e-12)

    fs, n = 200.0, 1500
    b, a = sps.butter(2, 10.0, fs=fs)
    rng = np.random.default_rng(5)

    def window(clip=False):
        chans = {}
        for c in ("a", "b"):
            x = sps.lfilter(b, a, rng.standard_normal(n))
            x /= x.std()
            chans[c] = x - 0.9 * np.maximum(x - 0.5, 0.0) if clip else x
        return Signals(np.arange(n) / fs, chans)

    term = ShapeTerm(["a", "b"], weight=1.0)
    meas = [window() for _ in range(4)]
    term.prepare("held", meas, [[window() for _ in range(4)] for _ in range(8)])
    z0 = np.array([term.z([window() for _ in range(4)], "held") for _ in range(40)])
    assert 0.6 < z0.std() < 1.6
    assert abs(term.z([window(True) for _ in range(4)], "held")) > 5


def test_static_offset_term_means_and_floor():
    """:class:`diagnosis.which.StaticOffsetTerm`: the per-window mean of each displacement
    channel (exact on a hand window), ``rho`` the channel-mean of sim - meas, and ``z`` on the
    floor's scale: simulations whose window means scatter by 0.01 mm (far below the 0.5 mm
    floor) against a measurement 10 mm lower (a payload's sag) give z = 10 mm / (0.5 mm
    sqrt 2) per window, sqrt(4) of that over four windows, 28.3; the same offset as measured
    gives 0 (to the scatter's 0.03); a channel the model lacks does not count."""
    from diagnosis.signals import Signals
    from diagnosis.which import StaticOffsetTerm

    t = StaticOffsetTerm(["susp_disp_1L", "susp_disp_1R"], weight=1.0)
    hand = Signals(np.arange(4) / 4.0, {"susp_disp_1L": np.array([0.0, 1.0, 2.0, 5.0]),
                                        "susp_disp_1R": np.array([1.0, 1.0, 1.0, 1.0])})
    assert np.allclose(t.stats([hand])[0], [2.0, 1.0], rtol=0, atol=1e-15)
    assert t.SIGMA_FLOOR == pytest.approx(5e-4)

    rng = np.random.default_rng(3)

    def window(offset):
        n = 400
        return Signals(np.arange(n) / 200.0,
                       {c: offset + 1e-5 * rng.standard_normal() + 0.01 * np.sin(np.arange(n) / 7.0)
                        for c in ("susp_disp_1L", "susp_disp_1R", "body_acc_1L")})

    meas = [window(-0.010) for _ in range(4)]
    t.prepare("held", meas, [[window(0.0) for _ in range(4)] for _ in range(6)])
    assert np.all(t._sigma["held"] == pytest.approx(5e-4))          # the floor, not the scatter
    z_nom = t.z([window(0.0) for _ in range(4)], "held")
    # the nominal simulations sit 10 mm above the measured (sagging) drive
    assert z_nom == pytest.approx(0.010 / (5e-4 * np.sqrt(2.0)) * 2.0, rel=0.02)
    assert abs(t.z([window(-0.010) for _ in range(4)], "held")) < 0.1
    assert t.term([window(0.0) for _ in range(4)], "held") == pytest.approx(z_nom ** 2, rel=0.01)


def test_static_term_only_where_the_zero_is_declared():
    """The static offset is evidence only where the measurement says its displacements read 0
    on the nominal vehicle at rest; a sensor zeroed on the laden truck (or an unknown zero)
    says nothing about the static load."""
    from types import SimpleNamespace

    from diagnosis.pipeline import static_term
    from diagnosis.signals import Signals
    from diagnosis.which import StaticOffsetTerm

    model = SimpleNamespace(channels=["susp_disp_3L", "susp_disp_3R", "axle_acc_3L"])
    sig = lambda zero: Signals(np.arange(4) / 4.0, {"susp_disp_3L": np.zeros(4)},
                               meta={} if zero is None else {"susp_disp_zero": zero})
    term = static_term(model, sig("nominal_static"))
    assert isinstance(term, StaticOffsetTerm) and term.channels == ["susp_disp_3L", "susp_disp_3R"]
    assert static_term(model, sig("unknown")) is None
    assert static_term(model, sig(None)) is None


#: the toy library plus a speed-signal scale (identified through the delay term): five
#: candidates, so the verdict is a choice among many, not between two
FIVE = list(toy.TOY_CANDIDATES) + [Candidate("speed_scale", (Param("scale", 0.85, 1.15),))]


@pytest.mark.parametrize("truth, want, param, value", [
    ({"damper": {"scale": 0.6}}, "damper", "scale", 0.6),
    ({"payload": {"mass_scale": 1.3}}, "payload", "mass_scale", 1.3),
    ({}, "none", None, None),
], ids=["damper", "payload", "null"])
def test_verdict_among_five_candidates(truth, want, param, value):
    """Verdict among five candidates (tyre stiffness, payload, damper, sensor low-pass,
    speed scale with the front-to-rear delay term) where the answer is known by construction:
    the measurement is the toy with exactly one effect (damper x0.6 or sprung mass x1.3,
    truths the other ranking tests do not use) or with none.  Required: that effect, "clear"
    (payload and damper both change the body mode and each is accepted as a rival when the
    other is the truth, so "clear" means the right one is clearly better), the calibrated
    parameter within 10 % (the search ranges span 0.5-2 and 0.7-1.5; measured errors 4 % and
    3 %), every held-out seed's gap shrunk; for the null measurement "none" with no entry
    accepted.  Same budget as the other toy rankings (80 s measured, 4 held-out seeds,
    8 surrogates, grid 4 + golden 5, no pairs); about 10 s per case."""
    from diagnosis.which import DelayTerm

    calib, held = _windows(truth, 21)
    r = rank_effects(FIVE, toy.fit, toy.simulate, calib, held, seed=9, n_seeds=4, n_null=8,
                     grid=4, refine=5, pairs=False,
                     delay=DelayTerm([("axle_acc_1L", "axle_acc_3L")], [4.0]))
    assert len(r.entries) == 5
    assert r.verdict == want
    if want == "none":
        assert r.confidence == "none"
        assert not any(e.accepted for e in r.entries)
        return
    assert r.confidence == "clear"
    w = r.winner
    assert w.accepted and np.all(w.shrink_per_seed > 0)
    assert w.effects[want][param] == pytest.approx(value, rel=0.10)


def test_transmissibility_term_reads_the_body_gain():
    """:class:`diagnosis.which.TransmissibilityTerm`: a body channel that is the axle channel
    through the same filter times a gain ``g`` has ``ln|H1|`` = ln g + the filter's log gain in
    every band, so the per-window mismatch of two records with gains g1 and g2 is ln(g1/g2)
    exactly up to the estimator's leakage (Welch H1 of noise-free linear data: no bias from
    noise; tolerance 0.02 in log units, measured 1e-3).  Windows whose cells are mostly
    unresolved (coherence below the threshold: body pure noise) give NaN, not a number."""
    from scipy.signal import butter, lfilter

    from diagnosis.signals import Signals
    from diagnosis.which import TransmissibilityTerm

    fs, n = 200.0, 1500
    t = np.arange(n) / fs
    rng = np.random.default_rng(3)
    b, a = butter(2, 6.0 / (fs / 2))

    def window(gain, noise_only=False):
        ax = rng.standard_normal(n)
        body = rng.standard_normal(n) if noise_only else gain * lfilter(b, a, ax)
        return Signals(t, {"axle_acc_1L": ax, "body_acc_1L": body})

    term = TransmissibilityTerm([("axle_acc_1L", "body_acc_1L")])
    sim = term.stats([window(1.5), window(1.5)])
    meas = term.stats([window(1.0), window(1.0, noise_only=True)])
    rho = term._rho(sim, meas)
    assert rho[0] == pytest.approx(np.log(1.5), abs=0.02)
    assert np.isnan(rho[1])


def test_a_payload_is_refined_on_the_static_offset_and_only_where_the_gap_falls():
    """``refine_from_static``: secant steps on the static-offset mismatch (about linear in the
    mass: 2.3 mm per tonne, with a small curvature) take a payload searched to 6870 kg to the
    7676 kg that zeroes it (within 10 kg: the curvature after two steps), and the result is kept
    because the whole objective (here lowest at 7676 too) falls.  Where the objective prefers
    another mass (its minimum at 5000 kg, where the search left it) the refinement is dropped
    and the search's result stands; a zero beyond the range is clipped to its edge."""
    from diagnosis.which import Calibration, _Scorer

    cand = Candidate("payload", (Param("mass", -16000.0, 16000.0),), {"dx": 0.0})

    class Stub:
        n_calls = 0

        def __init__(self, m_zero, m_gap):
            self.m_zero, self.m_gap = m_zero, m_gap

        def static_rho(self, eff):
            Stub.n_calls += 1
            d = eff["payload"]["mass"] - self.m_zero
            assert eff["payload"]["dx"] == 0.0                 # the fixed parameters travel
            return 2.3e-6 * d + 2e-11 * d * d

        def calib_gap(self, eff):
            return 0.25 + ((eff["payload"]["mass"] - self.m_gap) / 3000.0) ** 2

    def start(stub, m):
        eff = {"payload": {"dx": 0.0, "mass": m}}
        return Calibration(eff, (0.0,), stub.calib_gap(eff), 7, [(eff, stub.calib_gap(eff))])

    stub = Stub(7676.0, 7676.0)
    cal = _Scorer.refine_from_static(stub, cand, start(stub, 6870.0))
    assert cal.effects["payload"]["mass"] == pytest.approx(7676.0, abs=10.0)
    assert cal.calib_gap < start(stub, 6870.0).calib_gap and cal.n_evals == 7 + 2 + 2 + 1
    assert cal.effects["payload"]["dx"] == 0.0
    stub = Stub(7676.0, 5000.0)
    cal = _Scorer.refine_from_static(stub, cand, start(stub, 5000.0))
    assert cal.effects["payload"]["mass"] == 5000.0                    # kept the search's
    assert len(cal.history) == 2 and cal.history[-1][0]["payload"]["mass"] == pytest.approx(7676.0, abs=10.0)
    stub = Stub(20000.0, 20000.0)
    cal = _Scorer.refine_from_static(stub, cand, start(stub, 12000.0))
    assert cal.effects["payload"]["mass"] == 16000.0                   # clipped to the range


def test_term_weight_is_half_the_band_gaps_null_sd_over_root_two():
    """Closed form: null band gaps 1, 2, 3 have sd 1 (ddof 1), so every term weighs
    0.5 / sqrt(2); an undefined sd (one value, or a NaN) switches the terms off."""
    import math

    from diagnosis.which import term_weight

    assert term_weight([1.0, 2.0, 3.0]) == pytest.approx(0.5 / math.sqrt(2.0), rel=1e-12)
    assert term_weight([4.0, 4.0]) == 0.0
    assert term_weight([1.0]) == 0.0
    assert term_weight([1.0, float("nan"), 2.0]) == 0.0


def test_folds_in_one_batch_are_the_folds_one_after_the_other():
    """``rank_effects_folds`` hands both folds' calibrations to the executor in one batch and
    routes the results back: each fold's ranking must be the one ``rank_effects`` makes for that
    fold alone (same entries, gaps, calibrations, verdict).  On the toy model, two folds with the
    windows' roles swapped, a thread pool so that the batch is really interleaved."""
    from concurrent.futures import ThreadPoolExecutor

    from diagnosis import toy
    from diagnosis.which import rank_effects, rank_effects_folds

    truth = toy.make_state({"sensor": {"cutoff_hz": 15.0}})
    meas = toy.simulate_drive(truth, 60.0, 10.0, 3)
    w = [meas.window(i * 15.0, (i + 1) * 15.0) for i in range(4)]
    calib, held = [w[0], w[2]], [w[1], w[3]]
    kw = dict(n_seeds=3, n_null=3, grid=3, refine=3, pairs=False)
    one = [rank_effects(toy.TOY_CANDIDATES, toy.fit, toy.simulate, c, h, seed=sd, **kw)
           for c, h, sd in ((calib, held, 1), (held, calib, 2))]
    said = []
    with ThreadPoolExecutor(2) as ex:
        both = rank_effects_folds(toy.TOY_CANDIDATES, toy.fit, toy.simulate,
                                  [(calib, held, 1), (held, calib, 2)], executor=ex,
                                  progress=said.append, **kw)
    assert len(both) == 2
    # each fold's lines say which fold they are (a user sees two blocks of candidate lines), in
    # the form the progress bar of diagnosis/cli.py counts (its step pattern, written out here)
    n = len(toy.TOY_CANDIDATES)
    for f in (1, 2):
        assert f"calibrating {n} candidates [fold {f} of 2]" in said
        lines = [m for m in said if m.endswith(f"[fold {f} of 2]") and ": held-out gap" in m]
        assert len(lines) == n and all(re.search(r"^\s+\S+: held-out gap", m) for m in lines)
    for a, b in zip(one, both):
        assert (a.verdict, a.confidence) == (b.verdict, b.confidence)
        assert [e.effect for e in a.entries] == [e.effect for e in b.entries]
        for ea, eb in zip(a.entries, b.entries):
            assert ea.effects == eb.effects
            np.testing.assert_array_equal(ea.after, eb.after)
        np.testing.assert_array_equal(a.before, b.before)


def test_fold_edge_choice_takes_the_value_the_whole_record_fits_better():
    """diagnosis.which.fold_edge_choice: only where exactly one of two folds lies at a range end
    (EDGE_TOL in unit coordinates); each fold's value is scored on the whole record (its
    calibration gap plus its held-out gap, the other fold's windows) and the edge fold is set
    aside when the inside fold's sum is lower (the numbers of blind frame 1.6 of
    results/diagnosis_blind/20261129-linear-fresh-40; fold gaps as in
    results/diagnosis_blind/20261129-fold-edge-choice/curves.txt)."""
    from diagnosis.which import fold_edge_choice

    c = Candidate("frame_flex", (Param("stiffness_factor", 0.1, 100.0, log=True),))
    fe = [{"frame_flex": {"stiffness_factor": 0.1}}, {"frame_flex": {"stiffness_factor": 1.585}}]
    fg = [{"calib_gap": 0.4389, "heldout_gap": 0.2222}, {"calib_gap": 0.1790, "heldout_gap": 0.4480}]
    ch = fold_edge_choice(c, fe, fg)
    assert ch["edge_fold"] == 0 and ch["edge_discarded"]
    assert ch["whole_record_gap"] == pytest.approx([0.6611, 0.6270])
    # the edge value fits the record better: it stands
    fg2 = [{"calib_gap": 0.40, "heldout_gap": 0.20}, {"calib_gap": 0.18, "heldout_gap": 0.45}]
    assert not fold_edge_choice(c, fe, fg2)["edge_discarded"]
    # no disagreement about an edge: no choice (both inside, both at an edge, one fold)
    inside = [{"frame_flex": {"stiffness_factor": 0.8}}, {"frame_flex": {"stiffness_factor": 1.6}}]
    both = [{"frame_flex": {"stiffness_factor": 0.1}}, {"frame_flex": {"stiffness_factor": 100.0}}]
    assert fold_edge_choice(c, inside, fg) is None and fold_edge_choice(c, both, fg) is None
    assert fold_edge_choice(c, fe[:1], fg[:1]) is None
