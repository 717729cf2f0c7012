"""The honest baseline (issue 18, item 1) and the lack-of-fit test the selection stands on: what the data can
identify, parameters at bounds or of the wrong sign, and a residual test that is quiet on noise and names the
condition a systematic error follows."""

from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.validation import synthetic as syn
from wheelsoil.validation.calibration import calibrate_baseline, response_scales
from wheelsoil.validation.discovery import Candidate, _parameter_problems
from wheelsoil.validation.extensions import BASELINE_FREE, BASELINE_OFF, EXTENSIONS, Parameter
from wheelsoil.validation.measured import Measurements
from wheelsoil.validation.residuals import LACK_OF_FIT_ALPHA, systematic_residual, unexplained_trends
from wheelsoil.validation.terramechanics import SoilParameters

RESPONSES = ("drawbar_pull", "lateral_force", "sinkage", "torque")


def _baseline(data):
    return calibrate_baseline(data, replace(SoilParameters(), **BASELINE_OFF), RESPONSES, response_scales(data, RESPONSES))


def test_the_baseline_frees_every_soil_parameter_the_data_can_inform():
    names = {p.name for p in BASELINE_FREE}
    assert {"kc_prime", "kphi_prime", "n0", "cohesion", "friction_angle", "shear_modulus_x", "a1"} <= names
    # the synthetic truth lies inside the calibrated space: every free parameter within its bounds
    for p in BASELINE_FREE:
        assert p.lower <= getattr(syn.TRUE_SOIL, p.name) <= p.upper, p.name


@pytest.mark.parametrize("seed", [0, 1])
def test_fisher_information_flags_kc_and_kphi_unidentified_at_one_gravity(seed):
    """Reece's pressure (c k'_c + rho g b k'_phi)(r/b)^n: with one gravity level and one wheel width only the sum is
    seen, so k'_c and k'_phi cannot be told apart; a second gravity level separates them (seed 000 eq. 3)."""
    one = syn.synthetic_measurements({}, np.random.default_rng(seed), cond=syn.conditions(gravities=(9.81,)))
    assert set(_baseline(one).unidentified()) == {"kc_prime", "kphi_prime"}
    two = syn.synthetic_measurements({}, np.random.default_rng(seed), cond=syn.conditions())
    fit = _baseline(two)
    assert fit.unidentified() == {}
    table = {r["name"]: r for r in fit.parameter_table()}
    assert all(r["identified"] for r in table.values())
    # and the identified values are the truth's within a few standard errors
    for name in ("kc_prime", "friction_angle", "n0"):
        assert abs(table[name]["value"] - getattr(syn.TRUE_SOIL, name)) < 4 * table[name]["std_error"], name


def test_at_bound_and_opposite_sign_are_not_a_physical_mechanism():
    p = Parameter("n1", -0.3, 1.5, sign=1)
    assert p.at_bound(-0.3) == "lower" and p.at_bound(1.5) == "upper" and p.at_bound(0.4) is None
    log = Parameter("kphi_prime", 10.0, 1e5, log=True)
    assert log.at_bound(10.0) == "lower" and log.at_bound(1e5 * (1 - 1e-6)) == "upper" and log.at_bound(500) is None

    class FakeFit:
        def __init__(self, value, binding=None):
            self.free, self.binding = {"cohesion_gravity_exponent": value}, binding or {}

        def binding_bounds(self):
            return self.binding

    ext = EXTENSIONS["gravity_cohesion"]
    problems = _parameter_problems(ext, FakeFit(-0.6))
    assert len(problems) == 1 and "opposite of the mechanism" in problems[0]
    assert "upper bound" in _parameter_problems(ext, FakeFit(3.0, {"cohesion_gravity_exponent": "upper"}))[0]
    assert _parameter_problems(ext, FakeFit(3.0)) == []  # resting on a bound that does not bind: one-sided
    assert _parameter_problems(ext, FakeFit(1.2)) == []


@pytest.mark.parametrize("pull,binds", [(1.0, True), (0.0, False)])
def test_a_bound_binds_only_when_the_data_push_against_it(pull, binds):
    """A parameter at its upper bound: the residuals r = r0 - pull * J x (x past the bound) fall when x grows
    only if ``pull`` > 0; with a flat profile (no pull) the bound does not bind."""
    from wheelsoil.validation.calibration import Fit

    rng = np.random.default_rng(0)
    n = 200
    col = rng.standard_normal(n)
    noise = 0.1 * rng.standard_normal(n)
    noise -= col * (col @ noise) / (col @ col)  # no accidental pull from the noise
    residuals = noise - pull * 0.5 * col  # gradient J^T r = -pull * 0.5 |J|^2 < 0: the SSE falls past the bound
    fit = Fit(None, {"x": 1.0}, residuals, True, parameters=(Parameter("x", 0.0, 1.0),), jacobian=col[:, None])
    assert fit.at_bounds() == {"x": "upper"}
    assert (fit.binding_bounds() == {"x": "upper"}) is binds
    assert fit.parameter_table()[0]["bound_binds"] is binds


