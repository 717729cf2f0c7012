"""Best-fit rigid motion of a set of points, and the deformation beyond it (NumPy; shared by the wheel's load
tests and the testbed's measured kinematics).

* :func:`rigid_fit` -- the rotation R and translation t that carry reference points X onto current points x
  best in the (weighted) least-squares sense, min sum_k w_k |x_k - (R X_k + t)|^2 (Kabsch 1976, Acta Cryst.
  A32, 922; the reflection guard of Umeyama 1991, IEEE TPAMI 13, 376, eqs. 39-41);
* :func:`deformation` -- x - (R X + t) for that fit: what the points moved beyond the body's rigid motion;
* :func:`rotation_vector` -- the matrix logarithm of a rotation;
* :func:`rotation_about` -- the best-fit rotation angle of a set of points about an axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import WheelsoilInputError


@dataclass(frozen=True)
class RigidFit:
    """x ~ R X + t: rotation (3, 3) and translation (3,) [m] of a best fit."""

    rotation: np.ndarray
    translation: np.ndarray

    def apply(self, reference: np.ndarray) -> np.ndarray:
        """The rigidly moved reference points, R X + t."""
        return np.asarray(reference) @ self.rotation.T + self.translation


def rigid_fit(points, reference, weights=None) -> RigidFit:
    """Best-fit rigid motion carrying ``reference`` (N, 3) onto ``points`` (N, 3) (weights (N,) >= 0).

    Kabsch's solution: with centroids p, q and the weighted cross-covariance H = sum w (X - q)(x - p)^T
    = U S V^T, R = V diag(1, 1, det(V U^T)) U^T and t = p - R q (the diagonal keeps R a proper rotation).
    """
    x = np.asarray(points, float)
    ref = np.asarray(reference, float)
    if x.shape != ref.shape or x.ndim != 2 or x.shape[1] != 3 or len(x) < 3:
        raise WheelsoilInputError(f"rigid_fit needs two (N, 3) arrays of the same shape with N >= 3, got "
                                  f"{x.shape} and {ref.shape}")
    w = np.ones(len(x)) if weights is None else np.asarray(weights, float)
    if w.shape != (len(x),) or np.any(w < 0) or not w.sum() > 0:
        raise WheelsoilInputError("rigid_fit weights must be (N,) non-negative numbers with a positive sum")
    w = w / w.sum()
    p = w @ x
    q = w @ ref
    h = (ref - q).T @ ((x - p) * w[:, None])
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    r = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    return RigidFit(r, p - r @ q)


def deformation(points, reference, weights=None) -> np.ndarray:
    """Displacement beyond the best-fit rigid motion, x - (R X + t) [m], (N, 3)."""
    return np.asarray(points, float) - rigid_fit(points, reference, weights).apply(reference)


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """theta with exp(spin(theta)) = r, |theta| < pi (the matrix logarithm of a rotation)."""
    w = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])  # sin(g) * axis
    s = float(np.linalg.norm(w))
    c = 0.5 * (float(np.trace(r)) - 1.0)
    g = math.atan2(s, c)
    return w * (g / s if s > 1e-12 else 1.0 + g * g / 6.0)


def rotation_about(points, reference, axis, weights=None) -> float:
    """The angle [rad] of the best-fit rigid rotation carrying ``reference`` onto ``points``, about ``axis``
    (the axis component of its rotation vector; |angle| < pi)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return float(rotation_vector(rigid_fit(points, reference, weights).rotation) @ axis)
