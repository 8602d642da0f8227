"""Per-segment spectral fit from sampled sensitivities, trust region, CasADi/IPOPT.

What it is for: finding, for every road segment of a drive, the spectral road
parameters (Gq_n0, w, nmin, nmax) whose simulated responses have the measured
response statistics (:mod:`inverse.features`), with any response simulator given
as a callable.  What it is not: a simulator, a segmentation, or the validation.

Simulator contract
------------------
``simulate(params, seed) -> dict[str, ndarray]``: ``params`` (K, 4) physical
per-segment parameters (columns Gq_n0 [m^3], w [-], nmin, nmax [cycles/m], see
:mod:`inverse.spectral`); ``seed`` an int that fixes every random draw of the
road (phases) independently of ``params``, so that two calls with the same seed
differ only through ``params`` (common random numbers); the result maps channel
names to arrays on the measured record's time grid.  The segment layout is bound
into the simulator.  For parallel sampling, the simulator (and the FeatureSet)
must be picklable and ``map_fn`` a parallel map such as
``concurrent.futures.ProcessPoolExecutor(2).map``.

Algorithm (per iteration)
-------------------------
1. Sample: around the current iterate theta_c (K, 4), 2p = 8 simulations, the
   i-th parameter of EVERY segment moved by +h_ki, then by -h_ki (a central
   star design; p = 4), h_ki = clip(``step_frac`` * radius_k, ``h_min``,
   ``h_max``) * scale_i, mirrored or shortened at the bounds.  All simulations
   use the same seed (common random numbers).  Segments are independent in
   time, so one simulation serves all K segment fits: each segment's features
   come from its own window, margins removed.
2. Model: per segment, the feature Jacobian J_k (m_k, 4) by least squares on the
   sampled differences F_s - F_c against theta_s - theta_c (linear in the
   log-parameters; the intercept is the centre simulation, so the model is exact
   there).
3. Identifiability: in prior-scaled coordinates the data information is
   G_k = S J_k^T W_k J_k S, S = diag(prior_sigma).  A parameter whose
   posterior-to-prior variance ratio diag((G_k + I)^-1) exceeds ``id_ratio``
   (default 0.25: the data do not halve the prior standard deviation) is NOT
   IDENTIFIABLE:
   it is held at its current value for this step (and reported so); the others
   move.  The singular values of W^1/2 J_k S are reported as well.
4. Step: one IPOPT solve (casadi.nlpsol) of the bounded trust-region subproblem
   min_d sum_k |W_k^1/2 (y_k - F_c,k - J_k d_k)|^2
         + sum_k |(theta_c,k + d_k - theta_prior,k) / prior_sigma|^2
   s.t. box |d_ki| <= radius_k scale_i, bounds on theta_c + d (class and physics
   bounds, :class:`inverse.spectral.ParamBounds`) and
   ln nmax - ln nmin >= ln(min_ratio).
5. Trial: one simulation at theta_c + d; per segment the ratio rho_k of actual
   to predicted reduction of the objective decides: rho_k > ``eta_accept``
   accepts the segment's step, rho_k < 0.25 halves radius_k (rho_k < 0
   quarters it), rho_k > 0.75 with the step on the trust-region edge doubles it
   (up to ``radius_max``).  Since
   the segments are separable, every segment has its own radius and acceptance.
6. A segment has converged when an accepted step is below ``step_tol`` (scaled
   inf-norm), its predicted reduction is below ``pred_tol``, or its radius falls
   below ``radius_min``; the fit stops when all have, or after ``max_iter``.

Cost: 1 + (2p + 1) simulations per iteration, whatever K is.
"""
from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError, SimulationError
from inverse.features import FeatureSet
from inverse.spectral import (N0, PARAM_NAMES, THETA_NAMES, ParamBounds, grid_spacing, iso_class,
                              params_to_theta, theta_to_params)

P = 4  # parameters per segment


