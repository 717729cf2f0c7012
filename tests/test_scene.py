"""Scene API: input validation, time-step refusal, instability detection, invariances."""

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from wheelsoil.granular import (
    Material,
    PairProperties,
    Scene,
    SimulationUnstableError,
    WheelsoilInputError,
    estimate_time_step,
)
from wheelsoil.granular.materials import SOIL_SOIL, SOIL_STEEL


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(youngs_modulus=0.0, poisson_ratio=0.3, density=3200.0), "material 'm': youngs_modulus = 0.0 Pa is out of range"),
        (dict(youngs_modulus=-5.0, poisson_ratio=0.3, density=3200.0), "youngs_modulus = -5.0 Pa"),
        (dict(youngs_modulus=1e13, poisson_ratio=0.3, density=3200.0), "0 < youngs_modulus <= 1.2e+12 (or inf) (Pa)"),
        (dict(youngs_modulus=5e7, poisson_ratio=0.5, density=3200.0), "poisson_ratio = 0.5 is out of range: allowed "
                                                                       "-1 < poisson_ratio < 0.5"),
        (dict(youngs_modulus=5e7, poisson_ratio=0.7, density=3200.0), "poisson_ratio = 0.7"),
        (dict(youngs_modulus=5e7, poisson_ratio=0.3, density=0.0), "density = 0.0 kg/m^3"),
        (dict(youngs_modulus=float("nan"), poisson_ratio=0.3, density=1.0), "youngs_modulus = nan"),
    ],
)
def test_bad_material_is_named(kwargs, fragment):
    with pytest.raises(WheelsoilInputError, match=re.escape(fragment)):
        Material("m", **kwargs)


def test_a_rigid_material_is_allowed():
    assert Material("rigid wall", math.inf, 0.3, 7850.0).is_rigid


@pytest.mark.parametrize("e", [0.0, -0.1, 1.01, float("nan")])
def test_bad_restitution_is_named(e):
    with pytest.raises(WheelsoilInputError, match=r"contact pair restitution = .* allowed 0 < restitution <= 1"):
        PairProperties(restitution=e, static_friction=0.4, rolling_friction=0.1)


def test_bad_friction_is_named():
    with pytest.raises(WheelsoilInputError, match="static_friction = -0.1 is out of range: allowed 0 <= static_friction"):
        PairProperties(restitution=0.5, static_friction=-0.1, rolling_friction=0.1)


def small_scene(**kw):
    s = Scene((0, 0, 0), (0.2, 0.2, 0.2), **kw)
    s.add_box_walls()
    return s


def test_bad_spheres_are_named():
    s = small_scene()
    with pytest.raises(WheelsoilInputError, match=r"radius -0.01 m of sphere 1"):
        s.add_spheres([[0.1, 0.1, 0.1], [0.05, 0.05, 0.05]], [0.01, -0.01])
    with pytest.raises(WheelsoilInputError, match=r"radius 0.0 m of sphere 0"):
        s.add_spheres([[0.1, 0.1, 0.1]], [0.0])
    with pytest.raises(WheelsoilInputError, match=r"positions contains a non-finite value nan at index \(0, 2\)"):
        s.add_spheres([[0.1, 0.1, np.nan]], [0.01])
    with pytest.raises(WheelsoilInputError, match=r"velocities contains a non-finite value inf"):
        s.add_spheres([[0.1, 0.1, 0.1]], [0.01], velocities=[[0, np.inf, 0]])
    with pytest.raises(WheelsoilInputError, match=r"sphere 0 at \[0.1, 0.1, 0.3\] m lies outside the domain"):
        s.add_spheres([[0.1, 0.1, 0.3]], [0.01])
    with pytest.raises(WheelsoilInputError, match=r"radii has shape \(3,\); expected \(2\)"):
        s.add_spheres([[0.1, 0.1, 0.1], [0.05, 0.05, 0.05]], [0.01, 0.01, 0.01])
    assert s.n_particles == 0  # nothing was half-added


def test_time_step_above_stable_is_refused_with_numbers():
    s = small_scene()
    s.add_spheres([[0.1, 0.1, 0.1]], [0.008])
    est = s.stable_time_step()
    assert est.stable == pytest.approx(min(0.2 * est.rayleigh, est.hertz_duration / 10))
    # Rayleigh step for 8 mm lunar simulant spheres, by hand: pi R sqrt(rho/G) / (0.1631 nu + 0.8766)
    g = 50e6 / (2 * 1.3)
    assert est.rayleigh == pytest.approx(math.pi * 0.008 * math.sqrt(3200 / g) / (0.1631 * 0.3 + 0.8766), rel=1e-12)
    with pytest.raises(WheelsoilInputError, match=r"time step 1.000e-03 s exceeds the stable time step: stable step"):
        s.time_step = 1e-3
    s.time_step = 0.5 * est.stable
    assert s.time_step == 0.5 * est.stable


