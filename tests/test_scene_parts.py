"""The scene's plain parts (issue 38 item 5): its domain, the checks on its input, its health verdict and its
checkpoint, each on its own; and that a refused edit leaves the scene as it was."""

import math

import numpy as np
import pytest

from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError
from wheelsoil.granular.contact_history import ContactHistory
from wheelsoil.granular.health import HealthFigures, require_healthy
from wheelsoil.granular.materials import LUNAR_SOIL_SIMULANT
from wheelsoil.granular.scene_checkpoint import SceneCheckpoint
from wheelsoil.granular.scene_domain import SceneDomain
from wheelsoil.granular.scene_input import checked_mask, checked_plane, checked_spheres, checked_wall_rows
from wheelsoil.granular.sphere_state import SphereState
from wheelsoil.granular.timestep import estimate_time_step


def test_domain_refuses_an_empty_box_and_wraps_a_periodic_one():
    with pytest.raises(WheelsoilInputError, match=r"domain_max \[1.0, 0.0, 1.0\] must exceed"):
        SceneDomain.of((0, 0, 0), (1, 0, 1))
    domain = SceneDomain.of((-0.1, 0, 0), (0.3, 1, 1), periodic_x=True)
    assert domain.period == pytest.approx(0.4)
    # a period either way lands on the same point; the period's end maps to its start
    assert np.allclose(domain.wrapped(np.array([0.05, 0.45, -0.35, 0.3])), [0.05, 0.05, 0.05, -0.1])
    x = np.array([[0.5, 0.5, 0.5], [0.6, 0.5, 0.5], [0.1, 1.2, 0.5]])
    placed = domain.placed(x)
    assert placed[:, 0] == pytest.approx([0.1, 0.2, 0.1])
    assert x[1, 0] == 0.6  # a copy
    assert domain.outside(placed).tolist() == [2]  # y is not periodic
    assert SceneDomain.of((0, 0, 0), (1, 1, 1)).period == 0.0


def test_sphere_input_names_the_argument_and_the_value():
    x, r, v, w = checked_spheres([[0, 0, 0], [1, 1, 1]], 0.01)
    assert r.tolist() == [0.01, 0.01] and v.shape == w.shape == (2, 3) and not v.any()
    with pytest.raises(WheelsoilInputError, match=r"radius -0.5 m of sphere 1 is invalid"):
        checked_spheres([[0, 0, 0], [1, 1, 1]], [0.1, -0.5])
    with pytest.raises(WheelsoilInputError, match=r"radii = nan must be finite"):
        checked_spheres([[0, 0, 0]], math.nan)
    with pytest.raises(WheelsoilInputError, match=r"velocities has shape \(1, 3\); expected \(2, 3\)"):
        checked_spheres([[0, 0, 0], [1, 1, 1]], 0.1, velocities=[[0, 0, 0]])
    with pytest.raises(WheelsoilInputError, match=r"positions contains a non-finite value inf at index \(0, 2\)"):
        checked_spheres([[0, 0, math.inf]], 0.1)
    with pytest.raises(WheelsoilInputError, match=r"wall_history has shape \(2, 1, 3\); expected \(2, 5, 3\)"):
        checked_wall_rows("wall_history", np.zeros((2, 1, 3)), 2, 5)
    assert checked_wall_rows("wall_history", None, 2, 5) is None
    with pytest.raises(WheelsoilInputError, match=r"mask has shape \(3,\); expected \(4,\)"):
        checked_mask([True, False, True], 4)


def test_plane_input():
    point, normal = checked_plane((0, 0, 1), (0, 0, 2), None, _pair(), 0, 31)
    assert point == (0.0, 0.0, 1.0) and normal == (0.0, 0.0, 1.0)
    with pytest.raises(WheelsoilInputError, match="has no direction"):
        checked_plane((0, 0, 1), (0, 0, 0), None, _pair(), 0, 31)
    with pytest.raises(WheelsoilInputError, match="at most 31 planar walls"):
        checked_plane((0, 0, 1), (0, 0, 1), None, _pair(), 31, 31)


def _pair():
    from wheelsoil.granular.materials import SOIL_STEEL
    return SOIL_STEEL