@dataclass(frozen=True)
class FitConfig:
    """Settings of the trust-region fit.

    Parameters
    ----------
    scale : tuple of 4 float
        Unit of each theta component for the trust region and the sampling
        steps: ln Gq_n0, w, ln nmin, ln nmax [-].
    radius0, radius_min, radius_max : float
        Initial, smallest and largest trust-region radius in those units [-].
    step_frac : float
        Sampling step as a fraction of the radius.
    h_min, h_max : float
        Sampling step limits in scaled units [-].
    eta_accept : float
        Smallest ratio actual / predicted reduction that accepts a step.
    step_tol : float
        Accepted steps below this (scaled inf-norm) mark convergence.
    pred_tol : float
        Predicted reductions below this mark convergence [objective units].  The
        objective is a chi-square; a gain of 0.5 moves the parameters by well
        under one standard deviation, below what the data resolve.
    max_iter : int
        Most iterations.
    prior_sigma : tuple of 4 float
        Standard deviation of the Gaussian prior around the initial guess, per
        theta component: ln Gq_n0 (ln 4 = one ISO class), w, ln nmin, ln nmax.
    id_ratio : float
        Posterior / prior variance above which a parameter is not identifiable.
    n_workers : int
        Processes for sampling when no ``map_fn`` is given (1 = serial).
    polish_replicates : int
        Road realisations (other seeds) simulated at the converged point for the
        final polishing step; 0 switches it off.  The trust-region iterations see
        ONE simulated realisation, so they match the measured features to that
        realisation's scatter as well as to the parameters; the polish averages the
        log features over 1 + R realisations at the converged point and takes one
        bounded Gauss-Newton step with the last sampled Jacobians (valid because,
        with common random numbers, the Jacobian hardly depends on the
        realisation).  It divides the simulation side's share of the parameter
        variance by 1 + R for R + 1 simulations.
    """

    scale: tuple = (1.0, 0.25, 0.5, 0.3)
    radius0: float = 1.0
    radius_min: float = 0.05
    radius_max: float = 3.0
    step_frac: float = 0.3
    h_min: float = 0.05
    h_max: float = 0.5
    eta_accept: float = 0.1
    step_tol: float = 0.02
    pred_tol: float = 0.5
    max_iter: int = 12
    prior_sigma: tuple = (math.log(4.0), 0.5, 1.0, 0.5)
    id_ratio: float = 0.25
    n_workers: int = 1
    polish_replicates: int = 4


@dataclass
class SegmentFit:
    """Fitted parameters of one segment.

    Attributes
    ----------
    params : dict
        Gq_n0 [m^3], w [-], nmin, nmax [cycles/m].
    cls : str
        ISO 8608 class of Gq_n0.
    dx, dy : float
        Road grid steps [m] implied by nmax (:func:`inverse.spectral.grid_spacing`).
    identifiable : dict
        Parameter name -> bool (False: held, value is prior/last value).
    sd : dict
        Approximate posterior standard deviation of each theta component
        (Laplace, from the last local model) [ln units or -].
    singular_values : list
        Singular values of the weighted, prior-scaled Jacobian [-].
    objective : float
        Weighted feature misfit at the fit [-].
    n_features : int
    converged : bool
    best_level : dict
        Where the data pin the road level best: ``n_best`` [cycles/m], the
        spatial frequency at which the Laplace variance of ln Gd(n) = ln Gq_n0
        - w ln(n / n0) is smallest (ln(n_best / n0) = cov(ln Gq, w) / var(w),
        kept inside [nmin, nmax]), ``G_n_best`` [m^3] the fitted Gd there and
        ``sd_ln_G_n_best`` its standard deviation [-].  Gq_n0 itself is an
        extrapolation along w from about there.
    """

    params: dict
    cls: str
    dx: float
    dy: float
    identifiable: dict
    sd: dict
    singular_values: list
    objective: float
    n_features: int
    converged: bool
    best_level: dict = field(default_factory=dict)
    sd_robust: dict = field(default_factory=dict)
    consistency: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        """JSON-ready dict."""
        return {**self.params, "class": self.cls, "dx": self.dx, "dy": self.dy,
                "identifiable": self.identifiable, "sd": self.sd,
                "singular_values": self.singular_values, "objective": self.objective,
                "n_features": self.n_features, "converged": self.converged, **self.best_level,
                **({"sd_robust": self.sd_robust} if self.sd_robust else {}),
                **({"consistency": self.consistency} if self.consistency else {})}


