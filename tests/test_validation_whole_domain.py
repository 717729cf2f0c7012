"""The semi-empirical model over the whole measured domain (issue 36): braking, the dragged wheel and 90 deg of
steering, with the kinematics in velocity components. Each form is held to a closed form or a limit: the linear
soil's integrals (n = 1, theta_m = 0, c = 0) for the fully sliding wheel, continuity through slip 0 and towards
omega = 0 and 90 deg, and the Mohr--Coulomb bound on the shear."""

from dataclasses import replace

import numpy as np
import pytest

from terramechanics_closed_forms import closed_form_integrals, linear_soil
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.slip import WheelSpeeds, heading_slip_from_travel
from wheelsoil.validation.terramechanics import (
    RigidWheel,
    SoilParameters,
    contact_forces,
    janosi_hanamoto,
    predict,
)

WHEEL = RigidWheel(radius=0.15, width=0.15)
SAND = SoilParameters()  # seed 003 Table III, unit 1 (dry sand)
QUANTITIES = ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage")


def _linear_soil(**kw):
    """The linear soil (closed-form stress integrals) without side terms."""
    return linear_soil(SAND, **({"sidewall_scale": 0.0} | kw))


# --- the wheel's speeds ---------------------------------------------------------------------------------------

def test_speeds_from_either_slip_agree_and_are_normalised():
    slips = np.linspace(-1.0, 0.95, 40)
    for beta in (0.0, -20.0, 45.0, 75.0, 89.0):
        from_travel = WheelSpeeds.from_travel_slip(slips, beta)
        back = WheelSpeeds.from_heading_slip(from_travel.heading_slip, beta)
        for key in ("rim", "along", "across"):
            np.testing.assert_allclose(getattr(back, key), getattr(from_travel, key), atol=1e-12)
        np.testing.assert_allclose(back.travel_slip, slips, atol=1e-12)
        # every state in units of max(r omega, V): the larger is 1
        np.testing.assert_allclose(np.maximum(from_travel.rim, from_travel.speed), 1.0, atol=1e-12)
        # v_y = v_x tan(beta) wherever tan(beta) is finite (the architecture's definition)
        np.testing.assert_allclose(from_travel.across, from_travel.along * np.tan(np.radians(beta)), atol=1e-12)
    np.testing.assert_allclose(heading_slip_from_travel(slips, 30.0), WheelSpeeds.from_travel_slip(slips, 30.0).heading_slip)


def test_speeds_at_90_degrees_come_from_the_travel_slip_only():
    at_90 = WheelSpeeds.from_travel_slip([-1.0, -0.5, 0.0, 0.5], 90.0)
    np.testing.assert_array_equal(at_90.along, 0.0)  # no advance along the heading
    np.testing.assert_allclose(at_90.rim, [0.0, 0.5, 1.0, 1.0])
    np.testing.assert_allclose(at_90.across, [1.0, 1.0, 1.0, 0.5])
    np.testing.assert_allclose(at_90.heading_slip, [-1.0, 1.0, 1.0, 1.0])  # dragged: -1 at any angle
    with pytest.raises(WheelsoilInputError, match=r"slip_angle\[1\] = 90 deg.*travel_slip"):
        WheelSpeeds.from_heading_slip([0.2, 0.2], [30.0, 90.0])


# --- the shear law ----------------------------------------------------------------------------------------------

def test_shear_never_exceeds_the_mohr_coulomb_strength():
    j = np.array([-np.inf, -1.0, -0.01, 0.0, 0.01, 1.0, np.inf])
    tau = janosi_hanamoto(2.0, j, 0.01)
    assert np.all(np.abs(tau) <= 2.0)
    np.testing.assert_allclose(tau[[0, -1]], [-2.0, 2.0])
    np.testing.assert_allclose(tau, -tau[::-1])  # odd in j: braking shears as driving does, reversed
    np.testing.assert_allclose(tau[4], 2.0 * (1.0 - np.exp(-1.0)))  # seed 003 eq. 9 where j >= 0


# --- braking and the dragged wheel ------------------------------------------------------------------------------

