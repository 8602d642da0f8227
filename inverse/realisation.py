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
"""
from __future__ import annotations

import math

import numpy as np

from inverse.validation import response_table

#: spawn key prefix of the candidate phase seeds
SEED_KEY_CANDIDATES = (5, 3)

#: default channels of the selection statistic: Table 2 (axle 3, both sides) RMS
#: of the acceleration and of the suspension displacement
SELECT_CHANNELS = ("axle_acc_3L", "axle_acc_3R", "susp_disp_3L", "susp_disp_3R")


def candidate_seeds(root: int, m: int) -> list:
    """The M candidate phase seeds of a root seed (documented stream ``(5, 3, i)``)."""
    from inverse.pipeline import stream_seed

    return [stream_seed(root, SEED_KEY_CANDIDATES + (i,)) for i in range(int(m))]


#: weight of each channel's terms in the statistic: Table 2 is about acceleration;
#: the displacement keeps the choice from a realisation with a wrong travel
SELECT_WEIGHTS = {"axle_acc_3L": 1.0, "axle_acc_3R": 1.0, "susp_disp_3L": 0.25, "susp_disp_3R": 0.25}


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
    weights = SELECT_WEIGHTS if weights is None else weights
    total = 0.0
    for c in channels:
        if c not in measured or c not in simulated:
            continue
        m = np.asarray(measured[c], float)
        s = np.asarray(simulated[c], float)
        term = math.log(np.std(s) / np.std(m)) ** 2
        if use_mean_abs and "_acc_" in c:
            term += math.log(np.mean(np.abs(s - s.mean())) / np.mean(np.abs(m - m.mean()))) ** 2
        total += weights.get(c, 1.0) * term
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
        median, 16th and 84th percentile of mean_abs_err as ``mean_abs_*``).
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
    i = int(np.argmin([c["mismatch"] for c in cands]))
    out = {"index": i, "seed": seeds[i], "label": labels[i], "simulated": sims[i], "candidates": cands,
           "spread": spread, "sides": False}
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
