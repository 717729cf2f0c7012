"""The box a scene's spheres live in (plain NumPy, no Taichi): its corners, and whether it is periodic along x."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import WheelsoilInputError
from .scene_input import as_vector


@dataclass(frozen=True)
class SceneDomain:
    """Corners ``lo`` and ``hi`` [m] of the box the spheres must stay in (it sizes the neighbour grid).

    ``periodic_x``: the box is periodic along x with period ``hi[0] - lo[0]`` (a sphere leaving one end comes back at
    the other)."""

    lo: np.ndarray
    hi: np.ndarray
    periodic_x: bool = False

    @classmethod
    def of(cls, domain_min, domain_max, periodic_x: bool = False) -> "SceneDomain":
        """The domain of the given corners, checked: ``domain_max`` exceeds ``domain_min`` on every axis."""
        lo, hi = as_vector("domain_min", domain_min), as_vector("domain_max", domain_max)
        if np.any(hi <= lo):
            raise WheelsoilInputError(f"domain_max {hi.tolist()} must exceed domain_min {lo.tolist()} on every axis")
        return cls(lo, hi, bool(periodic_x))

    @property
    def period(self) -> float:
        """The period along x [m] (0 when the domain is not periodic)."""
        return float(self.hi[0] - self.lo[0]) if self.periodic_x else 0.0

    def wrapped(self, xs: np.ndarray) -> np.ndarray:
        """x coordinates [m] brought into [lo x, lo x + period) (periodic domains)."""
        u = np.mod(np.asarray(xs, float) - self.lo[0], self.period)
        u[u >= self.period] -= self.period
        return self.lo[0] + u

    def placed(self, x: np.ndarray) -> np.ndarray:
        """Sphere centres (N, 3) [m] with x wrapped into the period where the domain is periodic (a copy)."""
        x = np.array(x, float)
        if self.periodic_x:
            x[:, 0] = self.wrapped(x[:, 0])
        return x

    def outside(self, x: np.ndarray) -> np.ndarray:
        """Indices of the centres (N, 3) [m] outside the box."""
        return np.flatnonzero(np.any((x < self.lo) | (x > self.hi), axis=1))

    def describe(self) -> str:
        return f"[{self.lo.tolist()}, {self.hi.tolist()}]"
