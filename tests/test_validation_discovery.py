"""Hidden-effect tests: synthetic measurements from the classical model plus mechanisms the workflow is not told
about (magnitudes drawn at random, realistic noise); it must name each hidden mechanism, recover it, and show a
positive held-out gain; name both of a hidden pair; find nothing when nothing is hidden; and report an effect the
catalogue does not hold as unexplained rather than give it a catalogue name. Rates over many draws are measured by
the campaigns in docs/validation/campaigns.md; these tests cover a few seeds each, fixed in advance."""

from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.discovery import discover, holdout_mask, mechanism_effect
from wheelsoil.validation.extensions import (CATALOGUE_DRIFTS, EXTENSIONS, drift_reference, drift_rivals,
                                              varied_conditions)
from wheelsoil.validation.synthetic import (
    HIDDEN_RANGES,
    LOAD_EFFECTS,
    OUT_OF_CATALOGUE,
    TRUE_SOIL,
    conditions,
    draw_hidden_effect,
    draw_out_of_catalogue,
    load_gravity_conditions,
    synthetic_measurements,
    whole_domain_conditions,
)
from wheelsoil.validation.terramechanics import DRIFT_FIELDS, DRIFT_MEASURES, SoilParameters, drift_conditions

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
#: The pressure modulus with a gravity exponent is A + B g^(1 - eps), A = c k'_c: eps trades against the constant
#: part. In the seed-109 draw k'_c rests on 0 (truth 50), the fit raises eps by 0.04 (0.559 against 0.517, inside
#: the 0.15 checked below), and switching eps off at the fitted k'_phi removes 41 % more than the truth's: the
#: exponent is the recovered quantity, its effect is known to 50 %.
EFFECT_TOLERANCE["gravity_pressure"] = 0.5
DEFAULT_EFFECT_TOLERANCE = 0.3


#: Random seed of each mechanism's hidden-effect draw (new mechanisms are appended: the draws of the others
#: do not change when one is added).
DRAW_SEEDS = {name: 100 + k for k, name in enumerate(
    ["gravity_cohesion", "grouser", "sidewall", "slip_sinkage", "soil_flow", "surrogate_radius", "theta_m_slip",
     "bulldozing", "multipass", "gravity_pressure", "gravity_soil_flow"])}
DIRECT_TOLERANCE.update({"kphi_gravity_exponent": 0.15, "soil_flow_gravity": 0.08})


def test_every_hidden_mechanism_has_a_draw_seed():
    assert set(DRAW_SEEDS) == set(HIDDEN_RANGES)


@pytest.mark.slow
@pytest.mark.parametrize("mechanism", sorted(HIDDEN_RANGES))
def test_hidden_mechanism_is_named_recovered_and_gains_on_heldout_data(mechanism):
    rng = np.random.default_rng(DRAW_SEEDS[mechanism])
    name, hidden = draw_hidden_effect(rng, [mechanism])
    data = synthetic_measurements(hidden, rng)
    d = discover(data, seed=1)
    assert d.found == [name], (d.found, name, hidden)
    found = d.accepted[0]
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
    assert d.found == ["grouser_tip_radius"], hidden
    found = d.accepted[0]
    assert found.fit.free["grouser_tip_fraction"] == pytest.approx(hidden["grouser_tip_fraction"], abs=0.25)
    assert found.gain > 0 and found.delta_bic < -10


@pytest.mark.slow
@pytest.mark.parametrize("seed", [7, 8, 9])
def test_nothing_is_found_where_nothing_is_hidden(seed):
    """Null data from the package's own generator (its truth inside the calibrated space), noise drawn with
    a heteroscedastic part: nothing named, nothing partial, no unexplained trend."""
    rng = np.random.default_rng(seed)
    data = synthetic_measurements({}, rng, noise=rng.uniform(0.01, 0.05), relative_noise=rng.uniform(0.0, 0.04))
    d = discover(data, seed=seed)
    assert d.accepted == [], [c.to_dict() for c in d.accepted]
    assert d.unexplained == [] and d.ambiguities == []
    # the classical model then fits to the noise level on held-out conditions
    assert d.baseline_heldout_rmse < 0.15


