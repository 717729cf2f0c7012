"""Testbed cases: seed 004 at full scale and reduced-scale smoke cases for 2 CPU cores.

A case is a bed, a wheel and the rig settings. Full scale (seed 004 sec. 2.3, Table 2): soil bin
3.5 x 1.0 x 0.4 m of 16--24 mm particles, the lunar-rover wheel (r = 0.6 m, b = 0.5 m, about 26,000 shell
facets), r omega = 0.6 m/s, slip 10--60 %, steering angle 0--20 deg, 1g with W = 3000 N or 500 N and
1/6 g with W = 500 N. Smoke scale keeps the wheel's size and load but uses a coarse wheel mesh (element
0.05 m) and a 2.0 x 0.9 x 0.2 m bin of 25--37.5 mm particles (about 12,000), so that one case runs in
about two minutes on two CPU cores.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import LUNAR_ROVER, WheelGeometry
from wheelsoil.granular.bed import BedSpec

from .testbed import TestbedSpec

EARTH = (0.0, 0.0, -9.81)
MOON = (0.0, 0.0, -9.81 / 6.0)


@dataclass(frozen=True)
class Case:
    """A bed to prepare (under the test gravity), a wheel and the rig settings."""

    name: str
    bed: BedSpec
    wheel: WheelGeometry
    testbed: TestbedSpec


def seed004_bed(gravity=EARTH) -> BedSpec:
    """Seed 004 Table 2 soil bin: 3.5 x 1.0 x 0.4 m, particles 16--24 mm (about 390,000)."""
    return BedSpec(length=3.5, width=1.0, depth=0.4, diameter_min=0.016, diameter_max=0.024, gravity=tuple(gravity))


def smoke_bed(gravity=EARTH) -> BedSpec:
    """The smoke bin: 2.0 x 0.9 x 0.2 m of 25--37.5 mm particles (about 12,000)."""
    return BedSpec(length=2.0, width=0.9, depth=0.2, diameter_min=0.025, diameter_max=0.0375, gravity=tuple(gravity))


SMOKE_WHEEL = LUNAR_ROVER.with_element_size(0.05)


def seed004_case(*, slip: float, slip_angle: float, load: float, gravity=EARTH, rigid: bool = False) -> Case:
    """A full-scale seed-004 case (r omega = 0.6 m/s, 2.5 s of driving)."""
    g = "1g" if abs(gravity[2]) > 5 else "moon"
    spec = TestbedSpec(slip=slip, slip_angle=slip_angle, load=load, angular_velocity=1.0, drive_time=2.5,
                       rigid=rigid)
    name = f"seed004-{g}-W{load:g}-i{slip:g}-b{slip_angle:g}{'-rigid' if rigid else ''}"
    return Case(name, seed004_bed(gravity), LUNAR_ROVER, spec)


def smoke_case(*, slip: float = 0.3, slip_angle: float = 10.0, load: float = 3000.0, gravity=EARTH,
               rigid: bool = False, drive_time: float = 0.6) -> Case:
    """A smoke-scale case (same wheel size and loads, coarse mesh and particles)."""
    g = "1g" if abs(gravity[2]) > 5 else "moon"
    spec = TestbedSpec(slip=slip, slip_angle=slip_angle, load=load, angular_velocity=1.0, drive_time=drive_time,
                       rigid=rigid)
    name = f"smoke-{g}-W{load:g}-i{slip:g}-b{slip_angle:g}{'-rigid' if rigid else ''}"
    return Case(name, smoke_bed(gravity), SMOKE_WHEEL, spec)


#: Named cases: the two smoke steering runs (1g with W = 3000 N, 1/6 g with W = 500 N: equal wheel mass,
#: seed 004's gravity comparison) and their full-scale counterparts.
PRESETS = {
    "smoke-1g-steer": smoke_case(load=3000.0, gravity=EARTH),
    "smoke-moon-steer": smoke_case(load=500.0, gravity=MOON),
    "seed004-1g-steer": seed004_case(slip=0.3, slip_angle=10.0, load=3000.0, gravity=EARTH),
    "seed004-moon-steer": seed004_case(slip=0.3, slip_angle=10.0, load=500.0, gravity=MOON),
}


def preset_case(name: str, **overrides) -> Case:
    """A named case; keyword overrides replace rig settings (e.g. ``slip=0.5``, ``rigid=True``)."""
    try:
        case = PRESETS[name]
    except KeyError:
        raise WheelsoilInputError(f"unknown testbed case {name!r}; choose one of {sorted(PRESETS)}") from None
    if not overrides:
        return case
    tb = replace(case.testbed, **overrides)
    g = "1g" if abs(case.bed.gravity[2]) > 5 else "moon"
    scale = name.split("-")[0]
    rigid = "-rigid" if tb.rigid else ""
    return replace(case, testbed=tb, name=f"{scale}-{g}-W{tb.load:g}-i{tb.slip:g}-b{tb.slip_angle:g}{rigid}")