@pytest.mark.parametrize("beta", [0.0, 30.0, 75.0])
@pytest.mark.parametrize("shear_form", ["independent", "resultant"])
def test_driving_and_braking_meet_at_zero_slip(beta, shear_form):
    """The branches meet continuously at slip 0. Braking at -eps, the resultant form's shear reverses over a sliver
    |theta| < sqrt(2 eps) where the rim moves slower than the ground beneath it, so the model's own outputs differ
    from those at +eps by O(sqrt(eps)) (5e-6 of the drawbar pull at eps = 1e-9, integrated finely), and eps = 1e-13
    keeps that well below the tolerance."""
    soil = replace(SAND, shear_form=shear_form)
    below, above = (predict(soil, WHEEL, slip=s, slip_angle=beta, load=150.0) for s in (-1e-13, 1e-13))
    for q in QUANTITIES:
        assert below[q] == pytest.approx(above[q], rel=1e-6, abs=1e-6), q


def test_braking_uses_the_sources_theta_split_and_exit_angle():
    """Seed 003 uses eq. 8, theta_m = (a1 + a2 i) theta_f, on both branches (a skid formula would jump at i = 0), and
    one exit angle theta_r = -c3 theta_f."""
    soil = replace(SAND, a1=0.4, a2=0.3, c3=0.2)
    i = np.array([-0.9, -0.5, -0.2, 0.0, 0.3])
    out = contact_forces(soil, WHEEL, 0.02, i, 10.0, 9.81)
    np.testing.assert_allclose(out["theta_m"], np.clip(0.4 + 0.3 * i, 0.0, 1.0) * out["theta_f"])
    np.testing.assert_allclose(out["theta_r"], -0.2 * out["theta_f"])


def test_dragged_wheel_slides_fully_on_the_closed_form():
    """omega = 0 at 0 deg: the rim slides back over the whole contact, tau = -sigma tan(phi) (c = 0), so
    F_x = -r b K (mu A + B), F_z = r b K (A - mu B), T = -r^2 b mu K t (the linear soil's integrals)."""
    soil = _linear_soil()
    z, g = 0.03, 9.81
    out = contact_forces(soil, WHEEL, z, -1.0, 0.0, g)
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    mu = np.tan(np.radians(soil.friction_angle))
    a, bb, t = closed_form_integrals(np.arccos(1 - z / r))
    assert out["drawbar_pull"][0] == pytest.approx(-r * b * k * (mu * a + bb), rel=1e-6)
    assert out["vertical_force"][0] == pytest.approx(r * b * k * (a - mu * bb), rel=1e-6)
    assert out["torque"][0] == pytest.approx(-r * r * b * mu * k * t, rel=1e-6)


@pytest.mark.parametrize("shear_form", ["independent", "resultant"])
@pytest.mark.parametrize("beta", [0.0, 40.0, 75.0])
def test_dragged_wheel_is_the_limit_of_a_vanishing_rim_speed(shear_form, beta):
    soil = replace(SAND, shear_form=shear_form, shear_modulus_x=0.002, shear_modulus_y=0.002)
    dragged = predict(soil, WHEEL, travel_slip=-1.0, slip_angle=beta, load=150.0)
    nearly = predict(soil, WHEEL, travel_slip=-1.0 + 1e-7, slip_angle=beta, load=150.0)
    for q in QUANTITIES:
        assert dragged[q] == pytest.approx(nearly[q], rel=1e-4, abs=1e-4), q
    assert np.isfinite(np.concatenate([np.ravel(dragged[q]) for q in QUANTITIES])).all()


def test_dragged_at_90_degrees_is_the_limit_along_the_steering_angle():
    """At 90 deg the heading slip is singular in the rim speed (1 for any, -1 for none), so the dragged wheel there
    is the limit along the angle. The resultant shear is continuous; with no slip-dependent theta_m or exponent
    (a2 = n1 = 0) it is the vanishing rim speed's limit as well."""
    soil = replace(SAND, shear_form="resultant", sidewall_scale=1.0)
    at_90 = predict(soil, WHEEL, travel_slip=-1.0, slip_angle=90.0, load=150.0)
    near = predict(soil, WHEEL, travel_slip=-1.0, slip_angle=90.0 - 1e-6, load=150.0)
    for q in QUANTITIES:
        assert at_90[q] == pytest.approx(near[q], rel=1e-4, abs=1e-4), q
    flat = replace(soil, a2=0.0, n1=0.0)
    dragged = predict(flat, WHEEL, travel_slip=-1.0, slip_angle=90.0, load=150.0)
    turning = predict(flat, WHEEL, travel_slip=-1.0 + 1e-7, slip_angle=90.0, load=150.0)
    for q in QUANTITIES:
        assert dragged[q] == pytest.approx(turning[q], rel=1e-4, abs=1e-4), q


