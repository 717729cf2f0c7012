"""Each sphere's displacement allowance between neighbour rebuilds (granular.neighbors.displacement_allowance).

The Verlet lists must hold every pair that can touch before the next rebuild. With each sphere allowed half its own
clearance (its gap to the nearest sphere or wall it does not list) instead of half the skin, a grain thrown clear
of the bed moves further between rebuilds; these tests check, against brute force, that the clearance never exceeds
a true gap, that the lists stay complete (the trajectory is the one with lists rebuilt at every step, to the bit),
and that a thrown grain no longer sets the rebuild rate: its search widens beyond the 27 cells (also above the grid's
top, where the grid clamps it), and a body's candidate lists bound each sphere by its own gap to what they do not list.
"""

import functools

import numpy as np
import pytest

from wheelsoil.granular import Scene
from wheelsoil.granular.interaction import HalfSkinRule

from lifted_grains import lift


def _box(seed: int) -> Scene:
    rng = np.random.default_rng(seed)
    grid = np.stack(np.meshgrid(*[np.arange(6)] * 3, indexing="ij"), -1).reshape(-1, 3)
    x = 0.015 + grid * 0.021 + rng.uniform(-1e-3, 1e-3, grid.shape)
    r = rng.uniform(0.006, 0.0105, len(x))
    s = Scene((0, 0, 0), (0.15, 0.15, 0.3))
    s.add_box_walls()
    s.add_spheres(x, r, velocities=rng.normal(0, 0.2, x.shape))
    s.time_step = 5e-5
    return s


@functools.lru_cache(maxsize=None)
def _settled_state(seed: int, settle_steps: int) -> dict:
    s = _box(seed)
    s.step(settle_steps)
    return s.state()


def settled_box(seed: int, settle_steps: int = 1500) -> Scene:
    """216 spheres (6-10.5 mm) dropped into a 0.15 x 0.15 x 0.3 m box and let settle (settled once per seed; each
    call restores that state, which steps bit for bit like the scene it was taken from)."""
    s = _box(seed)
    s.restore_state({key: np.array(value, copy=True) for key, value in _settled_state(seed, settle_steps).items()})
    return s


def throw_top_grains(s: Scene, count: int, speed: float) -> np.ndarray:
    """Send the ``count`` highest spheres up at ``speed`` [m/s] (as a wheel throws grains off the surface)."""
    top = np.argsort(s.positions[:, 2])[-count:]
    v = s.velocities
    v[top] = (0.3 * speed, -0.2 * speed, speed)
    s.set_velocities(v)
    return top


def least_unlisted_gaps(s: Scene) -> np.ndarray:
    """Brute force at the last rebuild: each sphere's least gap [m] to a sphere listed with it by neither row or to a
    wall it does not list."""
    device = s.device
    nl = device.neighbor_list
    x = device.particles.x_ref.to_numpy()
    r = s.radii
    gap = np.linalg.norm(x[:, None] - x[None], axis=-1) - r[:, None] - r[None]
    listed = np.zeros(gap.shape, bool)
    start, j = nl.pairs.start.to_numpy(), nl.pairs.j.to_numpy()[: nl.n_pairs]
    owners = np.repeat(np.arange(len(r)), np.diff(start))
    listed[owners, j] = listed[j, owners] = True
    np.fill_diagonal(listed, True)
    sphere = np.where(listed, np.inf, gap).min(axis=1)
    points = np.array([w.point for w in s.walls])
    normals = np.array([w.normal for w in s.walls])
    wall_gap = np.einsum("iwk,wk->iw", x[:, None, :] - points[None], normals) - r[:, None]
    near = device.walls.near.to_numpy()
    not_near = (near[:, None] & (1 << np.arange(len(s.walls)))[None]) == 0
    wall = np.where(not_near, wall_gap, np.inf).min(axis=1)
    return np.minimum(sphere, wall)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_clearance_is_a_lower_bound_on_every_unlisted_gap_and_no_less_than_the_block_allows(seed):
    s = settled_box(seed)
    throw_top_grains(s, 6, 1.5)
    s.step(300)
    nl = s.device.neighbor_list
    clearance = nl.clearance.to_numpy()
    true = least_unlisted_gaps(s)
    assert np.all(clearance <= true * (1 + 1e-12))  # never more than a true gap: the lists stay complete
    assert np.all(clearance >= nl.skin * (1 - 1e-12))  # every sphere is inside the grid here
    # beyond the 27 cells searched, the bound is at least one cell edge less the two radii
    cell, r = nl.grid.cell, s.radii
    assert np.all(clearance >= np.minimum(true, cell - r - r.max()) * (1 - 1e-12))
    # the allowance: half the clearance, at least half the skin (no interaction caps it here)
    allowance = 1.0 / np.sqrt(nl.allowance_inv2.to_numpy())
    np.testing.assert_allclose(allowance, 0.5 * np.maximum(nl.skin, clearance), rtol=1e-12)
    assert nl.cap == np.inf


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_thrown_grains_leave_the_trajectory_unchanged_and_rebuild_less(seed):
    """Lists rebuilt at every step are complete by construction; the per-sphere allowance must give the same
    trajectory to the bit (rows sorted by partner index fix the summation order) with fewer rebuilds than the
    half-skin rule."""
    runs = {}
    for rule in ("every step", "allowance", "half skin"):
        s = settled_box(seed)
        if rule == "half skin":
            s.add_interaction(HalfSkinRule())
        throw_top_grains(s, 4, 2.0)
        before = s.neighbor_rebuilds
        if rule == "every step":
            for _ in range(600):
                s.request_neighbor_rebuild()
                s.step(1)
        else:
            s.step(600)
        runs[rule] = (s.positions, s.angular_velocities, s.neighbor_rebuilds - before)
    ref = runs["every step"]
    for rule in ("allowance", "half skin"):
        np.testing.assert_array_equal(runs[rule][0], ref[0])
        np.testing.assert_array_equal(runs[rule][1], ref[1])
    assert ref[2] == 600
    # a grain at 2 m/s crosses the half skin (0.9 mm) in 9 steps; in the air its allowance is up to half its
    # clearance, which the 22.8 mm cells bound at about 5 mm here (seeds 0-5 gave 0.45-0.64 of the half-skin rule's
    # rebuilds)
    assert runs["allowance"][2] < 0.75 * runs["half skin"][2]


