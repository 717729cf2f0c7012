"""A scene's health check: non-finite states, spheres that left the domain, runaway speeds.

:func:`measure_health` reads the figures off the device in one pass (:func:`.integrator.state_health`);
:func:`require_healthy` stops the run with :class:`SimulationUnstableError` when they say it blew up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from . import integrator
from .errors import SimulationUnstableError
from .scene_domain import SceneDomain

#: A sphere moving more than this fraction of the smallest radius in one step is a blow-up.
SPEED_LIMIT_RADII_PER_STEP = 0.2


@dataclass(frozen=True)
class HealthFigures:
    """One health check's figures: spheres with a non-finite state, spheres outside the domain's hard bounds, the
    largest speed [m/s], the kinetic energy (translational and rotational) [J], and the spheres above the domain's
    top (grains launched from under a wheel, which fall back)."""

    non_finite: int
    outside: int
    max_speed: float
    kinetic_energy: float
    above_top: int

    def as_dict(self) -> dict:
        """``kinetic_energy`` [J], ``max_speed`` [m/s], ``above_top`` (count): what :meth:`.Scene.check_health`
        returns."""
        return {"kinetic_energy": self.kinetic_energy, "max_speed": self.max_speed, "above_top": self.above_top}


def measure_health(particles, out, domain: SceneDomain, open_ends_x: bool) -> HealthFigures:
    """The figures of the spheres on the device (``particles``: :class:`.particles.ParticleArrays`; ``out``: a
    five-entry f64 ndarray to read them through). The domain's floor and walls are hard bounds; its top is not (a
    grain above it is counted), nor are the x ends where the domain is periodic or its ends are open."""
    lo, hi = domain.lo.tolist(), domain.hi.tolist()
    if domain.periodic_x or open_ends_x:  # centres wrap at each rebuild; in between they may cross the ends
        lo[0], hi[0] = -math.inf, math.inf
    top, hi[2] = hi[2], math.inf
    integrator.state_health(particles.x, particles.v, particles.w, particles.m, particles.I, lo, hi, top, out)
    bad, outside, vmax2, energy, above = out.to_numpy()
    return HealthFigures(int(bad), int(outside), math.sqrt(vmax2), float(energy), int(above))


def require_healthy(figures: HealthFigures, domain: SceneDomain, *, where: str, dt: float, r_min: float,
                    stable_step: Callable[[], str]) -> None:
    """Raise :class:`SimulationUnstableError` on non-finite states, escaped spheres or a sphere moving more than
    :data:`SPEED_LIMIT_RADII_PER_STEP` of ``r_min`` [m] in a step of ``dt`` [s]. ``where`` says when (time and step);
    ``stable_step()`` describes the stable time step for the message."""
    if figures.non_finite:
        raise SimulationUnstableError(
            f"{figures.non_finite} particles have non-finite position or velocity {where}; "
            f"the time step {dt:.3e} s may be too large ({stable_step()})"
        )
    if figures.outside:
        raise SimulationUnstableError(
            f"{figures.outside} particles left the domain {domain.describe()} m {where}; "
            "the bin may be missing a wall or the run blew up"
        )
    limit = SPEED_LIMIT_RADII_PER_STEP * r_min / dt
    if figures.max_speed > limit:
        raise SimulationUnstableError(
            f"energy blow-up {where}: a particle moves at {figures.max_speed:.3g} m/s, more than "
            f"{SPEED_LIMIT_RADII_PER_STEP:g} r_min per step ({limit:.3g} m/s); kinetic energy "
            f"{figures.kinetic_energy:.3g} J. Reduce the time step ({stable_step()})"
        )
