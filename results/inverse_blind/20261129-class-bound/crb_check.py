"""Check of class_bound.py's Fisher information: the maximum-likelihood fit of (ln Gq, w) to
periodogram ordinates drawn from the Whittle model (independent exponentials of mean G(n_k), bins
k / L over [0.1, 5] cycles/m, two tracks) scatters as the Cramer-Rao sd says.  Run from the
repository root: python results/inverse_blind/20261129-class-bound/crb_check.py"""
import math
import sys

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, "results/inverse_blind/20261129-class-bound")
from class_bound import info   # noqa: E402

rng = np.random.default_rng(1)
for L, w in ((48.0, 2.0), (117.7, 1.6)):
    k = np.arange(math.ceil(0.1 * L), math.floor(5.0 * L) + 1)
    x = -np.log(k / L / 0.1)
    lnG0 = math.log(256e-6)
    est = []
    for _ in range(2000):
        I = rng.exponential(np.exp(lnG0 + w * x), size=(2, x.size))

        def nll(t):
            lg = t[0] + t[1] * x
            return float(np.sum(lg + I * np.exp(-lg)))
        est.append(minimize(nll, [lnG0 + 0.3, w - 0.2], method="Nelder-Mead",
                            options={"xatol": 1e-7, "fatol": 1e-9, "maxiter": 4000}).x)
    est = np.array(est)
    crb = np.sqrt(np.diag(np.linalg.inv(info(L, 0.1, 5.0))))
    print(f"L {L:6.1f} m: ML sd ln Gq {est[:, 0].std():.4f} (bias {est[:, 0].mean() - lnG0:+.4f}), w {est[:, 1].std():.4f}; "
          f"Cramer-Rao {crb[0]:.4f}, {crb[1]:.4f}")
