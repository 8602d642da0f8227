"""Realisation selection: which random-phase road of the fitted spectra to keep.

What this module is for: after the spectral fit, the identified road is a
SPECTRUM; a road surface needs phases too.  One realisation's 30 s response RMS
scatters from realisation to realisation by about 3% (axle acceleration) to
9-11% (body acceleration, suspension displacement) -- far more than the
Table 2 target of 2%.  So M candidate phase seeds are drawn, the nominal model
is run on each, and the seed whose Table 2 statistics (RMS of the selected
channels, left and right) are nearest the measurement is kept as the global
road.  Both the selected realisation's errors AND the median and spread over all
candidates are reported: the spread is the statistical floor of a random-phase
road, the selection only picks a member of it that matches a few numbers
(docs/inverse.md, section 8).  What it is not: the fit (the selection never
changes the spectral parameters).

Seeds: candidate i uses ``SeedSequence(root, spawn_key=(5, 3, i))``
(``inverse.pipeline.stream_seed``); the fit's own phases ``(5, 1)`` are
candidate "fit".

Two ways to score the candidates: :func:`select_realisation` simulates every one in
time; :func:`select_realisation_linear` (what ``eroad invert`` runs by default) scores
them with the linear truck's time response (:mod:`inverse.linear_response`), corrected
by the mean log ratio simulation / linear of the candidates it does simulate, and
simulates only the fit's realisation and the most promising ones until the best
candidate is a simulated one (docs/inverse.md, section 12).
"""
from __future__ import annotations

import math

import numpy as np

from inverse.validation import response_table

#: spawn key prefix of the candidate phase seeds
SEED_KEY_CANDIDATES = (5, 3)

def select_channels(axle: int = 3) -> tuple:
    """Channels of the selection statistic: Table 2's axle (axle 3, or the reference axle of
    a drive logged elsewhere), both sides, RMS of the acceleration and of the suspension
    displacement."""
    return (f"axle_acc_{axle}L", f"axle_acc_{axle}R", f"susp_disp_{axle}L", f"susp_disp_{axle}R")


#: default channels of the selection statistic (axle 3)
SELECT_CHANNELS = select_channels(3)


def candidate_seeds(root: int, m: int) -> list:
    """The M candidate phase seeds of a root seed (documented stream ``(5, 3, i)``)."""
    from inverse.pipeline import stream_seed

    return [stream_seed(root, SEED_KEY_CANDIDATES + (i,)) for i in range(int(m))]


#: weight of each channel kind's terms in the statistic: Table 2 is about acceleration;
#: the displacement keeps the choice from a realisation with a wrong travel
SELECT_WEIGHT_DISP = 0.25


def channel_weight(channel: str) -> float:
    """The selection statistic's weight of one channel: :data:`SELECT_WEIGHT_DISP` for a
    suspension displacement, 1 otherwise."""
    return SELECT_WEIGHT_DISP if channel.startswith("susp_disp_") else 1.0


def select_weights(axle: int = 3) -> dict:
    """Channel -> weight of the selection statistic for :func:`select_channels` ``(axle)``."""
    return {c: channel_weight(c) for c in select_channels(axle)}


#: the weights of axle 3's statistic
SELECT_WEIGHTS = select_weights(3)


def mismatch(measured: dict, simulated: dict, channels=SELECT_CHANNELS, use_mean_abs: bool = True,
             weights=None) -> float:
    """Selection statistic: weighted sum of squared log ratios, simulated to measured.

    Parameters
    ----------
    measured, simulated : dict
        Channel -> (N,) array.
    channels : sequence of str
        Channels present in both are used.
    use_mean_abs : bool
        Also the rectified mean (Table 2's "mean") of the acceleration channels.
    weights : dict, optional
        Channel -> weight (default :data:`SELECT_WEIGHTS`, 1 for others).

    Returns
    -------
    float
        sum_c w_c [ln(rms_sim / rms_meas)^2 (+ ln(mean_abs_sim / mean_abs_meas)^2 for
        ``*_acc_*`` channels)] [-].
    """
    from inverse.linear_response import channel_stats

    use = [c for c in channels if c in measured and c in simulated]
    return mismatch_stats(channel_stats(measured, use), channel_stats(simulated, use), use,
                          use_mean_abs=use_mean_abs, weights=weights)