def test_time_step_estimate_arguments_checked():
    soil = Material("s", 5e7, 0.3, 3200)
    with pytest.raises(WheelsoilInputError, match="rayleigh_fraction"):
        estimate_time_step(0.01, soil, rayleigh_fraction=2.0)


def test_escaping_particle_stops_the_run():
    s = Scene((0, 0, 0), (0.2, 0.2, 0.2), check_interval=10)  # no walls: it falls out
    s.add_spheres([[0.1, 0.1, 0.02]], [0.01])
    with pytest.raises(SimulationUnstableError, match="left the domain"):
        s.step(2000)


def test_blow_up_stops_the_run():
    s = small_scene(check_interval=5)
    # a sphere pushed 90 % of its radius into the floor: the released elastic energy throws it
    # faster than the time step can resolve
    s.add_spheres([[0.1, 0.1, 0.001]], [0.01])
    with pytest.raises(SimulationUnstableError, match=r"energy blow-up .* a particle moves at"):
        s.step(50)


def random_packing(seed=0, n_side=6):
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(n_side)] * 3, indexing="ij"), -1).reshape(-1, 3)
    x = 0.015 + grid * 0.021 + rng.uniform(-1e-3, 1e-3, grid.shape)
    r = rng.uniform(0.006, 0.0105, len(x))
    v = rng.normal(0, 0.2, x.shape)
    return x, r, v


def run_packing(x, r, v, steps=3000, **kw):
    s = Scene((0, 0, 0), (0.15, 0.15, 0.3), **kw)
    s.add_box_walls()
    s.add_spheres(x, r, velocities=v)
    s.time_step = 5e-5
    s.step(steps)
    return s


def test_results_independent_of_particle_order():
    x, r, v = random_packing()
    ref = run_packing(x, r, v)
    perm = np.random.default_rng(1).permutation(len(r))
    other = run_packing(x[perm], r[perm], v[perm])
    assert ref.contact_count > 100
    inv = np.argsort(perm)
    # summation order differs, so agreement is to round-off amplified by the granular dynamics over
    # 3000 steps (observed 1e-12 m, 1e-9 m/s)
    np.testing.assert_allclose(other.positions[inv], ref.positions, rtol=0, atol=1e-10)
    np.testing.assert_allclose(other.velocities[inv], ref.velocities, rtol=0, atol=1e-7)


def test_results_independent_of_cell_size_and_skin():
    x, r, v = random_packing()
    ref = run_packing(x, r, v)
    coarse = run_packing(x, r, v, cell_size=0.05)
    wide_skin = run_packing(x, r, v, skin=0.006)
    assert coarse.neighbor_rebuilds >= 1 and wide_skin.neighbor_rebuilds < ref.neighbor_rebuilds
    # neighbour rows are sorted by index, so the summation order -- and the result -- is identical
    np.testing.assert_array_equal(coarse.positions, ref.positions)
    np.testing.assert_array_equal(wide_skin.positions, ref.positions)
    np.testing.assert_array_equal(wide_skin.angular_velocities, ref.angular_velocities)


def test_pair_list_matches_brute_force_and_partner_runs_are_sorted():
    """The pair list holds exactly the pairs within r_i + r_j + skin at the last rebuild, each once
    (owner i < j, partners ascending), and the reverse index gives every pair one partner slot, in
    runs by partner with owners ascending."""
    x, r, v = random_packing()
    s = run_packing(x, r, v, steps=400)
    nl = s.device.neighbor_list
    pairs, n_pairs = nl.pairs, nl.n_pairs
    assert s.neighbor_rebuilds >= 2
    owners = np.repeat(np.arange(s.n_particles), np.diff(pairs.start.to_numpy()))
    partners = pairs.j.to_numpy()[:n_pairs]
    x_ref = s.device.particles.x_ref.to_numpy()
    dist = np.linalg.norm(x_ref[:, None, :] - x_ref[None, :, :], axis=-1)
    ii, jj = np.nonzero(np.triu(dist < r[:, None] + r[None, :] + nl.skin, k=1))
    np.testing.assert_array_equal(owners, ii)  # np.nonzero lists row-major: owner, then partner
    np.testing.assert_array_equal(partners, jj)
    rev = pairs.rev.to_numpy()[:n_pairs]
    assert np.array_equal(np.sort(rev), np.arange(n_pairs))
    by_slot = np.empty(n_pairs, dtype=np.int64)
    by_slot[rev] = np.arange(n_pairs)  # the pair in each slot
    rev_start = nl.rev_start.to_numpy()
    np.testing.assert_array_equal(np.repeat(np.arange(s.n_particles), np.diff(rev_start)), partners[by_slot])
    same_run = np.diff(partners[by_slot]) == 0
    assert np.all(np.diff(owners[by_slot])[same_run] > 0)


