"""Roads made of segments with different spectra, with smoothed junctions (eq (8)).

What this module is for: concatenating road segments with different ISO 8608
parameters along x, in given proportions, and removing the height step at each
junction with Gaussian-windowed cosine patches (the paper's eq (8), in its
intended form).  What it is not: the spectral synthesis itself
(``roadlib.synthesis``) or the road container (``roadlib.surface``).

Junction patches (docs/roadlib.md has the reasoning)
----------------------------------------------------
Segment s is synthesised on its own x range with its own phase stream
``SeedSequence(seed, spawn_key=(s,))``.  Junction j sits half-way between two
grid samples, at x_j; the independent fields on its two sides differ there by
d(y) = z_right(x_j, y) - z_left(x_j, y) (both evaluated exactly).  The patched
surface is::

    z + sum_j sum_m  +-a_jm exp(-(x-x_j)^2/(2 sx_j^2) - (y-y_m)^2/(2 sy^2)) cos(2 pi n_j (x - x_j))

with ``+`` on the left of x_j and ``-`` on the right, so both sides meet at the
mean (z_left + z_right)/2 and the step disappears.

- y_m: every lateral grid line; sy = dy/2; the a_jm solve the small Gaussian
  system  sum_m a_jm exp(-(y_i-y_m)^2/(2 sy^2)) = d(y_i)/2  so the correction is
  exactly d/2 on every grid line (A_j in the issue's notation is a_jm).
- sx_j: the smallest width for which the patch's own largest step along x is at
  most half the median step of the unpatched field,
  sx_j = c_h max|d|/2 dx / (0.5 median|dz|), with c_h = max |h'(u)| sx of the
  window shape h; at least 10 dx, at most a third of the shorter neighbouring
  segment (the patch must not reach the next junction).
- n_j = 1 / (12 sx_j): the cosine's first zero falls on |x - x_j| = 3 sx_j, where
  the window is cut off, so the finite support adds no step of its own.
"""
from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass, replace

import numpy as np

from eroad.errors import EroadInputError
from roadlib.psd import ISO_BAND, class_gd0
from roadlib.synthesis import SpectralParams, _grid_count, _lateral_axis, harmonic_field

#: patch window support in units of sx (the cosine is zero there)
PATCH_SUPPORT = 3.0
#: the patch's largest step is at most this fraction of the field's median step
PATCH_STEP_FRACTION = 0.5
#: lateral patch width as a fraction of dy
PATCH_SY_OVER_DY = 0.5


def _window(u, sx):
    """Patch shape h(u) = exp(-u^2/(2 sx^2)) cos(2 pi u / (12 sx)), zero for |u| > 3 sx."""
    u = np.asarray(u, float)
    h = np.exp(-0.5 * (u / sx) ** 2) * np.cos(2.0 * np.pi * u / (4.0 * PATCH_SUPPORT * sx))
    return np.where(np.abs(u) <= PATCH_SUPPORT * sx, h, 0.0)


def _window_slope_constant() -> float:
    u = np.linspace(0.0, PATCH_SUPPORT, 20001)
    h = _window(u, 1.0)
    return float(np.max(np.abs(np.gradient(h, u))))


#: max |h'(u)| * sx of the window shape (dimensionless, about 0.69)
WINDOW_SLOPE = _window_slope_constant()

#: level at which a segment is synthesised before it is scaled to its own: the field is
#: linear in the harmonics' amplitudes, which are proportional to sqrt(Gq_n0), so a segment
#: of level Gq_n0 is sqrt(Gq_n0 / UNIT_GQ) times the unit one of the same phases
UNIT_GQ = 1e-6
#: unit segments kept per process (the inversion and the diagnosis draw the same phases
#: at many levels; one entry is the segment's grid and its two end evaluations, about
#: 0.1-1 MB for the roads they draw): at most this many entries and this many bytes
UNIT_CACHE_SIZE = 64
UNIT_CACHE_BYTES = 128 * 2 ** 20
_unit_cache: OrderedDict = OrderedDict()


