"""Longitudinal slip: the definition every layer shares (architecture conventions), the conversion from the
CMU rig's convention, which takes slip against the carriage's whole travel speed, to wheelsoil's, which takes it
against the travel speed's component along the wheel's heading, and the wheel's speeds in velocity components
(:class:`WheelSpeeds`), regular at every steering angle up to 90 deg and for a wheel dragged without turning.
NumPy only, so the testbed (``coupling``) and the semi-empirical model's data (``validation``) read slip the same
way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wheelsoil.errors import WheelsoilInputError

#: |cos(beta)| below this is 0: cos(90 deg) is 6e-17 in floating point, and a wheel at 90 deg does not advance
#: along its heading.
COS_ZERO = 1e-12


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
    and a dragged one -1, as at every angle (:attr:`WheelSpeeds.heading_slip`). A wheel spinning in place (travel
    slip 1) keeps 1. Arrays broadcast; degrees."""
    out = WheelSpeeds.from_travel_slip(travel_slip, slip_angle_deg).heading_slip
    return out if out.ndim else float(out)


def travel_slip_from_heading(slip, slip_angle_deg) -> np.ndarray:
    """The slip against the whole travel speed (the rig's) of a wheel given by its slip along the heading: the
    converse of :func:`heading_slip_from_travel`, NaN at 90 deg and where the heading slip is missing or outside
    [-1, 1) (those rows cannot say it). Arrays broadcast; degrees."""
    i = np.asarray(slip, float)
    beta = np.asarray(slip_angle_deg, float)
    i, beta = np.broadcast_arrays(i, beta)
    ok = np.isfinite(i) & np.isfinite(beta) & (i >= -1.0) & (i < 1.0) & (np.abs(beta) < 90.0)
    out = WheelSpeeds.from_heading_slip(np.where(ok, i, 0.0), np.where(ok, beta, 0.0)).travel_slip
    return np.where(ok, out, np.nan)


def _cos(beta_rad):
    c = np.cos(beta_rad)
    return np.where(np.abs(c) < COS_ZERO, 0.0, c)


@dataclass(frozen=True)
class WheelSpeeds:
    """A wheel's kinematic state in velocity components (architecture: near 90 deg never through tan beta), each
    in units of s = max(r omega, V), the larger of the rim speed and the travel speed V = |(v_x, v_y)|. Every state
    has finite components with max(rim, V) = 1: the wheel dragged without turning (rim 0), the one spinning in
    place (V 0) and the one pushed sideways at 90 deg (along 0) included.

    rim: r omega / s [-] (>= 0); along: v_x / s [-], the travel velocity's component along the heading (>= 0 for
    |beta| <= 90 deg); across: v_y / s [-], along the axle, of the sign of beta (v_y = V sin beta, which is
    v_x tan beta wherever tan beta is finite). Arrays of one shape.
    """

    rim: np.ndarray
    along: np.ndarray
    across: np.ndarray

    @classmethod
    def from_travel_slip(cls, travel_slip, slip_angle_deg) -> "WheelSpeeds":
        """From a slip taken against the whole travel speed V (the CMU rig's ``slip``: 1 - V / (r omega) when
        r omega >= V, r omega / V - 1 when braking) and the slip angle beta [deg]: regular everywhere, 90 deg and
        the dragged wheel (-1) included. A travel slip of 1 is a wheel spinning in place (V = 0)."""
        s = np.asarray(travel_slip, float)
        beta = np.radians(np.asarray(slip_angle_deg, float))
        s, beta = np.broadcast_arrays(s, beta)
        driving = s >= 0.0
        rim = np.where(driving, 1.0, 1.0 + s)
        speed = np.where(driving, 1.0 - s, 1.0)
        return cls(rim=rim, along=speed * _cos(beta), across=speed * np.sin(beta))

    @classmethod
    def from_heading_slip(cls, slip, slip_angle_deg) -> "WheelSpeeds":
        """From wheelsoil's slip along the heading (architecture: i = 1 - v_x / (r omega) driving, r omega / v_x - 1
        braking) and the slip angle beta [deg], |beta| < 90 deg: at 90 deg the heading slip is 1 (turning) or 0
        (dragged) whatever the sideways speed, so it cannot give v_y; use :meth:`from_travel_slip` there."""
        i = np.asarray(slip, float)
        beta = np.radians(np.asarray(slip_angle_deg, float))
        i, beta = np.broadcast_arrays(i, beta)
        cos = _cos(beta)
        if (cos == 0.0).any():
            k = int(np.argmax(cos.ravel() == 0.0))
            raise WheelsoilInputError(
                f"slip_angle[{k}] = {np.degrees(beta.ravel()[k]):g} deg: at 90 deg the slip along the heading cannot "
                "say how fast the wheel slides sideways; give the slip against the whole travel speed (travel_slip)")
        driving = i >= 0.0
        rim = np.where(driving, 1.0, 1.0 + i)
        along = np.where(driving, 1.0 - i, 1.0)
        speed = along / np.abs(cos)
        scale = np.maximum(rim, speed)
        return cls(rim=rim / scale, along=along / scale, across=speed * np.sin(beta) / scale)

    @property
    def speed(self) -> np.ndarray:
        """V / s [-]."""
        return np.hypot(self.along, self.across)

    @property
    def heading_slip(self) -> np.ndarray:
        """Slip along the heading, (r omega - v_x) / max(r omega, v_x) (:func:`longitudinal_slip`, both branches).
        A wheel that does not turn has -1 at every angle (architecture: "a wheel dragged without turning has
        i = -1"), 90 deg included, where v_x = 0 too: the limit along the steering angle. At 90 deg the heading slip
        is singular in the rim speed, 1 for any r omega > 0 and -1 for none."""
        return _ratio_slip(self.rim, self.along)

    @property
    def travel_slip(self) -> np.ndarray:
        """Slip against the whole travel speed (the CMU rig's), (r omega - V) / max(r omega, V)."""
        return _ratio_slip(self.rim, self.speed)


def _ratio_slip(rim, speed):
    """(rim - speed) / max(rim, speed), -1 where the wheel does not turn (rim = 0), whatever the speed."""
    top = np.maximum(rim, speed)
    turning = rim > 0.0
    return np.where(turning, (rim - speed) / np.where(turning, top, 1.0), -1.0)
