"""Verification of the Hertz--Mindlin contact law against analytical answers.

References
----------
* Hertz impact: Johnson, *Contact Mechanics* (1985), sec. 11.4: maximum overlap
  delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5), maximum force F = 4/3 E* sqrt(R*) delta_max^(3/2),
  duration t_c = 2 (delta_max / v) int_0^1 (1 - x^(5/2))^(-1/2) dx.
* Oblique impact in gross sliding (rigid-body impulse theory, e.g. Brach, *Mechanical Impact
  Dynamics*; Maw, Barber & Fawcett 1976): P_n = m v_n (1 + e), P_t = mu P_n, so
  v_t' = v_t - mu (1 + e) v_n and omega' = 5/2 mu (1 + e) v_n / R for a solid sphere.
* Rolling resistance with constant torque M = mu_r m g R on a sphere rolling without slip:
  (m + I/R^2) dv/dt = -mu_r m g  =>  omega(t) = omega_0 - 5/7 mu_r g t / R (both rolling laws).
* EPSD rolling resistance (Ai et al. 2011, model C; k_r = S_t R*^2, Iwashita & Oda 1998): a sphere on a floor
  under an applied torque M below M_m = mu_r F_n R comes to rest rolled by theta = M / k_r (the floor's friction
  carries no force at rest, so the spring alone balances M); above M_m it rolls on against M_m:
  (I + m R^2) d omega/dt = M - M_m.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from wheelsoil.granular import (
    Material,
    PairProperties,
    Scene,
    effective_mass,
    effective_modulus,
    effective_radius,
    effective_shear_modulus,
)

SOIL = Material("test soil", youngs_modulus=50e6, poisson_ratio=0.3, density=3200.0)
DURATION_INTEGRAL = quad(lambda x: 1.0 / math.sqrt(1.0 - x**2.5), 0.0, 1.0)[0]


def hertz_theory(m_eff, r_eff, e_eff, speed):
    delta = (15.0 * m_eff * speed**2 / (16.0 * e_eff * math.sqrt(r_eff))) ** 0.4
    force = 4.0 / 3.0 * e_eff * math.sqrt(r_eff) * delta**1.5
    return delta, force, 2.0 * DURATION_INTEGRAL * delta / speed


def record_impact(scene, overlap_of, steps):
    """Step one at a time; return arrays of overlap and |total contact force on particle 0|."""
    overlaps, forces = [], []
    for _ in range(steps):
        scene.step(1)
        overlaps.append(overlap_of(scene.positions))
        forces.append(np.linalg.norm(scene.contact_forces[0]))
    return np.array(overlaps), np.array(forces)


def pair_scene(restitution=1.0, mu=0.0, mu_r=0.0, r=(0.01, 0.01), speed=1.0, n_per_contact=400):
    pair = PairProperties(restitution, mu, mu_r)
    scene = Scene((-1, -1, -1), (1, 1, 1), gravity=(0, 0, 0), material=SOIL, pair=pair)
    gap = 1e-5
    x = np.array([[-r[0] - gap, 0, 0], [r[1] + gap, 0, 0]])
    v = np.array([[speed / 2, 0, 0], [-speed / 2, 0, 0]])
    scene.add_spheres(x, np.array(r), velocities=v)
    m = scene.masses
    e_eff = effective_modulus(SOIL, SOIL)
    theory = hertz_theory(effective_mass(*m), effective_radius(*r), e_eff, speed)
    scene.time_step = theory[2] / n_per_contact
    return scene, theory


def wall_scene(restitution=1.0, mu=0.0, mu_r=0.0, r=0.01, v_normal=1.0, v_tangent=0.0, wall_material=None,
               n_per_contact=400):
    pair = PairProperties(restitution, mu, mu_r)
    scene = Scene((-1, -1, -1), (1, 1, 1), gravity=(0, 0, 0), material=SOIL, pair=pair)
    scene.add_wall((0, 0, 0), (0, 0, 1), material=wall_material, pair=pair)
    scene.add_spheres([[0, 0, r + 1e-5]], [r], velocities=[[v_tangent, 0, -v_normal]])
    e_eff = effective_modulus(SOIL, wall_material)
    theory = hertz_theory(scene.masses[0], r, e_eff, v_normal)
    scene.time_step = theory[2] / n_per_contact
    return scene, theory


def contact_window(overlaps, dt):
    touching = np.flatnonzero(overlaps > 0)
    return (touching[-1] - touching[0] + 1) * dt


@pytest.mark.parametrize("radii", [(0.01, 0.01), (0.008, 0.012)])
def test_hertz_normal_impact_two_spheres(radii):
    scene, (delta_max, f_max, t_c) = pair_scene(r=radii)
    rsum = sum(radii)
    overlaps, forces = record_impact(scene, lambda x: rsum - np.linalg.norm(x[1] - x[0]), 700)
    dt = scene.time_step
    # tolerances: 0.5 % on peak overlap and force (time sampling at t_c/400), 1 % on duration
    assert overlaps.max() == pytest.approx(delta_max, rel=5e-3)
    assert forces.max() == pytest.approx(f_max, rel=5e-3)
    assert contact_window(overlaps, dt) == pytest.approx(t_c, rel=1e-2)


@pytest.mark.parametrize("wall_material", [None, Material("steel", 210e9, 0.3, 7850.0)])
def test_hertz_normal_impact_on_wall(wall_material):
    scene, (delta_max, f_max, t_c) = wall_scene(wall_material=wall_material)
    overlaps, forces = record_impact(scene, lambda x: 0.01 - x[0, 2], 700)
    assert overlaps.max() == pytest.approx(delta_max, rel=5e-3)
    assert forces.max() == pytest.approx(f_max, rel=5e-3)
    assert contact_window(overlaps, scene.time_step) == pytest.approx(t_c, rel=1e-2)


@pytest.mark.parametrize("e", [0.1, 0.3, 0.5, 0.7, 0.9, 1.0])
def test_restitution_out_equals_in(e):
    # particle pair, speed 1 m/s, 400 steps per elastic contact time; tolerance 1 %
    scene, (_, _, t_c) = pair_scene(restitution=e, n_per_contact=400)
    scene.step(int(3 * t_c / scene.time_step))
    v = scene.velocities
    assert (v[1, 0] - v[0, 0]) / 1.0 == pytest.approx(e, rel=1e-2)
    # sphere on a steel wall at another speed (restitution must not depend on speed)
    scene, (_, _, t_c) = wall_scene(restitution=e, v_normal=0.3, wall_material=Material("steel", 210e9, 0.3, 7850.0),
                                    n_per_contact=400)
    scene.step(int(3 * t_c / scene.time_step))
    assert scene.velocities[0, 2] / 0.3 == pytest.approx(e, rel=1e-2)


def test_restitution_converges_with_time_step():
    """The damping force uses the half-step velocity, so the restitution error is first order in dt:
    halving the step must halve the error (ratio 2 +- 15 %), converging to the input e."""
    errors = []
    for n in (100, 200, 400):
        scene, (_, _, t_c) = pair_scene(restitution=0.1, n_per_contact=n)
        scene.step(int(3 * t_c / scene.time_step))
        v = scene.velocities
        errors.append(abs((v[1, 0] - v[0, 0]) - 0.1))
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.15)
    assert errors[1] / errors[2] == pytest.approx(2.0, rel=0.15)


def test_oblique_impact_gross_sliding():
    mu, e, r, vn, vt = 0.3, 0.5, 0.01, 1.0, 5.0
    assert vt / vn > 3.5 * mu * (1 + e)  # gross sliding throughout the impact
    scene, (_, _, t_c) = wall_scene(restitution=e, mu=mu, r=r, v_normal=vn, v_tangent=vt)
    scene.step(int(3 * t_c / scene.time_step))
    v, w = scene.velocities[0], scene.angular_velocities[0]
    # tolerance 1 %: the tangential spring needs a few steps to reach the Coulomb limit
    assert v[2] == pytest.approx(e * vn, rel=1e-2)
    assert v[0] == pytest.approx(vt - mu * (1 + e) * vn, rel=1e-2)
    # topspin (omega_y > 0) for sliding along +x on a floor with normal +z
    assert w[1] == pytest.approx(2.5 * mu * (1 + e) * vn / r, rel=1e-2)
    assert abs(w[0]) < 1e-9 and abs(w[2]) < 1e-9


@pytest.mark.parametrize("law", ["cdt", pytest.param("epsd", marks=pytest.mark.slow)])  # EPSD held at rest: fast
def test_rolling_resistance_spin_decay(law):
    mu_r, r, g = 0.1, 0.01, 9.81
    pair = PairProperties(restitution=0.3, static_friction=0.8, rolling_friction=mu_r, rolling_model=law)
    scene = Scene((-5, -1, -1), (5, 1, 1), gravity=(0, 0, -g), material=SOIL, pair=pair)
    scene.add_wall((0, 0, 0), (0, 0, 1), material=None, pair=pair)
    m = SOIL.density * 4 / 3 * math.pi * r**3
    static_overlap = (m * g / (4 / 3 * effective_modulus(SOIL, None) * math.sqrt(r))) ** (2 / 3)
    omega0 = 40.0
    scene.add_spheres([[0, 0, r - static_overlap]], [r], velocities=[[omega0 * r, 0, 0]],
                      angular_velocities=[[0, omega0, 0]])
    dt = scene.time_step
    slope_theory = -5.0 / 7.0 * mu_r * g / r
    t_stop = omega0 / -slope_theory
    times, spins = [], []
    for _ in range(20):
        scene.step(int(0.04 * t_stop / dt))
        times.append(scene.time)
        spins.append(scene.angular_velocities[0, 1])
    times, spins = np.array(times), np.array(spins)
    live = spins > 0.1 * omega0
    slope, intercept = np.polyfit(times[live], spins[live], 1)
    assert slope == pytest.approx(slope_theory, rel=2e-2)  # tolerance 2 %
    assert intercept == pytest.approx(omega0, rel=1e-2)
    # rolling without slip throughout
    assert scene.velocities[0, 0] == pytest.approx(scene.angular_velocities[0, 1] * r, abs=2e-3 * omega0 * r)
    # and the torque brings the sphere to rest rather than reversing it
    scene.step(int(0.3 * t_stop / dt))
    assert abs(scene.angular_velocities[0, 1]) < 1e-3 * omega0


def sphere_under_torque(fraction, dt_factor=1.0, law="epsd", ramp=0.0):
    """One sphere resting on a rigid floor (mu_r = 0.5, mu_s = 0.5) with a torque about y of ``fraction`` of
    M_m = mu_r m g R, raised linearly from zero over ``ramp`` seconds (0: applied at once; a sudden torque
    overshoots the spring's static twist up to twice); returns the scene, the torque [N m] and M_m [N m]."""
    from wheelsoil.granular.scene import Interaction

    r, g, mu_r = 0.004, 9.81, 0.5
    pair = PairProperties(restitution=0.5, static_friction=0.5, rolling_friction=mu_r, rolling_model=law)
    scene = Scene((-0.05, -0.05, 0.0), (0.05, 0.05, 0.05), gravity=(0, 0, -g), material=SOIL, pair=pair)
    scene.add_wall((0, 0, 0), (0, 0, 1), material=None, pair=pair)
    m = SOIL.density * 4 / 3 * math.pi * r**3
    overlap = (m * g / (4 / 3 * effective_modulus(SOIL, None) * math.sqrt(r))) ** (2 / 3)
    scene.add_spheres([[0, 0, r - overlap]], [r])
    scene.time_step = scene.time_step * dt_factor
    m_full = mu_r * m * g * r
    torque = fraction * m_full

    class Torque(Interaction):
        def add_forces(self, scene, dt):
            state = scene.device_state()
            t = state.external_torque.to_numpy()
            t[0, 1] += torque * (min(1.0, scene.time / ramp) if ramp > 0.0 else 1.0)
            state.external_torque.from_numpy(t)
            return 0

    scene.add_interaction(Torque())
    return scene, torque, m_full


@pytest.mark.parametrize("dt_factor", [1.0, 0.5])
@pytest.mark.parametrize("fraction", [0.3, 0.9])
def test_epsd_holds_a_torque_below_mobilisation_at_rest(fraction, dt_factor):
    """The EPSD spring balances the torque and the sphere stops, rolled by theta = M / k_r, at any time step (the
    CDT law rolls on at M dt / I: docs/soillab/rolling/creep.md)."""
    scene, torque, _ = sphere_under_torque(fraction, dt_factor, ramp=0.01)
    r = 0.004
    scene.step(int(0.03 / scene.time_step))
    x_rest = scene.positions[0, 0]
    scene.step(int(0.02 / scene.time_step))
    m = scene.masses[0]
    overlap = (m * 9.81 / (4 / 3 * effective_modulus(SOIL, None) * math.sqrt(r))) ** (2 / 3)
    k_roll = 8 * effective_shear_modulus(SOIL, None) * math.sqrt(r * overlap) * r**2  # S_t R*^2, R* = R
    theta = torque / k_roll
    assert abs(scene.angular_velocities[0, 1]) * 0.01 < 1e-3 * theta  # at rest: < 0.1 % of theta more in 10 ms
    assert scene.positions[0, 0] == pytest.approx(r * theta, rel=2e-2)  # rolled by r theta, tolerance 2 %
    assert scene.positions[0, 0] == pytest.approx(x_rest, rel=1e-3)  # and stays there
    spring = scene.contact_history().roll_wall[0, 0]
    assert spring == pytest.approx([0.0, -torque, 0.0], rel=1e-4, abs=1e-9 * torque)  # the spring carries M


@pytest.mark.parametrize("law", ["cdt", "epsd"])
def test_rolling_resistance_gives_way_above_mobilisation(law):
    """Above M_m the sphere rolls on against M_m under either law: (I + m R^2) d omega/dt = M - M_m."""
    scene, torque, m_full = sphere_under_torque(1.5, law=law)
    r, m = 0.004, scene.masses[0]
    scene.step(int(0.01 / scene.time_step))
    t0, w0 = scene.time, scene.angular_velocities[0, 1]
    scene.step(int(0.02 / scene.time_step))
    rate = (scene.angular_velocities[0, 1] - w0) / (scene.time - t0)
    assert rate == pytest.approx((torque - m_full) / (1.4 * m * r**2), rel=2e-2)  # tolerance 2 %


def elastic_energy(scene):
    x, r = scene.positions, scene.radii
    e_eff = effective_modulus(scene.material, scene.material)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    overlap = np.triu(r[:, None] + r[None] - d, 1)
    rr = r[:, None] * r[None] / (r[:, None] + r[None])
    touching = overlap > 0
    energy = np.sum(8 / 15 * e_eff * np.sqrt(rr[touching]) * overlap[touching] ** 2.5)
    for w in scene.walls:
        gap = (x - np.array(w.point)) @ np.array(w.normal)
        ov = np.clip(r - gap, 0, None)
        energy += np.sum(8 / 15 * effective_modulus(scene.material, w.material) * np.sqrt(r) * ov**2.5)
    return energy


def test_energy_conserved_elastic_frictionless():
    rng = np.random.default_rng(3)
    pair = PairProperties(restitution=1.0, static_friction=0.0, rolling_friction=0.0)
    scene = Scene((0, 0, 0), (0.1, 0.1, 0.1), gravity=(0, 0, 0), material=SOIL, pair=pair)
    scene.add_box_walls(top=True, material=None, pair=pair)
    grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    x = 0.0125 + grid * 0.025 + rng.uniform(-1e-3, 1e-3, grid.shape)
    scene.add_spheres(x, rng.uniform(0.008, 0.011, len(x)), velocities=rng.normal(0, 0.5, x.shape))
    e0 = scene.kinetic_energy() + elastic_energy(scene)
    scene.step(4000)
    assert scene.steps_taken == 4000 and scene.neighbor_rebuilds > 1
    e1 = scene.kinetic_energy() + elastic_energy(scene)
    assert e1 == pytest.approx(e0, rel=2e-3)  # tolerance 0.2 % over ~hundreds of impacts


def test_momentum_conserved_in_every_pair():
    rng = np.random.default_rng(7)
    pair = PairProperties(restitution=0.4, static_friction=0.5, rolling_friction=0.2)
    scene = Scene((-1, -1, -1), (1, 1, 1), gravity=(0, 0, 0), material=SOIL, pair=pair)
    grid = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3)
    x = (grid - 1.5) * 0.04 + rng.uniform(-2e-3, 2e-3, grid.shape)
    n = len(x)
    r = rng.uniform(0.006, 0.018, n)
    scene.add_spheres(x, r, velocities=-x * 5 + rng.normal(0, 0.1, (n, 3)),
                      angular_velocities=rng.normal(0, 50, (n, 3)))
    m = scene.masses
    p0 = (m[:, None] * scene.velocities).sum(0)
    forces_seen = 0.0
    for _ in range(60):
        scene.step(10)
        f = scene.contact_forces
        forces_seen = max(forces_seen, np.abs(f).max())
        assert np.abs(f.sum(0)).max() <= 1e-12 * np.abs(f).sum()
    assert forces_seen > 1.0  # the cluster did collide
    p1 = (m[:, None] * scene.velocities).sum(0)
    assert np.abs(p1 - p0).max() <= 1e-12 * np.abs(m[:, None] * scene.velocities).sum()


def test_pair_forces_are_exact_mirrors():
    """Each pair is evaluated once and the partner receives the negated force: action = reaction
    to the bit."""
    scene, _ = pair_scene(restitution=0.5, mu=0.4, mu_r=0.2, r=(0.008, 0.013))
    scene.set_velocities([[0.5, 0.1, 0.2], [-0.5, -0.3, 0.0]], [[10, -5, 3], [0, 20, -7]])
    touched = 0
    for _ in range(200):
        scene.step(1)
        f = scene.contact_forces
        touched += bool(np.any(f))
        assert np.array_equal(f[0], -f[1])
    assert touched > 20
