"""The misspecification-robust (sandwich) sd of the spectral fit (inverse.sensitivity.robust_sd),
against Monte Carlo truth on a weighted linear least-squares problem whose answer is known."""
import math

import numpy as np

from inverse.sensitivity import robust_sd


def _wls(J, w, y, prior_w):
    A = J.T @ (w[:, None] * J) + np.diag(prior_w)
    return np.linalg.solve(A, J.T @ (w * y))


def _monte_carlo(true_sd, assumed_sd, n_rep=2000, m=120, seed=3):
    """Estimates of theta over n_rep draws, and the mean Laplace and sandwich sd of theta[0]."""
    rng = np.random.default_rng(seed)
    n = np.linspace(0.2, 3.0, m)
    J = np.column_stack([np.ones(m), -np.log(n), 0.3 * np.sin(3 * n), 0.2 * np.cos(2 * n)])
    w = 1.0 / assumed_sd ** 2
    prior_w = np.full(4, 1e-6)
    A = J.T @ (w[:, None] * J) + np.diag(prior_w)
    lap = math.sqrt(np.linalg.inv(A)[0, 0])
    est, rob = [], []
    for _ in range(n_rep):
        y = rng.normal(0.0, true_sd)
        th = _wls(J, w, y, prior_w)
        est.append(th[0])
        rob.append(robust_sd(J, w, y - J @ th, prior_w)["ln_Gq_n0"])
    return float(np.std(est)), lap, float(np.mean(rob))


def test_sandwich_equals_laplace_when_the_weights_are_right():
    """Correct weights: the sandwich agrees with the Laplace sd and with the Monte Carlo sd.
    10 %: the Monte Carlo sd of 2000 draws is within 3.2 % (2 sigma), the sandwich's small-sample
    bias is about P / m = 3 % low."""
    sd = np.full(120, 0.1)
    mc, lap, rob = _monte_carlo(sd, sd)
    assert abs(lap / mc - 1) < 0.1
    assert abs(rob / mc - 1) < 0.1


def test_sandwich_follows_the_true_scatter_when_the_weights_are_wrong():
    """Half the features scatter 3x more than the weights say (a model error the weights do not
    know): the Laplace sd is far too small, the sandwich tracks the Monte Carlo sd (same 10 %)."""
    assumed = np.full(120, 0.1)
    true = assumed.copy()
    true[::2] *= 3.0
    mc, lap, rob = _monte_carlo(true, assumed)
    assert lap / mc < 0.6
    assert abs(rob / mc - 1) < 0.1


def test_ln_G_n_best_is_the_level_along_the_slope():
    """sd of ln Gq - w ln(n / n0) at n = n0 is the sd of ln Gq itself."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(40, 4))
    out = robust_sd(J, np.ones(40), rng.normal(size=40), np.ones(4), n_best=0.1)
    assert math.isclose(out["ln_G_n_best"], out["ln_Gq_n0"], rel_tol=1e-12)
