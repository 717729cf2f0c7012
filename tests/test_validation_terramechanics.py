"""The semi-empirical wheel--soil model against closed forms, published factors and exact similarities."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad

from terramechanics_closed_forms import closed_form_integrals, linear_soil
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation.extensions import BASELINE_OFF
from wheelsoil.validation.terramechanics import (
    DRIFT_FLOOR,
    RigidWheel,
    SoilParameters,
    bearing_capacity_factors,
    contact_forces,
    predict,
    sidewall_force,
)

WHEEL = RigidWheel(radius=0.15, width=0.15)
SAND = SoilParameters()  # seed 003 Table III, unit 1 (dry sand)


def _linear_soil(**kw):
    """n = 1, theta_m = 0 (no rear region), cohesionless: stress integrals have closed forms."""
    return linear_soil(SAND, **kw)


@pytest.mark.parametrize("sinkage", [0.005, 0.02, 0.06])
def test_pure_compaction_matches_the_closed_form(sinkage):
    """No shear (huge k_x): F_z = r b K A and DP = -r b K B, the compaction resistance (n = 1)."""
    soil = _linear_soil(shear_modulus_x=1e9)
    g = 9.81
    out = contact_forces(soil, WHEEL, sinkage, 0.0, 0.0, g)
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    a, bb, _ = closed_form_integrals(np.arccos(1 - sinkage / r))
    assert out["vertical_force"][0] == pytest.approx(r * b * k * a, rel=1e-9)
    assert out["drawbar_pull"][0] == pytest.approx(-r * b * k * bb, rel=1e-6)


def test_fully_mobilised_shear_matches_the_closed_form():
    """At slip near 1 and a tiny k_x the shear is sigma tan(phi) everywhere (Mohr--Coulomb, c = 0)."""
    soil = _linear_soil(shear_modulus_x=1e-9)
    z, g = 0.03, 9.81
    out = contact_forces(soil, WHEEL, z, 0.999, 0.0, g)
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    mu = np.tan(np.radians(soil.friction_angle))
    a, bb, t = closed_form_integrals(np.arccos(1 - z / r))
    assert out["drawbar_pull"][0] == pytest.approx(r * b * k * (mu * a - bb), rel=1e-6)
    assert out["vertical_force"][0] == pytest.approx(r * b * k * (mu * bb + a), rel=1e-6)
    assert out["torque"][0] == pytest.approx(r * r * b * k * mu * t, rel=1e-6)


def test_resultant_shear_is_the_classical_form_straight_ahead_and_shares_the_strength_sideways():
    """The CMU lab's shear form (``shear_form = "resultant"``, Pavlov's tau_t.m / tau_l.m): at 0 deg and driving
    slip the slip velocity is along the heading, so it is the classical form exactly; fully mobilised (tiny k_x) at
    89.99 deg the whole strength acts along the axle: lateral force r b k mu t (the closed form of the torque's
    integral), no shear along the heading, so drawbar pull is the compaction resistance -r b k int(...) sin and the
    torque vanishes, where the classical form keeps both directions at full strength."""
    for slip in (0.05, 0.3, 0.8):
        for z in (0.01, 0.04):
            a = contact_forces(SAND, WHEEL, z, slip, 0.0, 9.81)
            b_ = contact_forces(replace(SAND, shear_form="resultant"), WHEEL, z, slip, 0.0, 9.81)
            for q in ("drawbar_pull", "vertical_force", "torque"):
                assert b_[q][0] == pytest.approx(a[q][0], rel=1e-12, abs=1e-12)
    soil = _linear_soil(shear_modulus_x=1e-9, shear_modulus_y=1e-9, sidewall_scale=0.0)
    z, g = 0.03, 9.81
    r, b = WHEEL.radius, WHEEL.width
    k = soil.density * g * b * soil.kphi_prime * (r / b)
    mu = np.tan(np.radians(soil.friction_angle))
    a, bb, t = closed_form_integrals(np.arccos(1 - z / r))
    out = contact_forces(replace(soil, shear_form="resultant"), WHEEL, z, 0.5, 89.99, g)
    assert abs(out["lateral_force"][0]) == pytest.approx(r * b * k * mu * t, rel=1e-3)
    assert out["drawbar_pull"][0] == pytest.approx(-r * b * k * bb, rel=1e-3)
    assert abs(out["torque"][0]) < 1e-3 * r * r * b * k * mu * t
    classical = contact_forces(soil, WHEEL, z, 0.5, 89.99, g)
    assert classical["drawbar_pull"][0] == pytest.approx(r * b * k * (mu * a - bb), rel=1e-3)
    with pytest.raises(WheelsoilInputError, match="shear_form = 'sideways'"):
        replace(SAND, shear_form="sideways")


@pytest.mark.parametrize("n0", [1.1, 0.6])
def test_quadrature_matches_adaptive_integration_with_a_rear_region(n0):
    """Default sand (n = 1.1, theta_m = (a1 + a2 i) theta_f, rebound c3), and a sinkage exponent of 0.6, whose stress
    vanishes steeply at both ends: the graded Gauss--Legendre rule vs scipy quad, to 1e-9 (the plain rule with twice
    the nodes missed n = 0.6 by 1e-6: docs/validation/quadrature.md)."""
    soil = replace(SAND, c3=0.2, n0=n0)
    z, i, g = 0.02, 0.3, 9.81
    r, b = WHEEL.radius, WHEEL.width
    out = contact_forces(soil, WHEEL, z, i, 0.0, g)
    tf = np.arccos(1 - z / r)
    tm, tr = (soil.a1 + soil.a2 * i) * tf, -soil.c3 * tf
    n = soil.n0
    k = (soil.cohesion * soil.kc_prime + soil.density * g * b * soil.kphi_prime) * (r / b) ** n

    def sigma(t):
        eq = t if t >= tm else tf - (t - tr) / (tm - tr) * (tf - tm)
        return k * max(np.cos(eq) - np.cos(tf), 0.0) ** n

    def tau(t):
        j = r * (tf - t - (1 - i) * (np.sin(tf) - np.sin(t)))
        return (soil.cohesion + sigma(t) * np.tan(np.radians(soil.friction_angle))) * (1 - np.exp(-j / soil.shear_modulus_x))

    fz = r * b * sum(quad(lambda t: tau(t) * np.sin(t) + sigma(t) * np.cos(t), lo, hi, epsabs=0, epsrel=1e-11)[0]
                     for lo, hi in ((tr, tm), (tm, tf)))
    fx = r * b * sum(quad(lambda t: tau(t) * np.cos(t) - sigma(t) * np.sin(t), lo, hi, epsabs=0, epsrel=1e-11)[0]
                     for lo, hi in ((tr, tm), (tm, tf)))
    assert out["vertical_force"][0] == pytest.approx(fz, rel=1e-9)
    assert out["drawbar_pull"][0] == pytest.approx(fx, rel=1e-9)


def test_terzaghi_factors_match_the_published_table():
    """Coduto (2001) modified Terzaghi factors at phi = 30 deg: N_c = 37.2, N_q = 22.5, N_gamma = 19.7."""
    n_gamma, n_c, n_q = bearing_capacity_factors(30.0)
    assert n_c == pytest.approx(37.2, abs=0.1)
    assert n_q == pytest.approx(22.5, abs=0.1)
    assert n_gamma == pytest.approx(19.7, abs=0.5)


def test_sidewall_force_matches_direct_integration():
    z, beta, g = 0.03, np.radians(20.0), 9.81
    r = WHEEL.radius
    n_gamma, n_c, _ = bearing_capacity_factors(SAND.friction_angle)
    tf = np.arccos(1 - z / r)

    def integrand(x):
        f = np.sqrt(r * r - x * x) - r * np.cos(tf)
        return (SAND.density * g * n_gamma * f + SAND.cohesion * n_c) * f

    expected = np.sin(beta) * quad(integrand, -r * np.sin(tf), r * np.sin(tf), epsrel=1e-11)[0]
    assert sidewall_force(SAND, WHEEL, np.array([z]), beta, np.array([g]))[0] == pytest.approx(expected, rel=1e-8)


def test_sinkage_solves_vertical_equilibrium():
    slip = np.linspace(-0.5, 0.8, 7)
    out = predict(SAND, WHEEL, slip=slip, slip_angle=10.0, load=120.0)
    assert out["supported"].all()
    np.testing.assert_allclose(out["vertical_force"], 120.0, rtol=1e-9)


def test_cohesionless_soil_at_equal_mass_sinks_the_same_at_any_gravity():
    """Reece's pressure ~ rho g and Mohr--Coulomb strength ~ sigma when c = 0: with W ~ g the sinkage is
    gravity independent and every force scales with g (the similarity behind seed 004's finding)."""
    soil = replace(SAND, cohesion=0.0, kc_prime=0.0)
    wheel = replace(WHEEL, grouser_height=0.01, grouser_count=12)
    earth = predict(soil, wheel, slip=0.3, slip_angle=10.0, load=120.0, gravity=9.81)
    moon = predict(soil, wheel, slip=0.3, slip_angle=10.0, load=120.0 / 6.0, gravity=9.81 / 6.0)
    assert moon["sinkage"] == pytest.approx(earth["sinkage"], rel=1e-9)
    for q in ("drawbar_pull", "lateral_force", "torque"):
        assert moon[q] == pytest.approx(earth[q] / 6.0, rel=1e-8)
    # with cohesion the strength no longer scales with g: the Moon wheel sinks less
    cohesive = predict(SAND, wheel, slip=0.3, load=[120.0, 20.0], gravity=[9.81, 9.81 / 6.0])
    assert cohesive["sinkage"][1] < 0.9 * cohesive["sinkage"][0]


def test_trends_and_symmetry():
    slips = np.linspace(0.0, 0.8, 9)
    dp = predict(SAND, WHEEL, slip=slips, load=100.0)["drawbar_pull"]
    assert np.all(np.diff(dp) > 0)  # drawbar pull rises with slip
    betas = np.array([-20.0, -10.0, 0.0, 10.0, 20.0])
    out = predict(SAND, WHEEL, slip=0.2, slip_angle=betas, load=100.0)
    fy = out["lateral_force"]
    assert fy[2] == 0.0
    np.testing.assert_allclose(fy[::-1], -fy, rtol=1e-12)
    assert fy[3] < 0 and fy[4] < fy[3]  # opposes the lateral slip and grows with beta
    grouser = predict(SAND, replace(WHEEL, grouser_height=0.01, grouser_count=15), slip=0.2, load=100.0)
    assert grouser["drawbar_pull"] > out["drawbar_pull"][2]


@pytest.mark.parametrize("kwargs, match", [
    (dict(slip=1.0, load=50.0), r"slip\[0\] = 1.0 is out of range"),
    (dict(slip=0.2, slip_angle=90.0, load=50.0), r"slip\[0\] = 0.2 .*at 90 deg give travel_slip"),
    (dict(slip=0.2, slip_angle=95.0, load=50.0), r"slip_angle\[0\] = 95.0 .*-90 <= slip_angle <= 90"),
    (dict(travel_slip=[0.2, 1.0], slip_angle=90.0, load=50.0), r"travel_slip\[1\] = 1.0 .*spinning in place"),
    (dict(slip=0.2, travel_slip=0.5, slip_angle=30.0, load=50.0), r"slip\[0\] = 0.2 along the heading disagrees"),
    (dict(slip=[0.1, 0.2], load=[50.0, -1.0]), r"load\[1\] = -1.0 is out of range: allowed 0 < load"),
    (dict(slip=0.2, load=50.0, gravity=float("nan")), r"gravity\[0\] = nan"),
])
def test_bad_conditions_name_the_value(kwargs, match):
    with pytest.raises(WheelsoilInputError, match=match):
        predict(SAND, WHEEL, **kwargs)


def test_bad_parameters_name_the_key():
    with pytest.raises(WheelsoilInputError, match="friction_angle = 75"):
        SoilParameters(friction_angle=75.0)
    with pytest.raises(WheelsoilInputError, match="density = -1"):
        SoilParameters(density=-1.0)
    with pytest.raises(WheelsoilInputError, match="theta_m outside"):
        SoilParameters(a1=0.8, a2=0.5)
    with pytest.raises(WheelsoilInputError, match="grouser_height"):
        RigidWheel(radius=0.1, width=0.1, grouser_height=0.2)


def test_bulldozing_is_bekkers_passive_pressure_against_travel_only():
    """R_b = b (0.67 c z K_pc + 0.5 rho g z^2 K_pgamma) with K_pc = (N_c - tan phi) cos^2 phi and
    K_pgamma = (2 N_gamma / tan phi + 1) cos^2 phi (Bekker; Wong ch. 2): it lowers the drawbar pull by
    exactly scale x R_b and leaves sinkage, vertical force and torque as they were."""
    from wheelsoil.validation.terramechanics import bearing_capacity_factors, bulldozing_force

    soil = SoilParameters(density=1500.0, cohesion=1000.0, friction_angle=30.0)
    wheel = RigidWheel(radius=0.2, width=0.15)
    z = np.array([0.005, 0.02])
    n_gamma, n_c, _ = bearing_capacity_factors(30.0)
    tan, cos2 = np.tan(np.radians(30.0)), np.cos(np.radians(30.0)) ** 2
    expected = 0.15 * (0.67 * 1000.0 * z * (n_c - tan) * cos2 + 0.5 * 1500.0 * 9.81 * z ** 2 * (2 * n_gamma / tan + 1) * cos2)
    np.testing.assert_allclose(bulldozing_force(soil, wheel, z, 9.81), expected, rtol=1e-12)
    # cohesionless: proportional to z^2 and to gravity
    dry = replace(soil, cohesion=0.0)
    r1, r2 = bulldozing_force(dry, wheel, z, 9.81), bulldozing_force(dry, wheel, 2 * z, 1.62)
    np.testing.assert_allclose(r2 / r1, 4.0 * 1.62 / 9.81, rtol=1e-12)
    kw = dict(slip=np.array([0.1, 0.4]), slip_angle=0.0, load=200.0, gravity=9.81)
    off, on = predict(soil, wheel, **kw), predict(replace(soil, bulldozing_scale=0.5), wheel, **kw)
    for q in ("sinkage", "vertical_force", "torque"):
        np.testing.assert_array_equal(on[q], off[q])
    np.testing.assert_allclose(off["drawbar_pull"] - on["drawbar_pull"],
                               0.5 * bulldozing_force(soil, wheel, off["sinkage"], 9.81), rtol=1e-12)


def test_multipass_is_seed003_eq23_compaction_of_density_and_cohesion():
    """On pass n_p the wheel meets soil of density and cohesion times k1 + k2 n_p with k1 = 1 - k2 (seed 003 eq.
    23): the model on pass n_p must equal the model on a first pass over soil compacted by that factor, for every
    force (pressure-sinkage, shear, sidewall, grousers, bulldozing), and the first pass must not change."""
    soil = replace(SAND, cohesion=800.0, multipass_k2=0.2, sidewall_scale=1.0, grouser_scale=1.0, bulldozing_scale=0.5)
    wheel = RigidWheel(radius=0.15, width=0.12, grouser_height=0.008, grouser_count=18)
    kw = dict(slip=np.array([0.1, 0.4, 0.7]), slip_angle=np.array([0.0, 15.0, 30.0]), load=120.0, gravity=9.81)
    first = predict(soil, wheel, passes=1, **kw)
    undisturbed = predict(replace(soil, multipass_k2=0.0), wheel, **kw)
    for q in ("sinkage", "drawbar_pull", "lateral_force", "torque"):
        np.testing.assert_array_equal(first[q], undisturbed[q])
    for n_p in (2, 3):
        factor = 1.0 + 0.2 * (n_p - 1)
        later = predict(soil, wheel, passes=n_p, **kw)
        compacted = predict(replace(soil, multipass_k2=0.0, density=SAND.density * factor, cohesion=800.0 * factor),
                            wheel, **kw)
        for q in ("sinkage", "drawbar_pull", "lateral_force", "torque"):
            np.testing.assert_allclose(later[q], compacted[q], rtol=1e-9, err_msg=f"{q}, pass {n_p}")
        assert np.all(later["sinkage"] < first["sinkage"])  # compacted soil carries the load with less sinkage
    with pytest.raises(WheelsoilInputError, match=r"passes\[0\] = 0.0 is out of range"):
        predict(soil, wheel, slip=0.2, load=50.0, passes=0)


def test_constant_pressure_modulus_makes_sinkage_independent_of_gravity_at_equal_load():
    """kphi_gravity_exponent = 1 turns Reece's rho g b k'_phi into seed 000's constant K_phi (ref. [32]): the normal
    stress no longer depends on g, nor does the shear (Mohr-Coulomb on that stress), so at equal load the sinkage,
    drawbar pull and torque are the same at any gravity -- exactly, not approximately (sidewall and grousers off:
    they carry rho g of their own)."""
    soil = replace(SAND, kphi_gravity_exponent=1.0, sidewall_scale=0.0, grouser_scale=0.0)
    out = [predict(soil, WHEEL, slip=[0.1, 0.4], slip_angle=10.0, load=80.0, gravity=g) for g in (9.81, 3.71, 1.62)]
    for other in out[1:]:
        for q in ("sinkage", "drawbar_pull", "torque", "lateral_force"):
            assert other[q] == pytest.approx(out[0][q], rel=1e-9, abs=1e-12), q
    # and Reece's form (epsilon = 0) does depend on gravity
    reece = [predict(replace(soil, kphi_gravity_exponent=0.0), WHEEL, slip=0.1, load=80.0, gravity=g)["sinkage"]
             for g in (9.81, 1.62)]
    assert reece[1] > 1.2 * reece[0]


def test_gravity_soil_flow_is_the_soil_flow_of_seed000_eq8_at_each_gravity():
    """eta(g) = eta_g (1 - g / 9.81): none at Earth gravity, and at lunar gravity exactly the constant soil flow of
    that value."""
    at_earth = predict(replace(SAND, soil_flow_gravity=0.4), WHEEL, slip=0.3, load=60.0, gravity=9.81)
    plain = predict(SAND, WHEEL, slip=0.3, load=60.0, gravity=9.81)
    assert at_earth["drawbar_pull"] == pytest.approx(plain["drawbar_pull"], rel=1e-12)
    moon = predict(replace(SAND, soil_flow_gravity=0.4), WHEEL, slip=0.3, load=60.0, gravity=1.62)
    same = predict(replace(SAND, soil_flow=0.4 * (1 - 1.62 / 9.81)), WHEEL, slip=0.3, load=60.0, gravity=1.62)
    for q in ("drawbar_pull", "torque", "sinkage"):
        assert moon[q] == pytest.approx(same[q], rel=1e-12), q
    assert moon["drawbar_pull"] < predict(SAND, WHEEL, slip=0.3, load=60.0, gravity=1.62)["drawbar_pull"]


@pytest.mark.parametrize("field, condition", [("cohesion", "slip"), ("friction_angle", "slip_angle"),
                                              ("shear_modulus_x", "gravity"), ("n0", "passes"), ("a1", "gravity"),
                                              ("kc_prime", "slip"), ("kphi_prime", "passes"),
                                              ("friction_angle", "load"), ("shear_modulus_x", "load")])
def test_a_drift_is_the_soil_of_each_condition_with_its_own_parameter(field, condition):
    """A drift p max(1 + rate u, floor) is exactly the model run condition by condition with p set to that value (u = |i|,
    sin|beta|, 1 - g / 9.81, n_p - 1, ln(W / W_ref)); rate 0 is the soil without a drift, bit for bit. On the
    classical model: the sidewall, bulldozing and grouser terms keep the soil's own value (documented)."""
    soil = replace(SAND, **BASELINE_OFF)
    cond = dict(slip=np.array([0.05, 0.3, 0.6]), slip_angle=np.array([0.0, 10.0, 25.0]), load=np.array([40.0, 60.0, 120.0]),
                gravity=np.array([9.81, 3.71, 1.62]), passes=np.array([1.0, 2.0, 3.0]))
    u = {"slip": np.abs(cond["slip"]), "slip_angle": np.sin(np.radians(cond["slip_angle"])),
         "gravity": 1.0 - cond["gravity"] / 9.81, "passes": cond["passes"] - 1.0, "load": np.log(cond["load"] / 80.0)}[condition]
    rate = -0.6
    drifted = predict(replace(soil, drift_field=field, drift_condition=condition, drift_rate=rate, drift_reference=80.0),
                      WHEEL, **cond)
    for k in range(3):
        value = getattr(soil, field) * max(1.0 + rate * u[k], DRIFT_FLOOR)  # held above the floor
        changes = {field: value, **({"shear_modulus_y": value} if field == "shear_modulus_x" else {})}
        one = predict(replace(soil, **changes), WHEEL, **{q: (v[k] if np.ndim(v) else v) for q, v in cond.items()})
        for q in ("drawbar_pull", "lateral_force", "sinkage", "torque"):
            assert drifted[q][k] == pytest.approx(float(one[q]), rel=1e-12, abs=1e-12), (q, k)
    still = predict(replace(SAND, drift_field=field, drift_condition=condition), WHEEL, **cond)
    plain = predict(SAND, WHEEL, **cond)  # with every extension on
    for q in ("drawbar_pull", "lateral_force", "sinkage", "torque"):
        assert np.array_equal(still[q], plain[q]), q


def test_bad_drifts_name_the_key():
    with pytest.raises(WheelsoilInputError, match="drift_field = 'density'"):
        SoilParameters(drift_field="density", drift_condition="slip", drift_rate=0.1)
    with pytest.raises(WheelsoilInputError, match="drift_condition = 'speed'"):
        SoilParameters(drift_field="cohesion", drift_condition="speed", drift_rate=0.1)
    with pytest.raises(WheelsoilInputError, match="drift_reference = -80"):
        SoilParameters(drift_field="cohesion", drift_condition="load", drift_rate=0.1, drift_reference=-80.0)
    with pytest.raises(WheelsoilInputError, match="needs the load of every condition"):
        contact_forces(SoilParameters(drift_field="cohesion", drift_condition="load", drift_rate=0.1), WHEEL, 0.02, 0.2,
                       0.0, 9.81)
    with pytest.raises(WheelsoilInputError, match="drift_rate = 0.1 needs a drift_field"):
        SoilParameters(drift_rate=0.1)


def test_side_bulldozing_is_the_cmu_labs_r_b_integrated():
    """The CMU lab's side bulldozing (R_b.m, forces.m; Wong 2008) against a direct scipy quadrature of its formula,
    written out again from the lab's code: h_b the side face's depth below the entry--exit line, X_c = 45 - phi/2,
    F = sin(beta) |sin(beta)| int r cos(theta) R_b d theta. Zero without steering, and sin^2 beta in between."""
    from scipy.integrate import quad

    from wheelsoil.validation.side_forces import side_bulldozing_force

    soil = replace(SAND, cohesion=900.0, friction_angle=31.0, density=1400.0)
    wheel = RigidWheel(radius=0.1, width=0.06)
    g, r = 9.81, 0.1
    theta_f, theta_r = 0.6, -0.25
    phi, gamma, c = np.radians(31.0), 1400.0 * g, 900.0
    x_c = np.pi / 4 - phi / 2

    def r_b(theta):  # R_b.m, non-Ishigami branch, without the |sin beta| factor
        h = min(2 * r * np.cos(theta), (np.sin(theta) - np.sin(theta_r)) / (np.sin(theta_f) - np.sin(theta_r))
                * r * (np.cos(theta_r) - np.cos(theta_f)) - r * (np.cos(theta_r) - np.cos(theta)))
        return 0.5 * gamma * h**2 / np.tan(x_c) ** 2 * (1 + np.tan(phi) / np.tan(x_c) / 2) + 2 * h * c / np.tan(x_c)

    integral = quad(lambda t: r * np.cos(t) * r_b(t), theta_r, theta_f, epsabs=0, epsrel=1e-12)[0]
    betas = np.radians([0.0, 30.0, 75.0])
    got = side_bulldozing_force(soil, wheel, np.full(3, theta_f), np.full(3, theta_r), betas, g)
    np.testing.assert_allclose(got, np.sin(betas) ** 2 * integral, rtol=1e-9, atol=1e-12)
    assert got[0] == 0.0 and got[2] > 0.0


def test_side_bulldozing_scale_adds_the_side_force_to_the_lateral_force_only():
    from wheelsoil.validation.side_forces import side_bulldozing_force
    from wheelsoil.validation.terramechanics import contact_forces

    soil = replace(SAND, c3=0.4, sidewall_scale=0.0)
    args = (WHEEL, np.array([0.02]), np.array([0.3]), np.array([40.0]), np.array([9.81]))
    off = contact_forces(soil, *args)
    on = contact_forces(replace(soil, side_bulldozing_scale=2.0), *args)
    side = side_bulldozing_force(soil, WHEEL, off["theta_f"], off["theta_r"], np.radians([40.0]), 9.81)
    assert side[0] > 0.0
    np.testing.assert_allclose(on["lateral_force"], off["lateral_force"] - 2.0 * side, rtol=1e-12)  # beta > 0: -y
    for key in ("drawbar_pull", "vertical_force", "torque"):
        np.testing.assert_array_equal(on[key], off[key])
