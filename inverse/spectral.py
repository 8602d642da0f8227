"""Spectral road parameters as the inverse fit sees them: layout, bounds, classes, grid.

What it is for: one place that says how the per-segment road parameters are laid
out in arrays, how they map to the fit's log-parameters, which bounds the fit
respects, which ISO 8608 class a level belongs to, and which road grid (dx, dy) a
fitted band implies.  What it is not: a road generator (``roadlib.synthesis``) or
the PSD library (``roadlib.psd``).

Layout
------
Physical parameters of K segments are an array ``params`` of shape (K, 4) with
columns ``PARAM_NAMES = ("Gq_n0", "w", "nmin", "nmax")``:

* ``Gq_n0`` [m^3]   one-sided displacement PSD at n0 = 0.1 cycles/m (ISO 8608),
* ``w`` [-]         waviness, Gd(n) = Gq_n0 (n / n0)^-w,
* ``nmin`` [cycles/m], ``nmax`` [cycles/m]  band of the harmonic synthesis.

The fit works in ``theta`` (same shape) with columns
``THETA_NAMES = ("ln_Gq_n0", "w", "ln_nmin", "ln_nmax")``: level and band edges in
natural logarithms (a factor, not a difference, is what the data resolve), ``w``
as is.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eroad.errors import EroadInputError
from roadlib.psd import ISO_CLASSES, N0, class_of  # N0 re-exported for inverse.*

#: column names of a (K, 4) physical parameter array
PARAM_NAMES = ("Gq_n0", "w", "nmin", "nmax")
#: units of the physical parameters
PARAM_UNITS = ("m^3", "-", "cycles/m", "cycles/m")
#: column names of the fit's (K, 4) log-parameter array
THETA_NAMES = ("ln_Gq_n0", "w", "ln_nmin", "ln_nmax")

#: ISO 8608 road classes: geometric mean of Gd(n0) [m^3] (Table 1 of the standard;
#: class A 16e-6 m^3, each class a factor 4 above the previous one; the class
#: bounds lie a factor 2 either side), from ``roadlib.psd.ISO_CLASSES``.
ISO_CLASS_GD0 = {c: v.gd0 for c, v in ISO_CLASSES.items()}


def iso_class(Gq_n0: float) -> str:
    """ISO 8608 class of a displacement PSD level.

    Parameters
    ----------
    Gq_n0 : float
        Gd(n0) [m^3], one-sided, n0 = 0.1 cycles/m.

    Returns
    -------
    str
        'A' ... 'H': the class whose bounds (a factor 2 either side of its
        geometric mean) contain ``Gq_n0``, i.e. the class nearest in log
        (``roadlib.psd.class_of``; A open downwards, H upwards).
    """
    if not (Gq_n0 > 0 and math.isfinite(Gq_n0)):
        raise EroadInputError(f"iso_class: Gq_n0 must be a positive number, got {Gq_n0!r}")
    return class_of(Gq_n0)


def params_to_theta(params) -> np.ndarray:
    """Physical (K, 4) parameters [Gq_n0 m^3, w, nmin, nmax cycles/m] -> fit's theta.

    Parameters
    ----------
    params : array_like, shape (K, 4) or (4,)

    Returns
    -------
    ndarray, shape (K, 4)
        Columns ln Gq_n0 [ln m^3], w [-], ln nmin, ln nmax [ln cycles/m].
    """
    p = np.atleast_2d(np.asarray(params, dtype=float))
    if p.shape[1] != 4:
        raise EroadInputError(f"params must have 4 columns {PARAM_NAMES}, got shape {p.shape}")
    if np.any(p[:, [0, 2, 3]] <= 0):
        raise EroadInputError("params: Gq_n0, nmin and nmax must be positive")
    th = p.copy()
    th[:, [0, 2, 3]] = np.log(p[:, [0, 2, 3]])
    return th


def theta_to_params(theta) -> np.ndarray:
    """Inverse of :func:`params_to_theta`; returns a new (K, 4) array."""
    th = np.atleast_2d(np.asarray(theta, dtype=float))
    p = th.copy()
    p[:, [0, 2, 3]] = np.exp(th[:, [0, 2, 3]])
    return p


@dataclass(frozen=True)
class ParamBounds:
    """Bounds of the per-segment fit, from the road classes and from physics.

    Parameters
    ----------
    Gq_n0 : (float, float)
        [m^3].  Default 1e-6 to 4.096e-3: from well below class A to class E's
        MEAN (ISO 8608 as ``roadlib.psd.ISO_CLASSES``: E spans 2.048e-3 to
        8.192e-3).  This line said "to the upper bound of class F" until 2026-11-30;
        the bound never was.  A road in the upper half of class E is fitted on the
        bound (reported "ON A BOUND"); its class stays E, its Gq(n0) reads low and
        w compensates.  Raising the bound to F's top was tested and not adopted: it
        brought ln Gq(n0) on such segments from 0.42 to 0.14 (median abs error) but
        the freed fits report intervals too narrow for them and the stated bar failed
        (results/inverse_blind/20261130-gq-upper-bound/).
    w : (float, float)
        [-].  Default 1.5 to 3.5, the range published measurements of real road
        profiles span (the previous 1.2-3.0 had no source, and a measured profile
        driven by the independent truck put w on the 3.0 bound in 3 of 4 segments):

        * Mitschke / Wallentowitz, "Dynamik der Kraftfahrzeuge" (Springer), as
          quoted by the euromotor vehicle-dynamics course notes (slides 8,
          https://www.euromotor.org/, section 1.2, eq (1.2-19)): the waviness of
          measured road spectra "varies depending on road design between 1.7 and
          3.3" (ISO/standardised road: w = 2).  SECONDARY: the book itself was not
          read; the quotation is the course's.
        * Mucka, P. and Kropac, O., "Sensitivity of road unevenness indicators to
          road waviness", J. Testing and Evaluation 37(2), 2009 (ASTM JTE102005),
          abstract: waviness "varied in the range from w = 1.5 to 3.5" as the span
          of real roads their study covers.  (Kropac and Mucka, Int. J. Vehicle
          Design 36(2/3), 2004, 149-172, treat waviness that differs between
          wavelength bands -- the two-slope form of ``roadlib.psd.two_slope_psd``.)
        * Andren, P., "Power spectral density approximations of longitudinal road
          profiles", Int. J. Vehicle Design 40, 2006 (DOI 10.1504/IJVD.2006.008450):
          a survey of one- and two-slope PSD fits tested on the whole Swedish state
          road network; only its abstract was available here, so no number is
          quoted from it.

        The bound is the union 1.5-3.5 of the two ranges (1.7-3.3 lies inside).
        Outside it the "road" is a different kind of object (a ramp, white noise).
        A two-slope road (``inverse.road_model``) uses the same range for each of
        its two exponents.
    nmin : (float, float)
        [cycles/m].  Default 0.005 (200 m wavelength) to 0.2 (5 m).
    nmax : (float, float)
        [cycles/m].  Default 1 (1 m wavelength) to 10 (0.1 m, about a tyre contact
        length); :meth:`for_record` lowers the top to the temporal Nyquist limit.
    min_ratio : float
        Smallest nmax / nmin [-]; default 5, so the band is never empty.
    """

    Gq_n0: tuple = (1e-6, 4.096e-3)
    w: tuple = (1.5, 3.5)
    nmin: tuple = (0.005, 0.2)
    nmax: tuple = (1.0, 10.0)
    min_ratio: float = 5.0

    def __post_init__(self):
        for name in PARAM_NAMES:
            lo, hi = getattr(self, name)
            if not (lo < hi):
                raise EroadInputError(f"ParamBounds.{name}: lower {lo} must be below upper {hi}")
        if self.Gq_n0[0] <= 0 or self.nmin[0] <= 0 or self.nmax[0] <= 0:
            raise EroadInputError("ParamBounds: Gq_n0, nmin and nmax bounds must be positive")
        if self.min_ratio <= 1:
            raise EroadInputError("ParamBounds.min_ratio must exceed 1")
        if self.nmax[1] / self.nmin[0] < self.min_ratio:
            raise EroadInputError("ParamBounds: nmax upper / nmin lower is below min_ratio")

    def for_record(self, fs: float, v_max: float) -> "ParamBounds":
        """Bounds with nmax capped at the temporal Nyquist limit fs / (2 v_max).

        Parameters
        ----------
        fs : float
            Sample rate of the measured record [Hz].
        v_max : float
            Highest speed in the record [m/s].

        Returns
        -------
        ParamBounds
            Road content above fs / (2 v_max) [cycles/m] would alias in the
            measurement, so the data cannot speak for it.
        """
        cap = fs / (2.0 * v_max)
        hi = min(self.nmax[1], cap)
        lo = min(self.nmax[0], 0.5 * hi)
        return ParamBounds(self.Gq_n0, self.w, self.nmin, (lo, hi), self.min_ratio)

    def theta_lower(self) -> np.ndarray:
        """Lower bounds of theta, shape (4,)."""
        return np.array([math.log(self.Gq_n0[0]), self.w[0],
                         math.log(self.nmin[0]), math.log(self.nmax[0])])

    def theta_upper(self) -> np.ndarray:
        """Upper bounds of theta, shape (4,)."""
        return np.array([math.log(self.Gq_n0[1]), self.w[1],
                         math.log(self.nmin[1]), math.log(self.nmax[1])])

    def clip_theta(self, theta) -> np.ndarray:
        """Project theta (K, 4) into the bounds, including nmax / nmin >= min_ratio."""
        th = np.clip(np.atleast_2d(np.asarray(theta, float)), self.theta_lower(), self.theta_upper())
        gap = math.log(self.min_ratio)
        low = th[:, 3] - th[:, 2] < gap
        th[low, 2] = np.maximum(th[low, 3] - gap, math.log(self.nmin[0]))
        th[low, 3] = th[low, 2] + gap
        return th


#: grid steps the road grid is rounded down to [m]
_NICE_STEPS = (0.005, 0.01, 0.0125, 0.02, 0.025, 0.05, 0.1, 0.125, 0.2, 0.25, 0.5, 1.0)


def grid_spacing(nmax: float, points_per_wavelength: float = 4.0) -> float:
    """Road grid step dx = dy [m] for a synthesis band that ends at ``nmax``.

    The largest step of (0.005, 0.01, 0.0125, 0.02, 0.025, 0.05, 0.1, ...) m not above
    1 / (points_per_wavelength * nmax).  With the default 4 points per shortest
    wavelength a bilinear read-out keeps the amplitude at nmax within
    sinc^2(1/4) = 0.81 and everything below 0.5 nmax within 5%; 2 points
    (dx = 1 / (2 nmax), the Nyquist step) would halve it (sinc^2(1/2) = 0.41).
    The lateral step dy is taken equal to dx (an isotropic grid).

    Parameters
    ----------
    nmax : float
        Highest spatial frequency of the synthesis [cycles/m].
    points_per_wavelength : float
        Grid points per shortest wavelength 1 / nmax, >= 2.

    Returns
    -------
    float
        dx [m].
    """
    if not (nmax > 0) or points_per_wavelength < 2:
        raise EroadInputError("grid_spacing: nmax must be positive and points_per_wavelength >= 2")
    limit = 1.0 / (points_per_wavelength * nmax)
    fitting = [s for s in _NICE_STEPS if s <= limit * (1 + 1e-12)]
    return max(fitting) if fitting else limit
