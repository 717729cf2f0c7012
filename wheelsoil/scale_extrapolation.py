"""A result extrapolated to zero particle size: the scale error measured, not assumed.

A DEM result q depends on the particle size d. Over a few refinements q(d) = q0 + a d + O(d^2) (a first-order
error in d, as for a granular assembly whose discreteness enters through d / L at fixed packing); the line fitted
by least squares through every run (each seed a point, so the seeds' spread is the noise) gives q0, the result of
an infinitely fine soil, with its standard error from the residuals (ordinary least squares, Student's t at n - 2
degrees of freedom for intervals). The scale error of a run at size d is q(d) - q0 = a d, and its standard error
is d se(a). "Converged at size d" (the project's definition) means that extrapolated change plus ``k`` of its
standard errors lies within the tolerance times |q0| -- not that one refinement moved little.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class ZeroSizeExtrapolation:
    """q(d) = value + slope d fitted to runs at ``sizes`` (value at d = 0 with its standard error; slope [per
    unit of d] with its; ``dof`` = points - 2, the residuals' degrees of freedom)."""

    value: float
    value_se: float
    slope: float
    slope_se: float
    dof: int
    points: int

    def change(self, size: float) -> tuple[float, float]:
        """The scale error q(size) - q0 and its standard error."""
        return self.slope * size, abs(size) * self.slope_se

    def relative_change(self, size: float) -> tuple[float, float]:
        """The scale error relative to |q0|, and its standard error."""
        change, se = self.change(size)
        return change / abs(self.value), se / abs(self.value)

    def converged(self, size: float, tolerance: float, k: float = 2.0) -> bool:
        """|q(size) - q0| + k standard errors within ``tolerance`` |q0|."""
        change, se = self.change(size)
        return bool(abs(change) + k * se <= tolerance * abs(self.value))


def extrapolate_to_zero_size(sizes, values) -> ZeroSizeExtrapolation:
    """The least-squares line q = q0 + a d through (``sizes``, ``values``) (NaN values dropped): at least three
    points over at least two sizes, so that the residuals give the noise."""
    d = np.asarray(sizes, float)
    q = np.asarray(values, float)
    if d.shape != q.shape or d.ndim != 1:
        raise WheelsoilInputError(f"sizes and values must be 1-D of one length, got {d.shape} and {q.shape}")
    ok = np.isfinite(d) & np.isfinite(q)
    d, q = d[ok], q[ok]
    if d.size < 3 or np.unique(d).size < 2:
        raise WheelsoilInputError(f"extrapolating to zero particle size needs three finite results over two sizes "
                                  f"at least, got {d.size} over {np.unique(d).size}")
    a = np.c_[np.ones(d.size), d]
    coef, *_ = np.linalg.lstsq(a, q, rcond=None)
    resid = q - a @ coef
    dof = d.size - 2
    cov = float(resid @ resid) / dof * np.linalg.inv(a.T @ a) if dof > 0 else np.full((2, 2), math.nan)
    return ZeroSizeExtrapolation(value=float(coef[0]), value_se=float(math.sqrt(cov[0, 0])), slope=float(coef[1]),
                                 slope_se=float(math.sqrt(cov[1, 1])), dof=dof, points=int(d.size))
