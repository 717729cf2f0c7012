"""What each virtual soil-lab test is, as plain data: sizes, speeds and stresses, each checked against its range
and against the bed it runs on before any work (no Taichi here).

The bed itself is a :class:`wheelsoil.granular.BedSpec` (particles, material, bin); these specs describe what
is done to it:

* :class:`PlateSpec`   -- a rigid circular plate pressed into the bed at constant speed (plate sinkage);
* :class:`WheelPressSpec` -- a rigid wheel pressed straight down (static wheel sinkage);
* :class:`ShearSpec`   -- a direct shear box at several normal stresses;
* :class:`ReposeSpec`  -- the angle of repose by the draw-down (ledge) method.

Limits that depend on the bed (the plate inside the box, enough particles across the plate, a normal stress the
soft-sphere contact can carry) are in :func:`check_plate_fits`, :func:`check_resolution` and
:func:`max_normal_stress`; each names the key, the value and the limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.parameters import soil_lab
from wheelsoil.ranges import Range, check_ranges, positive

#: Fewest particles (of the largest diameter) across a plate or a wheel's width. Below it the force-sinkage
#: curve of one bed is a staircase of single-particle events: the plate study in docs/soillab (the 60 mm plate on
#: 6.4-9.6 mm particles, 6.3 across, already steps by +-20 % from sample to sample).
MIN_PARTICLES_ACROSS = 6.0

#: Largest mean Hertz overlap, as a fraction of the mean particle radius, that a lab stress may cause. Beyond a few
#: per cent the soft spheres' own compression adds to the measured settlement (a soft-sphere artefact).
MAX_OVERLAP_FRACTION = 0.05


def check_seeds(owner: str, seeds) -> tuple[int, ...]:
    """The seeds as a tuple of ints; refused unless one or more, distinct and >= 0."""
    values = tuple(int(s) for s in seeds)
    if not values or len(set(values)) != len(values) or min(values) < 0:
        raise WheelsoilInputError(f"{owner} seeds = {list(seeds)}: give one or more distinct seeds >= 0")
    return values


def _check_sampling(owner: str, interval: float, depth: float) -> None:
    if interval > 0.25 * depth:
        raise WheelsoilInputError(f"{owner} sample_interval = {interval!r} m must be at most a quarter of max_sinkage "
                                  f"({0.25 * depth:g} m)")


@dataclass(frozen=True)
class PlateSpec:
    """A rigid circular plate pushed vertically into the bed at constant speed (SI units).

    diameter: plate diameter [m] (the CMU plates: 0.06 and 0.1 m).
    thickness: plate thickness [m]; its faces lie half of it either side of the mesh.
    speed: pressing speed [m/s] (the CMU carriage: 1.3-8 mm/s; faster in the DEM as long as the flow stays
        quasi-static, see :func:`inertial_number`).
    max_sinkage: how deep it is pressed below the bed's surface [m].
    sample_interval: sinkage between two recorded samples [m]; each sample is the mean force over it.
    rings: rings of the plate's triangle mesh (ring k holds 6 k nodes and 6 (2 k - 1) triangles).
    """

    diameter: float = soil_lab.PLATE_DIAMETERS[-1]
    thickness: float = 0.004
    speed: float = soil_lab.PRESS["speed"]
    max_sinkage: float = soil_lab.PRESS["max_sinkage"]
    sample_interval: float = soil_lab.PRESS["sample_interval"]
    rings: int = 8

    RANGES: ClassVar[dict[str, Range]] = {
        "diameter": positive(), "thickness": positive(), "speed": Range(0.0, 1.0, lo_open=True),
        "max_sinkage": positive(), "sample_interval": positive(), "rings": Range(1, 64, integer=True),
    }
    UNITS: ClassVar[dict[str, str]] = {"diameter": "m", "thickness": "m", "speed": "m/s", "max_sinkage": "m",
                                       "sample_interval": "m"}

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "plate", self.UNITS)
        if self.thickness >= 0.5 * self.diameter:
            raise WheelsoilInputError(f"plate thickness = {self.thickness!r} m must be below half its diameter "
                                      f"({0.5 * self.diameter:g} m)")
        _check_sampling("plate", self.sample_interval, self.max_sinkage)

    @property
    def area(self) -> float:
        """Plate area [m^2]."""
        return math.pi * (0.5 * self.diameter) ** 2

    @property
    def footprint(self) -> float:
        """Width of the loaded area across its smaller side [m]."""
        return self.diameter


@dataclass(frozen=True)
class WheelPressSpec:
    """A rigid wheel pushed straight down into the bed at constant speed, axle horizontal (SI units).

    wheel: ``"smooth"`` or ``"grouser"`` (the CMU K10-mini wheels, :mod:`wheelsoil.parameters.cmu_k10`).
    speed, max_sinkage, sample_interval: as :class:`PlateSpec`.
    element_size: edge length of the wheel's surface mesh [m].
    """

    wheel: str = "smooth"
    speed: float = soil_lab.PRESS["speed"]
    max_sinkage: float = soil_lab.PRESS["max_sinkage"]
    sample_interval: float = soil_lab.PRESS["sample_interval"]
    element_size: float = 0.006

    RANGES: ClassVar[dict[str, Range]] = {
        "speed": Range(0.0, 1.0, lo_open=True), "max_sinkage": positive(), "sample_interval": positive(),
        "element_size": positive(),
    }
    UNITS: ClassVar[dict[str, str]] = {"speed": "m/s", "max_sinkage": "m", "sample_interval": "m", "element_size": "m"}
    WHEELS: ClassVar[tuple[str, ...]] = ("smooth", "grouser")

    def __post_init__(self) -> None:
        if self.wheel not in self.WHEELS:
            raise WheelsoilInputError(f"wheel press wheel = {self.wheel!r} is unknown; choose one of {list(self.WHEELS)}")
        check_ranges(self, self.RANGES, "wheel press", self.UNITS)
        _check_sampling("wheel press", self.sample_interval, self.max_sinkage)


@dataclass(frozen=True)
class ShearSpec:
    """A direct shear box (a fixed lower box, an upper ring moved along x, a loading cap free to rise or sink under
    a constant normal force), square in plan (SI units).

    normal_stresses: the normal stresses imposed by the cap, one test each [Pa]; at least three for a
        Mohr--Coulomb envelope.
    side: inner side of the box [m]; height: height of the soil sample [m] (half in each half of the box).
    speed: shear speed of the upper ring [m/s]; max_displacement: its travel [m].
    sample_interval: displacement between two recorded samples [m].
    consolidation_time: time under the normal stress before shearing [s].
    """

    normal_stresses: tuple[float, ...] = soil_lab.SHEAR["normal_stresses"]
    side: float = soil_lab.SHEAR["side"]
    height: float = soil_lab.SHEAR["height"]
    speed: float = soil_lab.SHEAR["speed"]
    max_displacement: float = soil_lab.SHEAR["max_displacement"]
    sample_interval: float = soil_lab.SHEAR["sample_interval"]
    consolidation_time: float = soil_lab.SHEAR["consolidation_time"]

    RANGES: ClassVar[dict[str, Range]] = {
        "side": positive(), "height": positive(), "speed": Range(0.0, 1.0, lo_open=True),
        "max_displacement": positive(), "sample_interval": positive(), "consolidation_time": positive(),
    }
    UNITS: ClassVar[dict[str, str]] = {"side": "m", "height": "m", "speed": "m/s", "max_displacement": "m",
                                       "sample_interval": "m", "consolidation_time": "s"}

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "shear box", self.UNITS)
        stresses = tuple(float(s) for s in self.normal_stresses)
        object.__setattr__(self, "normal_stresses", stresses)
        if len(stresses) < 3:
            raise WheelsoilInputError(f"shear box normal_stresses = {list(stresses)} Pa: give at least three for a "
                                      "Mohr-Coulomb envelope with standard errors")
        for s in stresses:
            positive().check("shear box", "normal_stresses[...]", s, "Pa")
        if self.max_displacement > 0.25 * self.side:
            raise WheelsoilInputError(f"shear box max_displacement = {self.max_displacement!r} m is over a quarter of "
                                      f"the side ({0.25 * self.side:g} m): the shear plane's area would shrink too far")
        if self.sample_interval > 0.1 * self.max_displacement:
            raise WheelsoilInputError(f"shear box sample_interval = {self.sample_interval!r} m must be at most a tenth "
                                      f"of max_displacement ({0.1 * self.max_displacement:g} m)")

    @property
    def area(self) -> float:
        """Nominal area of the shear plane [m^2]."""
        return self.side**2


@dataclass(frozen=True)
class ReposeSpec:
    """The angle of repose by the draw-down (ledge) method: a box of soil whose end wall is taken away; the soil
    runs out onto an open floor, and the slope left standing in the box is the angle of repose (SI units).

    length, width, height: the soil's box before the wall is removed [m]; run_out: floor beyond the box [m].
    max_time: longest run-out before the verdict [s]; the test stops once the soil is at rest.
    seeds: beds (random packings) tested; the angle's spread over them is its error bar.
    """

    length: float = soil_lab.REPOSE["length"]
    width: float = soil_lab.REPOSE["width"]
    height: float = soil_lab.REPOSE["height"]
    run_out: float = soil_lab.REPOSE["run_out"]
    max_time: float = soil_lab.REPOSE["max_time"]
    seeds: tuple[int, ...] = soil_lab.REPOSE["seeds"]

    RANGES: ClassVar[dict[str, Range]] = {
        "length": positive(), "width": positive(), "height": positive(), "run_out": positive(),
        "max_time": positive(),
    }
    UNITS: ClassVar[dict[str, str]] = {"length": "m", "width": "m", "height": "m", "run_out": "m", "max_time": "s"}

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "repose box", self.UNITS)
        object.__setattr__(self, "seeds", check_seeds("repose", self.seeds))
        if self.height > self.length:
            raise WheelsoilInputError(f"repose box height = {self.height!r} m exceeds its length {self.length!r} m: "
                                      "a slope at the angle of repose would reach the back wall")


# ---------------------------------------------------------------------- limits that involve the bed
def check_plate_fits(key: str, footprint: float, box_length: float, box_width: float) -> None:
    """Refuse a loaded width ``footprint`` [m] that is not well inside the box: the walls must stay at least one
    footprint away on each side (the plate's influence reaches about its own width sideways; a doubled box checks
    that, docs/soillab)."""
    smallest = min(box_length, box_width)
    if footprint >= smallest:
        raise WheelsoilInputError(f"{key} = {footprint:g} m is wider than the lab's box ({box_length:g} x {box_width:g} m)")
    if 3.0 * footprint > smallest * (1.0 + 1e-9):
        raise WheelsoilInputError(
            f"{key} = {footprint:g} m is too wide for the lab's box ({box_length:g} x {box_width:g} m): the walls must "
            f"stay one width away on each side (box side >= {3.0 * footprint:g} m)")


def check_resolution(key: str, footprint: float, diameter_max: float) -> None:
    """Refuse particles too coarse for the loaded width: at least :data:`MIN_PARTICLES_ACROSS` across."""
    across = footprint / diameter_max
    if across < MIN_PARTICLES_ACROSS:
        raise WheelsoilInputError(
            f"{key} = {footprint:g} m holds only {across:.1f} particles of diameter_max = {diameter_max:g} m across; the "
            f"lab needs at least {MIN_PARTICLES_ACROSS:g} (particles of at most {footprint / MIN_PARTICLES_ACROSS:.4g} m)")


def max_normal_stress(youngs_modulus: float, poisson_ratio: float, diameter_mean: float,
                      packing_fraction: float = 0.58, coordination: float = 6.0) -> float:
    """The largest normal stress [Pa] whose mean Hertz overlap stays below :data:`MAX_OVERLAP_FRACTION` of the mean
    radius.

    A stress sigma on a packing of spheres of diameter d carries a mean contact force F = pi d^2 sigma /
    (phi Z) (Rumpf's relation, Z contacts a sphere, phi the packing fraction); the Hertz overlap of two equal
    spheres is delta = (3 F / (4 E* sqrt(R*)))^(2/3) with R* = d/4 and E* = E / (2 (1 - nu^2)) (Johnson, Contact
    Mechanics, eq. 4.22). Setting delta = MAX_OVERLAP_FRACTION d/2 and solving for sigma gives the limit.
    """
    e_star = youngs_modulus / (2.0 * (1.0 - poisson_ratio**2))
    r_star = 0.25 * diameter_mean
    delta = MAX_OVERLAP_FRACTION * 0.5 * diameter_mean
    force = 4.0 / 3.0 * e_star * math.sqrt(r_star) * delta**1.5
    return force * packing_fraction * coordination / (math.pi * diameter_mean**2)


def inertial_number(strain_rate: float, diameter: float, pressure: float, density: float) -> float:
    """GDR MiDi's inertial number I = gamma_dot d / sqrt(p / rho_p) [-]: below about 1e-3 a granular flow is
    quasi-static (its stresses do not depend on the rate)."""
    return strain_rate * diameter / math.sqrt(pressure / density)


def mean_and_spread(values) -> tuple[float, float]:
    """Mean and sample standard deviation (ddof 1) of a result over seeds (packings); the spread is NaN for one."""
    values = [float(v) for v in values]
    mean = math.fsum(values) / len(values)
    if len(values) < 2:
        return mean, math.nan
    return mean, math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (len(values) - 1))
