"""ISO 8608 road displacement spectra: the class table, the 1D PSD, the surface PSD.

What this module is for: the *target* spectra a road is generated from or
classified against -- the ISO 8608 displacement PSD Gd(n) = Gd(n0) (n/n0)^-w,
the classes A-H with their geometric means and bounds, the class of a given
PSD level, and the anisotropic two-dimensional surface PSD (the paper's eq (5)).
A fitted two-slope form (:func:`two_slope_psd`, one break frequency and two
waviness exponents; :func:`road_psd` picks one or two slopes) describes real roads
whose spectrum bends.
What it is not: a generator (``roadlib.synthesis``) or an estimator of the PSD
of measured data (``roadlib.metrics``).

Conventions (used throughout roadlib)
-------------------------------------
- ``n`` is the spatial frequency in **cycles/m**; the angular spatial frequency
  is Omega = 2 pi n in **rad/m**.  Every function here takes and returns ``n``
  in cycles/m.  A PSD per rad/m converts as G(Omega) = G(n) / (2 pi).
- ISO 8608 PSDs are **one-sided** displacement PSDs in m^3 (m^2 per cycle/m):
  the profile variance is  sigma^2 = integral_0^inf Gd(n) dn.  A two-sided PSD
  is half of it on (-inf, inf).
- Reference frequency n0 = 0.1 cycles/m; the ISO class table assumes w = 2.
- Class values are the *geometric means* of the class (A: 16e-6 m^3, each
  following class a factor 4 higher).  The class bounds are a factor 2 either
  side of the mean (A: 8e-6..32e-6 m^3 in the table of ISO 8608, Annex); for
  classification A is open downwards and H open upwards.  Using the upper bound
  as "the class value" (a public generator does) overstates the level by 2x.

Surface PSD (eq (5) as implemented, see docs/roadlib.md)
--------------------------------------------------------
With n_x >= 0 along the road (one-sided) and n_y lateral (two-sided)::

    Gq(n_x, n_y) = Gd(n_x) * p(n_y | n_x)
    p(n_y | n_x) = lam * c_w / n_x * (1 + (lam n_y / n_x)^2)^(-(w+1)/2)
    c_w          = Gamma((w+1)/2) / (sqrt(pi) Gamma(w/2))

which equals Gd(n0) n0^w lam c_w (n_x^2 + lam^2 n_y^2)^(-(w+1)/2): for lam = 1
the isotropic surface whose every straight line has the 1D PSD Gd, for lam > 1
laterally stretched (more coherent across the road), lam < 1 laterally
compressed.  Since p integrates to 1 over n_y, every longitudinal track has
exactly the 1D PSD Gd(n_x), whatever lam.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from eroad.errors import EroadInputError

#: reference spatial frequency of ISO 8608 [cycles/m]
N0 = 0.1
#: ISO 8608 reference band for classification [cycles/m]
ISO_BAND = (0.011, 2.83)


@dataclass(frozen=True)
class IsoClass:
    """One ISO 8608 road class.

    Attributes
    ----------
    name : str
        Class letter "A" ... "H".
    gd0 : float
        Geometric mean Gd(n0) of the class [m^3].
    lower, upper : float
        Class bounds of Gd(n0) [m^3]; ``0`` for A's lower and ``inf`` for H's
        upper bound when classifying (the nominal bounds are ``gd0 / 2`` and
        ``2 gd0``, see :attr:`nominal_bounds`).
    """

    name: str
    gd0: float
    lower: float
    upper: float

    @property
    def nominal_bounds(self) -> tuple[float, float]:
        """Bounds gd0/2 and 2 gd0 [m^3] (the table values, A and H closed)."""
        return self.gd0 / 2.0, self.gd0 * 2.0

    @property
    def displacement_rms(self) -> float:
        """RMS height [m] of the class mean over the ISO band 0.011-2.83 cycles/m, w = 2."""
        lo, hi = ISO_BAND
        return math.sqrt(self.gd0 * N0**2 * (1.0 / lo - 1.0 / hi))


def _make_classes() -> dict[str, IsoClass]:
    out = {}
    for k, name in enumerate("ABCDEFGH"):
        gd0 = 16e-6 * 4.0**k
        lower = 0.0 if name == "A" else gd0 / 2.0
        upper = math.inf if name == "H" else gd0 * 2.0
        out[name] = IsoClass(name, gd0, lower, upper)
    return out


#: ISO 8608 classes A-H (name -> IsoClass), geometric means 16e-6 * 4^k m^3
ISO_CLASSES: dict[str, IsoClass] = _make_classes()


def class_gd0(name: str) -> float:
    """Geometric-mean Gd(n0) [m^3] of ISO class ``name`` ("A" ... "H", case-insensitive).

    Raises
    ------
    EroadInputError
        Unknown class name.
    """
    key = str(name).strip().upper()
    if key not in ISO_CLASSES:
        raise EroadInputError(f"unknown ISO 8608 road class {name!r}; expected one of A-H")
    return ISO_CLASSES[key].gd0


def class_of(gd0: float) -> str:
    """ISO 8608 class letter of a displacement PSD level.

    Parameters
    ----------
    gd0 : float
        Gd(n0) [m^3] at n0 = 0.1 cycles/m (w = 2 assumed by the table).

    Returns
    -------
    str
        "A" ... "H".  A boundary value belongs to the upper class
        (bounds are lower-inclusive).
    """
    gd0 = float(gd0)
    if not math.isfinite(gd0) or gd0 <= 0:
        raise EroadInputError(f"class_of: Gd(n0) must be a positive finite number [m^3], got {gd0!r}")
    for c in ISO_CLASSES.values():
        if c.lower <= gd0 < c.upper:
            return c.name
    return "H"  # pragma: no cover  (H is open upwards)


def _check_level(gd0, w):
    if not (np.isfinite(gd0) and gd0 > 0):
        raise EroadInputError(f"PSD level Gd(n0) must be positive and finite [m^3], got {gd0!r}")
    if not (np.isfinite(w) and 0 < w < 6):
        raise EroadInputError(f"waviness w must be in (0, 6), got {w!r}")


def iso_psd(n, gd0: float, w: float = 2.0) -> np.ndarray:
    """One-sided ISO 8608 displacement PSD Gd(n) = gd0 (n/n0)^-w.

    Parameters
    ----------
    n : array_like
        Spatial frequency [cycles/m], > 0.
    gd0 : float
        Gd(n0) [m^3].
    w : float
        Waviness [-] (2 in the ISO table).

    Returns
    -------
    ndarray
        Gd(n) [m^3] (m^2 per cycle/m), same shape as ``n``.
    """
    _check_level(gd0, w)
    n = np.asarray(n, dtype=float)
    if np.any(n <= 0):
        raise EroadInputError("iso_psd: spatial frequencies n must be > 0 cycles/m")
    return gd0 * (n / N0) ** (-w)


def _check_two_slope(w2, n_break):
    if (w2 is None) != (n_break is None):
        raise EroadInputError("two-slope PSD: give both w2 and n_break, or neither (one slope)")
    if w2 is None:
        return
    if not (np.isfinite(w2) and 0 < w2 < 6):
        raise EroadInputError(f"waviness above the break w2 must be in (0, 6), got {w2!r}")
    if not (np.isfinite(n_break) and n_break > 0):
        raise EroadInputError(f"break frequency n_break must be positive and finite [cycles/m], got {n_break!r}")


def two_slope_psd(n, gd0: float, w1: float, w2: float, n_break: float) -> np.ndarray:
    """Two-slope displacement PSD, continuous at the break [m^3].

    ``Gd(n) = gd0 (n/n0)^-w1`` for n <= n_break and
    ``Gd(n) = gd0 (n_break/n0)^-w1 (n/n_break)^-w2`` above: ISO 8608 fits a straight
    line in log-log, and allows a fit by more than one line where the measured
    spectrum bends; roads commonly fall off more steeply at long wavelengths than at
    short ones (Andren 2006, Int. J. Vehicle Design 40; Kropac and Mucka 2004,
    Int. J. Vehicle Design 36).  ``gd0`` keeps its meaning, Gd(n0), when
    n0 <= n_break; for n_break < n0 it is the level the LOW-frequency line would
    reach at n0 (the extrapolated line; Gd(n0) itself is :func:`road_psd` at n0).

    Parameters
    ----------
    n : array_like
        Spatial frequency [cycles/m], > 0.
    gd0 : float
        Level of the low-frequency line at n0 = 0.1 cycles/m [m^3].
    w1, w2 : float
        Waviness below and above the break [-].
    n_break : float
        Break frequency [cycles/m], > 0.

    Returns
    -------
    ndarray
        Gd(n) [m^3], the shape of ``n``.
    """
    _check_level(gd0, w1)
    _check_two_slope(w2, n_break)
    n = np.asarray(n, dtype=float)
    if np.any(n <= 0):
        raise EroadInputError("two_slope_psd: spatial frequencies n must be > 0 cycles/m")
    low = gd0 * (n / N0) ** (-w1)
    high = gd0 * (n_break / N0) ** (-w1) * (n / n_break) ** (-w2)
    return np.where(n <= n_break, low, high)


def road_psd(n, gd0: float, w: float = 2.0, w2: float | None = None,
             n_break: float | None = None) -> np.ndarray:
    """One-sided displacement PSD of a road: :func:`iso_psd` (one slope, ``w2`` and
    ``n_break`` None -- exactly the ISO call, bit for bit) or :func:`two_slope_psd`
    with ``w1 = w``.

    Returns
    -------
    ndarray
        Gd(n) [m^3].
    """
    _check_two_slope(w2, n_break)
    if w2 is None:
        return iso_psd(n, gd0, w)
    return two_slope_psd(n, gd0, w, w2, n_break)


def local_waviness(n, w: float, w2: float | None = None, n_break: float | None = None) -> np.ndarray:
    """Local log-log slope (negated) of :func:`road_psd` at ``n`` [-]: ``w`` below
    the break (everywhere for one slope), ``w2`` above."""
    n = np.asarray(n, dtype=float)
    if w2 is None:
        return np.full(n.shape, float(w))
    return np.where(n <= n_break, float(w), float(w2))


def _power_integral(c: float, w: float, a: float, b: float) -> float:
    """integral_a^b c n^-w dn (closed form; the logarithm at w = 1)."""
    if b <= a:
        return 0.0
    if abs(w - 1.0) < 1e-12:
        return c * math.log(b / a)
    return c * (b ** (1.0 - w) - a ** (1.0 - w)) / (1.0 - w)


def band_variance(gd0: float, w: float, nmin: float, nmax: float, w2: float | None = None,
                  n_break: float | None = None) -> float:
    """Variance [m^2] of a profile with PSD :func:`road_psd` over [nmin, nmax]
    (closed form: each straight piece integrates to a power of n).

    Parameters
    ----------
    gd0, w, w2, n_break
        As :func:`road_psd`.
    nmin, nmax : float
        Band [cycles/m], 0 < nmin < nmax.
    """
    _check_level(gd0, w)
    _check_two_slope(w2, n_break)
    if not (0 < nmin < nmax):
        raise EroadInputError(f"band_variance: need 0 < nmin < nmax, got {nmin}, {nmax}")
    c1 = gd0 * N0 ** w
    if w2 is None:
        return _power_integral(c1, w, nmin, nmax)
    c2 = gd0 * (n_break / N0) ** (-w) * n_break ** w2
    return (_power_integral(c1, w, nmin, min(nmax, n_break))
            + _power_integral(c2, w2, max(nmin, n_break), nmax))


def lateral_density(n_y, n_x, w: float = 2.0, lam: float = 1.0) -> np.ndarray:
    """Conditional lateral density p(n_y | n_x) of the surface PSD [m] (per cycle/m).

    p(n_y | n_x) = lam c_w / n_x (1 + (lam n_y / n_x)^2)^(-(w+1)/2), integrating to 1
    over n_y in (-inf, inf).

    Parameters
    ----------
    n_y : array_like
        Lateral spatial frequency [cycles/m] (two-sided, any sign).
    n_x : array_like
        Longitudinal spatial frequency [cycles/m], > 0 (broadcast with ``n_y``).
    w : float
        Waviness [-].
    lam : float
        Anisotropy factor [-], > 0 (1 = isotropic).
    """
    if not (np.isfinite(lam) and lam > 0):
        raise EroadInputError(f"anisotropy factor lambda must be > 0, got {lam!r}")
    n_y = np.asarray(n_y, float)
    n_x = np.asarray(n_x, float)
    c_w = math.gamma((w + 1) / 2) / (math.sqrt(math.pi) * math.gamma(w / 2))
    return lam * c_w / n_x * (1.0 + (lam * n_y / n_x) ** 2) ** (-(w + 1) / 2)


def surface_psd(n_x, n_y, gd0: float, w: float = 2.0, lam: float = 1.0) -> np.ndarray:
    """Anisotropic surface displacement PSD Gq(n_x, n_y) [m^4] (the paper's eq (5)).

    One-sided in ``n_x`` (> 0), two-sided in ``n_y``; its integral over n_y is
    the 1D ISO PSD Gd(n_x) for every lam, so every longitudinal track of the
    surface has the ISO spectrum.

    Parameters
    ----------
    n_x, n_y : array_like
        Spatial frequencies [cycles/m], broadcast together; n_x > 0.
    gd0 : float
        Gd(n0) [m^3].
    w : float
        Waviness [-].
    lam : float
        Anisotropy factor [-]: 1 isotropic, > 1 more coherent across the road.

    Returns
    -------
    ndarray
        Gq [m^4] (m^2 per (cycle/m)^2).
    """
    return iso_psd(n_x, gd0, w) * lateral_density(n_y, n_x, w, lam)