@pytest.mark.slow
@pytest.mark.parametrize("seed", [31, 32, 33])
def test_a_hidden_pair_is_named_or_reported_ambiguous_never_misnamed(seed):
    """Two mechanisms hidden together (drawn by the seed): no wrong name, at least one of the two named, and each
    named or inside a reported ambiguity (two candidates the data cannot tell apart). How often both are named
    outright is a rate (goal >= 80 %), measured by the pair campaign in docs/validation/campaigns.md."""
    rng = np.random.default_rng(seed)
    names = list(HIDDEN_RANGES)
    pair = [names[j] for j in rng.choice(len(names), 2, replace=False)]
    hidden = {}
    for name in pair:
        hidden.update(draw_hidden_effect(rng, [name])[1])
    d = discover(synthetic_measurements(hidden, rng), seed=seed)
    ambiguous = {n for group in d.ambiguities for entry in group for n in entry.split(' + ')}
    assert set(d.found) <= set(pair), (d.found, pair, hidden)
    assert d.found and all(n in d.found or n in ambiguous for n in pair), (d.found, pair, d.ambiguities, hidden)


@pytest.mark.slow
def test_a_mechanism_a_drift_withholds_is_named_beside_its_partner_in_context():
    """theta_m_slip beside grousers, over the rig's whole domain (braking and dragged rows): alone on the classical
    model, theta_m_slip loses to a pressure modulus drifting with the signed slip, which absorbs part of the unmodelled
    grousers' thrust (docs/validation/campaigns.md, pair-93). Tried again in a pair with grouser, the drift is refitted
    with the grousers in the model, and both are named, nothing else (magnitudes mid-range, seed fixed before the test
    first ran; how often this happens over draws is the pair campaign's rate)."""
    rng = np.random.default_rng(5)
    hidden = {"a2": 0.35, "grouser_scale": 2.0}
    data = synthetic_measurements(hidden, rng, noise=0.03, relative_noise=0.02, cond=whole_domain_conditions())
    d = discover(data, seed=5)
    assert sorted(d.found) == ["grouser", "theta_m_slip"], (d.found, d.ambiguities, [s.to_dict()["accepted"]
                                                                                       for s in d.steps])
    assert not d.ambiguities


#: Random seed of each out-of-catalogue effect's draw (new effects are appended, so the others' draws stay).
OOC_SEEDS = {name: 40 + k for k, name in enumerate(
    ["cohesion_slip_softening", "density_load", "friction_gravity", "friction_steering", "shear_modulus_load",
     "friction_slip_peak", "friction_slip_steering"])}


#: The effects that follow the load, drawn in the design where load and gravity vary independently (seeds fixed
#: before the test first ran).
LOAD_SEEDS = {"friction_load": 61, "cohesion_load": 62, "kphi_load": 63}


def test_every_out_of_catalogue_effect_has_a_draw_seed():
    assert set(OOC_SEEDS) | set(LOAD_SEEDS) == set(OUT_OF_CATALOGUE)
    assert set(LOAD_SEEDS) <= set(LOAD_EFFECTS)


@pytest.mark.slow
def test_effects_that_follow_the_load_are_not_read_as_gravity_mechanisms():
    """Load and gravity both act through the weight on the wheel; in a design that varies them independently
    (40 / 80 / 160 N at Earth and Moon gravity) an effect that follows the load must not take the name of a gravity
    mechanism: the drifts along the load are rivals too. At most one wrong name in the three draws (at the 5 % goal
    two or more happen with a probability of 0.7 %); the misfit reported in at least two."""
    wrong, reported = [], 0
    for effect, seed in LOAD_SEEDS.items():
        rng = np.random.default_rng(seed)
        name, strength = draw_out_of_catalogue(rng, [effect])
        d = discover(synthetic_measurements({}, rng, effect=(name, strength), cond=load_gravity_conditions()), seed=3)
        if d.found:
            wrong.append((effect, round(strength, 3), d.found))
        reported += bool(d.unexplained or d.partial or d.ambiguities)
    assert len(wrong) <= 1, wrong
    assert reported >= 2, reported


@pytest.mark.slow
def test_effects_outside_the_catalogue_rarely_get_a_catalogue_name():
    """One draw of each effect of forms the catalogue does not hold (a gravity effect through the friction angle,
    a load-dependent shear modulus or density, strain-softening cohesion, friction falling with the slip angle,
    friction peaking with slip, friction lost with slip and slip angle together), seeds fixed in advance. A wrong
    name is a rate, not an impossibility (goal <= 5 %; the ooc campaign in docs/validation/campaigns.md measures
    it): at that rate two or more wrong names in seven draws happen with a probability of 4.4 %, so at most one
    is allowed here. The misfit must be reported (unexplained, partial or ambiguous) in most of the seven."""
    wrong, reported = [], 0
    for effect, seed in OOC_SEEDS.items():
        rng = np.random.default_rng(seed)
        name, strength = draw_out_of_catalogue(rng, [effect])
        d = discover(synthetic_measurements({}, rng, effect=(name, strength)), seed=3)
        if d.found:
            wrong.append((effect, round(strength, 3), d.found))
        reported += bool(d.unexplained or d.partial or d.ambiguities)
    assert len(wrong) <= 1, wrong
    assert reported >= 4, reported