def test_wall_list_holds_the_walls_within_reach():
    """At each rebuild every particle lists the walls within r_i + skin of its centre (the force
    pass checks only those); a particle touching a wall has it listed."""
    x, r, v = random_packing()
    s = run_packing(x, r, v)  # settled: many particles rest on the floor and walls
    device = s.device
    assert s.neighbor_rebuilds >= 2
    points = np.array([w.point for w in s.walls])
    normals = np.array([w.normal for w in s.walls])
    gap = np.einsum("iwk,wk->iw", device.particles.x_ref.to_numpy()[:, None, :] - points[None], normals)
    expected = ((gap < r[:, None] + device.neighbor_list.skin) * (1 << np.arange(len(s.walls)))).sum(axis=1)
    near = device.walls.near.to_numpy()
    np.testing.assert_array_equal(near, expected)
    touching = device.walls.touching.to_numpy()
    assert np.count_nonzero(touching) > 10
    assert np.all(touching & ~near == 0)
    assert 0 < np.count_nonzero(near) < s.n_particles


def test_fused_step_follows_the_separate_kernels():
    """Scenes without interactions run forces and integration as one launch per step
    (granular.fused_step); the operations and their order are those of the separate kick--drift,
    force and kick kernels, so the trajectory must be the same. Health checks and callbacks (which
    read the state between steps) break the fusion at their steps and must see the same state."""
    x, r, v = random_packing()
    seen = {True: [], False: []}
    scenes = {}
    for fuse in (True, False):
        s = Scene((0, 0, 0), (0.15, 0.15, 0.3), check_interval=37)
        s.fuse_steps = fuse
        s.add_box_walls()
        s.add_spheres(x, r, velocities=v)
        s.time_step = 5e-5
        s.step(3000, callback=lambda sc, fuse=fuse: seen[fuse].append(sc.kinetic_energy()), callback_every=500)
        s.step(7)
        scenes[fuse] = s
    fused, separate = scenes[True], scenes[False]
    assert fused.contact_count > 100 and fused.neighbor_rebuilds >= 1
    assert fused.steps_taken == separate.steps_taken == 3007
    # the same arithmetic, but the compiler may contract multiply-adds differently in the two
    # kernels (fast math), so allow round-off amplified over 3000 steps (observed: bit-identical)
    np.testing.assert_allclose(fused.positions, separate.positions, rtol=0, atol=1e-10)
    np.testing.assert_allclose(fused.velocities, separate.velocities, rtol=0, atol=1e-7)
    np.testing.assert_allclose(fused.contact_forces, separate.contact_forces, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(seen[True], seen[False], rtol=1e-9)
    assert len(seen[True]) == 6
    # the contact view the force pass reads is written by the drift of either path
    for s in scenes.values():
        x_r = s.device.particles.x_r.to_numpy()
        np.testing.assert_array_equal(x_r[:, :3], s.positions)
        np.testing.assert_array_equal(x_r[:, 3], s.radii)
        np.testing.assert_array_equal(s.device.particles.v_m.to_numpy()[:, 3], s.masses)


def test_contact_history_survives_rebuilds_and_edits():
    """A sphere resting on a slope-free floor under a sideways push keeps its static-friction spring
    across forced neighbour rebuilds and across adding/removing other spheres."""
    s = small_scene()
    s.add_spheres([[0.05, 0.1, 0.0099], [0.15, 0.1, 0.0099]], [0.01, 0.01])
    s.step(2000)
    xi_before = s.device.walls.xi.to_numpy()[:2].copy()
    s.add_spheres([[0.1, 0.1, 0.15]], [0.01])  # structural edit: host round trip
    s.step(1)
    s._rebuild_neighbors()
    xi_after = s.device.walls.xi.to_numpy()[:2]
    np.testing.assert_allclose(xi_after, xi_before, atol=1e-9)
    s.keep_spheres(np.array([True, False, True]))
    assert s.n_particles == 2
    s.step(10)


def test_numpy_round_trip_of_state():
    s = small_scene()
    x = np.array([[0.05, 0.05, 0.05], [0.15, 0.15, 0.05]])
    w = np.array([[1.0, 2.0, 3.0], [0, 0, 0]])
    s.add_spheres(x, [0.01, 0.012], angular_velocities=w)
    np.testing.assert_array_equal(s.positions, x)
    np.testing.assert_array_equal(s.angular_velocities, w)
    assert s.contact_forces.shape == (2, 3) and s.contact_torques.shape == (2, 3)
    s.step(5)
    assert s.positions.dtype == np.float64 and s.velocities.shape == (2, 3)
    assert s.masses == pytest.approx(3200 * 4 / 3 * np.pi * np.array([0.01, 0.012]) ** 3)


@pytest.mark.parametrize("law", ["cdt", "epsd"])
def test_structural_edits_keep_pair_history_and_dynamics(law):
    """Adding and removing spheres that touch nothing -- which round-trips the state through the host
    and renumbers every pair -- must leave the pile's dynamics unchanged: only possible if every
    pair's tangential (and, under EPSD, rolling) history survives the edit."""
    x, r, v = random_packing()
    far = np.array([[0.14, 0.14, 0.29]])

    def pile(with_far):
        s = Scene((0, 0, 0), (0.15, 0.15, 0.3), pair=replace(SOIL_SOIL, rolling_model=law))
        s.add_box_walls(pair=replace(SOIL_STEEL, rolling_model=law))
        s.add_spheres(np.vstack([far, x]), np.concatenate([[0.006], r]), velocities=np.vstack([[0, 0, 0], v]))
        s.time_step = 5e-5
        return s

    edited, reference = pile(True), pile(True)
    edited.step(2500)
    n_pairs_before = edited.device.neighbor_list.n_pairs
    edited.add_spheres([[0.01, 0.14, 0.29]], [0.006])  # another far sphere
    edited.step(1)
    keep = np.ones(edited.n_particles, bool)
    keep[0] = False  # drop the first far sphere: every other index shifts down by one
    edited.keep_spheres(keep)
    edited.step(499)
    reference.step(3000)
    assert n_pairs_before > 100 and reference.contact_count > 100
    np.testing.assert_allclose(edited.positions[: len(r)], reference.positions[1:], rtol=0, atol=1e-12)
    np.testing.assert_allclose(edited.angular_velocities[: len(r)], reference.angular_velocities[1:], rtol=0, atol=1e-9)


def test_too_many_walls_is_refused_when_added():
    s = Scene((0, 0, 0), (1, 1, 1))
    for k in range(31):
        s.add_wall((0, 0, 0), (0, 0, 1))
    with pytest.raises(WheelsoilInputError, match="at most 31 planar walls"):
        s.add_wall((0, 0, 0), (0, 0, 1))
    assert len(s.walls) == 31


def test_an_unknown_rolling_law_is_named():
    with pytest.raises(WheelsoilInputError, match="rolling_model = 'viscous' is not one of cdt, epsd"):
        PairProperties(restitution=0.5, static_friction=0.4, rolling_friction=0.1, rolling_model="viscous")


def test_a_grain_launched_above_the_top_flies_and_falls_back():
    """A sphere thrown above the domain's top (a grain launched from under a wheel) is counted, not an escape: it
    falls back under gravity on its ballistic arc, its apex v^2 / 2g above the launch, and the run goes on; through
    the floor it would still stop the run (test_escaping_particle_stops_the_run)."""
    g, v0, z0 = 9.81, 1.5, 0.05
    s = Scene((0, 0, 0), (0.2, 0.2, 0.1), check_interval=10)
    s.add_box_walls()
    s.add_spheres([[0.1, 0.1, z0]], [0.005], velocities=[[0.0, 0.0, v0]])
    peak = 0.0
    flight = 2 * v0 / g
    for _ in range(int(round(0.9 * flight / 0.01))):
        s.step(max(1, int(round(0.01 / s.time_step))))
        peak = max(peak, float(s.positions[0, 2]))
    assert s.most_above_top == 1
    assert peak == pytest.approx(z0 + v0 ** 2 / (2 * g), abs=0.01)
    assert s.check_health()["above_top"] == 0 and s.positions[0, 2] < 0.1
