"""The shear under a rigid wheel's rim: the wheel's speeds from either slip, the shear displacements in velocity
components (seed 003 eqs. 11 and 14, regular at 90 deg and for a wheel that does not turn) and the two shear laws,
Janosi--Hanamoto along each direction (seed 003 eqs. 9 and 13) and the CMU lab's resultant form (``tau_t.m``,
``tau_l.m``). Rows are conditions, columns the contact angles theta [rad]; NumPy only.
"""

import numpy as np

from wheelsoil.slip import WheelSpeeds

__all__ = ["janosi_hanamoto", "lateral_displacement", "resultant_shear", "tangential_displacement", "wheel_speeds"]


def wheel_speeds(slip, slip_angle_deg, travel_slip) -> WheelSpeeds:
    """The wheel's speeds from the travel slip in rows where it is finite, else from the heading slip."""
    given = np.isfinite(travel_slip)
    if given.all():
        return WheelSpeeds.from_travel_slip(travel_slip, slip_angle_deg)
    heading = WheelSpeeds.from_heading_slip(np.where(given, 0.0, slip), np.where(given, 0.0, slip_angle_deg))
    if not given.any():
        return heading
    travel = WheelSpeeds.from_travel_slip(np.where(given, travel_slip, 0.0), slip_angle_deg)
    return WheelSpeeds(*(np.where(given, getattr(travel, k), getattr(heading, k)) for k in ("rim", "along", "across")))


def tangential_displacement(radius, theta_f, theta, speeds: WheelSpeeds, soil_flow, sin_theta=None):
    """Shear displacement j_x [m] along the rim (rows: conditions; columns: theta [rad]; theta_f [rad] and the soil
    flow eta per condition): seed 003 eq. 11 in velocity components, j = int_theta^theta_f (slip velocity)
    d theta' / omega,

        j_x = r ((theta_f - theta)(1 - eta) r omega - v_x (sin theta_f - sin theta)) / (r omega),

    which with v_x = (1 - i) r omega (driving) or r omega / (1 + i) (braking) is eq. 12 on both branches, and stays
    defined at 90 deg and, through :func:`_per_rim`, for omega = 0. ``sin_theta``: sin(theta), where the caller has
    it already (the same values; one pass over the quadrature points fewer)."""
    tf = theta_f[:, None]
    rim = speeds.rim[:, None]
    sin_theta = np.sin(theta) if sin_theta is None else sin_theta
    rate = (tf - theta) * (1.0 - soil_flow[:, None]) * rim - speeds.along[:, None] * (np.sin(tf) - sin_theta)
    return radius * _per_rim(rate, rim)


def lateral_displacement(radius, theta_f, theta, speeds: WheelSpeeds):
    """Shear displacement j_y [m] along the axle: seed 003 eq. 14 in velocity components,
    j_y = r (theta_f - theta) |v_y| / (r omega), eq. 16 (v_y = v_x tan beta) where tan beta is finite."""
    return radius * _per_rim((theta_f[:, None] - theta) * np.abs(speeds.across)[:, None], speeds.rim[:, None])


def _per_rim(displacement_rate, rim):
    """displacement_rate / rim, the integral over the contact of a slip velocity divided by omega [-]: a wheel
    that does not turn (rim = 0) slides without end, +-inf, the limit of a vanishing rim speed, so the shear it
    meets is fully mobilised; 0 where nothing slides (a component with no sliding speed: along the heading of a
    wheel dragged sideways at 90 deg). The independent shear form is discontinuous there (an arbitrarily slow
    tangential slide at 89.99 deg already mobilises the full strength along x); the resultant form, which shares
    one strength along the slip velocity, is not."""
    turning = rim > 0.0
    if np.all(turning):  # the common case: every wheel turns
        return displacement_rate / rim
    per_rim = displacement_rate / np.where(turning, rim, 1.0)
    still = np.broadcast_to(~turning, per_rim.shape)  # the conditions' rows whose wheel does not turn
    rate = np.broadcast_to(displacement_rate, per_rim.shape)[still]
    per_rim[still] = np.where(rate == 0.0, 0.0, np.copysign(np.inf, rate))
    return per_rim


def janosi_hanamoto(strength, displacement, modulus):
    """Janosi--Hanamoto shear (seed 003 eqs. 9 and 13) with the sign of the displacement: tau = (c + sigma tan phi)
    sign(j) (1 - exp(-|j| / k)) [Pa], so |tau| never exceeds the Mohr--Coulomb strength (seed 003 eq. 10) where the
    soil is sheared backwards (braking, Wong & Reece 1967b) and a sliding wheel's infinite j gives the full
    strength."""
    return strength * np.sign(displacement) * -np.expm1(-np.abs(displacement) / modulus)


def resultant_shear(strength, jx, jy, k_x, speeds: WheelSpeeds, soil_flow, theta, cos_theta=None):
    """The CMU lab's shear (``tau_t.m``, ``tau_l.m``; module docstring): strength [Pa] mobilised by sqrt(j_x^2 +
    j_y^2) / k_x [m / m] along the slip velocity. Rows: conditions (the wheel's speeds, soil flow eta); columns:
    theta [rad] (``cos_theta``: its cosine where the caller has it). Returns (tau_x, tau_y) [Pa], tau_y a magnitude
    (its sign is -sign(beta))."""
    # the slip velocity under the rim (v_jt.m, with the soil's own flow), in the speeds' units
    cos_theta = np.cos(theta) if cos_theta is None else cos_theta
    v_t = (speeds.rim * (1.0 - soil_flow))[:, None] - speeds.along[:, None] * cos_theta
    v_l = np.broadcast_to(np.abs(speeds.across)[:, None], v_t.shape)
    speed = np.hypot(v_t, v_l)
    mobilised = strength * -np.expm1(-np.hypot(jx, jy) / k_x) / np.where(speed > 0.0, speed, 1.0)
    return mobilised * v_t, mobilised * v_l
