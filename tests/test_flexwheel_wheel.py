"""The parametric wheel, its hub, the rigid variant, the coupling interface, bad input and the command."""

import json
import math
from dataclasses import replace

import meshio
import numpy as np
import pytest

from wheelsoil.cases.cli import main
from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError
from wheelsoil.flexwheel.geometry import EXOMARS, LUNAR_ROVER, SpokeRow, build_wheel_mesh, preset
from wheelsoil.flexwheel.loadtest import plate_load_curve, point_load_stiffness
from wheelsoil.material import Material
from wheelsoil.flexwheel.mesh import StructureMesh
from wheelsoil.flexwheel.structure import Structure

COARSE_EXOMARS = EXOMARS.with_element_size(0.015)


def test_presets_have_the_published_dimensions_and_the_paper_sized_mesh():
    assert (LUNAR_ROVER.radius, LUNAR_ROVER.width) == (0.6, 0.5)  # seed 004
    assert (LUNAR_ROVER.material.youngs_modulus, LUNAR_ROVER.material.poisson_ratio) == (800e6, 0.288)
    assert (EXOMARS.radius, EXOMARS.width, EXOMARS.grouser_count) == (0.1425, 0.12, 12)  # seed 000
    assert EXOMARS.spoke_pitch == pytest.approx(60.0)  # six virtual spokes
    mesh, hub = build_wheel_mesh(LUNAR_ROVER)
    assert 25_000 <= mesh.n_elements <= 35_000  # seed 004 Table 2: 29,644 elements
    # grousers sit on the tread and stick out by their height
    r = np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 2])
    assert r.max() == pytest.approx(LUNAR_ROVER.radius + LUNAR_ROVER.grouser_height, rel=1e-9)
    assert np.allclose(r[hub], LUNAR_ROVER.hub_radius)


def test_mesh_resolution_is_a_parameter_and_exports_with_meshio(tmp_path):
    coarse, _ = build_wheel_mesh(COARSE_EXOMARS)
    fine, _ = build_wheel_mesh(EXOMARS.with_element_size(0.0075))
    assert fine.n_elements > 3 * coarse.n_elements
    assert fine.total_mass == pytest.approx(coarse.total_mass, rel=0.02)  # same wheel, finer mesh
    for suffix in (".vtu", ".xdmf"):
        path = coarse.write(tmp_path / f"wheel{suffix}", point_data={"displacement": np.zeros((coarse.n_nodes, 3))})
        back = meshio.read(path)
        assert back.points.shape == coarse.nodes.shape
        assert back.cells_dict["triangle"].shape == coarse.triangles.shape
        assert "displacement" in back.point_data


def test_surface_normals_point_outwards_on_the_tread():
    mesh, _ = build_wheel_mesh(COARSE_EXOMARS)
    tread = mesh.surface[mesh.part[mesh.surface] == 0]
    p = mesh.nodes[mesh.triangles[tread]]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    centre = p.mean(axis=1)
    radial = centre * np.array([1.0, 0.0, 1.0])
    assert np.all(np.sum(normal * radial, axis=1) > 0)


def test_beam_spokes_are_an_option():
    g = replace(COARSE_EXOMARS, spoke_model="beam")
    mesh, hub = build_wheel_mesh(g)
    assert len(mesh.beams) > 0 and np.all(mesh.part[len(mesh.triangles):] == 2)
    assert 0.3 * point_load_stiffness(COARSE_EXOMARS) < point_load_stiffness(g) < 3 * point_load_stiffness(COARSE_EXOMARS)


def test_radial_stiffness_varies_with_the_spoke_layout_and_the_plate_curve_is_consistent():
    angles = np.linspace(0, COARSE_EXOMARS.spoke_pitch, 5)
    k = np.array([point_load_stiffness(COARSE_EXOMARS, a) for a in angles])
    assert k.max() / k.min() > 1.2  # a spoked wheel is stiffer over some positions than others (seed 000)
    curve = plate_load_curve(COARSE_EXOMARS, [0.002, 0.004, 0.008])
    assert np.all(np.diff(curve.force) > 0) and np.all(curve.contact_nodes > 0)
    # with the same contact nodes, the plate's first point equals the point-load stiffness within 5 %
    assert curve.secant_stiffness()[0] == pytest.approx(k[0], rel=0.05)


