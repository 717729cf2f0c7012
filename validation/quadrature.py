"""Gauss--Legendre quadrature over the wheel's contact arc, per condition (vectorised NumPy).

The normal stress vanishes at the contact's ends as a power of the distance to them: sigma ~ (cos theta -
cos theta_f)^n ~ (theta_f - theta)^n at the entry angle, and in the rear region, whose angles map onto the front's
(Wong & Reece), as (theta - theta_r)^n at the exit angle, with a sinkage exponent n that is rarely a whole number.
Plain Gauss--Legendre converges only algebraically on such an end, about as N^-(2n+2) (Davis & Rabinowitz, *Methods
of Numerical Integration*, 2nd ed., sec. 2.7.1): 48 nodes left relative errors up to 1.4e-6 at n = 0.5.
:func:`graded_gauss_on` clusters the nodes at the end where the stress vanishes by the substitution theta = end +
(other - end) s^k, s on [0, 1] (ibid., sec. 2.9.2, removing a singularity by a change of variable), which turns
(theta - end)^n into s^(k(n+1) - 1) and lifts the order of convergence to about N^-(2k(n+1)). Measured in
``docs/validation/quadrature.md`` (``python docs/validation_quadrature.py``): with 24 nodes a region of power 2 the
forces agree with a 400-node reference to 3.4e-10 (48 plain nodes: 1.4e-6), and a calibration runs 2.7 times faster
(median of alternating rounds, ``python benchmarks/validation_fit.py``). Braking rows are the exception for
every rule: their shear changes sign inside the contact, a kink in the independent form's integrand and a jump in
the resultant form's, so errors there stay near 1e-5 relative (48 plain nodes: 3.0e-5), which is also how far two
fine rules agree there.
"""

from contextlib import contextmanager
from functools import lru_cache

import numpy as np

#: Gauss--Legendre nodes of the plain rule (:func:`gauss_legendre`'s default): the side forces' integrals, whose
#: integrands are smooth on their intervals.
QUADRATURE_POINTS = 48

#: Nodes per contact region (front and rear of theta_m) of the graded rule (:func:`graded_gauss_on`), and the grading
#: power k, chosen from ``docs/validation/quadrature.md``: four thousand times more accurate than the plain rule's 48
#: nodes where the shear keeps its sign (sinkage exponents 0.5--2.2, both shear forms, driving, dragged and 90 deg
#: rows), within the 1e-5 that braking rows allow any rule, and a fit 2.7 times faster.
CONTACT_POINTS = 24
GRADING_POWER = 2


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


@lru_cache(maxsize=8)
def graded_nodes(points: int = CONTACT_POINTS, power: int = GRADING_POWER) -> tuple[np.ndarray, np.ndarray]:
    """Nodes s^k on [0, 1] and their weights k s^(k-1) w / 2 (s: the Gauss--Legendre nodes mapped onto [0, 1]),
    computed once per order: int_0^1 f(u) du ~ sum weight f(node) with u = s^k."""
    x, w = np.polynomial.legendre.leggauss(points)
    s = 0.5 * (x + 1.0)
    nodes, weights = s**power, 0.5 * w * power * s ** (power - 1)
    nodes.flags.writeable = False
    weights.flags.writeable = False
    return nodes, weights


#: The graded rule in use: [points, power] (:func:`contact_rule` changes it for a measurement).
_CONTACT_RULE = [CONTACT_POINTS, GRADING_POWER]


@contextmanager
def contact_rule(points: int, power: int):
    """Use ``points`` nodes per region and grading power ``power`` for the contact arc within the block (power 1:
    the plain Gauss--Legendre rule), e.g. to measure the quadrature's error against a finer rule."""
    if int(points) != points or points < 1 or int(power) != power or power < 1:
        raise ValueError(f"contact_rule(points={points!r}, power={power!r}): both must be whole numbers >= 1")
    saved = list(_CONTACT_RULE)
    _CONTACT_RULE[:] = [int(points), int(power)]
    try:
        yield
    finally:
        _CONTACT_RULE[:] = saved


def graded_gauss_on(end: np.ndarray, other: np.ndarray):
    """Quadrature points (C, Q) and weights (C, Q) on the interval between ``end`` and ``other`` per condition,
    clustered at ``end`` (where the integrand vanishes as a power of the distance): theta = end + (other - end) u,
    u = s^k, weights |other - end| k s^(k-1) w / 2 (:data:`CONTACT_POINTS` nodes, k = :data:`GRADING_POWER`, unless
    :func:`contact_rule` says otherwise). Empty intervals get zero weights."""
    u, wu = graded_nodes(*_CONTACT_RULE)
    span = (other - end)[:, None]
    return end[:, None] + span * u[None, :], np.abs(span) * wu[None, :]