def test_time_step_is_checked_against_its_estimate():
    estimate = estimate_time_step(0.005, LUNAR_SOIL_SIMULANT)
    assert estimate.checked(0.5 * estimate.stable) == 0.5 * estimate.stable
    with pytest.raises(WheelsoilInputError, match=r"exceeds the stable time step: stable step"):
        estimate.checked(2.0 * estimate.stable)
    for bad in (0.0, -1e-6, math.nan):
        with pytest.raises(WheelsoilInputError, match="must be a finite number > 0"):
            estimate.checked(bad)


@pytest.mark.parametrize("figures, message", [
    (HealthFigures(3, 0, 0.1, 1.0, 0), r"3 particles have non-finite position or velocity at t = 1 s"),
    (HealthFigures(0, 2, 0.1, 1.0, 0), r"2 particles left the domain \[\[0.0, 0.0, 0.0\], \[1.0, 1.0, 1.0\]\] m"),
    (HealthFigures(0, 0, 5.0, 7.0, 0), r"energy blow-up at t = 1 s: a particle moves at 5 m/s, more than 0.2 r_min "
                                       r"per step \(2 m/s\); kinetic energy 7 J"),
])
def test_health_verdict(figures, message):
    domain = SceneDomain.of((0, 0, 0), (1, 1, 1))
    with pytest.raises(SimulationUnstableError, match=message):
        require_healthy(figures, domain, where="at t = 1 s", dt=1e-3, r_min=0.01, stable_step=lambda: "stable")
    # just under the speed limit (0.2 r_min / dt = 2 m/s) is healthy
    require_healthy(HealthFigures(0, 0, 1.99, 7.0, 4), domain, where="", dt=1e-3, r_min=0.01, stable_step=str)
    assert HealthFigures(0, 0, 1.5, 7.0, 4).as_dict() == {"kinetic_energy": 7.0, "max_speed": 1.5, "above_top": 4}


@pytest.mark.parametrize("with_history", [False, True])
def test_checkpoint_round_trip(with_history):
    rng = np.random.default_rng(4)
    spheres = SphereState.empty().appended(rng.normal(size=(5, 3)), rng.normal(size=(5, 3)), rng.normal(size=(5, 3)),
                                           rng.uniform(0.01, 0.02, 5))
    history = None
    if with_history:
        history = ContactHistory.empty(5, 2).with_pairs([0, 3], [1, 4], rng.normal(size=(2, 3)))
    saved = SceneCheckpoint(spheres, history, 0.25, 100, 3, 7, 2)
    arrays = saved.to_arrays()
    assert any(k.startswith("hist_") for k in arrays) == with_history
    back = SceneCheckpoint.from_arrays(arrays)
    assert (back.time, back.steps_taken, back.neighbor_rebuilds, back.n_contacts, back.most_above_top) == (
        0.25, 100, 3, 7, 2)
    for key, value in spheres.to_arrays().items():
        assert np.array_equal(getattr(back.spheres, key), value)
    if with_history:
        for key, value in history.to_arrays().items():
            assert np.array_equal(back.history.to_arrays()[key], value)
    else:
        assert back.history is None
    # the arrays are copies: editing them does not reach the checkpoint
    arrays["x"][0, 0] = 99.0
    assert spheres.x[0, 0] != 99.0
    # a checkpoint written before most_above_top existed
    del arrays["most_above_top"]
    assert SceneCheckpoint.from_arrays(arrays).most_above_top == 0


def test_refused_spheres_leave_the_scene_as_it_was():
    from wheelsoil.granular import Scene
    scene = Scene((0, 0, 0), (0.1, 0.1, 0.1))
    scene.add_box_walls()
    scene.add_spheres([[0.05, 0.05, 0.05]], 0.01)
    with pytest.raises(WheelsoilInputError, match="wall_history has shape"):
        scene.add_spheres([[0.02, 0.05, 0.05]], 0.01, wall_history=np.zeros((1, 2, 3)))
    assert scene.n_particles == 1
    scene.add_spheres([[0.02, 0.05, 0.05]], 0.01, wall_history=np.full((1, 5, 3), 1e-4))
    history = scene.contact_history()
    assert scene.n_particles == 2 and history.xi_wall.shape == (2, 5, 3)
    assert not history.xi_wall[0].any() and np.all(history.xi_wall[1] == 1e-4)
