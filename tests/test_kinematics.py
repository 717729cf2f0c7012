"""Measured kinematics: the best-fit rigid motion (Kabsch) against known motions, the deformation it leaves,
and the tread tracker's wind-up, yaw and slip angle against constructed tread poses."""

import math

import numpy as np
import pytest

from wheelsoil.coupling.kinematics import TreadTracker, longitudinal_slip, rig_command, slip_angle_deg
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.rigid_motion import deformation, rigid_fit, rotation_about, rotation_vector
from wheelsoil.flexwheel.statics import rotation_matrices


def _ring(n=120, radius=0.6, width=0.5, seed=0):
    rng = np.random.default_rng(seed)
    phi = rng.uniform(0, 2 * np.pi, n)
    return np.c_[radius * np.cos(phi), rng.uniform(-width / 2, width / 2, n), radius * np.sin(phi)]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rigid_fit_recovers_a_rotation_and_translation(seed):
    rng = np.random.default_rng(seed)
    x0 = _ring(seed=seed)
    theta = rng.normal(size=3)
    rot = rotation_matrices(theta[None])[0]
    t = rng.normal(size=3)
    fit = rigid_fit(x0 @ rot.T + t, x0, weights=rng.uniform(0.5, 2.0, len(x0)))
    assert np.allclose(fit.rotation, rot, atol=1e-12)
    assert np.allclose(fit.translation, t, atol=1e-12)
    assert np.allclose(rotation_vector(rot), theta if np.linalg.norm(theta) < np.pi else rotation_vector(rot))
    # no deformation for a rigid motion; a deformation added to it is recovered when it has no rigid part
    assert np.abs(deformation(x0 @ rot.T + t, x0)).max() < 1e-12
    # what the fit leaves of a deformed body has no net translation or turn (least squares: the normal equations)
    w = rng.uniform(0.5, 2.0, len(x0))
    bump = 1e-3 * rng.normal(size=x0.shape)
    moved = (x0 + bump) @ rot.T + t
    d = deformation(moved, x0, w)
    fitted = moved - d
    assert np.abs(w @ d).max() < 1e-12
    assert np.abs(np.sum(w[:, None] * np.cross(fitted - w @ fitted / w.sum(), d), axis=0)).max() < 1e-12


def test_rigid_fit_refuses_bad_input():
    x = _ring()
    with pytest.raises(WheelsoilInputError, match="same shape"):
        rigid_fit(x[:5], x)
    with pytest.raises(WheelsoilInputError, match="weights"):
        rigid_fit(x, x, weights=-np.ones(len(x)))


@pytest.mark.parametrize("beta_deg", [0.0, 10.0, -20.0])
@pytest.mark.parametrize("lag_deg, yaw_deg", [(3.0, 0.0), (9.5, 0.0), (-2.0, 1.5)])
def test_tread_tracker_measures_the_wind_up_and_the_tread_yaw(beta_deg, lag_deg, yaw_deg):
    """The hub spun by phi about the axle; the tread by phi - lag, and yawed by psi about the vertical."""
    beta = math.radians(beta_deg)
    c, s = math.cos(-beta), math.sin(-beta)
    yaw = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # the testbed's wheel yaw by -beta
    heading, axle = yaw[:, 0], yaw[:, 1]
    ref = _ring() @ yaw.T + np.array([1.0, 0.45, 0.7])
    centre = np.array([1.0, 0.45, 0.7])
    tracker = TreadTracker(ref, heading, axle)
    phi = 1.234
    hub = rotation_matrices((phi * axle)[None])[0]
    tread_rot = (rotation_matrices((math.radians(yaw_deg) * np.array([0.0, 0.0, 1.0]))[None])[0]
                 @ rotation_matrices(((phi - math.radians(lag_deg)) * axle)[None])[0])
    moved = (ref - centre) @ tread_rot.T + centre + np.array([0.3, -0.01, -0.05])
    state = tracker.state(moved, hub)
    assert state.wind_up == pytest.approx(math.radians(lag_deg), abs=1e-3)  # to first order in lag x yaw
    assert state.yaw == pytest.approx(math.radians(yaw_deg), abs=1e-3)
    # the travel direction (+X) against the tread's heading: beta less the tread's yaw
    assert slip_angle_deg([0.4, 0.0, 0.0], state.heading, state.axle) == pytest.approx(beta_deg - yaw_deg, abs=0.1)


def test_slip_and_slip_angle_definitions():
    # driving, seed 004 eq. 14: i = 1 - v / (r omega)
    assert longitudinal_slip(0.42, 1.0, 0.6) == pytest.approx(0.3)
    # braking, the CMU rig's convention (its README): i = r omega / v - 1; dragged without turning: -1
    assert longitudinal_slip(0.6, 0.5, 0.6) == pytest.approx(-0.5)
    assert longitudinal_slip(0.42, 0.0, 0.6) == -1.0
    assert longitudinal_slip(0.0, 0.0, 0.6) == 0.0
    assert np.allclose(longitudinal_slip([0.42, 0.6, 0.9], [1.0, 1.0, 1.0], 0.6), [0.3, 0.0, 0.6 / 0.9 - 1.0])
    # the CMU trials' own rows: carriage 10 mm/s, rim speeds 0, 5, 10, 20, 40 mm/s
    rim = np.array([0.0, 5.0, 10.0, 20.0, 40.0])
    assert np.allclose(longitudinal_slip(10.0, rim, 1.0), [-1.0, -0.5, 0.0, 0.5, 0.75])
    # the rig's command gives back its slip on both branches, and meets itself at i = 0
    for slip in (-1.0, -0.7, -0.2, 0.0, 0.3, 0.9):
        spin, v = rig_command(slip, 2.0, 0.058)
        assert longitudinal_slip(v, spin, 0.058) == pytest.approx(slip, abs=1e-12)
    assert rig_command(-1e-12, 2.0, 0.058) == pytest.approx(rig_command(0.0, 2.0, 0.058))
    assert rig_command(-1.0, 2.0, 0.058) == (0.0, pytest.approx(0.116))
    assert slip_angle_deg([1.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]) == pytest.approx(45.0)
    # rotation_about: a ring turned by 0.3 rad about y
    x = _ring()
    turned = x @ rotation_matrices(np.array([[0.0, 0.3, 0.0]]))[0].T
    assert rotation_about(turned, x, [0, 1, 0]) == pytest.approx(0.3, abs=1e-12)