def mismatch_stats(measured: dict, simulated: dict, channels=SELECT_CHANNELS, use_mean_abs: bool = True,
                   weights=None) -> float:
    """:func:`mismatch` from per-channel statistics (``inverse.linear_response.channel_stats``:
    channel -> {"rms", "mean_abs"}) instead of signals; same value."""
    total = 0.0
    for c in channels:
        if c not in measured or c not in simulated:
            continue
        m, s = measured[c], simulated[c]
        term = math.log(s["rms"] / m["rms"]) ** 2
        if use_mean_abs and "_acc_" in c:
            term += math.log(s["mean_abs"] / m["mean_abs"]) ** 2
        w = weights.get(c, 1.0) if weights is not None else channel_weight(c)
        total += w * term
    return float(total)


class _Run:
    """Picklable (simulate, params) -> simulated channels for one seed."""

    def __init__(self, simulate, params):
        self.simulate, self.params = simulate, np.asarray(params, float)

    def __call__(self, seed):
        return self.simulate(self.params, int(seed))


def _side(channels, side: str) -> list:
    return [c for c in channels if c.endswith(side)]


def select_realisation(simulate, params, measured: dict, seeds, *, channels=SELECT_CHANNELS,
                       table_channels=None, map_fn=map, labels=None, sides: bool = True) -> dict:
    """Simulate every candidate seed and keep the realisation nearest the measured statistics.

    Parameters
    ----------
    simulate : callable
        Simulator contract of :mod:`inverse.sensitivity`; with ``sides`` it must
        also accept ``seed = (seed_left, seed_right)`` (``inverse.truck``).
    params : (K, 4) array
        Fitted parameters.
    measured : dict
        Channel -> (N,) array.
    seeds : sequence of int
        Candidate phase seeds.
    channels : sequence of str
        Channels of the selection statistic (:func:`mismatch`).
    table_channels : sequence of str, optional
        Channels of the reported per-candidate Table 2 errors (default ``channels``).
    map_fn : callable
        ``map_fn(func, seeds)``, e.g. a process pool's ``map``.
    labels : sequence of str, optional
        Names of the candidates (default the seeds).
    sides : bool
        Choose the left track's seed by the left channels' statistic and the
        right track's by the right ones (one more simulation on the joined
        road); otherwise one seed by the whole statistic.

    Returns
    -------
    dict
        ``seed`` (int, or [left, right]), ``label``, ``simulated`` (channels of
        the selected road), ``candidates`` (per candidate: seed, label, mismatch,
        mismatch_L, mismatch_R, rms_err and mean_abs_err per table channel),
        ``spread`` (per table channel: median, 16th and 84th percentile, median
        and largest |error| of rms_err over the candidates -- the statistical
        floor of one random-phase realisation -- their number ``n``, and the
        median, 16th and 84th percentile of mean_abs_err as ``mean_abs_*``),
        ``simulated_all`` (every candidate's channels, in the order of ``seeds``).
    """
    seeds = [int(s) for s in seeds]
    labels = [str(s) for s in seeds] if labels is None else [str(x) for x in labels]
    table_channels = list(table_channels or channels)
    sims = list(map_fn(_Run(simulate, params), seeds))
    cands = []
    for s, lab, sim in zip(seeds, labels, sims):
        rows = {r["channel"]: r for r in response_table(measured, sim, [c for c in table_channels
                                                                     if c in measured and c in sim])}
        cands.append({"seed": s, "label": lab, "mismatch": mismatch(measured, sim, channels),
                      "mismatch_L": mismatch(measured, sim, _side(channels, "L")),
                      "mismatch_R": mismatch(measured, sim, _side(channels, "R")),
                      "rms_err": {c: r["rms_err"] for c, r in rows.items()},
                      "mean_abs_err": {c: r["mean_abs_err"] for c, r in rows.items()}})
    spread = candidate_spread(cands, table_channels)
    i = int(np.argmin([c["mismatch"] for c in cands]))
    out = {"index": i, "seed": seeds[i], "label": labels[i], "simulated": sims[i], "candidates": cands,
           "spread": spread, "sides": False, "simulated_all": sims}
    if sides:
        il = int(np.argmin([c["mismatch_L"] for c in cands]))
        ir = int(np.argmin([c["mismatch_R"] for c in cands]))
        if il != ir:
            pair = (seeds[il], seeds[ir])
            sim = simulate(np.asarray(params, float), pair)
            if mismatch(measured, sim, channels) < cands[i]["mismatch"]:
                out.update(seed=list(pair), label=f"{labels[il]}|{labels[ir]}", simulated=sim, sides=True,
                           index=[il, ir])
            else:  # roll coupling spoilt the pair: keep the best single realisation
                out["sides_rejected"] = {"seed": list(pair), "mismatch": mismatch(measured, sim, channels)}
    out["mismatch"] = mismatch(measured, out["simulated"], channels)
    return out


