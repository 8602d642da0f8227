"""RoadSurface: a road height field z(x, y) on a regular grid.

What it is for: the one road object every other package consumes (vehicles read
wheel tracks from it, the inverse fit writes one).  What it is not: a generator
(see ``roadlib.synthesis`` and ``roadlib.segments``).

Conventions: ``x`` [m] along travel, ``y`` [m] lateral (positive left, 0 on the
centre line), ``z`` [m] up, array shape (nx, ny).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from eroad.errors import EroadInputError


@dataclass
class RoadSurface:
    """Height field on a regular grid.

    Parameters
    ----------
    x : (nx,) array, m, strictly increasing, uniform
    y : (ny,) array, m, strictly increasing, uniform (ny may be 1 for a profile)
    z : (nx, ny) array, m
    meta : dict, free metadata (generator parameters, seed, ...)
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    meta: dict = field(default_factory=dict)

    def __post_init__(self):
        self.x = np.asarray(self.x, dtype=float)
        self.y = np.asarray(self.y, dtype=float)
        self.z = np.asarray(self.z, dtype=float)
        if self.x.ndim != 1 or self.y.ndim != 1:
            raise EroadInputError("RoadSurface: x and y must be 1-D arrays")
        if self.z.shape != (self.x.size, self.y.size):
            raise EroadInputError(
                f"RoadSurface: z has shape {self.z.shape}, expected (nx, ny) = "
                f"({self.x.size}, {self.y.size})")
        if self.x.size < 2 or np.any(np.diff(self.x) <= 0):
            raise EroadInputError("RoadSurface: x must have >= 2 strictly increasing values")
        if self.y.size > 1 and np.any(np.diff(self.y) <= 0):
            raise EroadInputError("RoadSurface: y must be strictly increasing")

    @property
    def dx(self) -> float:
        return float(self.x[1] - self.x[0])

    @property
    def dy(self) -> float:
        return float(self.y[1] - self.y[0]) if self.y.size > 1 else 0.0

    @property
    def x_min(self) -> float:
        return float(self.x[0])

    @property
    def x_max(self) -> float:
        return float(self.x[-1])

    @property
    def length(self) -> float:
        return self.x_max - self.x_min

    def height(self, xq, yq) -> np.ndarray:
        """Bilinear interpolation of z at (xq, yq) [m], vectorised with broadcasting.

        Points outside the grid are clamped to the edge (the caller checks coverage).
        """
        xq, yq = np.broadcast_arrays(np.asarray(xq, float), np.asarray(yq, float))
        fx = np.clip((xq - self.x[0]) / self.dx, 0.0, self.x.size - 1.0)
        ix = np.minimum(fx.astype(np.intp), self.x.size - 2)
        tx = fx - ix
        if self.y.size == 1:
            z = self.z[:, 0]
            return (1 - tx) * z[ix] + tx * z[ix + 1]
        fy = np.clip((yq - self.y[0]) / self.dy, 0.0, self.y.size - 1.0)
        iy = np.minimum(fy.astype(np.intp), self.y.size - 2)
        ty = fy - iy
        z = self.z
        return ((1 - tx) * (1 - ty) * z[ix, iy] + tx * (1 - ty) * z[ix + 1, iy]
                + (1 - tx) * ty * z[ix, iy + 1] + tx * ty * z[ix + 1, iy + 1])

    def track(self, y: float, x=None) -> np.ndarray:
        """Profile z along ``x`` (default: the grid x) at lateral position ``y`` [m]."""
        xs = self.x if x is None else np.asarray(x, float)
        return self.height(xs, np.full_like(xs, float(y)))