def _unit_segment(params: SpectralParams, seg_len: float, width: float, lateral: bool,
                  seed: int, s: int, x_first: float, n_rows: int, y: np.ndarray, dx: float):
    """Segment ``s`` of the road of ``seed`` at level ``UNIT_GQ``: its grid (n_rows, ny) from
    ``x_first`` and its exact heights half a step before its first and after its last row
    (where the junctions sit).  Cached: only the level differs between many calls."""
    unit = replace(params, Gq_n0=UNIT_GQ)
    key = (unit, float(seg_len), float(width), bool(lateral), int(seed), int(s), float(x_first),
           int(n_rows), y.tobytes(), float(dx))
    hit = _unit_cache.get(key)
    if hit is not None:
        _unit_cache.move_to_end(key)
        return hit
    f = harmonic_field(unit, seg_len, width, np.random.SeedSequence(int(seed), spawn_key=(int(s),)),
                       lateral=lateral)
    zu = f.grid(x_first, n_rows, y)
    x_end = x_first + (n_rows - 1) * dx
    ends = (f.row(x_first - 0.5 * dx, y), f.row(x_end + 0.5 * dx, y))
    for a in (zu, *ends):
        a.setflags(write=False)
    _unit_cache[key] = (zu, ends)
    while len(_unit_cache) > 1 and (
            len(_unit_cache) > UNIT_CACHE_SIZE
            or sum(v[0].nbytes for v in _unit_cache.values()) > UNIT_CACHE_BYTES):
        _unit_cache.popitem(last=False)
    return zu, ends


@dataclass(frozen=True)
class RoadSegment:
    """One road segment: its spectrum and its share of the road length.

    Parameters
    ----------
    Gq_n0 : float
        Displacement PSD level Gd(n0) [m^3].
    share : float
        Relative length [-] (any positive number; the segment gets
        ``share / sum(shares)`` of the road length).  Giving lengths in metres
        as shares with the road length equal to their sum gives exact lengths.
    w : float
        Waviness [-].
    nmin, nmax : float
        Synthesis band [cycles/m].
    lam : float
        Anisotropy factor [-] (eq (5)).
    label : str
        Free name (e.g. the ISO class letter).
    w2, n_break : float, optional
        A two-slope spectrum (``roadlib.psd.two_slope_psd``): waviness ``w2`` [-] above
        the break frequency ``n_break`` [cycles/m], ``w`` below, ``Gq_n0`` the level of
        the low-frequency line at n0.  Both or neither; None is one ISO slope (and
        :meth:`to_dict` then has no such keys, as before the option existed).
    """

    Gq_n0: float
    share: float = 1.0
    w: float = 2.0
    nmin: float = ISO_BAND[0]
    nmax: float = ISO_BAND[1]
    lam: float = 1.0
    label: str = ""
    w2: float | None = None
    n_break: float | None = None

    def __post_init__(self):
        try:
            share = float(self.share)
        except (TypeError, ValueError):
            raise EroadInputError(f"RoadSegment.share must be a number, got {self.share!r}") from None
        if not (math.isfinite(share) and share > 0):
            raise EroadInputError(f"RoadSegment.share must be positive, got {self.share!r}")
        object.__setattr__(self, "share", share)

    @classmethod
    def from_class(cls, name: str, share: float = 1.0, **kw) -> "RoadSegment":
        """Segment with the geometric-mean level of ISO class ``name``."""
        kw.setdefault("label", str(name).strip().upper())
        return cls(Gq_n0=class_gd0(name), share=share, **kw)

    def params(self, dx: float, dy: float) -> SpectralParams:
        """The segment's :class:`SpectralParams` on a grid dx, dy [m] (validates)."""
        try:
            return SpectralParams(Gq_n0=self.Gq_n0, w=self.w, nmin=self.nmin, nmax=self.nmax,
                                  dx=dx, dy=dy, lam=self.lam, w2=self.w2, n_break=self.n_break)
        except EroadInputError as exc:
            raise EroadInputError(f"segment {self.label or ''}: {exc}".replace("segment : ", "segment: ")) from None

    def to_dict(self) -> dict:
        d = {"Gq_n0": self.Gq_n0, "share": self.share, "w": self.w, "nmin": self.nmin,
             "nmax": self.nmax, "lam": self.lam, "label": self.label}
        if self.w2 is not None or self.n_break is not None:
            d.update(w2=self.w2, n_break=self.n_break)
        return d


