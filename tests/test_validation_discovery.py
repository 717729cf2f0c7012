"""Hidden-effect tests: synthetic measurements from the classical model plus one mechanism the workflow is
not told about (magnitude drawn at random, realistic noise); it must name the mechanism, recover it, and
show a positive held-out gain -- and find nothing when nothing is hidden."""

from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.discovery import discover, holdout_mask, mechanism_effect
from wheelsoil.validation.extensions import EXTENSIONS
from wheelsoil.validation.synthetic import (
    HIDDEN_RANGES,
    TRUE_SOIL,
    conditions,
    draw_hidden_effect,
    synthetic_measurements,
)

#: Parameters the data fix directly, with the absolute tolerance of their recovery. The scale-type
#: parameters (sidewall, grouser) and the gravity exponent of cohesion trade against cohesion and friction
#: in their formulas (or saturate: c g^kappa is small at 1/6 g for any kappa > 1), so for them the recovered
#: quantity is the mechanism's effect on the responses (below).
DIRECT_TOLERANCE = {"n1": 0.1, "a2": 0.06, "soil_flow": 0.05, "radius_scale": 0.05, "bulldozing_scale": 0.08,
                    "multipass_k2": 0.03}
#: Relative tolerance of the recovered effect (RMS of the normalised responses the mechanism adds). The
#: gravity exponent of cohesion saturates (c (1/6)^kappa is small for any kappa > 1) and trades against the
#: Earth cohesion, so its effect is known to 40 %.
EFFECT_TOLERANCE = {"gravity_cohesion": 0.4}
DEFAULT_EFFECT_TOLERANCE = 0.3


#: Random seed of each mechanism's hidden-effect draw (new mechanisms are appended: the draws of the others
#: do not change when one is added).
DRAW_SEEDS = {name: 100 + k for k, name in enumerate(
    ["gravity_cohesion", "grouser", "sidewall", "slip_sinkage", "soil_flow", "surrogate_radius", "theta_m_slip",
     "bulldozing", "multipass"])}


def test_every_hidden_mechanism_has_a_draw_seed():
    assert set(DRAW_SEEDS) == set(HIDDEN_RANGES)


@pytest.mark.slow
@pytest.mark.parametrize("mechanism", sorted(HIDDEN_RANGES))
def test_hidden_mechanism_is_named_recovered_and_gains_on_heldout_data(mechanism):
    rng = np.random.default_rng(DRAW_SEEDS[mechanism])
    name, hidden = draw_hidden_effect(rng, [mechanism])
    data = synthetic_measurements(hidden, rng)
    d = discover(data, seed=1)
    found = d.found
    assert found is not None, f"nothing found; hidden {name} {hidden}"
    assert found.extension.name == name, (found.extension.name, name, hidden)
    (param, true), = hidden.items()
    if param in DIRECT_TOLERANCE:
        assert found.fit.free[param] == pytest.approx(true, abs=DIRECT_TOLERANCE[param])
    truth = mechanism_effect(replace(TRUE_SOIL, **hidden), EXTENSIONS[name], data, d.responses, d.scales)
    assert found.effect == pytest.approx(truth, rel=EFFECT_TOLERANCE.get(name, DEFAULT_EFFECT_TOLERANCE))
    assert found.gain > 0 and found.delta_bic < -10


@pytest.mark.slow
def test_grouser_tip_radius_is_named_in_a_two_wheel_set():
    """The shearing radius at the grouser tips acts only on a grousered wheel; with one wheel it is the same as a
    larger radius (the surrogate radius), so it is hidden in a set of the grousered wheel and its smooth twin,
    as the CMU rig tests both. It must be named over every other candidate, with its fraction recovered."""
    from wheelsoil.validation.synthetic import TWO_WHEEL_HIDDEN_RANGES, synthetic_two_wheel_measurements

    rng = np.random.default_rng(200)
    hidden = {k: float(rng.uniform(*b)) for k, b in TWO_WHEEL_HIDDEN_RANGES["grouser_tip_radius"].items()}
    d = discover(synthetic_two_wheel_measurements(hidden, rng), seed=1)
    assert d.found is not None and d.found.extension.name == "grouser_tip_radius", hidden
    assert d.found.fit.free["grouser_tip_fraction"] == pytest.approx(hidden["grouser_tip_fraction"], abs=0.25)
    assert d.found.gain > 0 and d.found.delta_bic < -10


@pytest.mark.slow
@pytest.mark.parametrize("seed", [7, 8])
def test_nothing_is_found_where_nothing_is_hidden(seed):
    rng = np.random.default_rng(seed)
    data = synthetic_measurements({}, rng)
    d = discover(data, seed=seed)
    assert d.found is None, d.found.to_dict()
    # the classical model then fits to the noise level on held-out conditions
    assert d.baseline_heldout_rmse < 0.15


def test_mechanisms_the_data_cannot_show_are_not_tried():
    rng = np.random.default_rng(3)
    cond = conditions(slip_angles=(0.0,), gravities=(9.81,))
    data = synthetic_measurements({}, rng, cond=cond)
    d = discover(data, seed=0, candidates=["sidewall", "gravity_cohesion", "slip_sinkage"])
    assert set(d.skipped) == {"sidewall", "gravity_cohesion"}
    assert [c.extension.name for c in d.candidates] == ["slip_sinkage"]


def test_holdout_by_level_and_bad_requests():
    data = synthetic_measurements({}, np.random.default_rng(0))
    mask = holdout_mask(data, by="slip_angle", level=30.0)
    assert mask.sum() == np.sum(data.slip_angle == 30.0) > 0
    with pytest.raises(WheelsoilInputError, match="leaves no training or no held-out rows"):
        holdout_mask(data, by="slip_angle", level=45.0)
    with pytest.raises(WheelsoilInputError, match="unknown response"):
        discover(data, responses=["power"])
