"""The contact arc's graded Gauss--Legendre rule against closed-form integrals of end singularities."""

import math

import numpy as np
import pytest

from wheelsoil.validation.quadrature import CONTACT_POINTS, contact_rule, graded_gauss_on


@pytest.mark.parametrize("alpha", [0.5, 0.7, 1.1, 2.3])
def test_graded_rule_integrates_a_power_that_vanishes_at_either_end(alpha):
    """int over [a, b] of |theta - end|^alpha = |b - a|^(alpha + 1) / (alpha + 1), the stress's shape near the contact's
    ends (alpha: the sinkage exponent), with the end below (the rear region's theta_r) and above (the front's
    theta_f) the other; empty intervals weigh nothing."""
    end = np.array([1.2, -0.3, 0.4])
    other = np.array([0.35, 0.25, 0.4])
    theta, weight = graded_gauss_on(end, other)
    assert theta.shape == weight.shape == (3, CONTACT_POINTS)
    integral = np.sum(weight * np.abs(theta - end[:, None]) ** alpha, axis=1)
    exact = np.abs(other - end) ** (alpha + 1.0) / (alpha + 1.0)
    np.testing.assert_allclose(integral, exact, rtol=1e-9, atol=0.0)  # 1.7e-10 measured at alpha = 0.7
    assert np.all((theta[:2] - np.minimum(end, other)[:2, None]) * (np.maximum(end, other)[:2, None] - theta[:2]) > 0)


def test_plain_rule_converges_slowly_on_the_same_power():
    """The reason for the grading: the plain rule (power 1) with twice the nodes misses x^0.5 on [0, 1] by more than
    1e-6, the graded rule by less than 1e-9."""
    end, other = np.array([0.0]), np.array([1.0])
    exact = 1.0 / 1.5
    with contact_rule(2 * CONTACT_POINTS, 1):
        theta, weight = graded_gauss_on(end, other)
    assert abs(np.sum(weight * theta**0.5) - exact) > 1e-6 * exact
    theta, weight = graded_gauss_on(end, other)
    assert abs(np.sum(weight * theta**0.5) - exact) < 1e-9 * exact


def test_smooth_integrand_and_rule_restored():
    """A smooth integrand (cos) to round-off; contact_rule restores the rule on leaving, even after an error, and
    refuses nonsense."""
    end, other = np.array([0.9]), np.array([-0.2])
    with contact_rule(8, 3):
        assert graded_gauss_on(end, other)[0].shape == (1, 8)
    theta, weight = graded_gauss_on(end, other)
    assert np.sum(weight * np.cos(theta)) == pytest.approx(math.sin(0.9) - math.sin(-0.2), rel=1e-13)
    with pytest.raises(RuntimeError):
        with contact_rule(4, 2):
            raise RuntimeError("inside")
    assert graded_gauss_on(end, other)[0].shape == (1, CONTACT_POINTS)
    for points, power in ((0, 2), (24, 0), (2.5, 2)):
        with pytest.raises(ValueError, match="whole numbers"):
            with contact_rule(points, power):
                pass
