"""The DE--FE contact interface: closest point, Hertz against a triangulated plate, each contact once,
action = reaction (force and moment), no tunnelling through a thin shell."""

import math

import numpy as np
import pytest
import taichi as ti

from wheelsoil.coupling.closest_point import EDGE_AB, EDGE_BC, EDGE_CA, FACE, VERTEX_A, closest_points
from wheelsoil.coupling.contact import WheelContact
from wheelsoil.coupling.surface import ContactSurface
from wheelsoil.flexwheel.geometry import LUNAR_ROVER, build_wheel_mesh
from wheelsoil.flexwheel.material import SEED004_WHEEL
from wheelsoil.flexwheel.mesh import StructureMesh
from wheelsoil.flexwheel.shapes import strip
from wheelsoil.flexwheel.structure import Structure
from wheelsoil.granular import LUNAR_SOIL_SIMULANT, SOIL_STEEL, PairProperties, Scene
from wheelsoil.granular.materials import effective_modulus
from wheelsoil.taichi_types import to_ndarray, vec3


def test_closest_point_matches_brute_force_and_names_the_region():
    rng = np.random.default_rng(1)
    n = 400
    a, b, c = rng.normal(size=(3, n, 3))
    p = 1.5 * rng.normal(size=(n, 3))
    bary, feat = to_ndarray(vec3, np.zeros((n, 3))), ti.ndarray(ti.i32, shape=n)
    closest_points(*(to_ndarray(vec3, q) for q in (p, a, b, c)), bary, feat)
    w, f = bary.to_numpy(), feat.to_numpy()
    q = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c
    # brute force over a fine barycentric grid of each triangle
    s = np.linspace(0, 1, 161)
    u, v = np.meshgrid(s, s, indexing="ij")
    keep = u + v <= 1
    u, v = u[keep], v[keep]
    grid = a[:, None] + u[None, :, None] * (b - a)[:, None] + v[None, :, None] * (c - a)[:, None]
    brute = np.linalg.norm(grid - p[:, None], axis=2).min(axis=1)
    exact = np.linalg.norm(q - p, axis=1)
    assert np.all(exact <= brute + 1e-12)  # never farther than any sampled point
    assert np.all(brute - exact < 0.02 * np.linalg.norm(b - a, axis=1) + 1e-3)
    assert np.allclose(w.sum(axis=1), 1.0) and np.all(w >= -1e-12)
    # the region code agrees with the weights: face interior, an edge (one weight zero), a vertex
    zeros = np.sum(w <= 1e-14, axis=1)
    assert np.all((f == FACE) == (zeros == 0))
    assert np.all(((f >= EDGE_AB) & (f <= EDGE_CA)) == (zeros == 1))
    assert np.all((f >= VERTEX_A) == (zeros == 2))
    assert set(np.unique(f)) == set(range(7))  # every region was exercised
    assert np.all(w[f == EDGE_BC, 0] <= 1e-14)


def _plate(h=0.004, n=8, size=0.2):
    """A flat triangulated plate whose upper contact surface is the plane z = 0."""
    nodes, tri = strip(size, size, n, n)
    nodes = nodes + np.array([-size / 2, 0.0, -h / 2])
    return StructureMesh(nodes=nodes, triangles=tri, thickness=h, material=SEED004_WHEEL)


def _drop(position, velocity, *, on_plate, pair, radius=0.01, steps=1500, dt=1e-6):
    scene = Scene((-0.15, -0.15, -0.05), (0.15, 0.15, 0.1), gravity=(0, 0, 0))
    scene.add_spheres(np.array([position]), np.array([radius]), velocities=np.array([velocity]))
    if on_plate:
        mesh = _plate()
        st = Structure(mesh, rigid=True, hub_nodes=np.arange(mesh.n_nodes))
        st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 0, 0))
        scene.add_interaction(WheelContact(st, LUNAR_SOIL_SIMULANT, pair))
    else:
        scene.add_wall((0, 0, 0), (0, 0, 1), material=SEED004_WHEEL, pair=pair)
    scene.time_step = dt
    z, fz = [], []
    for _ in range(steps):
        scene.step(1)
        z.append(scene.positions[0, 2])
        fz.append(scene.contact_forces[0, 2])
    return np.array(z), np.array(fz), scene


