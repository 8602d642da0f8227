"""Diagnostics: eq (6) RMSE, amplitude-distribution distances, Table 2 rows, plots."""
import math

import numpy as np
import pytest

from inverse.validation import (amplitude_distance, plot_amplitude_distributions, plot_time_compare,
                                response_table, rmse_eq6)


def test_rmse_eq6_reference_values():
    """Zero simulation: RMSE = measured RMS (normalised: 1); an independent record
    of equal variance: sqrt(2) (within 3% for 20000 samples)."""
    rng = np.random.default_rng(0)
    m = rng.normal(0, 2.0, 20000)
    assert rmse_eq6(m, np.zeros_like(m)) == pytest.approx(math.sqrt(np.mean(m ** 2)))
    assert rmse_eq6(m, np.zeros_like(m), normalise=True) == pytest.approx(1.0)
    assert rmse_eq6(m, rng.normal(0, 2.0, m.size), normalise=True) == pytest.approx(math.sqrt(2), rel=0.03)


def test_amplitude_distances():
    """Same distribution: W1/sd and KS near 0 (sampling scatter of 20000 samples:
    below 0.03); no response at all: W1/sd = mean |x| / sd = sqrt(2/pi)."""
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=20000), rng.normal(size=20000)
    assert amplitude_distance(a, b) < 0.03
    assert amplitude_distance(a, b, "ks") < 0.03
    assert amplitude_distance(a, np.zeros_like(a)) == pytest.approx(math.sqrt(2 / math.pi), rel=0.03)


def test_response_table_and_plots(tmp_path):
    rng = np.random.default_rng(2)
    t = np.arange(4000) / 200.0
    meas = {"body_acc_3L": rng.normal(0, 1.0, t.size), "body_acc_3R": rng.normal(0, 1.0, t.size)}
    sim = {"body_acc_3L": 1.1 * meas["body_acc_3L"], "body_acc_3R": meas["body_acc_3R"]}
    rows = response_table(meas, sim)
    assert [r["channel"] for r in rows] == ["body_acc_3L", "body_acc_3R"]
    assert rows[0]["rms_err"] == pytest.approx(0.1)
    assert rows[0]["mean_abs_err"] == pytest.approx(0.1)
    assert rows[1]["rms_err"] == 0.0 and rows[1]["rmse_eq6"] == 0.0
    f8 = plot_time_compare(t, meas, sim, ["body_acc_3L", "body_acc_3R"], tmp_path / "fig8.png", window=(0, 5))
    f9 = plot_amplitude_distributions(meas, sim, ["body_acc_3L", "body_acc_3R"], tmp_path / "fig9.png")
    assert f8.stat().st_size > 10_000 and f9.stat().st_size > 10_000


# --------------------------------------------------------------------------- Table 2 numbers by numpy

def _w1_equal_n(a, b):
    """Wasserstein-1 of two equal-size samples: mean |sorted a - sorted b| (the optimal
    transport pairs the order statistics)."""
    return float(np.mean(np.abs(np.sort(a) - np.sort(b))))


def _ks(a, b):
    """Largest gap of the two empirical distribution functions, over every sample point."""
    x = np.concatenate([a, b])
    fa = np.searchsorted(np.sort(a), x, side="right") / a.size
    fb = np.searchsorted(np.sort(b), x, side="right") / b.size
    return float(np.max(np.abs(fa - fb)))


def _table2_by_numpy(m, s):
    m0, s0 = m - m.mean(), s - s.mean()
    rm, rs = math.sqrt(np.mean(m0 ** 2)), math.sqrt(np.mean(s0 ** 2))
    am, as_ = np.mean(np.abs(m0)), np.mean(np.abs(s0))
    rmse = math.sqrt(np.mean((m0 - s0) ** 2))
    return {"rms_meas": rm, "rms_sim": rs, "rms_err": rs / rm - 1.0, "mean_meas": m.mean(), "mean_sim": s.mean(),
            "mean_abs_meas": am, "mean_abs_sim": as_, "mean_abs_err": as_ / am - 1.0, "rmse_eq6": rmse,
            "rmse_eq6_norm": rmse / rm, "wasserstein": _w1_equal_n(m0, s0) / rm, "ks": _ks(m0, s0)}


