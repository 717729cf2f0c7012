"""Measured wheel kinematics: the best-fit rigid motion of a set of nodes, and what the tread does.

A flexible wheel under drive torque winds up: the hub turns, the spokes bend, and the tread -- the part
that meets the soil -- lags the hub by a twist angle that grows with the torque. The slip the soil sees
is the **tread slip**, from the tread's own rotation (architecture conventions), not the hub's.

* :func:`~wheelsoil.rigid_motion.rigid_fit` and :func:`~wheelsoil.rigid_motion.deformation` (the shared
  core, re-exported here): the best-fit rigid motion of a set of nodes, and what the nodes moved beyond it
  (the wheel's deflection field; renders and result frames show this, not the rotation);
* :class:`TreadTracker` -- per sample, the tread's rigid rotation relative to the hub's: the twist about
  the axle (wind-up), the yaw about the vertical, the tread's spin rate and the tread slip and slip angle
  that follow from them.

Frames and signs (architecture): wheel frame x along the heading, y along the axle, z up; the hub spins
at +omega about the axle. ``wind_up`` > 0 means the tread lags the hub (a driving torque); the tread
slip i_t is :func:`longitudinal_slip` (i = 1 - v_x / (r omega) driving, r omega / v_x - 1 braking) with the
tread's spin omega_t and the hub's travel velocity v_x along the tread's heading, and the tread slip angle
is the angle between the tread's heading and the hub's travel direction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wheelsoil.rigid_motion import deformation, rigid_fit, rotation_vector  # noqa: F401  (re-exported)
from wheelsoil.slip import longitudinal_slip  # noqa: F401  (the shared definition, re-exported)


@dataclass(frozen=True)
class TreadState:
    """The tread's rotation relative to the hub at one instant.

    wind_up: twist about the axle [rad], > 0 when the tread lags the hub's spin.
    yaw: rotation about the vertical [rad] of the tread relative to the hub (> 0 turns the heading left).
    heading, axle: the tread's heading and axle directions in the horizontal plane (unit vectors, global frame).
    """

    wind_up: float
    yaw: float
    heading: np.ndarray
    axle: np.ndarray


class TreadTracker:
    """The tread's rigid rotation from node positions, relative to the hub.

    Parameters
    ----------
    reference: the tread nodes' positions (N, 3) [m] in the start pose (hub rotation = identity).
    heading, axle: the wheel's heading and axle directions in the start pose (unit vectors).
    weights: node weights of the fit (e.g. lumped masses; default equal).
    """

    def __init__(self, reference, heading, axle, weights=None) -> None:
        self.reference = np.asarray(reference, float).copy()
        self.heading0 = np.asarray(heading, float) / np.linalg.norm(heading)
        self.axle0 = np.asarray(axle, float) / np.linalg.norm(axle)
        self.weights = None if weights is None else np.asarray(weights, float)

    def state(self, positions, hub_rotation) -> TreadState:
        """Where the tread is, given its nodes' positions (N, 3) and the hub's rotation from the start pose."""
        fit = rigid_fit(positions, self.reference, self.weights)
        # relative rotation in the global frame: the tread's rotation with the hub's undone after it
        rel = fit.rotation @ np.asarray(hub_rotation).T
        theta = rotation_vector(rel)
        spin_axis = np.asarray(hub_rotation) @ self.axle0  # the hub spins about its axle: unchanged
        axle = rel @ spin_axis
        # the tread's heading in the horizontal plane (x = y x z for the wheel frame), whatever its wind-up
        heading = np.cross(axle, [0.0, 0.0, 1.0])
        heading /= np.linalg.norm(heading)
        return TreadState(
            wind_up=-float(theta @ spin_axis),
            yaw=float(theta[2]),
            heading=heading,
            axle=np.cross([0.0, 0.0, 1.0], heading),
        )


def rig_command(slip: float, reference_spin: float, radius: float) -> tuple[float, float]:
    """The hub spin omega [rad/s] and the travel speed along the heading v_x [m/s] that give the commanded
    ``slip`` (:func:`longitudinal_slip`'s convention) with the reference spin omega_0 = ``reference_spin``:
    driving (i >= 0) the hub spins at omega_0 and travels at v_x = (1 - i) r omega_0; braking (i < 0) it
    travels at the free-rolling speed v_x = r omega_0 and spins at omega = (1 + i) omega_0 (0: dragged).
    Both branches meet at i = 0, so a slip sweep through zero is continuous."""
    if slip >= 0.0:
        return reference_spin, (1.0 - slip) * radius * reference_spin
    return (1.0 + slip) * reference_spin, radius * reference_spin


def slip_angle_deg(velocity, heading, axle) -> float:
    """Angle [deg] between a heading and the horizontal travel velocity: atan2(v . axle, v . heading) (90 for a
    wheel ploughing sideways); 0 when it does not travel."""
    v = np.asarray(velocity, float).copy()
    v[2] = 0.0
    vx, vy = float(v @ heading), float(v @ axle)
    return math.degrees(math.atan2(vy, vx)) if math.hypot(vx, vy) > 1e-12 else 0.0


def yaw_matrix(angle_rad: float) -> np.ndarray:
    """The rotation [3 x 3] by ``angle_rad`` about the vertical (z) axis."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
