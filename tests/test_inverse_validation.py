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