def robust_sd(J, w, e, prior_w, n_best: float | None = None, n0: float = N0) -> dict:
    """Misspecification-robust ("sandwich") standard deviations of one segment's fit.

    The Laplace covariance ``A^-1`` (``A = J^T W J + diag(prior_w)``) holds when the
    weights are the features' true inverse variances and the model is right.  The
    sandwich ``A^-1 B A^-1`` with ``B = J^T diag(w^2 e^2) J + diag(prior_w)`` replaces the
    assumed variance of each feature by its squared residual (White's heteroscedasticity-
    consistent covariance; Huber's estimator under a misspecified model): where the fit
    leaves large residuals in the features that pin a parameter, that parameter's sd grows,
    and residuals in features it does not depend on leave it alone.  With a correct model
    E[w e^2] = 1 and B = A.  What it cannot see: a model error the parameters absorb
    without leaving a residual.

    Parameters
    ----------
    J : (m, P) array
        Feature sensitivities d features / d theta at the fit.
    w : (m,) array
        Feature weights (inverse variances).
    e : (m,) array
        Residuals measured - fitted.
    prior_w : (P,) array
        Prior precisions of theta.
    n_best : float, optional
        Where ln Gd(n) = ln Gq_n0 - w ln(n / n0) is evaluated for ``ln_G_n_best``.

    Returns
    -------
    dict
        THETA_NAMES -> sd, plus ``ln_G_n_best`` when ``n_best`` is given.
    """
    J = np.asarray(J, float)
    w = np.asarray(w, float)
    e = np.asarray(e, float)
    A = J.T @ (w[:, None] * J) + np.diag(prior_w)
    Js = J * (w * e)[:, None]
    B = Js.T @ Js + np.diag(prior_w)
    Ai = np.linalg.inv(A)
    C = Ai @ B @ Ai
    out = dict(zip(THETA_NAMES, map(float, np.sqrt(np.maximum(np.diag(C), 0.0)))))
    if n_best is not None:
        g = level_gradient(J.shape[1], n_best, n0)
        out["ln_G_n_best"] = float(math.sqrt(max(g @ C @ g, 0.0)))
    return out


def level_gradient(n_params: int, n: float, n0: float = N0) -> np.ndarray:
    """Gradient of ln Gd(n) = ln Gq_n0 - w ln(n / n0) with respect to theta (length ``n_params``)."""
    g = np.zeros(n_params)
    g[0], g[1] = 1.0, -math.log(n / n0)
    return g


def channel_kind(label: str) -> str:
    """A feature label's channel kind: 'susp_disp_3L@2.00Hz' -> 'susp_disp'."""
    return label.split("@")[0].split(":")[0].rsplit("_", 1)[0]


def channel_consistency(J, w, e, prior_w, labels, n_best: float | None = None, n0: float = N0) -> dict:
    """How far the channel kinds of one segment pull the fit apart (a model-form measure).

    From the joint fit, one Gauss-Newton step with the features of ONE channel kind
    (suspension displacement, axle acceleration, ...) gives where that kind alone would
    put the parameters: ``d_g = (J_g^T W_g J_g + P)^-1 J_g^T W_g e_g``.  With a correct model
    the kinds agree within noise: ``E[d_g^2] = v_g``, the difference of the kind-alone and
    the joint Laplace variances.  A vehicle the model lacks (leaf friction stiffens the
    suspension: the displacements say "smoother road", the axle accelerations do not)
    pulls the kinds apart by about the bias it puts into the joint fit, whether or not
    it leaves a residual.  Returned per quantity: the excess ``mean_g max(0, d_g^2 - v_g)``
    [ln^2 or -^2], the model-form variance :mod:`inverse.uncertainty` may add.

    Parameters
    ----------
    J : (m, P) array
        Feature sensitivities at the fit.
    w, e : (m,) arrays
        Feature weights (inverse variances) and residuals measured - fitted.
    prior_w : (P,) array
        Prior precisions.
    labels : list of str
        Feature labels (``WindowFeatures.labels``).
    n_best : float, optional
        Where ``ln_G_n_best`` is evaluated.

    Returns
    -------
    dict
        ``excess`` {quantity: variance}, ``kinds`` {kind: {quantity: step}}; empty
        ``excess`` when fewer than two kinds are fitted.
    """
    J, w, e = (np.asarray(a, float) for a in (J, w, e))
    kinds = np.array([channel_kind(lab) for lab in labels])
    names = list(THETA_NAMES)
    G = np.eye(J.shape[1])
    if n_best is not None:
        G = np.vstack([G, level_gradient(J.shape[1], n_best, n0)])
        names.append("ln_G_n_best")
    P = np.diag(prior_w)
    A_inv = np.linalg.inv(J.T @ (w[:, None] * J) + P)
    out_k, ex = {}, []
    for kind in sorted(set(kinds)):
        m = kinds == kind
        Jg, wg = J[m], w[m]
        Ag_inv = np.linalg.inv(Jg.T @ (wg[:, None] * Jg) + P)
        d = G @ (Ag_inv @ (Jg.T @ (wg * e[m])))
        v = np.einsum("ij,jk,ik->i", G, Ag_inv - A_inv, G)
        out_k[str(kind)] = dict(zip(names, map(float, d)))
        ex.append(np.maximum(d ** 2 - np.maximum(v, 0.0), 0.0))
    excess = dict(zip(names, map(float, np.mean(ex, axis=0)))) if len(out_k) >= 2 else {}
    return {"excess": excess, "kinds": out_k}


