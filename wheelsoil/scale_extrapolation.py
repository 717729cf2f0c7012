"""A result extrapolated to zero particle size: the scale error measured, not assumed.

A DEM result q depends on the particle size d. Over a few refinements q(d) = q0 + a d + O(d^2) (a first-order
error in d, as for a granular assembly whose discreteness enters through d / L at fixed packing); the line fitted
by least squares through every run gives q0, the result of an infinitely fine soil, with its standard error:

* without known errors (each seed a point, so the seeds' spread is the noise): ordinary least squares, the
  standard error from the residuals (Student's t at n - 2 degrees of freedom for intervals);
* with each run's own standard error s_k (one run per level, its batch-means error): weighted least squares,
  weights 1 / s_k^2, covariance (A^T W A)^-1, and where the points scatter about the line by more than their
  errors allow (chi^2 / (n - 2) > 1) the errors are scaled by sqrt(chi^2 / (n - 2)) (the Birge ratio, the Particle
  Data Group's scale factor), so a bent or noisy series does not get a falsely small error. The scale error of a run at size d is q(d) - q0 = a d, and its standard error
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
    unit of d] with its; ``dof`` = points - 2, the residuals' degrees of freedom; ``birge``: the factor the given
    errors were scaled by, sqrt(chi^2 / dof) when above 1, else 1; NaN without given errors)."""

    value: float
    value_se: float
    slope: float
    slope_se: float
    dof: int
    points: int
    birge: float = math.nan

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


def extrapolate_to_zero_size(sizes, values, errors=None) -> ZeroSizeExtrapolation:
    """The least-squares line q = q0 + a d through (``sizes``, ``values``), points with a NaN dropped. Without
    ``errors``: at least three points over two sizes (the residuals give the noise). With ``errors`` (each
    value's standard error, finite and > 0): weighted, at least two sizes; see the module docstring."""
    d = np.asarray(sizes, float)
    q = np.asarray(values, float)
    s = None if errors is None else np.asarray(errors, float)
    if d.shape != q.shape or d.ndim != 1 or (s is not None and s.shape != d.shape):
        raise WheelsoilInputError(f"sizes, values (and errors) must be 1-D of one length, got {d.shape} and "
                                  f"{q.shape}" + ("" if s is None else f" and {s.shape}"))
    ok = np.isfinite(d) & np.isfinite(q)
    if s is not None:
        ok &= np.isfinite(s) & (s > 0)
    d, q = d[ok], q[ok]
    need = 3 if s is None else 2
    if d.size < need or np.unique(d).size < 2:
        what = "three finite results over two sizes" if s is None else "two results with finite errors at two sizes"
        raise WheelsoilInputError(f"extrapolating to zero particle size needs {what} at least, got {d.size} over "
                                  f"{np.unique(d).size}")
    a = np.c_[np.ones(d.size), d]
    dof = d.size - 2
    if s is None:
        coef, *_ = np.linalg.lstsq(a, q, rcond=None)
        resid = q - a @ coef
        cov = float(resid @ resid) / dof * np.linalg.inv(a.T @ a) if dof > 0 else np.full((2, 2), math.nan)
        birge = math.nan
    else:
        w = 1.0 / s[ok] ** 2
        cov = np.linalg.inv(a.T @ (a * w[:, None]))
        coef = cov @ (a.T @ (w * q))
        chi2 = float(np.sum(w * (q - a @ coef) ** 2))
        birge = max(1.0, math.sqrt(chi2 / dof)) if dof > 0 else 1.0
        cov = cov * birge ** 2
    return ZeroSizeExtrapolation(value=float(coef[0]), value_se=float(math.sqrt(cov[0, 0])), slope=float(coef[1]),
                                 slope_se=float(math.sqrt(cov[1, 1])), dof=dof, points=int(d.size), birge=birge)
