"""Bekker's pressure-sinkage law fitted the same way to measured and simulated plate curves.

Bekker (1956; Wong, *Theory of Ground Vehicles*, eq. 2.48): p = (k_c / b + k_phi) z^n = k z^n, with b the smaller
dimension of the loaded area -- a circular plate's radius (Wong, sec. 2.4.1). Per curve the fit is the CMU lab's
(``read_force_displacement.m``: MATLAB ``fit(z, p, 'power1')``, unweighted least squares in linear space), here
scipy's ``curve_fit`` started from the log-log line. Free k and n trade off strongly (k varies x2.8 between the lab's
repeats while p(10 mm) varies 2-12 %), so plates are compared at a common n (:func:`fit_k_at_n`) and the two
plate sizes give k_c and k_phi from k = k_c / b + k_phi (:func:`split_k`).

Units: z [m], p [Pa], k [Pa/m^n], k_c [Pa/m^(n-1)], k_phi [Pa/m^n]; reports print k in kPa/m^n as the lab does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize, stats

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class PowerFit:
    """p = k z^n fitted to one curve: k [Pa/m^n], n [-], their standard errors, the RMS residual [Pa] and the number
    of points used."""

    k: float
    n: float
    k_se: float
    n_se: float
    rms: float
    points: int

    def pressure(self, z) -> np.ndarray:
        """k z^n [Pa] at sinkage ``z`` [m]."""
        return self.k * np.power(np.clip(np.asarray(z, float), 0.0, None), self.n)


def _usable(z, p, label: str) -> tuple[np.ndarray, np.ndarray]:
    z, p = np.asarray(z, float), np.asarray(p, float)
    if z.shape != p.shape or z.ndim != 1:
        raise WheelsoilInputError(f"{label}: sinkage and pressure must be 1-D arrays of one length, got {z.shape} and {p.shape}")
    keep = np.isfinite(z) & np.isfinite(p) & (z > 0) & (p > 0)
    if keep.sum() < 3:
        raise WheelsoilInputError(f"{label}: {int(keep.sum())} points with sinkage > 0 and pressure > 0; a power law "
                                  "needs at least 3")
    return z[keep], p[keep]


def fit_power_law(z, p, *, label: str = "curve") -> PowerFit:
    """Fit p = k z^n to sinkage ``z`` [m] and pressure ``p`` [Pa] (points with z, p > 0), unweighted in linear space."""
    z, p = _usable(z, p, label)
    slope, intercept = np.polyfit(np.log(z), np.log(p), 1)
    (k, n), cov = optimize.curve_fit(lambda zz, kk, nn: kk * zz**nn, z, p, p0=(np.exp(intercept), slope), maxfev=20000)
    resid = p - k * z**n
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None)) if np.all(np.isfinite(cov)) else (np.nan, np.nan)
    return PowerFit(float(k), float(n), float(se[0]), float(se[1]), float(np.sqrt(np.mean(resid**2))), int(z.size))


def fit_k_at_n(z, p, n: float, *, label: str = "curve") -> tuple[float, float]:
    """k [Pa/m^n] of p = k z^n at a given exponent ``n`` (least squares in linear space, closed form) and its
    standard error."""
    z, p = _usable(z, p, label)
    basis = z**n
    k = float(basis @ p / (basis @ basis))
    resid = p - k * basis
    dof = max(z.size - 1, 1)
    se = float(np.sqrt(resid @ resid / dof / (basis @ basis)))
    return k, se


@dataclass(frozen=True)
class BekkerSplit:
    """k = k_c / b + k_phi from plates of several radii b at a common n: k_c [Pa/m^(n-1)], k_phi [Pa/m^n], their
    standard errors (NaN when the fit has no spare degree of freedom), n, and the points used."""

    k_c: float
    k_phi: float
    k_c_se: float
    k_phi_se: float
    n: float
    points: int

    def k(self, radius: float) -> float:
        """The modulus k [Pa/m^n] of a plate of radius ``radius`` [m]."""
        return self.k_c / radius + self.k_phi


def split_k(radii, ks, n: float) -> BekkerSplit:
    """Regress k [Pa/m^n] on 1 / b over plates of radius b [m] (two or more sizes; several trials per size give the
    standard errors)."""
    b, k = np.asarray(radii, float), np.asarray(ks, float)
    if b.shape != k.shape or b.size < 2:
        raise WheelsoilInputError(f"Bekker split: {b.size} plate(s); k_c and k_phi need plates of at least two sizes")
    if np.unique(np.round(b, 9)).size < 2:
        raise WheelsoilInputError(f"Bekker split: every plate has radius {b[0]:g} m; k_c and k_phi need two sizes")
    if b.size == 2:
        k_c = (k[0] - k[1]) / (1.0 / b[0] - 1.0 / b[1])
        return BekkerSplit(float(k_c), float(k[0] - k_c / b[0]), np.nan, np.nan, float(n), 2)
    reg = stats.linregress(1.0 / b, k)
    return BekkerSplit(float(reg.slope), float(reg.intercept), float(reg.stderr), float(reg.intercept_stderr), float(n),
                       int(b.size))


def common_exponent(fits: list[PowerFit]) -> float:
    """The median n of several fits (the lab's choice for comparing plates, data README)."""
    if not fits:
        raise WheelsoilInputError("no Bekker fits to take a common exponent from")
    return float(np.median([f.n for f in fits]))
