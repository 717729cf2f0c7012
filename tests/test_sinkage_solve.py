"""The sinkage solve of vertical equilibrium (validation/sinkage_solve.py) against closed-form roots: a power-law
pressure-sinkage F_z = k z^n has the root z = (W / k)^(1 / n). Cold and warm solves must agree to the tolerance,
a warm start near the root must take few evaluations, and a bad warm start must cost evaluations, not the answer."""

from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.validation.sinkage_solve import SinkageWarmStart, solve_sinkage
from wheelsoil.validation.terramechanics import RigidWheel, SoilParameters, predict

Z_MAX = 0.05
TOLERANCE = 1e-10


def random_power_laws(seed, count, log_k=(4, 7), n=(0.5, 1.6), load=(5.0, 500.0)):
    """``count`` power laws F_z = k z^n with k, n and W drawn uniformly (k in log) from the given ranges: k, n, W."""
    rng = np.random.default_rng(seed)
    return 10 ** rng.uniform(*log_k, count), rng.uniform(*n, count), rng.uniform(*load, count)


def power_law(k, n, load):
    """excess(z, rows) for F_z = k z^n - W, and the closed-form roots."""
    def excess(z, rows):
        return k[rows] * z ** n[rows] - load[rows]
    return excess, (load / k) ** (1.0 / n)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cold_solve_finds_the_closed_form_root_and_flags_unsupported_loads(seed):
    count = 200
    k, n, load = random_power_laws(seed, count)
    excess, root = power_law(k, n, load)
    sol = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE)
    carried = k * Z_MAX ** n >= load
    assert 0 < carried.sum() < count  # both kinds of condition are drawn
    np.testing.assert_array_equal(sol.supported, carried)
    # |F_z - W| <= tol W bounds the root's error by tol W / (dF_z/dz) = tol z / n
    np.testing.assert_allclose(sol.sinkage[carried], root[carried], rtol=TOLERANCE / 0.5 * 10)
    assert np.all(sol.sinkage[~carried] == Z_MAX)


@pytest.mark.parametrize("seed", [3, 4])
def test_a_warm_start_near_the_root_takes_few_evaluations_and_agrees_with_a_cold_solve(seed):
    count = 100
    k, n, load = random_power_laws(seed, count, log_k=(5, 6), n=(0.6, 1.4), load=(10.0, 100.0))
    warm = SinkageWarmStart()
    excess, _ = power_law(k, n, load)
    first = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE, warm=warm)
    assert first.supported.all()
    # the next call of a finite-difference Jacobian: the soil moved by a relative step of 1e-4
    k2 = k * (1.0 + 1e-4)
    excess2, root2 = power_law(k2, n, load)
    cold = solve_sinkage(excess2, load, Z_MAX, tolerance=TOLERANCE)
    hot = solve_sinkage(excess2, load, Z_MAX, tolerance=TOLERANCE, warm=warm)
    np.testing.assert_allclose(hot.sinkage, root2, rtol=1e-9)
    np.testing.assert_allclose(hot.sinkage, cold.sinkage, rtol=1e-9)
    assert hot.evaluations.max() <= 3 < cold.evaluations.mean()
    np.testing.assert_array_equal(warm.sinkage, hot.sinkage)


@pytest.mark.parametrize("seed", [5, 6])
def test_a_bad_warm_start_costs_evaluations_not_the_answer(seed):
    count = 100
    k, n, load = random_power_laws(seed, count)
    excess, root = power_law(k, n, load)
    rng = np.random.default_rng(seed + 100)
    warm = SinkageWarmStart(sinkage=rng.uniform(0.0, 2 * Z_MAX, count), stiffness=rng.uniform(-1e6, 1e6, count))
    hot = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE, warm=warm)
    cold = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE)
    np.testing.assert_array_equal(hot.supported, cold.supported)
    ok = cold.supported
    np.testing.assert_allclose(hot.sinkage[ok], root[ok], rtol=TOLERANCE / 0.5 * 10)
    assert np.all(hot.sinkage[~ok] == Z_MAX)
    # a warm start over another number of conditions is ignored, not misapplied
    short = SinkageWarmStart(sinkage=np.full(3, 0.01), stiffness=np.full(3, 1e5))
    again = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE, warm=short)
    np.testing.assert_array_equal(again.sinkage, cold.sinkage)


def test_predict_warm_and_cold_agree_on_the_wheel_model():
    """The whole model: a CMU-sized grousered wheel over slips -1 to 0.9 and 0-90 deg, solved cold, then warm
    after the soil's friction angle moved by a finite-difference step."""
    wheel = RigidWheel(radius=0.058, width=0.05, grouser_height=0.005, grouser_count=20)
    soil = SoilParameters(cohesion=200.0, friction_angle=33.0, kc_prime=20.0, kphi_prime=800.0, n0=1.0,
                          shear_modulus_x=0.01, shear_modulus_y=0.01, density=1330.0)
    travel = np.tile(np.linspace(-1.0, 0.9, 8), 4)
    beta = np.repeat([0.0, 30.0, 60.0, 90.0], 8)
    warm = SinkageWarmStart()
    predict(soil, wheel, travel_slip=travel, slip_angle=beta, load=20.0, warm_start=warm)
    moved = replace(soil, friction_angle=33.0 * (1 + 1e-4))
    cold = predict(moved, wheel, travel_slip=travel, slip_angle=beta, load=20.0)
    hot = predict(moved, wheel, travel_slip=travel, slip_angle=beta, load=20.0, warm_start=warm)
    assert cold["supported"].all()
    np.testing.assert_allclose(hot["vertical_force"], 20.0, rtol=1e-9)
    for q in ("sinkage", "drawbar_pull", "lateral_force", "torque"):
        np.testing.assert_allclose(hot[q], cold[q], rtol=1e-7, atol=1e-9 * np.abs(cold[q]).max())


def test_a_condition_the_model_cannot_evaluate_ends_unsupported_not_in_an_endless_loop():
    """F_z NaN (a soil outside the model's domain) for one condition: it is reported unsupported at z_max, as the
    solve before the warm start did, and the others are solved."""
    k, n, load = np.array([1e5, np.nan, 2e5]), np.array([1.0, 1.0, 1.2]), np.array([50.0, 50.0, 80.0])
    excess, root = power_law(k, n, load)
    for warm in (None, SinkageWarmStart(sinkage=np.full(3, 0.01), stiffness=np.full(3, 1e4))):
        sol = solve_sinkage(excess, load, Z_MAX, tolerance=TOLERANCE, warm=warm)
        np.testing.assert_array_equal(sol.supported, [True, False, True])
        assert sol.sinkage[1] == Z_MAX
        np.testing.assert_allclose(sol.sinkage[[0, 2]], root[[0, 2]], rtol=1e-9)