def test_kinematic_hub_drives_the_wheel_and_reports_the_reaction():
    mesh, hub = build_wheel_mesh(COARSE_EXOMARS)
    wheel = Structure(mesh, hub_nodes=hub, hub_center=[0, 0, 0], damping=200.0, gravity=[0, 0, -9.81])
    wheel.drive_hub(velocity=[0.1, 0, 0], angular_velocity=[0, 2.0, 0])
    n = wheel.advance(2e-3)
    assert n == int(np.ceil(2e-3 / wheel.stable_time_step))  # stable sub-steps over the interval
    assert wheel.hub_position == pytest.approx([2e-4, 0, 0], abs=1e-12)
    rot = wheel.hub_rotation
    assert np.arccos(rot[0, 0]) == pytest.approx(4e-3, rel=1e-6)
    f, _ = wheel.hub_reaction()
    # the rig holds the wheel's weight (plus inertia of the start, which averages out to ~0 vertically)
    assert f[2] > 0


def test_force_driven_hub_falls_freely_and_the_rigid_variant_moves_as_one_body():
    mesh, hub = build_wheel_mesh(COARSE_EXOMARS)
    for rigid in (False, True):
        wheel = Structure(mesh, hub_nodes=hub, rigid=rigid, hub_mass=1.0, gravity=[0, 0, -1.62])
        wheel.drive_hub(free_translation=[True, True, True], free_rotation=[True, True, True])
        t = 0.01
        for _ in range(100):  # a rigid wheel takes one step per interval: give it 100 intervals
            wheel.advance(t / 100)
        x = wheel.positions()
        # free fall of the whole wheel: every node dropped g t^2 / 2 (to leapfrog's O(dt) start error)
        drop = mesh.nodes[:, 2] - x[:, 2]
        assert np.allclose(drop, 0.5 * 1.62 * t**2, rtol=0.02)
        if rigid:
            assert np.allclose(x - x[0], mesh.nodes - mesh.nodes[0], atol=1e-12)
            wheel.advance(t)  # a rigid wheel takes any interval in one step, longer ones too


def test_external_forces_over_an_interval_and_health_check():
    mesh, hub = build_wheel_mesh(COARSE_EXOMARS)
    wheel = Structure(mesh, hub_nodes=hub)
    bottom = np.argmin(mesh.nodes[:, 2])
    f = np.zeros((mesh.n_nodes, 3))
    f[bottom, 2] = 5.0
    n = wheel.advance(1e-4, forces=f)
    assert n == int(np.ceil(1e-4 / wheel.stable_time_step))
    assert wheel.velocities()[bottom, 2] > 0
    assert wheel.surface_triangles.shape[1] == 3
    f[bottom, 2] = 1e12  # absurd load: the health check stops the run with a clear error
    with pytest.raises(SimulationUnstableError, match="unstable"):
        for _ in range(50):
            wheel.advance(1e-4, forces=f)


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(tread_thickness=0.0), "tread_thickness"),
        (dict(radius=-1.0), "radius"),
        (dict(hub_radius=0.2), "hub_radius"),
        (dict(spoke_rows=(SpokeRow(0.2, 0.1),)), "spoke_rows"),
        (dict(spoke_model="cable"), "spoke_model"),
        (dict(element_size=0.1), "element_size"),
    ],
)
def test_bad_geometry_is_refused_with_the_key_and_value(change, match):
    with pytest.raises(WheelsoilInputError, match=match):
        replace(EXOMARS, **change)


def test_bad_material_mesh_and_step_are_refused():
    with pytest.raises(WheelsoilInputError, match="youngs_modulus"):
        Material("m", 0.0, 0.3, 7850.0)
    with pytest.raises(WheelsoilInputError, match="poisson_ratio"):
        Material("m", 1e9, 0.5, 7850.0)
    with pytest.raises(WheelsoilInputError, match="finite modulus"):
        StructureMesh(np.eye(3), [[0, 1, 2]], 0.01, Material("rigid", math.inf, 0.3, 7850.0))
    mat = Material("m", 1e9, 0.3, 1000.0)
    nodes = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], float)
    with pytest.raises(WheelsoilInputError, match="degenerate"):
        StructureMesh(nodes, [[0, 1, 2]], 0.01, mat)
    with pytest.raises(WheelsoilInputError, match="thickness"):
        StructureMesh(nodes, [[0, 1, 3]], -0.01, mat)
    with pytest.raises(WheelsoilInputError, match="node indices"):
        StructureMesh(nodes, [[0, 1, 7]], 0.01, mat)
    with pytest.raises(WheelsoilInputError, match="belongs to no element"):
        Structure(StructureMesh(nodes, [[0, 1, 3]], 0.01, mat))  # node 2 floats free
    s = Structure(StructureMesh(nodes[[0, 1, 3]], [[0, 1, 2]], 0.01, mat))
    with pytest.raises(WheelsoilInputError, match="critical step"):
        s.step(1, 2.0 * s.critical_time_step)
    with pytest.raises(WheelsoilInputError, match="unknown wheel preset"):
        preset("tractor")