class _RecordingSimulator:
    """A made-up simulator: channels = a seeded random record scaled by sqrt(Gq_n0 / 256e-6)
    and shifted by w (so params reach the output), remembering the seed it got."""

    def __init__(self, n):
        self.n, self.seeds = n, []

    def __call__(self, params, seed):
        self.seeds.append(seed)
        rng = np.random.default_rng(seed)
        g = math.sqrt(params[0, 0] / 256e-6)
        return {"axle_acc_3L": g * rng.standard_t(5, self.n) + params[0, 1],
                "susp_disp_3L": g * 1e-3 * np.cumsum(rng.normal(size=self.n)) / 30.0}


def test_validate_table_against_numpy():
    """pipeline.validate: simulates once with the documented stream seed
    (SeedSequence(seed, spawn_key=(5, 1)) for the fit's phases, (5, 2) for the independent
    realisation) and returns Table 2 rows whose every number equals its numpy definition
    on the same arrays: RMS and rectified mean about the mean, relative errors
    (sim - meas) / meas, eq 6 RMSE of the centred records, W1 over the measured sd (sorted
    samples), KS (largest ECDF gap).  Deterministic: 1e-10 relative (round-off of sums over
    6000 samples)."""
    from inverse.pipeline import SEED_KEY_VALIDATION, validate

    n = 6000
    rng = np.random.default_rng(11)
    meas = {"axle_acc_3L": rng.standard_t(5, n) + 0.2,
            "susp_disp_3L": 1e-3 * np.cumsum(rng.normal(size=n)) / 25.0}
    params = np.array([[400e-6, 2.1, 0.05, 5.0]])
    for stream, key in ((None, (5, 1)), (SEED_KEY_VALIDATION, (5, 2))):
        sim = _RecordingSimulator(n)
        kw = {} if stream is None else {"stream": stream}
        out, rows = validate(sim, params, meas, ["axle_acc_3L", "susp_disp_3L"], seed=4, **kw)
        assert sim.seeds == [int(np.random.SeedSequence(4, spawn_key=key).generate_state(1)[0])]
        assert [r["channel"] for r in rows] == ["axle_acc_3L", "susp_disp_3L"]
        for r in rows:
            c = r["channel"]
            np.testing.assert_array_equal(out[c], _RecordingSimulator(n)(params, sim.seeds[0])[c])
            ref = _table2_by_numpy(meas[c], out[c])
            for k, v in ref.items():
                assert r[k] == pytest.approx(v, rel=1e-10, abs=1e-15), (c, k)
        assert rows[0]["rms_err"] > 0.1   # sqrt(400 / 256) = 1.25 x the measured scale: not a trivial 0


def test_segment_errors_by_hand():
    """Boundary errors: for each interior true boundary, found minus true at the nearest
    interior found boundary (the outer ends are not boundaries).  True 10 and 18 s, found
    9.7, 18.4, 25 s: -0.3 and +0.4; a missed boundary takes the distance to the next found
    one (true 25 with found 18.4 only: -6.6); none found: nan."""
    from inverse.pipeline import segment_errors

    e = segment_errors([0.0, 10.0, 18.0, 30.0], [0.0, 9.7, 18.4, 25.0, 30.0])
    np.testing.assert_allclose(e, [-0.3, 0.4], atol=1e-12)
    e = segment_errors([0.0, 10.0, 25.0, 30.0], [0.0, 9.7, 18.4, 30.0])
    np.testing.assert_allclose(e, [-0.3, 18.4 - 25.0], atol=1e-12)
    # against numpy on random layouts: nearest by |found - true|, signed found - true
    rng = np.random.default_rng(3)
    for _ in range(20):
        tt = np.concatenate([[0.0], np.sort(rng.uniform(0, 30, 4)), [30.0]])
        tf = np.concatenate([[0.0], np.sort(rng.uniform(0, 30, 3)), [30.0]])
        inner = tf[1:-1]
        ref = [inner[np.argmin(np.abs(inner - b))] - b for b in tt[1:-1]]
        np.testing.assert_allclose(segment_errors(tt, tf), ref, atol=1e-12)
    assert np.all(np.isnan(segment_errors([0.0, 10.0, 30.0], [0.0, 30.0])))