# face interior, a shared edge (x = 0.025 is a grid line), a vertex shared by six facets
@pytest.mark.parametrize("xy", [(0.013, 0.011), (0.025, 0.013), (0.0, 0.0)], ids=["face", "edge", "vertex"])
def test_sphere_on_a_triangulated_plate_is_the_sphere_on_a_wall_and_hertz(xy):
    """Seed 004 eqs. 3-13 through the facet interface reproduce the wall contact to round-off wherever the
    sphere lands (each contact counted once), and the elastic impact matches Hertz theory."""
    elastic = PairProperties(restitution=1.0, static_friction=0.0, rolling_friction=0.0)
    r, v0 = 0.01, 0.5
    start = (xy[0], xy[1], r + 1e-4)
    z_wall, f_wall, _ = _drop(start, (0, 0, -v0), on_plate=False, pair=elastic)
    z_plate, f_plate, scene = _drop(start, (0, 0, -v0), on_plate=True, pair=elastic)
    assert np.max(np.abs(z_plate - z_wall)) < 1e-12
    assert np.max(np.abs(f_plate - f_wall)) < 1e-9 * f_wall.max()
    # Hertz (Johnson, Contact Mechanics, eq. 11.24): delta_max = (15 m v^2 / (16 E* sqrt(R)))^(2/5)
    m = LUNAR_SOIL_SIMULANT.density * 4 / 3 * math.pi * r**3
    e_star = effective_modulus(LUNAR_SOIL_SIMULANT, SEED004_WHEEL)
    delta = (15 * m * v0**2 / (16 * e_star * math.sqrt(r))) ** 0.4
    f_max = 4 / 3 * e_star * math.sqrt(r) * delta**1.5
    assert f_plate.max() == pytest.approx(f_max, rel=0.01)
    assert r - z_plate.min() == pytest.approx(delta, rel=0.01)
    assert scene.velocities[0, 2] == pytest.approx(v0, rel=1e-3)  # e = 1: elastic rebound


def test_restitution_and_friction_through_the_facets_equal_the_wall():
    """Seed 004 soil--steel pair (e = 0.5, mu_s = 0.39, mu_r = 0.15): an oblique spinning impact across
    a facet edge gives the wall's rebound, spin and tangential history to round-off."""
    start, vel = (0.02, 0.013, 0.0101), (0.4, -0.1, -0.5)
    _, _, wall = _drop(start, vel, on_plate=False, pair=SOIL_STEEL)
    _, _, plate = _drop(start, vel, on_plate=True, pair=SOIL_STEEL)
    assert np.allclose(plate.velocities, wall.velocities, atol=1e-12)
    assert np.allclose(plate.angular_velocities, wall.angular_velocities, atol=1e-9)
    assert plate.velocities[0, 2] == pytest.approx(0.5 * 0.5, rel=0.02)  # e = 0.5