@pytest.mark.slow
def test_wheel_command_meshes_and_load_tests_a_preset(tmp_path, capsys):
    out = tmp_path / "exo"
    assert main(["wheel", "exomars", "--element-size", "0.015", "--points", "3", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert 5e3 < summary["point_load_stiffness_mean_N_per_m"] < 5e4
    assert (out / "mesh.vtu").stat().st_size > 0 and (out / "load_test.png").stat().st_size > 0
    assert len((out / "load_test.csv").read_text().splitlines()) == 1 + 2 * 3
    assert "kN/m" in capsys.readouterr().out
    assert main(["wheel", "tractor", "--out", str(tmp_path / "x")]) == 2


@pytest.mark.parametrize("lead", ["anchor_lead", "none"])
def test_a_linearised_load_on_a_moving_wheel_delivers_its_evaluated_impulse(lead):
    """The coupling hands each node f - k (x - x_a) for the sub-steps of a DEM interval (coupling.contact). A free
    wheel moving steadily at v receives, over the interval, the impulse F dt only when x_a is the node's position
    carried ahead by coupling.contact.anchor_lead; anchored where it stands, it receives F dt - k v dt^2 (n - 1) / 2
    per node, the bias that held flexible wheels up by more than the soil's force (issue 35)."""
    from wheelsoil.coupling.contact import anchor_lead

    mesh, hub = build_wheel_mesh(COARSE_EXOMARS)
    wheel = Structure(mesh, hub_nodes=hub, hub_mass=1.0, gravity=[0, 0, 0])
    wheel.drive_hub(free_translation=[True, True, True], free_rotation=[True, True, True])
    v = np.array([0.0, 0.0, -0.2])
    wheel.set_hub_state(velocity=v)
    wheel.set_state(velocities=np.tile(v, (mesh.n_nodes, 1)))
    loaded = np.flatnonzero(mesh.nodes[:, 2] < mesh.nodes[:, 2].min() + 0.01)
    interval, force, k = 1e-5, 0.02, 2e4  # k dt^2 / m ~ 4e-3 for these ~1e-3 kg nodes: the motion stays steady
    n_sub = int(np.ceil(interval / wheel.stable_time_step * (1 - 1e-12)))
    assert n_sub >= 3
    a = wheel.device_arrays()
    f = np.zeros((mesh.n_nodes, 3))
    f[loaded, 2] = force
    stiffness = np.zeros(mesh.n_nodes)
    stiffness[loaded] = k
    x0 = wheel.positions()
    ahead = anchor_lead(interval, n_sub) if lead == "anchor_lead" else 0.0
    a.k_ext.from_numpy(stiffness)
    a.x_anchor.from_numpy(x0 + ahead * v)
    mass = a.mass.to_numpy()
    momentum = lambda: (mass[:, None] * wheel.velocities()).sum(0) + 1.0 * wheel.hub_velocity  # noqa: E731
    p0 = momentum()
    assert wheel.advance(interval, forces=f) == n_sub
    impulse = momentum() - p0
    expected = force * interval * len(loaded)
    bias = k * abs(v[2]) * interval**2 * (n_sub - 1) / (2 * n_sub) * len(loaded)  # the standing anchor's extra push
    assert bias > 0.2 * expected  # the test can tell the two apart
    if lead == "anchor_lead":
        assert impulse[2] == pytest.approx(expected, rel=0.02)  # second order: the nodes' own acceleration
    else:
        assert impulse[2] == pytest.approx(expected + bias, rel=0.02)
    assert abs(impulse[0]) < 1e-9 * expected and abs(impulse[1]) < 1e-9 * expected


@pytest.mark.parametrize("args, key", [(["--points", "1"], "--points=1"), (["--max-load-factor", "0"], "--max-load-factor=0"),
                                       (["--max-twist", "50"], "--max-twist=50")])
def test_wheel_command_checks_its_options_before_any_test(tmp_path, capsys, args, key):
    """A bad load-test setting is refused before the wheel is meshed (nothing is written), the torsion's included."""
    out = tmp_path / "w"
    assert main(["wheel", "exomars", "--out", str(out), *args]) == 2
    assert key in capsys.readouterr().err and not out.exists()
