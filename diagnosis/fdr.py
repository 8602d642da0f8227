"""Multiple testing over the many cells of a diagnosis: Benjamini-Hochberg and FCR intervals.

What it is for: deciding which of hundreds of channel x band x segment cells are
flagged, so that a model that is right flags (almost) nothing.

Choice: the Benjamini-Hochberg (1995) false-discovery-rate procedure at level ``q``
(default 0.05) over all estimable cells of one table.  Under the global null
(a correct model) BH controls the family-wise error too: with probability
``>= 1 - q`` nothing is flagged.  Where there is a real gap it flags far more
cells than Bonferroni would, at the price of up to a fraction ``q`` of the flagged
cells being false.  BH is valid for independent and positively dependent tests;
neighbouring bands and the left and right channels are positively correlated, which
is the case covered by Benjamini and Yekutieli (2001).

Intervals consistent with the flags are the false-coverage-rate adjusted intervals
of Benjamini and Yekutieli (2005): when ``R`` of ``m`` cells are flagged, each
interval is built at level ``1 - q R / m``; a flagged cell's interval then excludes
zero, an unflagged one contains it, and the expected fraction of flagged cells whose
interval misses the true value is at most ``q``.  With no flag, the level is the
Bonferroni level ``1 - q / m``.

What it is not: a test by itself; callers supply p-values and interval makers.
"""
from __future__ import annotations

import numpy as np

__all__ = ["benjamini_hochberg", "fcr_level"]


def benjamini_hochberg(p: np.ndarray, q: float = 0.05) -> np.ndarray:
    """Benjamini-Hochberg step-up procedure.

    Parameters
    ----------
    p : array
        p-values; NaN entries (untestable cells) are ignored and never rejected.
    q : float
        False discovery rate.

    Returns
    -------
    bool array, same shape as ``p``
        True where the null hypothesis is rejected (cell flagged).
    """
    p = np.asarray(p, dtype=float)
    flat = p.ravel()
    ok = np.flatnonzero(np.isfinite(flat))
    out = np.zeros(flat.shape, dtype=bool)
    m = ok.size
    if m == 0:
        return out.reshape(p.shape)
    order = ok[np.argsort(flat[ok], kind="stable")]
    thresh = q * np.arange(1, m + 1) / m
    below = np.flatnonzero(flat[order] <= thresh)
    if below.size:
        out[order[: below[-1] + 1]] = True
    return out.reshape(p.shape)


def fcr_level(n_rejected: int, n_tests: int, q: float = 0.05) -> float:
    """Confidence level of FCR-adjusted intervals, ``1 - q * max(R, 1) / m``.

    Parameters
    ----------
    n_rejected : int
        Cells flagged by :func:`benjamini_hochberg` (``R``).
    n_tests : int
        Cells tested (``m``).
    q : float
        False discovery / coverage rate.
    """
    if n_tests <= 0:
        return 1.0 - q
    return 1.0 - q * max(n_rejected, 1) / n_tests
