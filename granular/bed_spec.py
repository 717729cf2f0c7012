"""What a soil bed is, before any of it exists: the bin, the particles and the preparation protocol
(:class:`BedSpec`), and what a bed of it will hold (particle counts, memory), with no Taichi, so that a case file
can be checked without the engine (:mod:`.bed` prepares, caches and loads the beds)."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from wheelsoil.gravity import GRAVITY_PRESETS
from wheelsoil.parameters import smoke
from wheelsoil.ranges import Range, check_ranges, positive

from .errors import WheelsoilInputError
from .materials import SOIL_STEEL, STEEL, Material, PairProperties

#: Bump when the preparation protocol changes so that stale caches are not reused.
#: 2: spheres in column order (:mod:`.ordering`) from the lattice on.
#: 3: the settled bed keeps its tangential contact history (pairs and walls), so a scene made from it starts
#:    in the prepared equilibrium instead of re-seating (friction-held spheres slipping until it rebuilds).
#: 4: a pair whose owner changes in the column renumbering keeps its history's direction (format 3 stored the
#:    displacement of such pairs with the wrong sign), and the rolling spring torques are kept as well.
BED_FORMAT_VERSION = 4


@dataclass(frozen=True)
class BedSpec:
    """Everything that shapes a prepared soil bed (SI units).

    Attributes
    ----------
    length, width: bin size along x and y [m].
    depth: target height of the levelled surface above the floor [m].
    diameter_min, diameter_max: particle diameter range [m], uniform distribution.
    gravity: gravity vector the bed is prepared (and will be tested) under [m/s^2].
    material, pair: particle material and soil--soil pair properties.
    wall_material, wall_pair: bin walls (``wall_material=None`` is rigid) and soil--wall pair.
    seed: random seed of radii and lattice jitter.
    kinetic_energy_threshold: settled when the kinetic energy per particle is below this [J];
        ``None``: 0.5 m_mean (5 mm/s)^2.
    max_settle_time: give up (error) after this much simulated time per settling phase [s].
    overfill: particles for ``overfill`` x the target depth, so levelling has some to remove.
    time_step: DEM time step [s] of the preparation; ``None`` uses the stable estimate.
    periodic: the bin is periodic along x (no end walls; :class:`~.scene.Scene` ``periodic_x``): a soil
        patch that a moving-patch testbed can shift without end (``wheelsoil.coupling.patch``).
    pour_friction_factor: the sliding and rolling friction of the soil--soil and soil--wall pairs are multiplied
        by this while the bed is poured, settled and levelled [-], in [0, 3]. 1 (default) pours with the particles'
        own friction, a loose packing; below 1 the spheres slide into a denser packing (0 pours frictionless
        spheres, the densest); above 1 they lock sooner, a looser one (how a deep bed, which its own weight packs
        denser, is poured to a shallow bed's packing). The bed keeps ``pair`` and ``wall_pair`` for every test made
        on it.
    """

    length: float = smoke.SOIL["length"]
    width: float = smoke.SOIL["width"]
    depth: float = smoke.SOIL["depth"]
    diameter_min: float = smoke.SOIL["diameter_min"]
    diameter_max: float = smoke.SOIL["diameter_max"]
    gravity: tuple[float, float, float] = (0.0, 0.0, -GRAVITY_PRESETS[smoke.GRAVITY])
    material: Material = smoke.SOIL_MATERIAL
    pair: PairProperties = smoke.SOIL_SOIL
    wall_material: Material | None = STEEL
    wall_pair: PairProperties = SOIL_STEEL
    seed: int = smoke.SEED
    kinetic_energy_threshold: float | None = None
    max_settle_time: float = smoke.SOIL["max_settle_time"]
    overfill: float = 1.15
    time_step: float | None = None
    periodic: bool = smoke.SOIL["periodic"]
    pour_friction_factor: float = 1.0

    #: Allowed range of every scalar input (None: the computed default). The case schema's [soil] fields take
    #: their bounds from here.
    RANGES: ClassVar[dict[str, Range]] = {
        "length": positive(), "width": positive(), "depth": positive(), "diameter_min": positive(),
        "diameter_max": positive(), "max_settle_time": positive(), "seed": Range(lo=0, integer=True),
        "overfill": Range(1.0, 3.0), "kinetic_energy_threshold": positive(), "time_step": positive(),
        "pour_friction_factor": Range(0.0, 3.0),
    }
    UNITS: ClassVar[dict[str, str]] = {
        "length": "m", "width": "m", "depth": "m", "diameter_min": "m", "diameter_max": "m", "max_settle_time": "s",
        "kinetic_energy_threshold": "J", "time_step": "s",
    }

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "bed", self.UNITS)
        if self.diameter_max < self.diameter_min:
            raise WheelsoilInputError(
                f"bed diameter_max = {self.diameter_max!r} m is smaller than diameter_min = {self.diameter_min!r} m"
            )
        g = tuple(float(v) for v in self.gravity)
        if len(g) != 3 or not all(math.isfinite(v) for v in g) or g[2] >= 0.0:
            raise WheelsoilInputError(
                f"bed gravity = {self.gravity!r} is invalid: it must be a finite 3-vector pointing down (g_z < 0)"
            )
        object.__setattr__(self, "gravity", g)
        smallest = min(self.length, self.width)
        if self.diameter_max * 3 > smallest:
            raise WheelsoilInputError(
                f"bed of {self.length} x {self.width} m is too narrow for particles of diameter "
                f"{self.diameter_max} m: each side must hold at least 3 of the largest particles"
            )
        if self.depth < 2 * self.diameter_max:
            raise WheelsoilInputError(
                f"bed depth = {self.depth} m must be at least two of the largest particles ({2 * self.diameter_max} m)"
            )
        object.__setattr__(self, "periodic", bool(self.periodic))

    # ---------------------------------------------------------------- derived quantities
    @property
    def gravity_magnitude(self) -> float:
        return float(np.linalg.norm(self.gravity))

    @property
    def mean_particle_volume(self) -> float:
        """E[pi d^3 / 6] for d uniform in [d_min, d_max] [m^3]."""
        a, b = self.diameter_min, self.diameter_max
        mean_d3 = a**3 if b == a else (b**4 - a**4) / (4.0 * (b - a))
        return math.pi / 6.0 * mean_d3

    @property
    def settle_threshold(self) -> float:
        """Kinetic energy per particle below which the bed counts as settled [J]."""
        if self.kinetic_energy_threshold is not None:
            return float(self.kinetic_energy_threshold)
        return 0.5 * self.material.density * self.mean_particle_volume * 0.005**2

    def to_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["gravity"] = list(self.gravity)
        d["pair"], d["wall_pair"] = self.pair.to_dict(), self.wall_pair.to_dict()
        if not self.periodic:  # beds prepared before periodic bins existed keep their cache keys
            d.pop("periodic")
        if self.pour_friction_factor == 1.0:  # and so do loose pours, made before the factor existed
            d.pop("pour_friction_factor")
        return d

    def pour_pair(self, pair: PairProperties) -> PairProperties:
        """``pair`` as it is while the bed is poured: its sliding and rolling friction times
        ``pour_friction_factor``."""
        f = self.pour_friction_factor
        return dataclasses.replace(pair, static_friction=pair.static_friction * f,
                                   rolling_friction=pair.rolling_friction * f)

    @classmethod
    def from_dict(cls, d: dict) -> BedSpec:
        # the keys :meth:`to_dict` leaves out at their old value (a walled bin, a loose pour) mean that value, not
        # the current default (a periodic bin): a walled bed read back from the cache stays walled
        d = {"periodic": False, "pour_friction_factor": 1.0, **d}
        d["material"] = Material(**d["material"])
        d["pair"] = PairProperties(**d["pair"])
        d["wall_material"] = None if d.get("wall_material") is None else Material(**d["wall_material"])
        d["wall_pair"] = PairProperties(**d["wall_pair"])
        d["gravity"] = tuple(d["gravity"])
        return cls(**d)

    def cache_key(self) -> str:
        """SHA-256 over every parameter that shapes the bed and the protocol version."""
        payload = json.dumps({"format": BED_FORMAT_VERSION, "spec": self.to_dict()}, sort_keys=True)
        return hashlib.sha256(payload.encode()).hexdigest()



# ---------------------------------------------------------------------- sizes
#: Peak resident memory per particle while a bed is prepared and stepped [bytes]: an upper bound, about 2.5 x
#: the 1.5 KiB per sphere measured stepping a 388,026-sphere bed (692 MiB peak less the 110 MiB interpreter;
#: benchmarks/README.md, memory check), for the pair list of a dense bed and the host copies of the state.
BYTES_PER_PARTICLE = 4096


def fill_lattice(spec: BedSpec) -> tuple[int, int, int, float, float]:
    """The fill lattice of :func:`initial_packing`: (nx, ny, layers, spacing_x, spacing) [-, -, -, m, m]."""
    r_max = 0.5 * spec.diameter_max
    spacing = spec.diameter_max * 1.05
    nx = int((spec.length - 2 * r_max) // spacing) + 1
    ny = int((spec.width - 2 * r_max) // spacing) + 1
    spacing_x = spacing
    if spec.periodic:  # the lattice tiles the period exactly: no seam where the ends meet
        nx = int(spec.length // spacing)
        spacing_x = spec.length / nx
    needed = spec.overfill * 0.6 * spec.length * spec.width * spec.depth / spec.mean_particle_volume
    layers = max(2, int(math.ceil(needed / (nx * ny))))
    return nx, ny, layers, spacing_x, spacing


def estimated_particles(spec: BedSpec, packing_fraction: float = 0.6) -> int:
    """Spheres in the levelled bed: ``packing_fraction`` of the bin volume up to the target depth over the mean
    sphere volume (the prepared beds measure 0.57-0.58, so this is a few per cent high)."""
    return int(round(packing_fraction * spec.length * spec.width * spec.depth / spec.mean_particle_volume))


def fill_particles(spec: BedSpec) -> int:
    """Spheres in the fill lattice, the most a bed holds while it is prepared (before levelling)."""
    nx, ny, layers, _, _ = fill_lattice(spec)
    return nx * ny * layers


def machine_memory() -> int:
    """Physical memory of this machine [bytes] (0 where the platform does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, OSError, ValueError):
        return 0


def check_memory(spec: BedSpec, available: int | None = None, share: float = 0.8) -> int:
    """Refuse, before any work, a bed whose estimated peak memory (:data:`BYTES_PER_PARTICLE` per sphere of the
    fill) exceeds ``share`` of ``available`` bytes (default: this machine's memory); returns the estimate
    [bytes]. The message names the case keys that set the particle count."""
    n = fill_particles(spec)
    need = n * BYTES_PER_PARTICLE
    available = machine_memory() if available is None else int(available)
    if available > 0 and need > share * available:
        raise WheelsoilInputError(
            f"the bed (soil.length x width x depth = {spec.length:g} x {spec.width:g} x {spec.depth:g} m of "
            f"soil.diameter_min..diameter_max = {1e3 * spec.diameter_min:g}-{1e3 * spec.diameter_max:g} mm "
            f"particles) holds about {n:,} spheres while it is prepared, about {need / 2**30:.3g} GiB, more than "
            f"{share:.0%} of the {available / 2**30:.3g} GiB this machine has: use larger particles or a smaller bin"
        )
    return need
