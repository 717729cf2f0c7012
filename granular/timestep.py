"""Critical time-step estimates for Hertz--Mindlin DEM.

* Rayleigh time step (time for a Rayleigh surface wave to cross a particle; Li, Xu & Thornton,
  Powder Technol. 160 (2005), eq. 6; EDEM's default):
      dt_R = pi R sqrt(rho / G) / (0.1631 nu + 0.8766)
* Hertz contact duration of a binary impact at relative speed v (Johnson, *Contact Mechanics*,
  sec. 11.4, eqs. 11.24-11.25):
      delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5),   t_H = 2.9432 delta_max / v
  (2.9432 = 2 * integral_0^1 dx / sqrt(1 - x^(5/2))).

The stable step is ``min(rayleigh_fraction * dt_R, t_H / steps_per_contact)`` evaluated for the
smallest particle pair; requested steps above it are refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import WheelsoilInputError
from .materials import Material

#: 2 * int_0^1 (1 - x^(5/2))^(-1/2) dx, the Hertz impact-duration constant.
HERTZ_DURATION_CONSTANT = 2.943275


def rayleigh_time_step(radius: float, material: Material) -> float:
    """Rayleigh wave time step [s] for a sphere of ``radius`` [m]."""
    nu = material.poisson_ratio
    return math.pi * radius * math.sqrt(material.density / material.shear_modulus) / (0.1631 * nu + 0.8766)


def hertz_max_overlap(m_eff: float, r_eff: float, e_eff: float, speed: float) -> float:
    """Maximum overlap [m] of an undamped Hertz impact at normal relative ``speed`` [m/s]."""
    return (15.0 * m_eff * speed**2 / (16.0 * e_eff * math.sqrt(r_eff))) ** 0.4


def hertz_contact_duration(m_eff: float, r_eff: float, e_eff: float, speed: float) -> float:
    """Duration [s] of an undamped Hertz impact at normal relative ``speed`` [m/s]."""
    return HERTZ_DURATION_CONSTANT * hertz_max_overlap(m_eff, r_eff, e_eff, speed) / speed


@dataclass(frozen=True)
class TimeStepEstimate:
    """The pieces of the stable-step estimate [s] and the factors applied to them."""

    rayleigh: float
    hertz_duration: float
    rayleigh_fraction: float
    steps_per_contact: float
    impact_speed: float

    @property
    def stable(self) -> float:
        return min(self.rayleigh_fraction * self.rayleigh, self.hertz_duration / self.steps_per_contact)

    def describe(self) -> str:
        return (
            f"stable step {self.stable:.3e} s = min({self.rayleigh_fraction:g} x Rayleigh step "
            f"{self.rayleigh:.3e} s, Hertz contact time {self.hertz_duration:.3e} s at "
            f"{self.impact_speed:g} m/s / {self.steps_per_contact:g} steps)"
        )

    def checked(self, dt: float) -> float:
        """``dt`` [s] as a float, refused with the numbers unless finite, > 0 and at most the stable step."""
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0):
            raise WheelsoilInputError(f"time step {dt!r} s must be a finite number > 0")
        if dt > self.stable * (1.0 + 1e-12):
            raise WheelsoilInputError(f"time step {dt:.3e} s exceeds the stable time step: {self.describe()}")
        return dt


def estimate_time_step(
    r_min: float,
    material: Material,
    *,
    wall_moduli: tuple[float, ...] = (),
    impact_speed: float = 1.0,
    rayleigh_fraction: float = 0.2,
    steps_per_contact: float = 10.0,
) -> TimeStepEstimate:
    """Stable time step for particles of ``material`` with smallest radius ``r_min`` [m].

    ``wall_moduli`` are the effective moduli E* [Pa] of the particle--wall pairs (a wall contact
    is shorter than a particle pair's: R* = r, m* = m). ``impact_speed`` [m/s] is the largest
    relative normal speed expected in a contact; the Hertz duration scales as v^(-1/5), so the
    estimate is only weakly sensitive to it.
    """
    if not (0.0 < rayleigh_fraction <= 1.0):
        raise WheelsoilInputError(f"rayleigh_fraction = {rayleigh_fraction!r} must lie in (0, 1]")
    if steps_per_contact < 1.0:
        raise WheelsoilInputError(f"steps_per_contact = {steps_per_contact!r} must be >= 1")
    if impact_speed <= 0.0:
        raise WheelsoilInputError(f"impact_speed = {impact_speed!r} m/s must be > 0")
    mass = material.density * 4.0 / 3.0 * math.pi * r_min**3
    e_eff = 1.0 / (2.0 * (1.0 - material.poisson_ratio**2) / material.youngs_modulus)
    duration = hertz_contact_duration(0.5 * mass, 0.5 * r_min, e_eff, impact_speed)
    for wall_e_eff in wall_moduli:
        duration = min(duration, hertz_contact_duration(mass, r_min, wall_e_eff, impact_speed))
    return TimeStepEstimate(
        rayleigh=rayleigh_time_step(r_min, material),
        hertz_duration=duration,
        rayleigh_fraction=rayleigh_fraction,
        steps_per_contact=steps_per_contact,
        impact_speed=impact_speed,
    )