def test_generic_rivals_are_drifts_no_mechanism_states():
    """A mechanism's rivals are the classical parameters drifting with each condition the data vary, less the drifts
    that are catalogue mechanisms (n0 with slip is slip-sinkage, a1 with slip is theta_m_slip): a mechanism is never
    its own rival."""
    assert all(f in DRIFT_FIELDS and c in DRIFT_MEASURES for f, c in CATALOGUE_DRIFTS)
    for name, ext in EXTENSIONS.items():
        rivals = drift_rivals(ext)
        assert set(ext.drifts) <= set(CATALOGUE_DRIFTS)
        assert not set(rivals) & CATALOGUE_DRIFTS, name
        assert {c for _, c in rivals} <= set(ext.acts_through), name
        assert all(c in DRIFT_MEASURES for c in ext.acts_through), name
    assert ("a1", "slip") not in drift_rivals(EXTENSIONS["theta_m_slip"])
    assert ("cohesion", "slip") in drift_rivals(EXTENSIONS["theta_m_slip"])
    assert drift_rivals(EXTENSIONS["grouser"]) == []
    # the workflow fits the drifts along every condition the data vary, whatever the mechanism acts through
    data = synthetic_measurements({}, np.random.default_rng(4))
    varied = varied_conditions(data)
    assert set(varied) == {"slip", "slip_angle", "gravity", "passes", "load"}  # one wheel: radius and width fixed
    assert varied_conditions(data.select(data.load == data.load[0])) == ("slip", "slip_angle", "gravity", "passes")
    for name, ext in EXTENSIONS.items():
        rivals = drift_rivals(ext, varied)
        assert {c for _, c in rivals} == set(varied), name
        assert not set(rivals) & CATALOGUE_DRIFTS, name
    assert ("friction_angle", "load") in drift_rivals(EXTENSIONS["gravity_cohesion"], varied)
    # braking rows: the signed slip is a condition of its own, and a rival of theta_m_slip on cohesion, not on a1
    whole = synthetic_measurements({}, np.random.default_rng(4), cond=whole_domain_conditions())
    assert set(varied_conditions(whole)) == set(varied) | {"signed_slip"}
    rivals = drift_rivals(EXTENSIONS["theta_m_slip"], varied_conditions(whole))
    assert ("cohesion", "signed_slip") in rivals and ("a1", "signed_slip") not in rivals
    assert drift_reference(data, "load") == float(np.median(data.load)) and drift_reference(data, "slip") == 1.0


def test_a_signed_slip_drift_grows_on_driving_rows_and_falls_on_braking_ones():
    """p (1 + rate i) in the signed slip i, against |i|: the two agree on a driving row and differ on a braking one."""
    soil = SoilParameters(cohesion=100.0)
    rows = drift_conditions(np.array([-0.5, 0.0, 0.5]), 0.0, 9.81, 1, 90.0, 0.1, 0.1)
    signed = replace(soil, drift_field="cohesion", drift_condition="signed_slip", drift_rate=-0.4)
    absolute = replace(signed, drift_condition="slip")
    np.testing.assert_allclose(signed.drifted("cohesion", rows), [120.0, 100.0, 80.0])
    np.testing.assert_allclose(absolute.drifted("cohesion", rows), [80.0, 100.0, 80.0])


class _Passing:
    """A passing candidate as :meth:`_Search.choose` sees it: its mechanisms' names."""

    def __init__(self, *names):
        self.names = list(names)
        self.name = " + ".join(names)


def _chooser(unresolved: dict):
    """A selection state whose rival checks answer from ``unresolved`` (candidate name -> what it does not beat),
    recording the candidates checked."""
    from wheelsoil.validation.discovery import _Search

    search = _Search.__new__(_Search)
    search.checked = []
    search.unresolved = lambda step, cand, passing: search.checked.append(cand.name) or unresolved.get(cand.name, [])
    return search


