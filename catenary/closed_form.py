"""Closed-form solutions for a tensioned string / beam under a point force.

What it is for: the reference values of the contact line tests (static uplift, wave
speed and natural frequencies, moving constant force below the wave speed) and the
validation table in ``docs/pantograph_contact.md``.

All on one span ``0 <= x <= L`` with both ends pinned (``w = 0``), tension ``T`` [N],
mass per length ``rho_A`` [kg/m], bending stiffness ``EI`` [N m^2], point force ``F``
[N] positive up.  Sources: the string and tensioned-beam statics are textbook
(e.g. Graff, *Wave Motion in Elastic Solids*, 1975, ch. 1 and 3); the moving-load modal
solution is Fryba, *Vibration of Solids and Structures under Moving Loads*, 1972/1999,
ch. 1 (string case), summed here in closed form.

What it is not: a model of a catenary (droppers, messenger) -- those have no closed form.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["string_green", "string_static_uplift", "tensioned_beam_midspan_uplift",
           "string_frequencies", "moving_force_string"]


def string_green(x, xi, tension: float, length: float) -> np.ndarray:
    """Static deflection [m] of a pinned string at ``x`` [m] under a unit force [N] at
    ``xi`` [m]: ``x (L - xi) / (T L)`` for ``x <= xi``, ``xi (L - x) / (T L)`` beyond."""
    x = np.asarray(x, dtype=float)
    xi = np.asarray(xi, dtype=float)
    lo = np.minimum(x, xi)
    hi = np.maximum(x, xi)
    return lo * (length - hi) / (tension * length)


def string_static_uplift(force: float, tension: float, length: float, x=None) -> float:
    """Uplift [m] under a point force at ``x`` (default mid-span): ``F L / (4 T)`` there."""
    x = 0.5 * length if x is None else x
    return float(force * string_green(x, x, tension, length))


def tensioned_beam_midspan_uplift(force: float, tension: float, ei: float, length: float) -> float:
    """Mid-span uplift [m] of a pinned-pinned tensioned Euler-Bernoulli beam under a
    mid-span point force.

    With ``lam = sqrt(T / EI)``: ``w = F / (2 T lam) (lam L / 2 - tanh(lam L / 2))``,
    which tends to the string value ``F L / (4 T)`` as ``EI -> 0``.
    """
    if ei <= 0:
        return string_static_uplift(force, tension, length)
    lam = math.sqrt(tension / ei)
    u = 0.5 * lam * length
    return force / (2.0 * tension * lam) * (u - math.tanh(u))


def string_frequencies(tension: float, rho_a: float, length: float, n: int = 5) -> np.ndarray:
    """First ``n`` natural frequencies [Hz] of a pinned string: ``f_k = k c / (2 L)``,
    ``c = sqrt(T / rho_A)``."""
    c = math.sqrt(tension / rho_a)
    return np.arange(1, n + 1) * c / (2.0 * length)


def moving_force_string(x, t, force: float, speed: float, tension: float, rho_a: float,
                        length: float) -> np.ndarray:
    """Deflection [m] of a pinned string, at rest at t = 0, under a constant force moving
    from x = 0 at ``speed`` [m/s] below the wave speed, while it is on the span.

    The modal solution (Fryba 1972, string) with ``alpha = v / c < 1`` sums to::

        w(x, t) = F / (1 - alpha^2) [ G(x, v t) - alpha G~(x, c t) ]

    ``G`` the static Green's function (:func:`string_green`) and ``G~(x, s)`` its odd,
    2L-periodic extension in ``s`` (the free wave front that runs ahead at ``c`` and
    reflects at the far anchor).  The first term is the quasi-static shape amplified
    by ``1 / (1 - alpha^2)``.

    Parameters
    ----------
    x, t : array_like
        Position [m] and time [s] (broadcast); valid for ``0 <= v t <= L``.
    force, speed, tension, rho_a, length : float
        ``F`` [N], ``v`` [m/s], ``T`` [N], ``rho_A`` [kg/m], ``L`` [m].
    """
    c = math.sqrt(tension / rho_a)
    a = speed / c
    if not a < 1:
        raise ValueError("moving_force_string: speed must be below the wave speed")
    x = np.asarray(x, dtype=float)
    t = np.asarray(t, dtype=float)
    s = np.mod(c * t, 2.0 * length)
    sign = np.where(s <= length, 1.0, -1.0)
    s = np.where(s <= length, s, 2.0 * length - s)
    g_load = string_green(x, speed * t, tension, length)
    g_free = sign * string_green(x, s, tension, length)
    return force / (1.0 - a * a) * (g_load - a * g_free)
