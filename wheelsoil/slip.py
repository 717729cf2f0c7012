"""Longitudinal slip: the definition every layer shares (architecture conventions), and the conversion from the
CMU rig's convention, which takes slip against the carriage's whole travel speed, to wheelsoil's, which takes it
against the travel speed's component along the wheel's heading. NumPy only, so the testbed (``coupling``) and the
semi-empirical model's data (``validation``) read slip the same way.
"""

from __future__ import annotations

import numpy as np


def longitudinal_slip(travel_speed_along_heading, spin, radius: float):
    """Longitudinal slip by the measured rigs' convention (architecture): driving (r omega >= v_x),
    i = 1 - v_x / (r omega) (seed 004 eq. 14); braking (r omega < v_x), i = r omega / v_x - 1, so a wheel dragged
    without turning has i = -1 and a free-rolling one 0 on both branches (the CMU rig's definitions,
    ``../shared/data/measured/cmu_3d_terramechanics/README.md``). 0 where neither the wheel travels nor turns.

    travel_speed_along_heading: v_x [m/s]; spin: omega [rad/s] (the hub's, or the tread's own for the tread
    slip); radius: r [m]. Scalars or arrays (broadcast)."""
    v = np.asarray(travel_speed_along_heading, float)
    rim = radius * np.asarray(spin, float)
    v, rim = np.broadcast_arrays(v, rim)
    with np.errstate(divide="ignore", invalid="ignore"):
        driving = np.where(rim > 0.0, 1.0 - v / np.where(rim > 0.0, rim, 1.0), 0.0)
        braking = np.where(v > 0.0, rim / np.where(v > 0.0, v, 1.0) - 1.0, 0.0)
    out = np.where(rim >= v, driving, braking)
    return out if out.ndim else float(out)


def rim_speed_ratio(travel_slip):
    """r omega / V [-] of a slip taken against the whole travel speed V (the CMU rig's ``slip`` column): the
    inverse of :func:`longitudinal_slip` with v_x = V, i.e. 1 / (1 - i) driving (i >= 0; infinite at i = 1, a wheel
    spinning in place) and 1 + i braking (0: dragged)."""
    i = np.asarray(travel_slip, float)
    with np.errstate(divide="ignore"):
        out = np.where(i >= 0.0, 1.0 / np.where(i < 1.0, 1.0 - i, 0.0), 1.0 + i)
    return out if out.ndim else float(out)


def heading_slip_from_travel(travel_slip, slip_angle_deg):
    """Slip along the heading (wheelsoil's i, v_x = V cos beta) of a wheel whose slip was taken against its whole
    travel speed V (the CMU rig: ``v_jt.m`` compares r omega with V): :func:`longitudinal_slip` of
    v_x = V cos(beta) and the rim speed r omega = V :func:`rim_speed_ratio`. Equal at beta = 0; at beta = 60 deg a
    travel slip of 0.5 (r omega = 2 V, v_x = V / 2) is 0.75; at 90 deg every turning wheel has slip 1 (v_x = 0)
    and a dragged one 0. A wheel spinning in place (travel slip 1) keeps 1. Arrays broadcast; degrees."""
    i = np.asarray(travel_slip, float)
    beta = np.radians(np.asarray(slip_angle_deg, float))
    i, beta = np.broadcast_arrays(i, beta)
    v_x = np.cos(beta)
    v_x = np.where(np.abs(v_x) < 1e-12, 0.0, v_x)  # cos(90 deg) is 6e-17, not 0
    spinning = i >= 1.0
    rim = np.where(spinning, 1.0, rim_speed_ratio(np.where(spinning, 0.0, i)))
    out = np.where(spinning, 1.0, longitudinal_slip(v_x, rim, 1.0))
    return out if out.ndim else float(out)
