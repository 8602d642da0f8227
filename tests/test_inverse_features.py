"""Response features: third-octave band powers, their variance model, noise."""
import numpy as np
import pytest

from eroad.errors import EroadInputError
from inverse.features import (FeatureSet, FeatureSpec, estimate_noise_psd, log_power_variance,
                              third_octave_bands)

FS = 200.0


def test_third_octave_bands():
    """Base-10 third-octave centres 10^(k/10): 0.501 ... 50.1 Hz, 21 bands."""
    c, lo, hi = third_octave_bands(0.5, 50.0)
    assert c.size == 21
    assert c[0] == pytest.approx(10 ** -0.3) and c[-1] == pytest.approx(10 ** 1.7)
    np.testing.assert_allclose(hi[:-1], lo[1:], rtol=1e-12)


def test_variance_model_on_white_noise():
    """The predicted variance psi'(nu/2) of ln band power matches the scatter over
    200 white-noise records of 6 s.  A variance estimate from 200 records has a
    relative sd of 0.10 per band; the mean ratio over ~17 bands has about 0.03, so
    [0.8, 1.2] is a generous bound that still catches a factor-2 error in nu."""
    n = int(6 * FS)
    t = np.arange(n) / FS
    spec = FeatureSpec(channels=("a",), snr_min=0.0, min_dof=0.0, margin_s=0.0, station_weighting=False)
    rng = np.random.default_rng(1)
    ys = []
    for _ in range(200):
        fset = FeatureSet.from_measurement(t, {"a": rng.normal(size=n)}, [0.0, 6.0], spec, noise_psd={"a": 0.0})
        ys.append(fset.windows[0].y)
    wf = fset.windows[0]
    pred = log_power_variance(wf.dof)
    pred[-1] *= 0.25  # log RMS = half the log power
    ratio = np.var(ys, axis=0) / pred
    assert 0.8 < np.mean(ratio) < 1.2


def test_measured_features_reproduce_themselves():
    """Evaluating the measured channels with zero noise gives exactly the measured
    features (one code path for data and simulation)."""
    rng = np.random.default_rng(2)
    t = np.arange(int(20 * FS)) / FS
    ch = {"susp_disp_3L": rng.normal(size=t.size), "susp_disp_3R": rng.normal(size=t.size)}
    spec = FeatureSpec(channels=tuple(ch))
    fset = FeatureSet.from_measurement(t, ch, [0.0, 8.0, 20.0], spec, noise_psd={c: 0.0 for c in ch})
    F = fset.evaluate(ch)
    for wf, f in zip(fset.windows, F):
        np.testing.assert_allclose(f, wf.y, rtol=1e-12)
    assert np.allclose(fset.objective(F), 0.0)


def test_noise_estimate_and_snr_selection():
    """White noise of known PSD under a low-frequency signal: estimated within
    20% (median of ~70 bins of a 1 s Welch PSD over 4 s blocks, minimum of 5
    blocks: biased low by a few %); bands where the signal is below twice the
    noise are dropped."""
    rng = np.random.default_rng(3)
    t = np.arange(int(20 * FS)) / FS
    sd = 0.01
    x = np.sin(2 * np.pi * 2.0 * t) + rng.normal(0, sd, t.size)
    est = estimate_noise_psd(x, FS)
    assert est == pytest.approx(sd ** 2 / (FS / 2), rel=0.2)
    spec = FeatureSpec(channels=("x",))
    fset = FeatureSet.from_measurement(t, {"x": x}, [0.0, 20.0], spec)
    used = fset.centres[fset.windows[0].bands["x"]]
    assert 2.0 in np.round(used, 1) and used.max() < 5.0


def test_station_weighting_divides_weights():
    rng = np.random.default_rng(5)
    t = np.arange(int(10 * FS)) / FS
    ch = {c: rng.normal(size=t.size) for c in ("susp_disp_3L", "axle_acc_3L", "body_acc_3R")}
    kw = dict(noise_psd={c: 0.0 for c in ch})
    a = FeatureSet.from_measurement(t, ch, [0, 10], FeatureSpec(channels=tuple(ch)), **kw).windows[0]
    b = FeatureSet.from_measurement(t, ch, [0, 10], FeatureSpec(channels=tuple(ch), station_weighting=False),
                                    **kw).windows[0]
    ratio = b.weight / a.weight
    is_3l = np.array([lab.split("@")[0].split(":")[0].endswith("3L") for lab in a.labels])
    np.testing.assert_allclose(ratio[is_3l], 2.0)
    np.testing.assert_allclose(ratio[~is_3l], 1.0)


def test_missing_channel_refused():
    t = np.arange(2000) / FS
    with pytest.raises(EroadInputError, match="susp_disp_3R"):
        FeatureSet.from_measurement(t, {"susp_disp_3L": np.zeros(2000)}, [0, 10],
                                    FeatureSpec(channels=("susp_disp_3L", "susp_disp_3R")))