def best_level(params: dict, cov: np.ndarray, n0: float = N0) -> dict:
    """The best-determined road level of a segment (see ``SegmentFit.best_level``).

    Parameters
    ----------
    params : dict
        Gq_n0 [m^3], w [-], nmin, nmax [cycles/m].
    cov : (4, 4) array
        Laplace covariance of (ln Gq_n0, w, ln nmin, ln nmax).
    n0 : float
        Reference spatial frequency [cycles/m].
    """
    c11, c12, c22 = float(cov[0, 0]), float(cov[0, 1]), float(cov[1, 1])
    L = c12 / c22 if c22 > 0 and np.isfinite(c12 / c22) else 0.0
    L = float(np.clip(L, math.log(params["nmin"] / n0), math.log(params["nmax"] / n0)))
    var = max(c11 - 2 * L * c12 + L * L * c22, 0.0)
    n_best = n0 * math.exp(L)
    return {"n_best": n_best, "G_n_best": params["Gq_n0"] * (n_best / n0) ** (-params["w"]),
            "sd_ln_G_n_best": math.sqrt(var)}


@dataclass
class FitResult:
    """Result of :func:`fit_segments`.

    Attributes
    ----------
    params : ndarray, shape (K, 4)
        Fitted physical parameters.
    theta : ndarray, shape (K, 4)
    segments : list of SegmentFit
    history : list of dict
        One entry per iteration (iteration 0 = initial point): 'iter', 'kind'
        ('trust_region', or 'polish' for the final averaged step), 'theta',
        'params' (lists, the iterate after the iteration), 'objective' (data
        misfit + prior term, summed over segments), 'objective_segments',
        'radius', 'rho', 'accepted', 'identifiable', 'converged',
        'solver_status' (IPOPT's return status of the step), 'n_sims'
        (cumulative), 'wall_s'.
    n_sims : int
        Simulations run.
    wall_s : float
        Wall time [s].
    features : list of ndarray
        Simulated features at the fit.
    """

    params: np.ndarray
    theta: np.ndarray
    segments: list
    history: list
    n_sims: int
    wall_s: float
    features: list = field(default_factory=list)


def replicate_seeds(seed: int, replicates: int) -> list:
    """Seeds of the R simulated replicates: replicate r uses
    SeedSequence(seed, spawn_key=(r,)).generate_state(1)[0]; R = 1 uses ``seed``."""
    if replicates == 1:
        return [int(seed)]
    return [int(np.random.SeedSequence(seed, spawn_key=(r,)).generate_state(1)[0]) for r in range(replicates)]


