"""Which unmodelled effect closes the gap: calibrate each candidate, score it on held-out data, rank.

What it is for: the second and third answers of a diagnosis.  For each candidate
effect it calibrates the effect's (one or two) parameters on calibration data, then
scores the gap on held-out data (other segments or windows), penalises added
parameters (BIC), ranks, tries the best pairs, and answers ``"none"`` when no
candidate shrinks the held-out gap beyond what road-phase noise alone would do.

The callables (the whole coupling to a simulator)
-------------------------------------------------
``fit(effects, data) -> state``
    ``effects`` is ``{effect_name: {parameter: value}}`` (``{}`` = nominal model),
    ``data`` a list of measured windows (the objects passed as ``calib`` or
    ``heldout``).  Returns an opaque model state: vehicle with those effects plus
    the road identified on ``data`` with the effects fixed (the inverse fit).  May
    cache (e.g. reuse the nominal road as a start).
``simulate(state, window, seed) -> signals``
    Drives the state's model over a road realisation with road-phase seed ``seed``
    (int) for the duration, sample rate and speed profile of ``window``; returns
    anything :func:`diagnosis.signals.as_signals` reads, with the measured channels.

For process-parallel runs (``executor=ProcessPoolExecutor(...)``) both must be
picklable (module-level functions or ``functools.partial`` of them).

Procedure
---------
1. Seeds: every road-phase seed is ``SeedSequence(seed, spawn_key=key)``'s first
   state word with keys ``(0, i, j)`` calibration seed ``i`` window ``j``,
   ``(1, i, j)`` held-out seed ``i`` window ``j``, ``(2, i, j)`` null surrogates.
   Every model uses the same seeds (common random numbers), so differences between
   models are not differences between road realisations.
2. Calibration of a candidate: objective = mean gap (``diagnosis.gap``) on the
   calibration windows over ``n_calib_seeds`` seeds, each evaluation calling ``fit``
   then ``simulate``.  One parameter: a grid of ``grid`` points over the range
   (log-spaced where ``Param.log``), then golden-section search (``refine``
   evaluations) between the neighbours of the best grid point.  Two parameters:
   a ``(grid-1)^2`` grid, then one golden-section pass per parameter.
3. Held-out score: ``fit(effects, heldout)`` (road re-identified with the calibrated
   effect fixed), gap on each of ``n_seeds`` seeds; the nominal model the same way
   (``gap_before``).  ``shrink = 1 - mean(after) / mean(before)``; its spread is the
   standard deviation over seeds of the paired per-seed shrink.
4. Noise: the nominal-vs-nominal gap, nominal simulation against a surrogate
   measurement simulated by the nominal model with other seeds, over ``n_null``
   seed pairs: mean and standard deviation ``sd0``.
5. BIC (Gaussian residuals in log band power, ``n`` = number of cells, ``k`` =
   parameters added): ``BIC = n ln(gap) + k ln(n)``; ``delta_bic`` is against the
   nominal model.  Left and right channels and neighbouring bands are correlated,
   so ``n`` overstates the independent information and the penalty is mild; the
   noise gate below is the stronger guard.
6. A candidate is ACCEPTED when (a) the nominal gap is beyond noise
   (``mean(before) > mean0 + z sd0``), (b) its held-out improvement
   ``mean(before - after) > z sd0``, and (c) ``delta_bic < 0``.  Entries are ranked
   by ``delta_bic``.  Pairs of the ``n_pair_candidates`` best singles are
   calibrated jointly (start at the single optima, one golden pass per parameter)
   and accepted only when they also beat the best single by ``z sd0`` and in BIC.
   The verdict is the best accepted entry (``"a+b"`` for a pair) or ``"none"``.
   ``confidence`` is ``"ambiguous"`` when an entry sharing no effect with the
   winner reaches a held-out gap within ``sd0`` of the winner's, else ``"clear"``.

What it is not: a global optimiser.  Effects with more than two parameters are
calibrated over the two chosen in their :class:`Candidate` (others fixed).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import combinations
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from eroad.errors import EroadInputError

from .gap import Gap, band_gap, reference

__all__ = ["Param", "Candidate", "Calibration", "Entry", "NullReference", "Ranking",
           "candidates_from_library", "calibrate", "rank_effects", "seed_int"]

_GR = (math.sqrt(5) - 1) / 2


@dataclass(frozen=True)
class Param:
    """A calibrated parameter of a candidate effect.

    Parameters
    ----------
    name : str
        Parameter name as the effect knows it.
    lo, hi : float
        Search range (the parameter's unit).
    log : bool
        Search in log space (``lo > 0``).
    """

    name: str
    lo: float
    hi: float
    log: bool = False

    def __post_init__(self):
        if not self.hi > self.lo or (self.log and self.lo <= 0):
            raise EroadInputError(f"parameter {self.name}: bad range {self.lo}..{self.hi}")

    def value(self, u: float) -> float:
        """Parameter value at unit coordinate ``u`` in [0, 1]."""
        u = min(1.0, max(0.0, float(u)))
        if self.log:
            return float(math.exp(math.log(self.lo) + u * (math.log(self.hi) - math.log(self.lo))))
        return float(self.lo + u * (self.hi - self.lo))


@dataclass(frozen=True)
class Candidate:
    """A candidate unmodelled effect.

    Parameters
    ----------
    name : str
        Effect name (key of the ``effects`` mapping given to ``fit``).
    params : tuple of Param
        The one or two parameters calibrated.
    fixed : mapping, optional
        Other parameters of the effect, held at these values.
    """

    name: str
    params: tuple
    fixed: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self):
        if not 1 <= len(self.params) <= 2:
            raise EroadInputError(f"candidate {self.name}: calibrate 1 or 2 parameters, "
                                  f"got {len(self.params)}")

    @property
    def k(self) -> int:
        """Number of calibrated parameters."""
        return len(self.params)

    def effects(self, u: Sequence[float]) -> dict:
        """``{name: {param: value}}`` at unit coordinates ``u``."""
        d = dict(self.fixed)
        d.update({p.name: p.value(x) for p, x in zip(self.params, u)})
        return {self.name: d}


def candidates_from_library(library: Mapping[str, Any], names: Sequence[str] | None = None,
                            max_free: int = 2) -> list[Candidate]:
    """Candidates from an effect registry such as ``vehicles.effects.EFFECTS``.

    Each effect is read duck-typed: ``.parameters`` is a sequence of objects or dicts
    with ``name``, ``default`` and ``range`` (lo, hi); an optional attribute
    ``diagnosis_parameters`` (names) picks which ones are calibrated, else the first
    ``max_free`` with a range, the effect's ``primary`` parameter (the one
    ``NAME=VALUE`` sets) first.  Use ``max_free=1`` for the cheapest search.  Log search where ``lo > 0`` and ``hi / lo >= 10``.

    Parameters
    ----------
    library : mapping name -> effect (class or instance)
    names : sequence of str, optional
        Subset and order; default all.
    max_free : int
        At most this many calibrated parameters per effect (1 or 2).

    Returns
    -------
    list of Candidate
    """
    def get(p, key, default=None):
        return p.get(key, default) if isinstance(p, Mapping) else getattr(p, key, default)

    out = []
    for name in (names or list(library)):
        if name not in library:
            raise EroadInputError(f"unknown effect {name!r}; known: {', '.join(library)}")
        eff = library[name]
        params = list(get(eff, "parameters", []) or [])
        primary = get(eff, "primary", "") or ""
        params.sort(key=lambda p: get(p, "name") != primary)      # the primary parameter first
        chosen = list(get(eff, "diagnosis_parameters", []) or [])
        free, fixed = [], {}
        for p in params:
            pname, rng = get(p, "name"), get(p, "range")
            use = (pname in chosen) if chosen else (rng is not None and len(free) < max_free)
            if use and rng is not None:
                lo, hi = float(rng[0]), float(rng[1])
                free.append(Param(pname, lo, hi, log=(lo > 0 and hi / lo >= 10)))
            elif get(p, "default") is not None:
                fixed[pname] = get(p, "default")
        if free:
            out.append(Candidate(name, tuple(free[:max_free]), fixed))
    return out


def seed_int(seed: int, key: tuple) -> int:
    """Road-phase seed for a stream: ``SeedSequence(seed, spawn_key=key).generate_state(1)[0]``."""
    return int(np.random.SeedSequence(seed, spawn_key=tuple(int(k) for k in key)).generate_state(1)[0])


@dataclass(frozen=True)
class Calibration:
    """Result of calibrating one candidate (or pair).

    Attributes
    ----------
    effects : dict  ``{name: {param: value}}`` at the optimum
    unit : tuple    optimum in unit coordinates (for pairs: concatenated)
    calib_gap : float, (log units)^2
    n_evals : int
    history : list of (effects, gap)
    """

    effects: dict
    unit: tuple
    calib_gap: float
    n_evals: int
    history: list


def _golden(f, a: float, b: float, n: int) -> None:
    """Golden-section search of f on [a, b] with n evaluations (f memoised by caller)."""
    if n <= 0 or b - a < 1e-6:
        return
    c, d = b - _GR * (b - a), a + _GR * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(max(0, n - 2)):
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - _GR * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + _GR * (b - a)
            fd = f(d)


def calibrate(candidates: Sequence[Candidate], objective: Callable[[dict], float], *,
              grid: int = 5, refine: int = 8, start: Sequence[float] | None = None) -> Calibration:
    """Bounded search over the parameters of one candidate or of a pair.

    Parameters
    ----------
    candidates : sequence of Candidate
        One candidate, or two for a pair (their parameters are searched together).
    objective : callable effects -> float
        Calibration gap of a model with these effects.
    grid : int
        Grid points per parameter for a single 1-parameter candidate (``grid - 1``
        per parameter for two parameters).  Ignored when ``start`` is given.
    refine : int
        Golden-section evaluations (per parameter for 2 or more parameters).
    start : sequence of float, optional
        Start in unit coordinates: skip the grid, refine around it (pairs).

    Returns
    -------
    Calibration
    """
    cands = list(candidates)
    params = [(ci, p) for ci, c in enumerate(cands) for p in c.params]
    nd = len(params)
    memo: dict = {}
    history = []

    def effects_at(u):
        out, pos = {}, 0
        for c in cands:
            out.update(c.effects(u[pos:pos + c.k]))
            pos += c.k
        return out

    def f(u):
        key = tuple(round(float(x), 6) for x in u)
        if key not in memo:
            eff = effects_at(key)
            memo[key] = float(objective(eff))
            history.append((eff, memo[key]))
        return memo[key]

    if start is None:
        g = grid if nd == 1 else max(3, grid - 1)
        axes = [np.linspace(0.0, 1.0, g)] * nd
        for pt in np.array(np.meshgrid(*axes, indexing="ij")).reshape(nd, -1).T:
            f(pt)
        step = 1.0 / (g - 1)
    else:
        f(np.asarray(start, dtype=float))
        step = 1.0 / max(2, grid - 1)
    best = np.array(min(memo, key=memo.get))
    for i in range(nd):
        n = refine if nd == 1 else max(3, refine // 2 + 1)
        base = best.copy()

        def f1(x, i=i, base=base):
            u = base.copy()
            u[i] = x
            return f(u)

        _golden(f1, max(0.0, base[i] - step), min(1.0, base[i] + step), n)
        best = np.array(min(memo, key=memo.get))
    key = tuple(best)
    return Calibration(effects_at(key), key, memo[key], len(memo), history)


@dataclass(frozen=True)
class NullReference:
    """Nominal-vs-nominal gaps (model exactly right, road phases differ).

    Attributes
    ----------
    gaps : (n,) array, (log units)^2
    mean, std : float
    """

    gaps: np.ndarray

    @property
    def mean(self) -> float:
        return float(np.mean(self.gaps))

    @property
    def std(self) -> float:
        return float(np.std(self.gaps, ddof=1)) if self.gaps.size > 1 else float("nan")


@dataclass(frozen=True)
class Entry:
    """One ranked model (single effect or pair), scored on held-out data.

    Attributes
    ----------
    effect : str                 effect name, ``"a+b"`` for a pair
    effects : dict               ``{name: {param: value}}`` calibrated
    k : int                      parameters added
    calib_gap : float            calibration gap at the optimum
    before, after : (S,) arrays  held-out gap of the nominal / this model per seed
    per_band_before, per_band_after : (nb,) arrays, mean over seeds
    n_cells : int                held-out cells (BIC ``n``)
    n_evals : int                calibration evaluations
    delta_bic : float            BIC of this model minus nominal
    beyond_noise : bool          improvement exceeds ``z sd0``
    accepted : bool              passes all gates (see module docstring)
    floor : float                held-out gap expected of a correct model
    """

    effect: str
    effects: dict
    k: int
    calib_gap: float
    before: np.ndarray
    after: np.ndarray
    per_band_before: np.ndarray
    per_band_after: np.ndarray
    n_cells: int
    n_evals: int
    delta_bic: float = float("nan")
    beyond_noise: bool = False
    accepted: bool = False
    floor: float = float("nan")

    @property
    def heldout_gap_before(self) -> float:
        return float(np.mean(self.before))

    @property
    def heldout_gap_after(self) -> float:
        return float(np.mean(self.after))

    @property
    def improvement(self) -> float:
        """Mean over seeds of ``before - after``, (log units)^2."""
        return float(np.mean(self.before - self.after))

    @property
    def shrink_fraction(self) -> float:
        """``1 - mean(after) / mean(before)``."""
        return 1.0 - self.heldout_gap_after / self.heldout_gap_before

    @property
    def shrink_excess(self) -> float:
        """``1 - (after - floor) / (before - floor)``: shrink of the part above sampling noise."""
        den = self.heldout_gap_before - self.floor
        return float(1.0 - (self.heldout_gap_after - self.floor) / den) if den > 0 else float("nan")

    @property
    def shrink_per_seed(self) -> np.ndarray:
        return 1.0 - self.after / self.before

    @property
    def shrink_spread(self) -> float:
        """Standard deviation over road-phase seeds of the per-seed shrink."""
        s = self.shrink_per_seed
        return float(np.std(s, ddof=1)) if s.size > 1 else float("nan")

    def record(self) -> dict:
        """JSON-ready dict for ``summary.json["ranking"]``."""
        s = self.shrink_per_seed
        return {
            "effect": self.effect, "parameters": self.effects, "k": self.k,
            "heldout_gap_before": self.heldout_gap_before, "heldout_gap_after": self.heldout_gap_after,
            "heldout_gap_after_per_seed": [float(v) for v in self.after],
            "shrink_fraction": self.shrink_fraction, "shrink_spread": self.shrink_spread,
            "shrink_min": float(s.min()), "shrink_max": float(s.max()),
            "shrink_excess": self.shrink_excess, "noise_floor": self.floor,
            "improvement": self.improvement, "delta_bic": self.delta_bic, "calib_gap": self.calib_gap,
            "beyond_noise": self.beyond_noise, "accepted": self.accepted,
            "n_evaluations": self.n_evals, "n_cells": self.n_cells,
            "per_band_before": [None if not np.isfinite(v) else float(v) for v in self.per_band_before],
            "per_band_after": [None if not np.isfinite(v) else float(v) for v in self.per_band_after],
        }


@dataclass(frozen=True)
class Ranking:
    """Outcome of :func:`rank_effects`.

    Attributes
    ----------
    entries : list of Entry, best (lowest delta_bic) first
    before : (S,) array   held-out gap of the nominal model per seed
    per_band_before : (nb,) array
    floor : float         expected gap of a correct model (sampling noise)
    per_band_floor : (nb,) array
    null : NullReference
    gap_present : bool    nominal gap beyond noise
    verdict : str         accepted effect (``"a+b"`` for a pair) or ``"none"``
    confidence : str      ``"clear"``, ``"ambiguous"`` or ``"none"``
    reason : str          one sentence
    bands : (nb, 3) array, Hz
    settings : dict
    """

    entries: list
    before: np.ndarray
    per_band_before: np.ndarray
    floor: float
    per_band_floor: np.ndarray
    null: NullReference
    gap_present: bool
    verdict: str
    confidence: str
    reason: str
    bands: np.ndarray
    settings: dict

    @property
    def winner(self) -> Entry | None:
        return next((e for e in self.entries if e.effect == self.verdict), None)

    def records(self) -> list[dict]:
        return [e.record() for e in self.entries]


class _Scorer:
    """Evaluations shared by the search, the held-out scoring and the null (picklable)."""

    def __init__(self, fit, simulate, calib, heldout, seed, n_calib_seeds, n_seeds, channels, bands):
        self.fit, self.simulate = fit, simulate
        self.calib, self.heldout = list(calib), list(heldout)
        self.seed = seed
        self.n_calib_seeds, self.n_seeds = n_calib_seeds, n_seeds
        self.ref_calib = reference(self.calib, channels, bands)
        self.ref_held = reference(self.heldout, self.ref_calib.channels, self.ref_calib.bands)

    def sims(self, state, windows, stream, i):
        return [self.simulate(state, w, seed_int(self.seed, (stream, i, j))) for j, w in enumerate(windows)]

    def calib_gap(self, effects) -> float:
        state = self.fit(effects, self.calib)
        return float(np.mean([band_gap(self.sims(state, self.calib, 0, i), self.ref_calib).value
                              for i in range(self.n_calib_seeds)]))

    def heldout_gaps(self, effects) -> list[Gap]:
        state = self.fit(effects, self.heldout)
        return [band_gap(self.sims(state, self.heldout, 1, i), self.ref_held)
                for i in range(self.n_seeds)]

    def score(self, cands, grid, refine, start=None):
        cal = calibrate(cands, self.calib_gap, grid=grid, refine=refine, start=start)
        return cal, self.heldout_gaps(cal.effects)



def _score_task(args):
    scorer, cands, grid, refine, start = args
    return scorer.score(cands, grid, refine, start)


def _nanmean(rows) -> np.ndarray:
    """Column mean ignoring NaN, NaN where a column has no value (no warning)."""
    a = np.asarray(rows, dtype=float)
    ok = np.isfinite(a)
    n = ok.sum(axis=0)
    return np.where(n > 0, np.where(ok, a, 0.0).sum(axis=0) / np.maximum(n, 1), np.nan)


def _entry(cands, cal, gaps, before, k) -> Entry:
    return Entry("+".join(c.name for c in cands), cal.effects, k, cal.calib_gap, before,
                 np.array([g.value for g in gaps]),
                 np.zeros(0), _nanmean([g.per_band for g in gaps]),
                 gaps[0].n_cells, cal.n_evals)


def rank_effects(candidates: Sequence[Candidate], fit: Callable, simulate: Callable,
                 calib: Sequence, heldout: Sequence, *, seed: int = 0, n_seeds: int = 5,
                 n_calib_seeds: int = 1, n_null: int | None = None, pairs: bool = True,
                 n_pair_candidates: int = 3, channels: Sequence[str] | None = None,
                 bands: np.ndarray | None = None, z: float = 2.0, grid: int = 5, refine: int = 8,
                 executor=None, progress: Callable[[str], None] | None = None) -> Ranking:
    """Rank candidate effects by held-out gap, penalised for parameters; never force a verdict.

    Parameters
    ----------
    candidates : sequence of Candidate
    fit : callable ``(effects, data) -> state``
        See module docstring.
    simulate : callable ``(state, window, seed) -> signals``
        See module docstring.
    calib, heldout : sequence of measured windows (Signals-like, or objects ``fit`` and
        ``simulate`` understand that ``as_signals`` can read)
        Disjoint in time (other segments or windows).
    seed : int
        Root seed of all road-phase seeds.
    n_seeds : int
        Road-phase seeds for held-out scores (spread of the shrink fraction).
    n_calib_seeds : int
        Seeds averaged in the calibration objective.
    n_null : int, optional
        Nominal-vs-nominal pairs for the noise reference (default ``max(n_seeds, 8)``,
        at least 3); each costs one extra simulation per held-out window.
    pairs : bool
        Try pairs of the best single candidates.
    n_pair_candidates : int
        Singles (with positive improvement) considered for pairs.
    channels : sequence of str, optional
        Channels scored (default: those of the first calibration window).
    bands : (nb, 3) array, Hz, optional
    z : float
        Noise gate in standard deviations of the nominal-vs-nominal gap.
    grid, refine : int
        Search budget (see :func:`calibrate`).
    executor : concurrent.futures.Executor, optional
        Candidates are calibrated in parallel with ``executor.map``.
    progress : callable str -> None, optional

    Returns
    -------
    Ranking
    """
    say = progress or (lambda msg: None)
    if not candidates:
        raise EroadInputError("rank_effects: no candidate effect")
    if not calib or not heldout:
        raise EroadInputError("rank_effects: need calibration and held-out windows")
    n_null = max(3, max(n_seeds, 8) if n_null is None else n_null)
    sc = _Scorer(fit, simulate, calib, heldout, seed, n_calib_seeds, n_seeds, channels, bands)

    say("nominal model on held-out data")
    state0 = fit({}, sc.heldout)
    nominal_sims = [sc.sims(state0, sc.heldout, 1, i) for i in range(max(n_seeds, n_null))]
    g0 = [band_gap(nominal_sims[i], sc.ref_held) for i in range(n_seeds)]
    before = np.array([g.value for g in g0])
    null = []
    for i in range(n_null):
        surrogate = reference(sc.sims(state0, sc.heldout, 2, i), sc.ref_held.channels, sc.ref_held.bands)
        null.append(band_gap(nominal_sims[i], surrogate).value)
    null = NullReference(np.array(null))
    sd0 = null.std
    gap_present = bool(before.mean() > null.mean + z * sd0)
    n_cells = g0[0].n_cells
    floor = float(np.mean([g.floor for g in g0]))
    pb_before = _nanmean([g.per_band for g in g0])

    def finish(e: Entry) -> Entry:
        dbic = n_cells * math.log(e.heldout_gap_after / e.heldout_gap_before) + e.k * math.log(n_cells)
        bn = e.improvement > z * sd0
        return Entry(e.effect, e.effects, e.k, e.calib_gap, e.before, e.after, pb_before,
                     e.per_band_after, e.n_cells, e.n_evals, float(dbic), bool(bn),
                     bool(gap_present and bn and dbic < 0), floor)

    say(f"calibrating {len(candidates)} candidates")
    tasks = [(sc, [c], grid, refine, None) for c in candidates]
    mapper = executor.map if executor is not None else map
    singles = []
    for c, (cal, gaps) in zip(candidates, mapper(_score_task, tasks)):
        singles.append(finish(_entry([c], cal, gaps, before, c.k)))
        say(f"  {c.name}: held-out gap {singles[-1].heldout_gap_after:.4g} "
            f"(nominal {before.mean():.4g})")
    entries = list(singles)

    if pairs and len(candidates) > 1:
        good = sorted([(e, c) for e, c in zip(singles, candidates) if e.improvement > 0],
                      key=lambda t: -t[0].improvement)[:n_pair_candidates]
        best_single = min(singles, key=lambda e: e.delta_bic)
        ptasks, pc = [], []
        for (ea, ca), (eb, cb) in combinations(good, 2):
            ua = [_unit(p, ea.effects[ca.name][p.name]) for p in ca.params]
            ub = [_unit(p, eb.effects[cb.name][p.name]) for p in cb.params]
            ptasks.append((sc, [ca, cb], grid, refine, ua + ub))
            pc.append((ca, cb))
        if ptasks:
            say(f"trying {len(ptasks)} pairs")
        for (ca, cb), (cal, gaps) in zip(pc, mapper(_score_task, ptasks)):
            e = finish(_entry([ca, cb], cal, gaps, before, ca.k + cb.k))
            better = (best_single.heldout_gap_after - e.heldout_gap_after > z * sd0
                      and e.delta_bic < best_single.delta_bic)
            if not better:
                e = Entry(e.effect, e.effects, e.k, e.calib_gap, e.before, e.after, e.per_band_before,
                          e.per_band_after, e.n_cells, e.n_evals, e.delta_bic, e.beyond_noise, False,
                          e.floor)
            entries.append(e)

    entries.sort(key=lambda e: (not e.accepted, e.delta_bic))
    win = entries[0] if entries[0].accepted else None
    if not gap_present:
        verdict, conf = "none", "none"
        reason = (f"the nominal held-out gap {before.mean():.3g} is within noise "
                  f"(nominal-vs-nominal {null.mean:.3g} +- {sd0:.2g})")
    elif win is None:
        verdict, conf = "none", "none"
        reason = (f"no candidate reduces the held-out gap by more than {z:g} x {sd0:.2g} "
                  f"with a lower BIC")
    else:
        verdict = win.effect
        names = set(verdict.split("+"))
        rivals = [e for e in entries if not names & set(e.effect.split("+"))]
        close = [e for e in rivals if e.heldout_gap_after - win.heldout_gap_after < sd0]
        conf = "ambiguous" if close else "clear"
        reason = (f"{verdict} shrinks the held-out gap from {win.heldout_gap_before:.3g} to "
                  f"{win.heldout_gap_after:.3g} (noise sd {sd0:.2g})"
                  + (f"; {', '.join(e.effect for e in close)} comes close" if close else ""))
    settings = dict(seed=seed, n_seeds=n_seeds, n_calib_seeds=n_calib_seeds, n_null=n_null, z=z,
                    grid=grid, refine=refine, pairs=pairs, channels=sc.ref_held.channels,
                    n_calib_windows=len(sc.calib), n_heldout_windows=len(sc.heldout))
    return Ranking(entries, before, pb_before, floor, _nanmean([g.per_band_floor for g in g0]), null,
                   gap_present, verdict, conf, reason, sc.ref_held.bands, settings)


def _unit(p: Param, x: float) -> float:
    if p.log:
        return (math.log(x) - math.log(p.lo)) / (math.log(p.hi) - math.log(p.lo))
    return (x - p.lo) / (p.hi - p.lo)
