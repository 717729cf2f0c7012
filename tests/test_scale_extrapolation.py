"""Extrapolation to zero particle size against known lines, and its standard errors against their spread over
many noisy draws (several seeds)."""

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.scale_extrapolation import extrapolate_to_zero_size

SIZES = np.repeat([0.008, 0.0064, 0.00512], 2)  # three sizes, two seeds each


def test_an_exact_line_is_recovered_and_its_scale_error_is_the_slope_times_the_size():
    q = 30e3 - 2.5e6 * SIZES  # 30 kPa at d = 0, 20 kPa at 4 mm
    fit = extrapolate_to_zero_size(SIZES, q)
    assert fit.value == pytest.approx(30e3, rel=1e-12)
    assert fit.slope == pytest.approx(-2.5e6, rel=1e-12)
    assert fit.value_se == pytest.approx(0.0, abs=1e-6)
    change, se = fit.change(0.008)
    assert change == pytest.approx(-20e3, rel=1e-12)
    assert fit.relative_change(0.008)[0] == pytest.approx(-2.0 / 3.0, rel=1e-12)
    assert not fit.converged(0.008, 0.1)
    assert extrapolate_to_zero_size(SIZES, np.full(SIZES.size, 5.0)).converged(0.008, 0.1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_standard_errors_match_the_spread_of_repeated_studies(seed):
    rng = np.random.default_rng(seed)
    truth, slope, noise = 30e3, -1e6, 500.0
    fits = [extrapolate_to_zero_size(SIZES, truth + slope * SIZES + rng.normal(0, noise, SIZES.size))
            for _ in range(2000)]
    values = np.array([f.value for f in fits])
    assert values.mean() == pytest.approx(truth, abs=4 * values.std() / np.sqrt(len(fits)))
    # the mean reported standard error (sigma estimated from 4 dof) against the actual spread, within 10 %
    rms_se = np.sqrt(np.mean([f.value_se ** 2 for f in fits]))
    assert rms_se == pytest.approx(values.std(), rel=0.1)
    # a two-sided 95 % t interval (4 dof: t = 2.776) covers the truth about 95 % of the time
    cover = np.mean([abs(f.value - truth) <= 2.776 * f.value_se for f in fits])
    assert 0.93 <= cover <= 0.97


def test_too_few_points_or_one_size_are_refused():
    with pytest.raises(WheelsoilInputError, match="three finite results over two sizes"):
        extrapolate_to_zero_size([0.008, 0.0064], [1.0, 2.0])
    with pytest.raises(WheelsoilInputError, match="three finite results over two sizes"):
        extrapolate_to_zero_size([0.008] * 3, [1.0, 2.0, 3.0])
    with pytest.raises(WheelsoilInputError, match="three finite results"):
        extrapolate_to_zero_size([0.008, 0.0064, 0.005], [1.0, np.nan, 2.0])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_weighted_fit_with_known_errors_covers_the_truth_and_scales_up_for_lack_of_fit(seed):
    """One run per level with its own standard error (a convergence study's three particle levels): the errors
    propagate, and a series that scatters beyond them (or bends) gets its error scaled by the Birge ratio."""
    rng = np.random.default_rng(seed)
    sizes = np.array([0.0375, 0.03, 0.024])
    truth, slope = -600.0, 4000.0
    errors = np.array([10.0, 12.0, 15.0])
    fits = [extrapolate_to_zero_size(sizes, truth + slope * sizes + rng.normal(0, errors), errors)
            for _ in range(3000)]
    values = np.array([f.value for f in fits])
    assert values.mean() == pytest.approx(truth, abs=4 * values.std() / np.sqrt(len(fits)))
    # the scaled errors are never below the propagated ones, so the 2-sigma interval covers at least ~95 %
    unscaled = extrapolate_to_zero_size(sizes, truth + slope * sizes, errors).value_se
    assert unscaled == pytest.approx(values.std(), rel=0.1)
    cover = np.mean([abs(f.value - truth) <= 2.0 * f.value_se for f in fits])
    assert cover >= 0.94
    # a curved series (quadratic in d) far beyond its errors: the Birge ratio grows the error with it
    bent = extrapolate_to_zero_size(sizes, truth + slope * sizes + 2e6 * sizes ** 2, errors)
    assert bent.birge > 3.0 and bent.value_se > 3.0 * unscaled


def test_two_levels_with_errors_extrapolate_with_propagated_errors():
    fit = extrapolate_to_zero_size([0.02, 0.01], [3.0, 2.0], [0.1, 0.1])
    assert fit.value == pytest.approx(1.0) and fit.slope == pytest.approx(100.0)
    # q0 = 2 q(0.01) - q(0.02): sd = sqrt(4 + 1) x 0.1
    assert fit.value_se == pytest.approx(np.sqrt(5.0) * 0.1)
    assert fit.birge == 1.0 and fit.dof == 0
