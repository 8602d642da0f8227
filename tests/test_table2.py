"""Table 2 reports the median over road realisations, never a realisation picked by its own
statistic as the headline (inverse.report.table2, inverse.cli._headline, realisation spread)."""
from __future__ import annotations

import numpy as np
import pytest

from inverse.cli import _headline
from inverse.realisation import select_realisation
from inverse.report import table2


class _ScaledNoise:
    """A stand-in simulator: each seed gives white noise of a seed-dependent level, so the
    realisations' RMS errors are known in closed form (level - 1)."""

    levels = {1: 0.90, 2: 1.00, 3: 1.05, 4: 1.10, 5: 1.30}

    def __call__(self, params, seed):
        rng = np.random.default_rng(1234)   # the same waveform, scaled: errors are exact
        x = rng.standard_normal(4000)
        x = (x - x.mean()) / x.std()
        return {c: self.levels[seed] * x for c in ("axle_acc_3L", "axle_acc_3R", "susp_disp_3L", "susp_disp_3R")}


def _measured():
    rng = np.random.default_rng(1234)
    x = rng.standard_normal(4000)
    x = (x - x.mean()) / x.std()
    return {c: x.copy() for c in ("axle_acc_3L", "axle_acc_3R", "susp_disp_3L", "susp_disp_3R")}


def test_headline_is_the_median_over_realisations_not_the_selected_one():
    """Five realisations with RMS errors -10, 0, +5, +10, +30 %: the selected one (nearest,
    0 %) is reported under 'selected' only; the headline is the median +5 % with the 16/84th
    percentiles of those five numbers (numpy's linear interpolation: -4 % and +13.2 %)."""
    meas = _measured()
    sel = select_realisation(_ScaledNoise(), np.zeros((1, 4)), meas, [1, 2, 3, 4, 5], sides=False)
    assert sel["seed"] == 2
    sp = sel["spread"]["axle_acc_3L"]
    errs = np.array([-0.10, 0.0, 0.05, 0.10, 0.30])
    assert sp["median"] == pytest.approx(0.05, abs=1e-12)
    assert sp["p16"] == pytest.approx(np.percentile(errs, 16), abs=1e-12)
    assert sp["p84"] == pytest.approx(np.percentile(errs, 84), abs=1e-12)
    # rectified mean scales with the level too: the same errors
    assert sp["mean_abs_median"] == pytest.approx(0.05, abs=1e-12) and sp["n"] == 5
    from inverse.validation import response_table
    rows = response_table(meas, sel["simulated"], ["axle_acc_3L", "susp_disp_3L"])
    head = _headline(rows, sel["spread"])
    assert head["axle_acc_3L"]["rms_err"] == pytest.approx(0.05)
    assert head["axle_acc_3L"]["selected"]["rms_err"] == pytest.approx(0.0, abs=1e-12)
    assert head["axle_acc_3L"]["basis"] == "median over 5 realisations"
    df = table2(rows, sel["spread"])
    r = df.set_index("channel").loc["axle_acc_3L"]
    assert r["unit"] == "m/s^2" and df.set_index("channel").loc["susp_disp_3L", "unit"] == "m"
    assert r["rms_err_median_pct"] == pytest.approx(5.0) and r["selected_rms_err_pct"] == pytest.approx(0.0, abs=1e-9)
    assert r["rms_sim_median"] == pytest.approx(1.05 * r["rms_meas"])
    # no unlabelled 'mean' column: rectified means are named so, selected values prefixed
    assert not [c for c in df.columns if c.startswith("mean")]
    assert all(c.startswith(("selected_", "channel", "unit", "rms_", "rect_mean", "n_real")) for c in df.columns)


def test_summary_errors_name_the_rectified_mean():
    """summary.json's 'mean_err' holds the rectified mean's error (as Table 2's rect_mean);
    it is also given as 'rect_mean_err' with the same values, in the headline and the
    selected realisation."""
    from inverse.run import headline

    rows = [{"channel": "axle_acc_3L", "rms_err": 0.1, "mean_abs_err": 0.2, "rmse_eq6_norm": 1.0,
             "wasserstein": 0.3}]
    spread = {"axle_acc_3L": {"median": 0.1, "p16": 0.0, "p84": 0.2, "mean_abs_median": 0.25,
                              "mean_abs_p16": 0.1, "mean_abs_p84": 0.3, "n": 3}}
    h = headline(rows, spread)["axle_acc_3L"]
    assert h["rect_mean_err"] == h["mean_err"] == 0.25
    assert (h["rect_mean_err_p16"], h["rect_mean_err_p84"]) == (0.1, 0.3)
    assert h["selected"]["rect_mean_err"] == 0.2
    assert headline(rows)["axle_acc_3L"]["rect_mean_err"] == 0.2