@pytest.mark.parametrize("defer", [True, False])
def test_an_unresolved_mechanism_is_deferred_and_the_next_resolved_one_accepted(monkeypatch, defer):
    """_Search.choose: the best passing mechanism that a rival beats is deferred (tried again at the next step) and the
    next resolved one sharing no mechanism with a deferred group is accepted; where none is resolved, the first group
    is the step's ambiguity and selection stops. Without deferral the first unresolved one stops the search."""
    from wheelsoil.validation import discovery
    from wheelsoil.validation.selection import Step

    monkeypatch.setattr(discovery, "DEFER_UNRESOLVED", defer)
    theta, grouser, sinkage, pair = (_Passing("theta_m_slip"), _Passing("grouser"), _Passing("slip_sinkage"),
                                     _Passing("grouser", "bulldozing"))
    drift = {"theta_m_slip": ["kphi_prime ~ signed_slip"]}
    # a drift beats the best: the next one is accepted (deferral), or the search stops on the drift's ambiguity
    step = Step(0, (), 1.0, 1.0, [])
    search = _chooser(drift)
    chosen = search.choose(step, [theta, grouser, sinkage])
    if defer:
        assert chosen is grouser and step.deferred == [["theta_m_slip", "kphi_prime ~ signed_slip"]]
        assert step.ambiguity == [] and search.checked == ["theta_m_slip", "grouser"]
    else:
        assert chosen is None and step.ambiguity == ["theta_m_slip", "kphi_prime ~ signed_slip"]
        assert step.deferred == [] and search.checked == ["theta_m_slip"]
    # a mechanism the deferred one ties with is not accepted in its place, nor a pair holding it
    step = Step(0, (), 1.0, 1.0, [])
    search = _chooser({"theta_m_slip": ["grouser"]})
    chosen = search.choose(step, [theta, pair, grouser, sinkage])
    assert chosen is (sinkage if defer else None)
    assert search.checked == (["theta_m_slip", "slip_sinkage"] if defer else ["theta_m_slip"])
    # none resolved: the first group is the ambiguity, the others stay on record as deferred
    step = Step(0, (), 1.0, 1.0, [])
    search = _chooser({**drift, "slip_sinkage": ["n0 ~ gravity"]})
    assert search.choose(step, [theta, sinkage]) is None
    assert step.ambiguity == ["theta_m_slip", "kphi_prime ~ signed_slip"]
    assert step.deferred == ([["slip_sinkage", "n0 ~ gravity"]] if defer else [])
    # nothing unresolved: the best is accepted, as without deferral
    step = Step(0, (), 1.0, 1.0, [])
    assert _chooser({}).choose(step, [theta, grouser]) is theta and step.deferred == [] and step.ambiguity == []


def test_mechanisms_the_data_cannot_show_are_not_tried():
    rng = np.random.default_rng(3)
    cond = conditions(slip_angles=(0.0,), gravities=(9.81,))
    data = synthetic_measurements({}, rng, cond=cond)
    d = discover(data, seed=0, candidates=["sidewall", "gravity_cohesion", "gravity_pressure", "slip_sinkage"])
    assert set(d.skipped) == {"sidewall", "gravity_cohesion", "gravity_pressure"}
    assert [c.extension.name for c in d.candidates] == ["slip_sinkage"]
    assert d.found == [] and len(d.steps) == 1


def test_discovery_says_what_it_is_fitting():
    """The progress hook hears the classical fit first, then each fit of a step with the model it extends (what the
    command's status line shows)."""
    rng = np.random.default_rng(3)
    data = synthetic_measurements({}, rng, cond=conditions(slip_angles=(0.0,), gravities=(9.81,)))
    heard = []
    discover(data, seed=0, candidates=["slip_sinkage"], progress=heard.append)
    assert heard[0].startswith("fitting the classical model to ")
    assert "step 1: fitting classical + slip_sinkage" in heard[1:]


def test_gravity_pressure_needs_three_gravity_levels():
    """With k'_c free, two gravity levels fix c k'_c + rho g b k'_phi g^-eps at both exactly: the exponent cannot
    be told from the split between k'_c and k'_phi, so the mechanism is not tried; a third level can show it."""
    from wheelsoil.validation.extensions import EXTENSIONS

    two = synthetic_measurements({}, np.random.default_rng(0), cond=conditions(gravities=(9.81, 1.62)))
    three = synthetic_measurements({}, np.random.default_rng(0), cond=conditions())
    assert not EXTENSIONS["gravity_pressure"].applies(two) and EXTENSIONS["gravity_pressure"].applies(three)
    assert EXTENSIONS["gravity_cohesion"].applies(two)


def test_holdout_by_level_and_bad_requests():
    data = synthetic_measurements({}, np.random.default_rng(0))
    mask = holdout_mask(data, by="slip_angle", level=30.0)
    assert mask.sum() == np.sum(data.slip_angle == 30.0) > 0
    with pytest.raises(WheelsoilInputError, match="leaves no training or no held-out rows"):
        holdout_mask(data, by="slip_angle", level=45.0)
    with pytest.raises(WheelsoilInputError, match="unknown response"):
        discover(data, responses=["power"])
    with pytest.raises(WheelsoilInputError, match="unknown candidate"):
        discover(data, candidates=["magic"])