class _Evaluator:
    """Picklable simulate -> features map; log features averaged over replicates."""

    def __init__(self, simulate, features: FeatureSet, seed: int, features_fn=None):
        self.simulate, self.features, self.features_fn = simulate, features, features_fn
        self.seeds = replicate_seeds(seed, features.spec.replicates)

    def __call__(self, params):
        acc = None
        for s in self.seeds:
            try:
                if self.features_fn is not None:
                    F = [np.asarray(f, dtype=float) for f in self.features_fn(params, s)]
                else:
                    F = self.features.evaluate(self.simulate(params, s))
            except EroadInputError:
                raise
            except Exception as exc:  # a failed solve at a sample point
                raise SimulationError(f"simulation at params {np.round(params, 6).tolist()} "
                                      f"seed {s} failed: {exc}") from exc
            if len(F) != self.features.n_segments or any(f.shape != wf.y.shape
                                                         for f, wf in zip(F, self.features.windows)):
                raise EroadInputError("features callable must return one array per segment shaped like "
                                      "the measured features")
            acc = F if acc is None else [a + f for a, f in zip(acc, F)]
        return [a / len(self.seeds) for a in acc]


class _TrustRegionQP:
    """The bounded trust-region subproblem as one CasADi/IPOPT NLP, built once."""

    def __init__(self, K: int, min_gap: float):
        import casadi as ca

        self.K = K
        n = K * P
        d = ca.SX.sym("d", n)
        Q = ca.SX.sym("Q", K * P * P)
        b = ca.SX.sym("b", n)
        th = ca.SX.sym("th", n)
        prior = ca.SX.sym("prior", n)
        pw = ca.SX.sym("pw", n)
        f = 0
        g = []
        for k in range(K):
            dk = d[k * P:(k + 1) * P]
            Qk = ca.reshape(Q[k * P * P:(k + 1) * P * P], P, P)
            f += ca.dot(dk, ca.mtimes(Qk, dk)) - 2 * ca.dot(b[k * P:(k + 1) * P], dk)
            g.append((th[k * P + 3] + dk[3]) - (th[k * P + 2] + dk[2]))
        e = th + d - prior
        f += ca.dot(pw * e, e)
        nlp = {"x": d, "p": ca.vertcat(Q, b, th, prior, pw), "f": f, "g": ca.vertcat(*g)}
        opts = {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes",
                "ipopt.tol": 1e-10, "ipopt.max_iter": 200}
        self.solver = ca.nlpsol("trust_region_step", "ipopt", nlp, opts)
        self.min_gap = min_gap

    def solve(self, Q, b, theta, prior, pw, lbd, ubd):
        K = self.K
        p = np.concatenate([np.concatenate([Qk.T.ravel() for Qk in Q]), np.ravel(b), np.ravel(theta),
                            np.ravel(prior), np.ravel(pw)])
        # a feasible start: zero step, or the nearest point of the box
        x0 = np.clip(0.0, lbd.ravel(), ubd.ravel())
        sol = self.solver(x0=x0, p=p, lbx=lbd.ravel(), ubx=ubd.ravel(),
                          lbg=np.full(K, self.min_gap), ubg=np.full(K, np.inf))
        stats = self.solver.stats()
        d = np.array(sol["x"]).reshape(K, P)
        return np.clip(d, lbd, ubd), stats.get("return_status", "")


def _apply(job):
    """``job = (evaluator, params)`` -> evaluator(params); for maps over several seeds."""
    ev, params = job
    return ev(params)


def _prior_objective(theta, prior, pw):
    return np.sum(pw * (theta - prior) ** 2, axis=1)


def _design(theta, H, lo, hi):
    """Central star design: list of (K, 4) theta samples, 2P of them."""
    out = []
    for i in range(P):
        for sgn in (1.0, -1.0):
            th = theta.copy()
            step = sgn * H[:, i]
            target = th[:, i] + step
            # mirror at a bound, then shorten if both directions are blocked
            over = (target > hi[i]) | (target < lo[i])
            target[over] = th[over, i] - step[over]
            target = np.clip(target, lo[i], hi[i])
            th[:, i] = target
            out.append(th)
    return out


def polish_seeds(seed: int, replicates: int) -> list:
    """Seeds of the polishing realisations: SeedSequence(seed, spawn_key=(1000 + r,))."""
    return [int(np.random.SeedSequence(seed, spawn_key=(1000 + r,)).generate_state(1)[0])
            for r in range(replicates)]


