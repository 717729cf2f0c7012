"""The port of the CMU lab's terramechanics model (validation/cmu_lab_model.py) against closed forms, its own load
balance, symmetry and the continuity of its slipping and skidding branches."""

import numpy as np
import pytest

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.validation import cmu_lab_model as lab
from wheelsoil.validation.cmu_lab_model import LabSoil, LabState, LabWheel

SMOOTH = LabWheel(radius=0.058, width=0.05, grouser_height=0.0, tip_area_ratio=1.0)
K = 2.0e5  # N/m^3: n = 1


def _soil(**kw):
    base = dict(sinkage_modulus=K, specific_weight=13e3, friction_angle=1e-9, cohesion=0.0, shear_modulus=1e-9,
                n0=1.0, n1=0.0, n2=0.0)
    return LabSoil(**{**base, **kw})


def _state(slip=0.2, beta=0.0, tuned=(0.0, 0.0, 0.0, 0.0), speed=0.01, wheel=SMOOTH):
    """A slipping wheel: omega r_s = V / (1 - slip)."""
    b = np.radians(beta)
    return LabState(v_x=speed * np.cos(b), v_y=-speed * np.sin(b), omega=speed / (1 - slip) / wheel.shear_radius,
                    beta=b, tuned=tuned)


@pytest.mark.parametrize("sinkage", [0.005, 0.02])
def test_a_frictionless_soil_gives_the_closed_form_compaction_resistance_and_load(sinkage):
    """n = 1, theta_m = theta_r = 0 (the front profile over the whole contact), no shear: sigma = k r (cos theta - cos theta_f), so
    F_z = r^2 b k (theta_f / 2 - sin(2 theta_f) / 4) and F_x = -r^2 b k (1 - cos theta_f)^2 / 2. The lab's right-point
    sum over 101 angles is first order: within 2 %."""
    r, b = SMOOTH.radius, SMOOTH.width
    tf = np.arccos(1 - sinkage / r)
    fx, fy, fz = lab.forces(sinkage, _soil(), SMOOTH, _state())
    assert fz == pytest.approx(r ** 2 * b * K * (tf / 2 - np.sin(2 * tf) / 4), rel=0.02)
    assert fx == pytest.approx(-r ** 2 * b * K * (1 - np.cos(tf)) ** 2 / 2, rel=0.02)
    assert fy == 0.0


def test_a_purely_cohesive_soil_adds_its_cohesion_times_the_contact_to_the_pull():
    """phi = 0, c > 0, shear fully mobilised at once (K -> 0), a slipping wheel (the slip velocity is forward all
    along the contact): tau = c, so the drawbar pull gains r b c sin theta_f and the load r b c (1 - cos theta_f)."""
    r, b, c, h = SMOOTH.radius, SMOOTH.width, 3000.0, 0.01
    tf = np.arccos(1 - h / r)
    dry = lab.forces(h, _soil(), SMOOTH, _state(slip=0.3))
    wet = lab.forces(h, _soil(cohesion=c), SMOOTH, _state(slip=0.3))
    assert wet[0] - dry[0] == pytest.approx(r * b * c * np.sin(tf), rel=0.02)
    assert wet[2] - dry[2] == pytest.approx(r * b * c * (1 - np.cos(tf)), rel=0.02)


@pytest.mark.parametrize("slip", [0.3, -0.4])
def test_the_lateral_force_turns_with_the_steering_angle_and_nothing_else_does(slip):
    """Mirroring the steering angle (beta and v_y negated) negates F_y (lateral shear and side bulldozing) and leaves
    F_x and F_z as they are, slipping and skidding."""
    soil = lab.lab_soil("grouser")
    wheel = lab.lab_wheel("grouser")
    beta, V = np.radians(40.0), 0.01
    omega = V / (1 - slip) / wheel.shear_radius if slip >= 0 else V * (1 + slip) / wheel.shear_radius
    kw = dict(omega=omega, tuned=lab.tuned_angles("grouser", 45.0), theta_m0=0.3, theta_r0=-0.1)
    plus = lab.forces(0.02, soil, wheel, LabState(v_x=V * np.cos(beta), v_y=-V * np.sin(beta), beta=beta, **kw))
    minus = lab.forces(0.02, soil, wheel, LabState(v_x=V * np.cos(beta), v_y=V * np.sin(beta), beta=-beta, **kw))
    assert abs(plus[1]) > 0.1
    assert minus[1] == pytest.approx(-plus[1], rel=1e-12)
    assert minus[0] == pytest.approx(plus[0], rel=1e-12) and minus[2] == pytest.approx(plus[2], rel=1e-12)


def test_the_sinkage_carries_the_load_and_the_skidding_branch_meets_the_slipping_one():
    """find_sinkage balances F_z to the lab's 0.1 %; at the load that fixes the skidding wheel's stress angles, a
    wheel turning a hair slower than it travels (skidding) gives the forces of one at slip 0 (slipping)."""
    soil, wheel, V, load = lab.lab_soil("smooth"), lab.lab_wheel("smooth"), 0.01, 24.0
    tuned = lab.tuned_angles("smooth", 30.0)
    m0, r0 = lab.skid_angles("smooth", 30.0, V, load)
    beta = np.radians(30.0)
    out = []
    for omega in (np.nextafter(V / wheel.shear_radius, np.inf), V / wheel.shear_radius * (1 - 1e-9)):
        state = LabState(v_x=V * np.cos(beta), v_y=-V * np.sin(beta), omega=omega, beta=beta, tuned=tuned,
                         theta_m0=m0, theta_r0=r0)
        h, found = lab.find_sinkage(load, soil, wheel, state)
        assert found and lab.forces(h, soil, wheel, state)[2] == pytest.approx(load, rel=1e-3)
        out.append(lab.forces(h, soil, wheel, state))
    assert lab._slipping(wheel, LabState(v_x=V, v_y=0.0, omega=np.nextafter(V / wheel.shear_radius, np.inf),
                                         beta=0.0, tuned=tuned))
    np.testing.assert_allclose(out[1], out[0], rtol=0.01, atol=0.05)


def test_unknown_wheels_and_untuned_angles_are_refused():
    with pytest.raises(WheelsoilInputError, match="wheel 'lugged'"):
        lab.lab_soil("lugged")
    with pytest.raises(WheelsoilInputError, match="steering angle 20.0 deg"):
        lab.tuned_angles("grouser", 20.0)


def test_the_lab_model_runs_on_every_measured_trial(measured_dir):
    """Every row of both CMU files gets a number; the rows where the bisection could not carry the load are flagged,
    not hidden; the lab's model is tuned on these trials, so its drawbar pull at 0-60 deg stays within the trials'
    spread (a port that broke a sign or a unit would not)."""
    from wheelsoil.validation.measured import load_cmu_trials

    folder = f"{measured_dir}/cmu_3d_terramechanics"
    rows = lab.read_trials(folder)
    data = load_cmu_trials(folder)
    np.testing.assert_allclose(rows.load, data.load)
    p = lab.predict_trials(rows)
    assert np.isfinite(p["drawbar_pull"]).all() and np.isfinite(p["lateral_force"]).all()
    low = rows.slip_angle <= 60.0
    assert p["found"][low].all()
    for q in ("drawbar_pull", "lateral_force"):
        rms = np.sqrt(np.mean((p[q][low] - data.responses[q][low]) ** 2))
        assert rms < np.std(data.responses[q][low])
