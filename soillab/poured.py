"""The poured bed: bulk density and packing fraction of the bed the testbed and the lab use, over seeds.

The bed is prepared as the testbed prepares it (:func:`wheelsoil.granular.prepare_bed`: poured from a loose
lattice, settled under the test gravity, levelled, settled again; cached). Its packing fraction is the solid volume
fraction of the core region one d_max away from walls, floor and surface (``granular.bed.measure_packing_fraction``);
the bulk density is that fraction times the particle density. Several seeds (other random packings) give the
spread.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

from wheelsoil.granular.bed import prepare_bed

from wheelsoil.granular.bed_spec import BedSpec

from .specs import check_seeds, mean_and_spread


@dataclass(frozen=True)
class PouredBed:
    """One poured bed: seed, particles, packing fraction [-], bulk density [kg/m^3], surface height [m], settling
    time [s simulated] and the wall time it took to prepare [s] (0 from the cache)."""

    seed: int
    particles: int
    packing_fraction: float
    bulk_density: float
    surface_height: float
    settle_time: float
    wall_seconds: float


@dataclass(frozen=True)
class PouredBedResult:
    """The poured beds of several seeds, with the mean and standard deviation of packing fraction and bulk density."""

    beds: tuple[PouredBed, ...]

    @property
    def bulk_density(self) -> tuple[float, float]:
        """Mean and standard deviation (over seeds) of the bulk density [kg/m^3]."""
        return mean_and_spread(b.bulk_density for b in self.beds)

    @property
    def packing_fraction(self) -> tuple[float, float]:
        """Mean and standard deviation (over seeds) of the packing fraction [-]."""
        return mean_and_spread(b.packing_fraction for b in self.beds)


def poured_bed_test(bed_spec: BedSpec, seeds=(0, 1, 2), *, cache_dir=None, arch: str | None = None,
                    progress: bool = False) -> PouredBedResult:
    """Prepare the bed of ``bed_spec`` once per seed and measure each."""
    seeds = check_seeds("poured bed", seeds)
    beds = []
    for seed in seeds:
        spec = dataclasses.replace(bed_spec, seed=seed)
        start = time.perf_counter()
        bed = prepare_bed(spec, cache_dir=cache_dir, arch=arch, progress=progress)
        wall = 0.0 if bed.meta.get("from_cache") else time.perf_counter() - start
        beds.append(PouredBed(seed, bed.n_particles, bed.packing_fraction, bed.packing_fraction * spec.material.density,
                              bed.surface_height, bed.settle_time, wall))
    return PouredBedResult(tuple(beds))
