"""A fit's Jacobian through the sinkage (implicit differentiation) against differences of the whole prediction."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize._numdiff import approx_derivative

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation import calibration as cal
from wheelsoil.validation import synthetic as syn
from wheelsoil.validation.extensions import BASELINE_FREE
from wheelsoil.validation.fit_jacobian import forward_steps, model_jacobian


def _problem(seed: int, shear_form: str):
    rng = np.random.default_rng(seed)
    data = syn.synthetic_measurements({}, rng, cond=syn.whole_domain_conditions())
    start = replace(syn.TRUE_SOIL, n0=0.9, a1=0.3, c3=0.1, shear_form=shear_form)
    scales = cal.response_scales(data, cal.RESPONSES)

    def soil_of(x):
        values = {p.name: p.from_fit(v) for p, v in zip(BASELINE_FREE, x)}
        return replace(start, **values, shear_modulus_y=values["shear_modulus_x"])

    lo, hi = np.array([p.fit_bounds for p in BASELINE_FREE]).T
    x = np.array([p.to_fit(getattr(start, p.name)) for p in BASELINE_FREE])
    return data, scales, soil_of, x, lo, hi


@pytest.mark.parametrize("seed, shear_form", [(3, "independent"), (4, "resultant")])
def test_jacobian_through_the_sinkage_matches_central_differences_of_the_prediction(seed, shear_form):
    """Every column of the whole-domain synthetic set's Jacobian (driving, braking, dragged and 90 deg rows; all seven
    baseline parameters) within 1e-3 of a central difference of the whole prediction (step 1e-3, whose truncation
    error is about 1e-6), as close as the forward difference scipy used before (both carry an O(1e-4) truncation)."""
    data, scales, soil_of, x, lo, hi = _problem(seed, shear_form)

    def residual(v):
        return cal.normalised_residuals(soil_of(v), data, cal.RESPONSES, scales)

    reference = approx_derivative(residual, x, method="3-point", rel_step=1e-3, bounds=(lo, hi))
    forward = approx_derivative(residual, x, method="2-point", rel_step=1e-4, bounds=(lo, hi))
    derivative, invalid = model_jacobian(soil_of, x, forward_steps(x, lo, hi, 1e-4), data,
                                         cal.wheel_predictions(soil_of(x), data))
    implicit = cal.residuals_of(derivative, data, cal.RESPONSES, scales)
    assert not invalid.any()
    norm = np.linalg.norm(reference, axis=0)
    assert np.all(np.linalg.norm(implicit - reference, axis=0) < 1e-3 * norm)
    assert np.max(np.linalg.norm(implicit - reference, axis=0) / norm) < 10 * np.max(
        np.linalg.norm(forward - reference, axis=0) / norm)


def test_forward_steps_turn_back_at_a_bound():
    """scipy's two-point steps: rel_step sign(x) max(1, |x|), reversed where the step would leave the bounds."""
    lo, hi = np.array([0.0, -5.0, 0.0]), np.array([1.0, 5.0, 1.0])
    x = np.array([0.5, -2.0, 1.0])
    np.testing.assert_allclose(forward_steps(x, lo, hi, 1e-4), [1e-4, -2e-4, -1e-4], rtol=1e-9)


def test_a_step_outside_the_models_domain_is_flagged():
    """A step whose soil the model refuses (here a1 + a2 > 1) is flagged and its column left to the caller
    (calibrate gives it the difference a forward step would see)."""
    data, scales, soil_of, x, lo, hi = _problem(5, "independent")
    steps = forward_steps(x, lo, hi, 1e-4)
    k = [p.name for p in BASELINE_FREE].index("a1")

    def soil_refused_past_x(v):
        soil = soil_of(v)
        return replace(soil, a2=1.0) if v[k] != x[k] else soil  # a1 > 0, so a1 + a2 > 1: refused

    with pytest.raises(WheelsoilInputError, match="theta_m outside the contact"):
        soil_refused_past_x(x + steps[k] * np.eye(x.size)[k])
    derivative, invalid = model_jacobian(soil_refused_past_x, x, steps, data,
                                         cal.wheel_predictions(soil_of(x), data))
    assert invalid.tolist() == [j == k for j in range(x.size)]
    assert np.all(derivative["drawbar_pull"][:, k] == 0.0) and np.any(derivative["drawbar_pull"] != 0.0)


def test_a_fit_lands_where_the_difference_jacobian_lands():
    """The same fit with either Jacobian (the default through the sinkage, scipy's forward differences as before) ends
    at the same SSE to 1e-6 and the same parameters to 1e-3; an unknown Jacobian is refused by name."""
    data, scales, soil_of, x, lo, hi = _problem(7, "independent")
    start = replace(syn.TRUE_SOIL, a1=0.2, n0=0.8, friction_angle=30.0, cohesion=100.0, kphi_prime=500.0, kc_prime=20.0)
    fits = [cal.calibrate(data, start, BASELINE_FREE, responses=cal.RESPONSES, scales=scales, jacobian=j)
            for j in cal.JACOBIANS]
    assert all(f.success for f in fits)
    assert fits[0].sse == pytest.approx(fits[1].sse, rel=1e-6)
    for name, value in fits[1].free.items():
        assert fits[0].free[name] == pytest.approx(value, rel=1e-3), name
    with pytest.raises(WheelsoilInputError, match="jacobian = 'analytic'"):
        cal.calibrate(data, start, BASELINE_FREE, responses=cal.RESPONSES, scales=scales, jacobian="analytic")