def _polish(theta, Fc, J, y, W, evaluator, features, seed, config, qp, prior_theta, pw, ident,
            radius, lo, hi, map_fn, objective):
    """The final averaged Gauss-Newton step (see ``FitConfig.polish_replicates``)."""
    K = theta.shape[0]
    scale = np.asarray(config.scale, dtype=float)
    evs = [_Evaluator(evaluator.simulate, features, s, evaluator.features_fn)
           for s in polish_seeds(seed, config.polish_replicates)]
    params = theta_to_params(theta)
    extra = list(map_fn(_apply, [(ev, params) for ev in evs]))
    Fbar = [np.mean([Fc[k]] + [F[k] for F in extra], axis=0) for k in range(K)]
    Q = [J[k].T @ (W[k][:, None] * J[k]) for k in range(K)]
    b = np.array([J[k].T @ (W[k] * (y[k] - Fbar[k])) for k in range(K)])
    box = np.maximum(radius, 0.5)[:, None] * scale
    lbd = np.maximum(-box, lo - theta)
    ubd = np.minimum(box, hi - theta)
    lbd[~ident] = 0.0
    ubd[~ident] = 0.0
    d, _ = qp.solve(Q, b, theta, prior_theta, pw, lbd, ubd)
    new = theta + d
    # the kept realisation (the fit's seed) at the polished point, for the report
    Fn = list(map_fn(_apply, [(evaluator, theta_to_params(new))]))[0]
    return new, Fn, objective(Fn, new)


def check_common_random_numbers(simulate, params, seed: int = 0, steps=(0.1, 0.025, 0.1, 0.1)) -> dict:
    """Does a simulator keep its road phases when the parameters move?

    Runs the simulator at ``params`` and at ``params`` with one parameter of every
    segment moved by a small step (ln Gq_n0 + 0.1, w + 0.025, ln nmin + 0.1,
    ln nmax - 0.1), all with one seed, and correlates the responses.  With
    common random numbers the responses barely change (correlation near 1); a
    simulator that redraws phases when a parameter moves gives a correlation
    near 0, and sampled sensitivities from it are noise.

    Parameters
    ----------
    simulate : callable
        Simulator with the contract of this module.
    params : (K, 4) array
        Physical parameters to test at.
    seed : int
    steps : tuple of 4 float
        Steps in theta units.

    Returns
    -------
    dict
        Parameter name -> smallest correlation coefficient over the channels
        [-]; the fit needs all of them close to 1 (say > 0.9).
    """
    P0 = np.atleast_2d(np.asarray(params, dtype=float))
    base = simulate(P0, seed)
    out = {}
    for i, name in enumerate(PARAM_NAMES):
        th = params_to_theta(P0)
        th[:, i] += steps[i] if i != 3 else -steps[i]
        moved = simulate(theta_to_params(th), seed)
        out[name] = float(min(np.corrcoef(np.asarray(base[c], float), np.asarray(moved[c], float))[0, 1]
                              for c in base))
    return out