def candidate_spread(cands: list, table_channels) -> dict:
    """Per table channel: median, 16th and 84th percentile, largest and median |error| of the
    candidates' ``rms_err``, their number ``n``, and the same percentiles of ``mean_abs_err``
    as ``mean_abs_*`` (the statistical floor of one random-phase realisation)."""
    spread = {}
    for c in table_channels:
        e = np.array([cd["rms_err"][c] for cd in cands if c in cd["rms_err"]])
        if e.size:
            a = np.array([cd["mean_abs_err"][c] for cd in cands if c in cd["mean_abs_err"]])
            spread[c] = {"median": float(np.median(e)), "p16": float(np.percentile(e, 16)),
                         "p84": float(np.percentile(e, 84)), "max_abs": float(np.max(np.abs(e))),
                         "median_abs": float(np.median(np.abs(e))), "n": int(e.size),
                         "mean_abs_median": float(np.median(a)), "mean_abs_p16": float(np.percentile(a, 16)),
                         "mean_abs_p84": float(np.percentile(a, 84))}
    return spread


#: most rounds of time simulations of :func:`select_realisation_linear` after the first
#: (the fit's realisation): the loop normally ends after one (docs/inverse.md, section 12)
MAX_SIM_ROUNDS = 4


class _Task:
    """Picklable ``("sim" | "lin", seed) -> channels`` for one pool map over mixed tasks."""

    def __init__(self, simulate, linear, params):
        self.simulate, self.linear, self.params = simulate, linear, np.asarray(params, float)

    def __call__(self, item):
        kind, seed = item
        f = self.simulate if kind == "sim" else self.linear
        return f(self.params, int(seed))