def test_every_mechanism_with_a_two_sided_range_declares_its_sign():
    for ext in EXTENSIONS.values():
        for p in ext.parameters:
            off = ext.off[p.name]
            if p.lower < off < p.upper:
                assert p.sign in (-1, 1), (ext.name, p.name)


def _grid_data(rng, n_noise=0.1, signal=None):
    cond = syn.conditions()
    n = cond["slip"].size
    data = Measurements("grid", cond["slip"], cond["slip_angle"], cond["load"], cond["gravity"], np.full(n, 0.15),
                        np.full(n, 0.12), np.zeros(n), np.zeros(n), np.full(n, "g"), responses={},
                        passes=cond["passes"])
    res = n_noise * rng.standard_normal(n)
    if signal is not None:
        res = res + signal(data)
    return data, {"drawbar_pull": res}, {"drawbar_pull": np.ones(n, bool)}


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_lack_of_fit_is_quiet_on_noise(seed):
    """Pure noise: the F statistic follows F(p, n - p - 1), so p falls below the unexplained cut-off (1e-3 / 4
    here) one time in 4,000; five fixed seeds all above it."""
    data, res, rows = _grid_data(np.random.default_rng(seed))
    lack = systematic_residual(res, data, rows)
    assert lack["responses"]["drawbar_pull"]["p_value"] > LACK_OF_FIT_ALPHA / 4
    assert unexplained_trends(lack, []) == []


def test_lack_of_fit_p_values_are_uniform_on_noise():
    """Calibration of the test: over 200 noise draws the p-values are uniform (Kolmogorov-Smirnov p > 0.001)."""
    from scipy.stats import kstest

    rng = np.random.default_rng(123)
    ps = []
    for _ in range(200):
        data, res, rows = _grid_data(rng)
        ps.append(systematic_residual(res, data, rows)["responses"]["drawbar_pull"]["p_value"])
    assert kstest(ps, "uniform").pvalue > 1e-3


@pytest.mark.parametrize("condition,signal", [
    ("gravity", lambda d: 0.3 * (d.gravity < 5)),
    ("slip", lambda d: 0.6 * (d.slip - 0.4) ** 2 / 0.12),
    ("slip_angle", lambda d: 0.01 * d.slip_angle),
])
def test_a_systematic_error_is_reported_with_the_condition_it_follows(condition, signal):
    data, res, rows = _grid_data(np.random.default_rng(5), signal=signal)
    lack = systematic_residual(res, data, rows)
    assert lack["responses"]["drawbar_pull"]["p_value"] < 1e-8
    (u,) = unexplained_trends(lack, [])
    assert u["condition"] == condition and u["share"] > 0.5
    assert u["text"].startswith(f"error in drawbar pull trends with {condition.replace('_', ' ')}")


def test_a_candidate_passes_only_with_every_check():
    ext = EXTENSIONS["slip_sinkage"]

    def cand(**kw):
        base = dict(extension=ext, step=0, fit=None, heldout_rmse=0.1, gain=0.05, gain_std=0.01, delta_bic=-50.0,
                    effect=0.2, explained=0.9)
        return Candidate(**{**base, **kw})

    assert cand().passes and cand().reasons() == []
    assert not cand(delta_bic=-5.0).passes
    # the prediction check: the held-out error may not rise by more than GAIN_SIGMAS bootstrap standard deviations
    assert cand(gain=0.008).passes and cand(gain=-0.009).passes  # within one standard deviation either way
    assert not cand(gain=-0.011).passes and not cand(gain=-0.02, gain_std=0.001).passes
    assert "held-out gain -0.0110 ± 0.0100" in cand(gain=-0.011).reasons()[0]
    # a pair needs each member: one that adds nothing to the other alone is a passenger
    pair = cand(partner=EXTENSIONS["soil_flow"], needs={"soil_flow": -30.0, "slip_sinkage": -12.0})
    assert pair.passes and pair.names == ["slip_sinkage", "soil_flow"] and pair.name == "slip_sinkage + soil_flow"
    passenger = cand(partner=EXTENSIONS["soil_flow"], needs={"soil_flow": -3.0, "slip_sinkage": -40.0})
    assert not passenger.passes and "soil_flow adds ΔBIC -3.0" in passenger.reasons()[1]
    assert not cand(explained=0.3).passes
    assert not cand(problems=["n1 = 1.5 at its upper bound"]).passes
    assert "removes 30 %" in cand(explained=0.3).reasons()[0]
