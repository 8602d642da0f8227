"""The diagnosis's per-piece re-levelling keeps a model's static state (diagnosis.pipeline.relevel).

Reference (model-free): a road-level factor scales the response about the static state, not
the static state itself. A suspension displacement made of a static offset plus a zero-mean
motion, re-levelled by a factor that differs between two road pieces, must keep the offset in
both pieces and scale only the motion. The old code multiplied the whole signal: with a
payload change of -8.9 t (offset -23 mm on axle 3) and factors 0.7 / 1.3 it put a 14 mm step
between the pieces, which skewed the distribution and added low-frequency power the
measurement does not have.
"""
import numpy as np
import pytest

from diagnosis.pipeline import relevel


def _skew(x):
    x = x - x.mean()
    return float(np.mean(x ** 3) / np.mean(x ** 2) ** 1.5)


def test_relevel_keeps_the_static_offset_and_scales_the_motion():
    rng = np.random.default_rng(3)
    n = 4000
    offset = -0.023                                  # m: payload -8.9 t, axle 3
    motion = 0.008 * rng.standard_normal(n)          # zero-mean road response, m
    x = offset + motion
    g = np.where(np.arange(n) < n // 2, 0.7, 1.3)
    out = relevel({"susp_disp_3L": x}, g)["susp_disp_3L"]
    mu = x.mean()
    # both pieces keep the window mean (to rounding): no step between the pieces
    a, b = out[: n // 2], out[n // 2:]
    assert a.mean() == pytest.approx(mu + 0.7 * (x[: n // 2] - mu).mean(), abs=1e-15)
    assert b.mean() == pytest.approx(mu + 1.3 * (x[n // 2:] - mu).mean(), abs=1e-15)
    assert abs(a.mean() - b.mean()) < 1e-3          # the old x * g: 0.6 * 23 mm = 14 mm
    # the motion is scaled exactly
    assert np.allclose(out - mu, (x - mu) * g, atol=1e-15)
    # a Gaussian motion stays unskewed: the sample skewness of two Gaussian pieces of
    # different spread about one mean is 0 in expectation (se about sqrt(6/n) = 0.04);
    # the old scaling gave -0.66 here
    assert abs(_skew(out)) < 0.2


def test_relevel_with_a_constant_factor_is_a_scaling_about_the_mean():
    x = 0.5 + np.sin(np.linspace(0, 20, 1000))
    out = relevel({"c": x}, 2.0)["c"]
    assert np.allclose(out, x.mean() + 2.0 * (x - x.mean()))
    assert out.mean() == pytest.approx(x.mean())