def test_action_equals_reaction_in_force_and_moment():
    """Spheres pressed into a flexible wheel's tread and grousers: the forces on the particles are the
    negative of the nodal forces on the wheel, and so is their moment about any point (round-off)."""
    geometry = LUNAR_ROVER.with_element_size(0.05)
    mesh, hub = build_wheel_mesh(geometry)
    st = Structure(mesh, hub_nodes=hub, hub_center=(0, 0, 0), gravity=(0, 0, 0))
    st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 0, 0))
    contact = WheelContact(st, LUNAR_SOIL_SIMULANT, SOIL_STEEL, advance_structure=False)
    rng = np.random.default_rng(3)
    # spheres around the bottom of the wheel, overlapping tread or grousers by up to 2 mm
    surface = ContactSurface.from_mesh(mesh)
    aa, yy = np.meshgrid(np.linspace(-0.6, 0.6, 8), np.linspace(-0.2, 0.2, 5))  # spacing > 2 r_max
    n = aa.size
    angle = aa.ravel() + rng.uniform(-0.03, 0.03, n) - math.pi / 2
    y = yy.ravel() + rng.uniform(-0.03, 0.03, n)
    radius = rng.uniform(0.008, 0.012, n)
    rr = geometry.radius + radius - rng.uniform(0.0, 0.002, n)  # on the tread, some against a grouser
    pos = np.c_[rr * np.cos(angle), y, rr * np.sin(angle)]
    dist, _ = surface.closest_distance(pos, mesh.nodes)
    keep = dist > 0.5 * radius  # drop spheres whose centre sits on a grouser
    scene = Scene((-0.7, -0.4, -0.7), (0.7, 0.4, 0.0), gravity=(0, 0, 0))
    scene.add_spheres(pos[keep], radius[keep], velocities=rng.normal(0, 0.1, (keep.sum(), 3)),
                      angular_velocities=rng.normal(0, 5.0, (keep.sum(), 3)))
    scene.add_interaction(contact)
    scene.time_step = 1e-6
    for _ in range(3):
        scene.step(1)
    assert contact.contact_count >= 10
    # no sphere--sphere contacts here: the scene's contact forces are the wheel's alone
    assert scene.contact_count == contact.contact_count
    fp, tp, xp = scene.contact_forces, scene.contact_torques, scene.positions
    fw = contact.nodal_forces()
    xw = st.positions()
    scale = np.abs(fp).sum()
    assert np.allclose(fp.sum(axis=0), -fw.sum(axis=0), atol=1e-12 * scale)
    moment_particles = np.cross(xp, fp).sum(axis=0) + tp.sum(axis=0)
    moment_wheel = np.cross(xw, fw).sum(axis=0)
    assert np.allclose(moment_particles, -moment_wheel, atol=1e-11 * scale)
    force, moment = contact.resultant()  # about the hub centre (the origin here)
    assert np.allclose(force, fw.sum(axis=0), atol=1e-12 * scale)
    assert np.allclose(moment, moment_wheel, atol=1e-11 * scale)


def test_a_sphere_driven_hard_into_a_thin_shell_never_passes_through():
    """A sphere shot at 200 m/s into a 0.5 mm plate (Hertz overlap about 5 mm, more than r + h/2) rebounds
    on the side it came from: the contact keeps its side while the centre crosses the mid-surface."""
    h = 0.0005
    nodes, tri = strip(0.2, 0.2, 8, 8)
    mesh = StructureMesh(nodes=nodes + np.array([-0.1, 0.0, 0.0]), triangles=tri, thickness=h, material=SEED004_WHEEL)
    st = Structure(mesh, rigid=True, hub_nodes=np.arange(mesh.n_nodes))
    st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 0, 0))
    scene = Scene((-0.15, -0.15, -0.1), (0.15, 0.15, 0.1), gravity=(0, 0, 0), impact_speed=200.0)
    r = 0.002
    scene.add_spheres(np.array([[0.013, 0.011, r + h]]), np.array([r]), velocities=np.array([[0, 0, -200.0]]))
    scene.add_interaction(WheelContact(st, LUNAR_SOIL_SIMULANT, SOIL_STEEL))
    lowest = math.inf
    for _ in range(5000):
        scene.step(1)
        lowest = min(lowest, scene.positions[0, 2])
        if scene.velocities[0, 2] > 0.0 and scene.contact_count == 0:
            break
    assert lowest < 0.0  # the centre did cross the mid-surface ...
    assert scene.velocities[0, 2] > 0.0 and scene.positions[0, 2] > r  # ... and came back out on its side


def test_the_interface_counts_in_the_time_step():
    """The wheel contact (soil against steel, E* larger than soil--soil) lowers the scene's stable step
    where the Hertz estimate governs it (fast impacts; at 1 m/s the Rayleigh bound is the smaller)."""
    scene = Scene((0, 0, 0), (0.1, 0.1, 0.1), impact_speed=50.0)
    scene.add_spheres(np.array([[0.05, 0.05, 0.05]]), np.array([0.01]))
    before = scene.time_step
    mesh = _plate()
    st = Structure(mesh, rigid=True, hub_nodes=np.arange(mesh.n_nodes))
    scene.add_interaction(WheelContact(st, LUNAR_SOIL_SIMULANT, SOIL_STEEL))
    assert scene.stable_time_step().stable < before
    assert scene.time_step <= scene.stable_time_step().stable