def _solve_lateral(y: np.ndarray, target: np.ndarray, sy: float) -> np.ndarray:
    if y.size == 1:
        return target.copy()
    g = np.exp(-0.5 * ((y[:, None] - y[None, :]) / sy) ** 2)
    return np.linalg.solve(g, target)


def segmented_surface(segments, length: float, width: float, dx: float, dy: float,
                      seed=0, x0: float = 0.0):
    """Road of consecutive segments along x with patched junctions.

    Parameters
    ----------
    segments : sequence of RoadSegment
        In travel order; lengths in proportion to their ``share``.
    length : float
        Road length [m].
    width : float
        Road width [m], centred on y = 0 (0 gives a single track).
    dx, dy : float
        Grid spacing [m].
    seed : int
        Root seed; segment s uses ``SeedSequence(seed, spawn_key=(s,))``.
    x0 : float
        Start position [m].

    Returns
    -------
    RoadSurface
        ``meta`` lists the segments (start, end [m]), the junctions (x_j [m],
        sx [m], n_j [cycles/m], sy [m], largest step across the junction [m]),
        the field's median step [m], the seed.

    Raises
    ------
    EroadInputError
        No segments, a segment shorter than 2 samples, a bad parameter.
    """
    from roadlib.surface import RoadSurface

    segments = list(segments)
    if not segments:
        raise EroadInputError("segmented_surface: no segments given")
    for i, s in enumerate(segments):
        if not isinstance(s, RoadSegment):
            raise EroadInputError(f"segmented_surface: segment {i} is a {type(s).__name__}, not a RoadSegment")
    if not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise EroadInputError(f"seed must be a non-negative integer, got {seed!r}")
    for name, v in (("dx", dx), ("dy", dy)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise EroadInputError(f"grid spacing {name} must be a positive number of metres, got {v!r}")
    params = [s.params(dx, dy) for s in segments]
    nx = _grid_count(length, dx, "road length")
    x = x0 + np.arange(nx) * dx
    y = _lateral_axis(width, dy)
    ny = y.size

    shares = np.array([s.share for s in segments])
    bounds = np.concatenate([[0.0], np.cumsum(shares) / shares.sum()]) * (x[-1] - x0)
    # junction j between samples i_j and i_j + 1 (half-way); segment s owns samples [first_s, last_s]
    cut = [int(round(b / dx - 0.5)) for b in bounds[1:-1]]
    first = [0] + [c + 1 for c in cut]
    last = [c for c in cut] + [nx - 1]
    for s, (a, b) in enumerate(zip(first, last)):
        if b - a + 1 < 2:
            raise EroadInputError(
                f"segment {s} ({segments[s].label or 'unnamed'}) gets fewer than 2 samples of dx = {dx} m; "
                "lengthen the road or its share")

    def pieces(yy):
        """Every segment's rows at lateral positions ``yy`` and its exact end rows."""
        zz = np.empty((nx, yy.size))
        ee = []
        for s, (a, b) in enumerate(zip(first, last)):
            zu, e = _unit_segment(params[s], (b - a) * dx, width, ny > 1, int(seed), s, float(x[a]),
                                  b - a + 1, yy, dx)
            g = math.sqrt(params[s].Gq_n0 / UNIT_GQ)
            zz[a:b + 1] = g * zu
            ee.append((g * e[0], g * e[1]))
        return zz, ee

    z, ends = pieces(y)

    steps = np.abs(np.diff(z, axis=0))
    mask = np.ones(nx - 1, bool)
    mask[cut] = False
    med_step = float(np.median(steps[mask])) if mask.any() else float(np.median(steps))

    sy = PATCH_SY_OVER_DY * dy
    junctions = []
    patches = []
    for j, c in enumerate(cut):
        xj = x[c] + 0.5 * dx
        d = ends[j + 1][0] - ends[j][1]    # both exact at x_j (right field's start, left's end)
        a_lat = _solve_lateral(y, 0.5 * d, sy)
        half = 0.5 * float(np.max(np.abs(d)))
        sx_need = WINDOW_SLOPE * half * dx / (PATCH_STEP_FRACTION * med_step) if med_step > 0 else 0.0
        len_left = (last[j] - first[j] + 0.5) * dx
        len_right = (last[j + 1] - first[j + 1] + 0.5) * dx
        sx_cap = min(len_left, len_right) / PATCH_SUPPORT
        sx = min(max(sx_need, 10.0 * dx), sx_cap)
        reach = int(math.ceil(PATCH_SUPPORT * sx / dx)) + 1
        lo, hi = max(0, c + 1 - reach), min(nx, c + 1 + reach)
        u = x[lo:hi] - xj
        sign = np.where(u < 0, 1.0, -1.0)
        lat = 0.5 * d if ny == 1 else np.exp(
            -0.5 * ((y[:, None] - y[None, :]) / sy) ** 2) @ a_lat
        z[lo:hi] += (sign * _window(u, sx))[:, None] * lat[None, :]
        patches.append((lo, hi, sign * _window(u, sx)))
        junctions.append({"x": float(xj), "sx": float(sx), "n_j": float(1.0 / (4 * PATCH_SUPPORT * sx)),
                          "sy": float(sy), "sx_capped": bool(sx_need > sx_cap),
                          "max_offset_removed": float(np.max(np.abs(d)))})
    for j, c in enumerate(cut):
        junctions[j]["max_step"] = float(np.max(np.abs(z[c + 1] - z[c])))

    edges = [float(x[0])] + [jc["x"] for jc in junctions] + [float(x[-1])]
    meta = {
        "generator": "roadlib.segments.segmented_surface",
        "seed": int(seed),
        "segments": [dict(s.to_dict(), start=float(edges[i]), end=float(edges[i + 1]))
                     for i, s in enumerate(segments)],
        "junctions": junctions,
        "median_step": med_step,
        "dx": float(dx), "dy": float(dy),
    }

    def lines(ys):
        """The road itself at lateral positions ``ys``: each segment's field evaluated there,
        each junction's step removed on that line by the same window (the grid's patch is the
        lateral interpolant of these steps; on a grid line the two agree)."""
        yy = np.asarray(ys, float)
        zz, ee = pieces(yy)
        for j, (lo, hi, win) in enumerate(patches):
            zz[lo:hi] += win[:, None] * (0.5 * (ee[j + 1][0] - ee[j][1]))[None, :]
        return zz

    return RoadSurface(x, y, z, meta, lines=lines if ny > 1 else None)


def regenerate_segmented(meta: dict, x, y):
    """The road a ``segmented_surface`` metadata describes, on the grid ``x``, ``y`` of its
    file (for :class:`roadlib.surface.RoadSurface`'s exact lines after loading)."""
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    keys = ("Gq_n0", "share", "w", "nmin", "nmax", "lam", "label", "w2", "n_break")
    segs = [RoadSegment(**{k: d[k] for k in keys if k in d}) for d in meta["segments"]]
    width = float(y[-1] - y[0])
    return segmented_surface(segs, float(x[-1] - x[0]), width, float(meta["dx"]), float(meta["dy"]),
                             seed=int(meta["seed"]), x0=float(x[0]))
