"""Angle of repose by the draw-down (ledge) method, over several random packings.

A box of soil (the testbed's pouring, :func:`wheelsoil.granular.prepare_bed`) is opened by taking one end wall
away; the soil runs out onto the open floor beyond and the slope left standing at rest is the angle of repose
(Al-Hashemi & Al-Amoudi 2018, Powder Technol. 330, sec. 3.2: the "ledge" or draw-down method). The box is periodic
across its width, so no side wall props the slope up (the measured angle is that of an infinitely wide box), and a
far wall ends the run-out floor.

The slope: the surface profile along the run-out (each run-out bin of one d_max the mean, over d_max-wide columns
across the width, of the highest sphere top), fitted by a least-squares line over the bins whose height lies
between 15 % and 85 % of the profile's highest; the angle is atan of minus its slope. The run stops once the
kinetic energy per particle is below that of the mean particle at 5 mm/s, or at ``max_time`` (then the result says
it was not at rest). The spread over seeds is the error bar.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from wheelsoil.granular.bed import Bed, prepare_bed

from wheelsoil.granular.bed_spec import BedSpec
from wheelsoil.granular.scene import Scene

from .specs import ReposeSpec, check_resolution, mean_and_spread


@dataclass(frozen=True)
class ReposeRun:
    """One packing: seed, angle [deg], at rest (bool), simulated time [s], the profile (run-out position [m],
    surface height [m]) and the fitted bins' mask."""

    seed: int
    angle: float
    at_rest: bool
    time: float
    position: np.ndarray
    height: np.ndarray
    fitted: np.ndarray
    wall_seconds: float


@dataclass(frozen=True)
class ReposeResult:
    runs: tuple[ReposeRun, ...]

    @property
    def angle(self) -> tuple[float, float]:
        """Mean angle [deg] and its standard deviation over the seeds."""
        return mean_and_spread(r.angle for r in self.runs)


def surface_profile(positions: np.ndarray, radii: np.ndarray, width: float, reach: float,
                    bin_size: float) -> tuple[np.ndarray, np.ndarray]:
    """(bin centres [m], mean highest sphere top [m]) along y over [0, reach], each the mean over the x-columns of
    a bin (an empty column counts as the floor, height 0)."""
    ny, nx = int(math.ceil(reach / bin_size)), max(1, int(width // bin_size))
    tops = np.zeros((ny, nx))
    iy = np.clip((positions[:, 1] // bin_size).astype(np.int64), 0, ny - 1)
    ix = np.clip((np.mod(positions[:, 0], width) // (width / nx)).astype(np.int64), 0, nx - 1)
    np.maximum.at(tops, (iy, ix), positions[:, 2] + radii)
    return (np.arange(ny) + 0.5) * bin_size, tops.mean(axis=1)


def slope_angle(position: np.ndarray, height: np.ndarray) -> tuple[float, np.ndarray]:
    """Angle [deg] of the least-squares line through the profile's bins between 15 % and 85 % of its highest, and
    the mask of those bins (NaN when fewer than three)."""
    top = float(height.max())
    mask = (height > 0.15 * top) & (height < 0.85 * top)
    if mask.sum() < 3:
        return float("nan"), mask
    slope = np.polyfit(position[mask], height[mask], 1)[0]
    return math.degrees(math.atan(-slope)), mask


def _one_seed(bed: Bed, spec: ReposeSpec, arch) -> ReposeRun:
    start = time.perf_counter()
    s = bed.spec
    reach = spec.length + spec.run_out
    scene = Scene((0.0, 0.0, 0.0), (spec.width, reach, 1.5 * spec.height), gravity=s.gravity, material=s.material,
                  pair=s.pair, arch=arch, periodic_x=True)
    for point, normal in (((0, 0, 0), (0, 0, 1)), ((0, 0, 0), (0, 1, 0)), ((0, reach, 0), (0, -1, 0))):
        scene.add_wall(point, normal, material=s.wall_material, pair=s.wall_pair)
    scene.add_spheres(bed.positions, bed.radii)
    bed.set_pair_history(scene)
    threshold = s.settle_threshold
    fall = math.sqrt(2 * spec.height / s.gravity_magnitude)
    chunk = max(1, int(round(0.02 / scene.time_step)))
    at_rest = False
    while scene.time < spec.max_time:
        scene.step(chunk)
        if scene.time > 2 * fall and scene.kinetic_energy() / scene.n_particles < threshold:
            at_rest = True
            break
    position, height = surface_profile(scene.positions, scene.radii, spec.width, reach, s.diameter_max)
    angle, mask = slope_angle(position, height)
    return ReposeRun(s.seed, angle, at_rest, scene.time, position, height, mask, time.perf_counter() - start)


def repose_test(bed_spec: BedSpec, spec: ReposeSpec, *, cache_dir=None, arch: str | None = None,
                progress: bool = False) -> ReposeResult:
    """The angle of repose of the particles of ``bed_spec`` (its material and size range; the box of ``spec``
    replaces its bin), one packing per seed of ``spec``."""
    check_resolution("repose box height", spec.height, bed_spec.diameter_max)
    check_resolution("repose box width", spec.width, bed_spec.diameter_max)
    runs = []
    for seed in spec.seeds:
        bed_s = dataclasses.replace(bed_spec, length=spec.width, width=spec.length, depth=spec.height, periodic=True,
                                    seed=seed)
        bed = prepare_bed(bed_s, cache_dir=cache_dir, arch=arch, progress=progress)
        runs.append(_one_seed(bed, spec, arch))
    return ReposeResult(tuple(runs))