def test_the_cap_bounds_every_allowance_and_a_request_rebuilds_at_the_next_step():
    s = settled_box(0, settle_steps=200)
    s.add_interaction(HalfSkinRule())
    before = s.neighbor_rebuilds
    s.request_neighbor_rebuild()
    s.step(1)
    assert s.neighbor_rebuilds == before + 1
    nl = s.device.neighbor_list
    np.testing.assert_allclose(1.0 / np.sqrt(nl.allowance_inv2.to_numpy()), 0.5 * nl.skin, rtol=1e-12)
    assert s.displacement_cap() == pytest.approx(0.5 * s.skin)


@pytest.mark.parametrize("seed", [0, 3])
def test_a_moving_body_still_meets_every_grain_thrown_at_it(seed):
    """A rigid plate sweeping over the bed at 0.5 m/s while grains are thrown up into it: its candidate lists are
    rebuilt only with the scene's (and ask for a scene rebuild when the plate has moved), and the spheres' allowance
    is bounded by each one's gap to the facets it does not list less the plate's own skin, so the run is the one
    with everything rebuilt at every step."""
    from wheelsoil.coupling.contact import WheelContact
    from wheelsoil.flexwheel.material import SEED004_WHEEL
    from wheelsoil.flexwheel.mesh import StructureMesh
    from wheelsoil.flexwheel.shapes import strip
    from wheelsoil.flexwheel.structure import Structure
    from wheelsoil.granular import LUNAR_SOIL_SIMULANT, SOIL_STEEL

    runs = {}
    for rule in ("every step", "allowance"):
        s = settled_box(seed)
        top = s.positions[:, 2] + s.radii
        nodes, tri = strip(0.12, 0.12, 12, 12)
        nodes = nodes + np.array([0.0, 0.075, top.max() + 0.012])
        mesh = StructureMesh(nodes=nodes, triangles=tri, thickness=0.002, material=SEED004_WHEEL)
        plate = Structure(mesh, rigid=True, hub_nodes=np.arange(mesh.n_nodes), gravity=(0, 0, 0))
        plate.drive_hub(velocity=(0.5, 0.0, 0.0), angular_velocity=(0, 0, 0))
        # a thin margin for the plate's own motion, so that the spheres' share of it is what keeps the lists whole
        contact = WheelContact(plate, LUNAR_SOIL_SIMULANT, SOIL_STEEL, wheel_skin=0.5 * s.skin)
        s.add_interaction(contact)
        throw_top_grains(s, 8, 2.0)
        before, hits = s.neighbor_rebuilds, 0
        for _ in range(500):
            if rule == "every step":
                s.request_neighbor_rebuild()
            s.step(1)
            hits += contact.contact_count
        runs[rule] = (s.positions, s.velocities, s.neighbor_rebuilds - before, hits)
        if rule == "allowance":
            _check_wheel_gaps(s, contact, plate)
    ref, new = runs["every step"], runs["allowance"]
    assert ref[3] > 20  # sphere--plate contacts over the run, counted step by step
    assert new[3] == ref[3]
    np.testing.assert_allclose(new[0], ref[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(new[1], ref[1], rtol=0, atol=1e-9)
    assert new[2] < 0.5 * ref[2]


def _check_wheel_gaps(s: Scene, contact, plate) -> None:
    """After a rebuild of both lists: each sphere's gap to the plate's facets it does not list (the wheel contact's
    bound) is no more than the true gap to the plate for a sphere that lists none (brute force: the facets are the
    flat rectangle the plate covers), every allowance is within it less the plate's skin, and a grain thrown clear
    of the plate may move further than the candidates' margin."""
    s.request_neighbor_rebuild()
    s.step(1)
    x = s.device.particles.x_ref.to_numpy()
    r = s.radii
    nodes = plate.arrays.x.to_numpy()
    lo, hi = nodes.min(axis=0), nodes.max(axis=0)
    h = 0.5 * float(np.max(plate.mesh.thickness))  # one thickness over the plate
    true = np.linalg.norm(x - np.clip(x, lo, hi), axis=1) - r - h
    gap = contact._arrays["wheel_gap"].to_numpy()
    listless = contact._arrays["count"].to_numpy() == 0
    assert listless.sum() > 100
    assert np.all(gap[listless] <= true[listless] * (1 + 1e-12))
    allowance = 1.0 / np.sqrt(s.device.neighbor_list.allowance_inv2.to_numpy())
    assert np.all(allowance <= (gap - contact.wheel_skin) * (1 + 1e-12))
    assert np.all(gap >= contact.skin * (1 - 1e-12))  # no less than the candidates' own margin
    assert allowance.max() > 1.2 * contact.sphere_skins * s.skin  # a thrown grain is not held to the margin


@pytest.mark.parametrize("seed", [0, 2])
def test_a_grain_in_the_air_or_above_the_grid_searches_further(seed):
    """Two grains lifted clear of the bed, one of them above the grid's top (a thrown grain the grid clamps into its
    top layer): their search widens to 7 cells a side, and their clearance is still a lower bound on every unlisted
    gap (brute force), and at least three cells less the two radii unless a true gap is less."""
    s = settled_box(seed)
    top = np.argsort(s.positions[:, 2])[-2:]
    lift(s, top, [(0.06, 0.07, 0.22), (0.09, 0.08, 0.36)], 3.0)  # the second above the domain (0.3 m) and the grid
    nl = s.device.neighbor_list
    assert nl.widened >= 2
    clearance = nl.clearance.to_numpy()
    true = least_unlisted_gaps(s)
    assert np.all(clearance <= true * (1 + 1e-12))
    r, cell = s.radii, nl.grid.cell
    assert np.all(clearance[top] >= np.minimum(true[top], 3 * cell - r[top] - r.max()) * (1 - 1e-12))
    assert np.all(clearance[top] > 2 * cell)  # the walls, 60 mm off, bound them here, not the 27 cells (< 23 mm)


def test_the_widened_clearance_stops_at_the_block_it_searched():
    """A grain above a layer of spheres whose nearest one lies just beyond the 7 cells a side searched: its clearance
    is the wide block's bound, below the true gap (brute force) and at least three cells less the two radii."""
    rng = np.random.default_rng(5)
    xy = np.stack(np.meshgrid(*[np.arange(0.05, 0.351, 0.025)] * 2, indexing="ij"), -1).reshape(-1, 2)
    layer = np.c_[xy, np.full(len(xy), 0.011)]
    r = rng.uniform(0.006, 0.0105, len(layer) + 1)
    s = Scene((0, 0, 0), (0.4, 0.4, 0.4))
    s.add_box_walls()
    s.add_spheres(np.r_[layer, [[0.2, 0.2, 0.2]]], r)
    s.time_step = 5e-5
    s.step(1)
    grid = s.device.neighbor_list.grid
    origin_z, cell = grid.origin[2], grid.cell
    below = int((0.011 - origin_z) // cell)
    lift(s, [-1], [(0.2, 0.2, origin_z + (below + 4.5) * cell)], 3.0)  # four cells above the layer's, mid-cell
    nl = s.device.neighbor_list
    assert nl.widened >= 1
    clearance = nl.clearance.to_numpy()
    true = least_unlisted_gaps(s)[-1]
    assert clearance[-1] <= true * (1 + 1e-12)
    assert clearance[-1] >= 3 * cell - r[-1] - r.max()
    assert true < 5 * cell - r[-1] - r.max()  # what a bound two cells wider than the search would have claimed