def test_frictionless_soil_resists_only_by_compaction_at_every_slip_and_angle():
    """phi -> 0 and c = 0: no shear, so at a fixed sinkage F_x = -r b K B whatever the wheel does, T = 0 and no
    lateral force (seed 003 eq. 10 with tan phi = 0)."""
    soil = _linear_soil(friction_angle=1e-9)
    z, g = 0.03, 9.81
    travel = np.array([-1.0, -0.6, 0.0, 0.4, 0.9])
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    _, bb, _ = closed_form_integrals(np.arccos(1 - z / r))
    for beta in (0.0, 45.0, 90.0):
        out = contact_forces(soil, WHEEL, z, np.nan, beta, g, travel_slip=travel)
        np.testing.assert_allclose(out["drawbar_pull"], -r * b * k * bb, rtol=1e-6)
        # tan(1e-9 deg) = 2e-11 of the compaction's ~1 kN
        np.testing.assert_allclose(out["torque"], 0.0, atol=1e-6)
        np.testing.assert_allclose(out["lateral_force"], 0.0, atol=1e-6)


# --- 90 deg ----------------------------------------------------------------------------------------------------

def test_dragged_sideways_at_90_degrees_meets_compaction_ahead_and_full_shear_across():
    """At 90 deg and omega = 0 nothing slides along the heading (tau_x = 0) and the wheel slides sideways over the
    whole contact: F_x = -r b K B (compaction only), T = 0, F_y = -sign(beta) r b mu K t (no sidewall term)."""
    soil = _linear_soil()
    z, g = 0.03, 9.81
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    mu = np.tan(np.radians(soil.friction_angle))
    a, bb, t = closed_form_integrals(np.arccos(1 - z / r))
    for shear_form in ("independent", "resultant"):
        out = contact_forces(replace(soil, shear_form=shear_form), WHEEL, z, np.nan, [90.0, -90.0], g,
                             travel_slip=-1.0)
        np.testing.assert_allclose(out["drawbar_pull"], -r * b * k * bb, rtol=1e-6)
        np.testing.assert_allclose(out["vertical_force"], r * b * k * a, rtol=1e-6)
        np.testing.assert_allclose(out["torque"], 0.0, atol=1e-9)
        np.testing.assert_allclose(out["lateral_force"], [-r * b * mu * k * t, r * b * mu * k * t], rtol=1e-6)


@pytest.mark.parametrize("shear_form", ["independent", "resultant"])
@pytest.mark.parametrize("travel", [-0.5, 0.0, 0.5, 0.75])
def test_90_degrees_is_a_regular_case(travel, shear_form):
    soil = replace(SAND, sidewall_scale=1.0, bulldozing_scale=1.0, shear_form=shear_form)
    at_90 = predict(soil, WHEEL, travel_slip=travel, slip_angle=90.0, load=150.0)
    near = predict(soil, WHEEL, travel_slip=travel, slip_angle=90.0 - 1e-6, load=150.0)
    mirrored = predict(soil, WHEEL, travel_slip=travel, slip_angle=-90.0, load=150.0)
    for q in QUANTITIES:
        assert np.isfinite(at_90[q])
        assert at_90[q] == pytest.approx(near[q], rel=1e-4, abs=1e-4), q
        sign = -1.0 if q == "lateral_force" else 1.0
        assert mirrored[q] == pytest.approx(sign * at_90[q], rel=1e-9, abs=1e-9), q
    assert at_90["lateral_force"] < 0.0  # the soil resists the sideways travel (v_y > 0 for beta > 0)


def test_travel_and_heading_slips_give_one_prediction():
    travel = np.array([-1.0, -0.5, -0.1, 0.2, 0.6])
    beta = np.array([10.0, 30.0, 60.0, 75.0, 45.0])
    by_travel = predict(SAND, WHEEL, travel_slip=travel, slip_angle=beta, load=150.0)
    by_heading = predict(SAND, WHEEL, slip=heading_slip_from_travel(travel, beta), slip_angle=beta, load=150.0)
    for q in QUANTITIES:
        np.testing.assert_allclose(by_travel[q], by_heading[q], rtol=1e-7, atol=1e-9)


