"""Gauss--Legendre quadrature over the wheel's contact arc, per condition (vectorised NumPy)."""

from functools import lru_cache

import numpy as np

#: Gauss--Legendre nodes per contact region (front and rear of theta_m); 48 integrate the smooth stress
#: profiles to better than 1e-8 relative (see tests/test_validation_terramechanics.py).
QUADRATURE_POINTS = 48


@lru_cache(maxsize=8)
def gauss_legendre(points: int = QUADRATURE_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Gauss--Legendre nodes and weights on [-1, 1], computed once per order (NumPy's eigenvalue solve
    took half the time of a calibration when it was repeated on every force evaluation)."""
    x, w = np.polynomial.legendre.leggauss(points)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def gauss_on(lo: np.ndarray, hi: np.ndarray, nodes: np.ndarray, weights: np.ndarray):
    """Quadrature points (C, Q) and weights (C, Q) on [lo, hi] per condition (C conditions, Q nodes)."""
    half = 0.5 * (hi - lo)[:, None]
    return 0.5 * (hi + lo)[:, None] + half * nodes[None, :], half * weights[None, :]