def select_realisation_linear(simulate, linear, params, measured: dict, seeds, *, channels=SELECT_CHANNELS,
                              table_channels=None, map_fn=map, labels=None, fit_index: int = 0,
                              per_round: int = 2, max_rounds: int = MAX_SIM_ROUNDS) -> dict:
    """Rank the candidates by the linear truck's responses, simulate only the promising ones.

    1. One map over ``("sim", fit seed)`` and ``("lin", seed)`` for every candidate
       (the fit's included): the fit's realisation in time, every candidate's linear
       time response (:class:`inverse.linear_response.LinearRealisation`).
    2. Per channel c and statistic k (RMS, rectified mean) the correction
       ``d_ck = mean over the simulated candidates of ln(k_sim / k_lin)``; a candidate's
       statistics are its simulated ones where it was simulated, its linear ones times
       ``exp(d_ck)`` otherwise; each is scored by :func:`mismatch_stats`.
    3. While the best-scored candidate is not a simulated one, simulate the
       ``per_round`` best unsimulated candidates (one round; 2 = one per worker of a
       two-process pool, the same wall time as one), update ``d`` and rescore; at most
       ``max_rounds`` rounds, then the best simulated candidate is kept.

    The kept realisation is thus a simulated one whose statistic is no worse than the
    corrected prediction of any candidate not simulated.  Table 2's spread is over all
    candidates on that mixed basis (each candidate's ``basis`` says which).

    Parameters
    ----------
    simulate : callable
        Time simulator, ``(params, seed) -> channels``.
    linear : callable
        Linear responses, same contract (``LinearRealisation``).
    params : (K, 4) array
    measured : dict
        Channel -> (N,) array.
    seeds : sequence of int
        Candidate seeds; ``seeds[fit_index]`` is the fit's own (always simulated).
    channels, table_channels, labels
        As :func:`select_realisation`.
    map_fn : callable
        ``map_fn(func, items)``, e.g. a process pool's ``map``.
    per_round : int
        Candidates simulated per round (>= 1).
    max_rounds : int

    Returns
    -------
    dict
        As :func:`select_realisation` (``sides`` False), plus ``fit_simulated`` (the
        fit's realisation's channels), ``correction`` (per channel ``rms`` and
        ``mean_abs``: d, its standard deviation over the simulated candidates, and
        their number ``n``), ``n_simulated``, ``rounds`` and per candidate ``basis``
        (``simulated`` / ``linear_corrected``), ``simulated`` (bool),
        ``mismatch_linear`` (the corrected linear statistic's score, every candidate)
        and ``rms_err_linear`` (the corrected linear RMS errors).
    """
    from inverse.linear_response import channel_stats

    seeds = [int(s) for s in seeds]
    labels = [str(s) for s in seeds] if labels is None else [str(x) for x in labels]
    table_channels = list(table_channels or channels)
    stat_ch = [c for c in dict.fromkeys(list(channels) + table_channels) if c in measured]
    meas = channel_stats(measured, stat_ch)
    task = _Task(simulate, linear, params)
    items = [("sim", seeds[fit_index])] + [("lin", s) for s in seeds]
    res = list(map_fn(task, items))
    sims = {fit_index: res[0]}
    lin = [channel_stats(r, stat_ch) for r in res[1:]]
    sim_stats = {fit_index: channel_stats(res[0], stat_ch)}
    per_round = max(1, int(per_round))

    def correction():
        d = {}
        for c in stat_ch:
            d[c] = {}
            for k in ("rms", "mean_abs"):
                r = np.array([math.log(sim_stats[i][c][k] / lin[i][c][k]) for i in sim_stats])
                d[c][k] = float(r.mean())
                d[c][f"{k}_sd"] = float(r.std(ddof=1)) if r.size > 1 else float("nan")
            d[c]["n"] = len(sim_stats)
        return d

    def corrected(i, d):
        return {c: {k: lin[i][c][k] * math.exp(d[c][k]) for k in ("rms", "mean_abs")} for c in stat_ch}

    rounds = 0
    while True:
        d = correction()
        pred = [corrected(i, d) for i in range(len(seeds))]
        score_lin = [mismatch_stats(meas, p, channels) for p in pred]
        score = [mismatch_stats(meas, sim_stats[i], channels) if i in sim_stats else score_lin[i]
                 for i in range(len(seeds))]
        best = int(np.argmin(score))
        if best in sim_stats:
            break
        if rounds >= max_rounds:
            best = min(sim_stats, key=lambda i: score[i])
            break
        todo = [i for i in np.argsort(score) if i not in sim_stats][:per_round]
        for i, r in zip(todo, map_fn(task, [("sim", seeds[i]) for i in todo])):
            sims[int(i)] = r
            sim_stats[int(i)] = channel_stats(r, stat_ch)
        rounds += 1

    cands = []
    for i, (s, lab) in enumerate(zip(seeds, labels)):
        st = sim_stats.get(i, pred[i])
        tc = [c for c in table_channels if c in meas]
        cands.append({"seed": s, "label": lab, "mismatch": score[i],
                      "mismatch_L": mismatch_stats(meas, st, _side(channels, "L")),
                      "mismatch_R": mismatch_stats(meas, st, _side(channels, "R")),
                      "rms_err": {c: st[c]["rms"] / meas[c]["rms"] - 1.0 for c in tc},
                      "mean_abs_err": {c: st[c]["mean_abs"] / meas[c]["mean_abs"] - 1.0 for c in tc},
                      "basis": "simulated" if i in sim_stats else "linear_corrected",
                      "simulated": i in sim_stats, "mismatch_linear": score_lin[i],
                      "rms_err_linear": {c: pred[i][c]["rms"] / meas[c]["rms"] - 1.0 for c in tc}})
    return {"index": best, "seed": seeds[best], "label": labels[best], "simulated": sims[best],
            "fit_simulated": sims[fit_index], "candidates": cands,
            "spread": candidate_spread(cands, table_channels), "sides": False,
            "mismatch": score[best], "correction": d, "n_simulated": len(sim_stats), "rounds": rounds,
            "method": "linear"}