def test_the_whole_domain_synthetic_design_holds_braking_dragged_and_sideways_rows():
    """The campaigns' whole-domain design (issue 36 item 6): every kind of motion the rig sets, each at every load and
    gravity, its heading slip the one its travel slip gives, and measurements drawn on it kept as such."""
    from wheelsoil.validation.synthetic import SIDEWAYS_SLIPS, WHOLE_DOMAIN_SLIPS, synthetic_measurements, \
        whole_domain_conditions
    cond = whole_domain_conditions()
    n = 4 * len(WHOLE_DOMAIN_SLIPS) * 2 * 3 + len(SIDEWAYS_SLIPS) * 2 * 3
    assert all(np.shape(v) == (n,) for v in cond.values())
    np.testing.assert_allclose(cond["slip"], heading_slip_from_travel(cond["travel_slip"], cond["slip_angle"]))
    data = synthetic_measurements({}, np.random.default_rng(0), cond=cond)
    kinds = data.kinds()
    sideways = data.slip_angle == 90.0
    assert sideways.sum() == len(SIDEWAYS_SLIPS) * 2 * 3
    for kind in ("driving", "braking", "dragged"):
        for at_90 in (False, True):
            rows = (kinds == kind) & (sideways == at_90)
            if kind == "braking" and at_90:
                assert not rows.any()  # at 90 deg the design has a dragged wheel and turning ones only
                continue
            assert rows.any()
            assert set(data.load[rows]) == {60.0, 120.0} and len(set(data.gravity[rows])) == 3
    np.testing.assert_array_equal(data.travel_slip, cond["travel_slip"])
    assert all(np.isfinite(y).all() for y in data.responses.values())


def test_the_five_gravity_design_is_the_whole_domain_at_five_levels_with_the_passes_balanced():
    """The design fixed for the gravity ties (docs/validation/campaigns.md): the whole domain at 1.62-9.81 m/s^2 in five
    levels (seed 000's three among them), every row of the three-level design at each, and the pass number not
    aliased with the gravity (each level sees every pass about equally)."""
    from wheelsoil.validation.synthetic import FIVE_GRAVITY_LEVELS, whole_domain_conditions, \
        whole_domain_five_gravity_conditions
    five, three = whole_domain_five_gravity_conditions(), whole_domain_conditions()
    levels = np.unique(five["gravity"])
    assert len(levels) == 5 and {1.62, 3.71} <= set(levels.tolist()) and np.isclose(levels.max(), 9.81, atol=0.01)
    assert np.all(np.diff(np.log(levels)) < 1.6 * np.log(levels[-1] / levels[0]) / 4)  # none far from even in log g
    assert len(five["slip"]) == len(three["slip"]) // 3 * 5
    for g in FIVE_GRAVITY_LEVELS:
        at = five["gravity"] == g
        rows = sorted(zip(five["travel_slip"][at], five["slip_angle"][at], five["load"][at]))
        assert rows == sorted(zip(three["travel_slip"][three["gravity"] == 1.62],
                                  three["slip_angle"][three["gravity"] == 1.62], three["load"][three["gravity"] == 1.62]))
        counts = np.bincount(five["passes"][at].astype(int), minlength=4)[1:]
        assert counts.max() - counts.min() <= 2


def test_out_of_catalogue_effects_keep_a_valid_soil_on_the_whole_domain_at_their_strongest():
    """Every out-of-catalogue effect at the top of its strength range gives data on the whole domain (five gravity
    levels, the 90 deg rows at slip +-1) without leaving the soil's valid range: `ooc-124` stopped at its draw 26 on a
    friction angle the slip-and-steering law took below zero there."""
    from wheelsoil.validation.synthetic import OUT_OF_CATALOGUE, synthetic_measurements, \
        whole_domain_five_gravity_conditions
    cond = whole_domain_five_gravity_conditions()
    for name, spec in OUT_OF_CATALOGUE.items():
        data = synthetic_measurements({}, np.random.default_rng(1), cond=cond, effect=(name, spec["range"][1]))
        assert all(np.all(np.isfinite(v)) for v in data.responses.values()), name