@pytest.mark.parametrize("side_walls", [False, True])
def test_a_grain_moving_along_the_axle_enters_an_open_wheel_and_bounces_off_a_closed_one(side_walls):
    """``WheelGeometry.side_walls``: a sphere shot along the axle at the wheel's side, between the hub and the tread,
    passes into an open wheel (its drum: the tread, grousers and side walls are the contact surface, not the spokes)
    and rebounds from a closed one's side disc, as from a wall (elastic pair: the speed it came with, reversed); the
    discs close the annulus from the tread to the hub (their area, to the polygon's round-off)."""
    from dataclasses import replace

    from wheelsoil.flexwheel.geometry import CMU_K10_GROUSER

    geometry = replace(CMU_K10_GROUSER, side_walls=side_walls)
    mesh, hub = build_wheel_mesh(geometry)
    side = mesh.part[: len(mesh.triangles)] == mesh.part_names.index("side")
    tri, x = mesh.triangles[side], mesh.nodes
    area = 0.5 * np.linalg.norm(np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]]), axis=1).sum()
    annulus = 2 * math.pi * (geometry.tread_mid_radius ** 2 - geometry.hub_radius ** 2)
    assert area == pytest.approx(annulus * side_walls, rel=2e-3)
    assert np.isin(np.flatnonzero(side), mesh.surface).all()
    st = Structure(mesh, rigid=True, hub_nodes=hub)
    st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 0, 0))
    scene = Scene((-0.08, -0.08, -0.08), (0.08, 0.08, 0.08), gravity=(0, 0, 0))
    r, v0 = 0.003, 0.5
    y0 = 0.5 * geometry.width + 0.5 * geometry.tread_thickness + r + 1e-4
    scene.add_spheres(np.array([[0.0, y0, -0.04]]), np.array([r]), velocities=np.array([[0.0, -v0, 0.0]]))
    elastic = PairProperties(restitution=1.0, static_friction=0.0, rolling_friction=0.0)
    scene.add_interaction(WheelContact(st, LUNAR_SOIL_SIMULANT, elastic))
    inside = 0.5 * geometry.width - 0.5 * geometry.tread_thickness - r  # wholly past the side plane, in the drum
    steps = int(round(1e-3 / scene.time_step))  # 1 ms between checks, at the scene's stable step
    for _ in range(40):  # up to 40 ms: 20 mm of travel at 0.5 m/s
        scene.step(steps)
        if scene.positions[0, 1] < inside or scene.velocities[0, 1] > 0.0 and scene.contact_count == 0:
            break
    if side_walls:
        assert scene.velocities[0, 1] == pytest.approx(v0, rel=1e-3) and scene.positions[0, 1] > y0 - r
    else:
        assert scene.positions[0, 1] < inside and scene.velocities[0, 1] == pytest.approx(-v0, rel=1e-12)