def fit_segments(simulate, features: FeatureSet, params0, *, seed: int = 0,
                 bounds: ParamBounds = ParamBounds(), config: FitConfig = FitConfig(),
                 prior=None, map_fn=None, progress=None, features_fn=None) -> FitResult:
    """Fit the spectral parameters of every segment to the measured features.

    Parameters
    ----------
    simulate : callable
        ``simulate(params (K, 4), seed) -> dict channel -> (N,) array``; see the
        module docstring for the contract.
    features : FeatureSet
        Measured features of the K segments (:meth:`FeatureSet.from_measurement`).
    params0 : array_like, shape (K, 4)
        Initial physical parameters (e.g. the segmentation's level, w = 2,
        nmin = 0.05, nmax = 5); projected into ``bounds``.
    seed : int
        Seed of the road phases used for EVERY simulation of the fit (common
        random numbers).  Keep it different from anything that made the data.
    bounds : ParamBounds
        Bounds (use :meth:`ParamBounds.for_record` for the Nyquist cap of nmax).
    config : FitConfig
    prior : array_like, shape (K, 4), optional
        Prior mean in physical parameters; defaults to ``params0``.
    map_fn : callable, optional
        ``map_fn(func, list_of_params) -> iterable`` for the sampled simulations,
        e.g. ``ProcessPoolExecutor(2).map``; serial ``map`` by default, or a
        process pool of ``config.n_workers`` when that is above 1.
    progress : callable, optional
        Called with each history entry as it is made.
    features_fn : callable, optional
        ``features_fn(params (K, 4), seed) -> list of K arrays``: simulated
        features directly (aligned with ``features.windows[k].y``, e.g. from a
        linear model's response PSDs), used instead of
        ``features.evaluate(simulate(params, seed))``; ``simulate`` is then
        ignored (may be None).

    Returns
    -------
    FitResult
    """
    t_start = _time.perf_counter()
    K = features.n_segments
    theta = bounds.clip_theta(params_to_theta(params0))
    if theta.shape != (K, P):
        raise EroadInputError(f"fit_segments: params0 must have shape ({K}, 4), got {theta.shape}")
    prior_theta = theta.copy() if prior is None else bounds.clip_theta(params_to_theta(prior))
    lo, hi = bounds.theta_lower(), bounds.theta_upper()
    scale = np.asarray(config.scale, dtype=float)
    psig = np.asarray(config.prior_sigma, dtype=float)
    pw = np.broadcast_to(1.0 / psig ** 2, (K, P)).copy()
    y = [wf.y for wf in features.windows]
    W = [wf.weight for wf in features.windows]

    evaluator = _Evaluator(simulate, features, seed, features_fn)
    pool = None
    if map_fn is None:
        if config.n_workers > 1:
            from eroad.threads import process_pool
            pool = process_pool(config.n_workers)
            map_fn = pool.map
        else:
            map_fn = map
    n_sims = 0

    def run(batch):
        nonlocal n_sims
        n_sims += len(batch) * len(evaluator.seeds)
        return list(map_fn(evaluator, [theta_to_params(th) for th in batch]))

    def objective(F, th):
        return features.objective(F) + _prior_objective(th, prior_theta, pw)

    qp = _TrustRegionQP(K, math.log(bounds.min_ratio))
    history = []
    try:
        Fc = run([theta])[0]
        obj_c = objective(Fc, theta)
        radius = np.full(K, config.radius0)
        converged = np.zeros(K, dtype=bool)
        ident = np.ones((K, P), dtype=bool)
        sd = np.full((K, P), np.nan)
        cov = np.full((K, P, P), np.nan)
        svals = [[] for _ in range(K)]
        J_last = [None] * K

        def record(it, rho, accepted, status="", kind="trust_region"):
            entry = {"iter": it, "kind": kind, "solver_status": status, "theta": theta.tolist(), "params": theta_to_params(theta).tolist(),
                     "objective": float(obj_c.sum()), "objective_segments": obj_c.tolist(),
                     "radius": radius.tolist(), "rho": rho, "accepted": accepted,
                     "identifiable": ident.tolist(), "converged": converged.tolist(),
                     "n_sims": n_sims, "wall_s": _time.perf_counter() - t_start}
            history.append(entry)
            if progress is not None:
                progress(entry)

        record(0, [None] * K, [None] * K)
        for it in range(1, config.max_iter + 1):
            H = np.clip(config.step_frac * radius, config.h_min, config.h_max)[:, None] * scale[None, :]
            samples = _design(theta, H, lo, hi)
            Fs = run(samples)
            Q, bvec = [], np.zeros((K, P))
            for k in range(K):
                D = np.array([s[k] - theta[k] for s in samples])  # (S, P)
                R = np.array([F[k] - Fc[k] for F in Fs])  # (S, m)
                J = np.linalg.lstsq(D, R, rcond=None)[0].T  # (m, P)
                J_last[k] = J
                Qk = J.T @ (W[k][:, None] * J)
                # identifiability in prior-scaled coordinates
                G = psig[:, None] * Qk * psig[None, :]
                post = np.linalg.inv(G + np.eye(P))
                ident[k] = np.diag(post) <= config.id_ratio
                svals[k] = np.sqrt(np.maximum(np.linalg.eigvalsh(G)[::-1], 0.0)).tolist()
                cov[k] = np.linalg.inv(Qk + np.diag(pw[k]))
                sd[k] = np.sqrt(np.diag(cov[k]))
                Q.append(Qk)
                bvec[k] = J.T @ (W[k] * (y[k] - Fc[k]))
            # step bounds: trust region, parameter bounds, held parameters, converged segments
            lbd = np.maximum(-radius[:, None] * scale, lo - theta)
            ubd = np.minimum(radius[:, None] * scale, hi - theta)
            hold = ~ident | converged[:, None]
            lbd[hold] = 0.0
            ubd[hold] = 0.0
            d, status = qp.solve(Q, bvec, theta, prior_theta, pw, lbd, ubd)
            # predicted reduction per segment (data model + prior)
            pred = np.empty(K)
            for k in range(K):
                quad = d[k] @ Q[k] @ d[k] - 2 * bvec[k] @ d[k]
                prior_new = np.sum(pw[k] * (theta[k] + d[k] - prior_theta[k]) ** 2)
                prior_old = np.sum(pw[k] * (theta[k] - prior_theta[k]) ** 2)
                pred[k] = -(quad + prior_new - prior_old)
            trial = theta + d
            Ft = run([trial])[0]
            obj_t = objective(Ft, trial)
            rho, accepted = [None] * K, [False] * K
            for k in range(K):
                if converged[k]:
                    continue
                step = float(np.max(np.abs(d[k]) / scale))
                if pred[k] <= config.pred_tol:
                    converged[k] = True
                    continue
                r = float((obj_c[k] - obj_t[k]) / pred[k])
                rho[k] = r
                if r > config.eta_accept:
                    accepted[k] = True
                    theta[k] = trial[k]
                    Fc[k] = Ft[k]
                    obj_c[k] = obj_t[k]
                    if step < config.step_tol:
                        converged[k] = True
                if r < 0.0:  # the model was wrong about the direction: shrink hard
                    radius[k] = 0.25 * min(radius[k], max(step, config.radius_min))
                elif r < 0.25:
                    radius[k] = 0.5 * min(radius[k], max(step, config.radius_min))
                elif r > 0.75 and step > 0.9 * radius[k]:
                    radius[k] = min(2.0 * radius[k], config.radius_max)
                if radius[k] < config.radius_min:
                    converged[k] = True
            record(it, rho, accepted, status)
            if converged.all():
                break
        if config.polish_replicates > 0 and all(J is not None for J in J_last):
            theta, Fc, obj_c = _polish(theta, Fc, J_last, y, W, evaluator, features, seed, config,
                                       qp, prior_theta, pw, ident, radius, lo, hi, map_fn, objective)
            n_sims += (config.polish_replicates + 1) * len(evaluator.seeds)
            record(len(history), [None] * K, [True] * K, kind="polish")
    finally:
        if pool is not None:
            pool.shutdown()
    params = theta_to_params(theta)
    nf = features.n_features()
    obj_data = features.objective(Fc)
    segs = []
    for k in range(K):
        pk = dict(zip(PARAM_NAMES, map(float, params[k])))
        dx = grid_spacing(pk["nmax"])
        best = best_level(pk, cov[k]) if np.all(np.isfinite(cov[k])) else {}
        rob, cons = {}, {}
        if J_last[k] is not None:
            res = np.asarray(y[k]) - np.asarray(Fc[k])
            rob = robust_sd(J_last[k], W[k], res, pw[k], best.get("n_best"))
            cons = channel_consistency(J_last[k], W[k], res, pw[k], features.windows[k].labels, best.get("n_best"))
        segs.append(SegmentFit(
            params=pk, cls=iso_class(pk["Gq_n0"]), dx=dx, dy=dx,
            identifiable=dict(zip(PARAM_NAMES, map(bool, ident[k]))),
            sd=dict(zip(THETA_NAMES, map(float, sd[k]))), singular_values=svals[k],
            objective=float(obj_data[k]), n_features=int(nf[k]), converged=bool(converged[k]),
            best_level=best, sd_robust=rob, consistency=cons))
    return FitResult(params, theta, segs, history, n_sims, _time.perf_counter() - t_start, Fc)