@pytest.mark.parametrize("factor, stops", [(3.0, True), (0.3, False)])
def test_a_wheel_node_moving_past_its_share_of_an_edge_in_a_step_stops_the_run(factor, stops):
    """A node that moves more than NODE_MOVE_PER_STEP of the shortest facet edge in one DEM step stops the run with
    the node's speed, the limit and what to change (the contacts cannot follow it); a third of the limit does not."""
    from wheelsoil.coupling.node_speed import NODE_MOVE_PER_STEP
    from wheelsoil.errors import SimulationUnstableError

    mesh, hub = build_wheel_mesh(LUNAR_ROVER.with_element_size(0.05))
    st = Structure(mesh, hub_nodes=hub, hub_center=(0, 0, 0), gravity=(0, 0, 0))
    st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 0, 0))
    contact = WheelContact(st, LUNAR_SOIL_SIMULANT, SOIL_STEEL, health_every=1)
    scene = Scene((-0.7, -0.4, -0.7), (0.7, 0.4, 0.0), gravity=(0, 0, 0))
    scene.add_spheres(np.array([[0.0, 0.0, -0.65]]), np.array([0.01]))  # clear of the wheel
    scene.add_interaction(contact)
    dt = scene.time_step
    limit = NODE_MOVE_PER_STEP * contact.shortest_edge / dt
    assert 0.005 < contact.shortest_edge < 0.05
    tip = int(np.argmin(mesh.nodes[:, 2]))  # the lowest node: a grouser's tip, free of the hub
    v = np.zeros((mesh.n_nodes, 3))
    v[tip] = (0.0, 0.0, factor * limit)
    st.set_state(velocities=v)
    if stops:
        with pytest.raises(SimulationUnstableError, match=r"the wheel went unstable.*soil\.time_step") as info:
            scene.step(1)
        assert f"{limit:.3g} m/s" in str(info.value)
    else:
        scene.step(1)
        assert st.max_node_speed() < limit


def _grains_on_a_spinning_wheel(cull: bool, steps: int = 300):
    """Grains of 2.5-3.5 mm rained on the closed CMU grouser wheel (its 6 mm facets: many candidates a grain) while
    it spins; returns the scene's state, the wheel's nodes, the most candidates any step set aside, and the
    grain--wheel contacts summed over the steps."""
    from dataclasses import replace

    from wheelsoil.flexwheel.geometry import CMU_K10_GROUSER

    mesh, hub = build_wheel_mesh(replace(CMU_K10_GROUSER, side_walls=True))
    st = Structure(mesh, rigid=True, hub_nodes=hub)
    st.drive_hub(velocity=(0, 0, 0), angular_velocity=(0, 3.0, 0))
    scene = Scene((-0.3, -0.3, -0.3), (0.3, 0.3, 0.3), gravity=(0, 0, -9.81))
    rng = np.random.default_rng(7)
    x, radius = [], []
    while len(x) < 160:  # apart from each other, just outside the grousers' tips (0.063 m), all round
        r = rng.uniform(0.0025, 0.0035)
        angle, ring = rng.uniform(0, 2 * np.pi), 0.0645 + r + rng.uniform(0.0, 0.003)
        p = np.array([ring * np.cos(angle), rng.uniform(-0.03, 0.03), ring * np.sin(angle)])
        if all(np.linalg.norm(p - q) > r + rq for q, rq in zip(x, radius)):
            x.append(p), radius.append(r)
    x, radius = np.array(x), np.array(radius)
    scene.add_spheres(x, radius, velocities=-0.3 * x / np.linalg.norm(x, axis=1)[:, None])
    contact = WheelContact(st, LUNAR_SOIL_SIMULANT, SOIL_STEEL)
    contact.cull_far_candidates = cull
    scene.add_interaction(contact)
    most, touching = 0, 0
    for _ in range(steps):
        scene.step(1)
        most, touching = max(most, contact.candidates_set_aside), touching + contact.contact_count
    return (scene.positions, scene.velocities, scene.angular_velocities), st.positions(), most, touching


def test_candidates_set_aside_by_their_bounds_change_no_result():
    """The contact evaluation sets aside the candidates that a facet's plane or holding ball proves out of reach
    (``WheelContact.cull_far_candidates``, :func:`wheelsoil.coupling.kernels.surely_apart`); grains raining onto a
    spinning closed wheel move the same, to the bit, with it as without it, and it did set candidates aside while
    grains touched the wheel."""
    with_cull = _grains_on_a_spinning_wheel(True)
    without = _grains_on_a_spinning_wheel(False)
    assert with_cull[2] > 0 and without[2] == 0 and with_cull[3] >= 100 and without[3] == with_cull[3]
    for a, b in zip(with_cull[0], without[0]):
        assert np.array_equal(a, b)
    assert np.array_equal(with_cull[1], without[1])
