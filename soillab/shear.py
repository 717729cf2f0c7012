"""Direct shear box: peak and residual friction angle and cohesion of the particles, with standard errors.

The box (ASTM D3080's arrangement, square in plan): a fixed lower box (a planar floor and four walls up to half the
sample's height, with an outward flange at its rim so that spilled spheres stay), an upper ring of four walls that
moves along +x at constant speed, and a loading cap free to rise or sink under the constant normal force sigma A
(it moves along x with the ring). The sample is the prepared bed of the box's plan and height
(:func:`wheelsoil.granular.prepare_bed`, the testbed's pouring), consolidated under the cap before shearing.

Measured per sample (each the mean over the DEM steps of one ``sample_interval`` of displacement): the shear force,
minus the soil's force along x on the ring and the cap; the normal force, the soil's force on the cap; the cap's
height (dilatancy). Stresses are these forces over the nominal area A = side^2. The normal stress on the shear plane
is the cap's plus the weight of the spheres above the plane (measured after consolidation) over A; the envelope is
fitted against it. The peak is the largest shear stress of a 5-sample running mean (with the displacement it was
reached at: a loose packing may still harden at the end of the travel, and then the peak is no peak), the residual
the mean of the same running mean over the last fifth of the travel (so never above the peak). Mohr--Coulomb tau = c + sigma tan(phi) is fitted by least squares over
the normal stresses (scipy.stats.linregress), giving phi and c with their standard errors.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import stats

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.granular.bed import Bed, prepare_bed
from wheelsoil.granular.bed_spec import BedSpec
from wheelsoil.granular.materials import STEEL
from wheelsoil.granular.scene import Scene

from .rigid import RigidTool
from .shapes import panel, square_ring
from .specs import ShearSpec, check_resolution, max_normal_stress

#: Shell thickness of the box's walls and cap [m].
WALL_THICKNESS = 0.002
#: Width of the lower box's flange, as a fraction of the side.
FLANGE = 0.3


@dataclass(frozen=True)
class ShearRun:
    """One normal stress: imposed sigma [Pa]; per sample the displacement [m], shear and cap normal stress [Pa] and
    the cap's rise [m]; peak and residual shear stress [Pa], the displacement at the peak [m], the mean normal stress
    the cap measured while shearing [Pa] and the normal stress on the shear plane (cap and the soil above) [Pa]."""

    normal_stress: float
    displacement: np.ndarray
    shear_stress: np.ndarray
    measured_normal: np.ndarray
    cap_rise: np.ndarray
    peak: float
    residual: float
    mean_normal: float
    wall_seconds: float
    peak_displacement: float = float("nan")
    plane_normal: float = float("nan")

    @property
    def peak_reached(self) -> bool:
        """The peak came before the last fifth of the travel (else the sample was still hardening)."""
        return bool(self.peak_displacement < 0.8 * self.displacement[-1])


@dataclass(frozen=True)
class MohrCoulomb:
    """tau = c + sigma tan(phi): friction angle [deg] and cohesion [Pa] with standard errors."""

    friction_angle: float
    friction_angle_se: float
    cohesion: float
    cohesion_se: float


@dataclass(frozen=True)
class ShearResult:
    """The shear box at every normal stress: each run, the peak and residual envelopes, the sample's particle count
    and bulk density [kg/m^3], and the upper ring's shear speed [m/s]."""

    runs: tuple[ShearRun, ...]
    peak: MohrCoulomb
    residual: MohrCoulomb
    particles: int
    bulk_density: float
    speed: float


def mohr_coulomb(normal, shear) -> MohrCoulomb:
    """Least-squares line tau = c + sigma tan(phi) through (sigma, tau) [Pa]; the angle's standard error from the
    slope's by the delta method (d phi = d(tan phi) / (1 + tan^2 phi))."""
    fit = stats.linregress(np.asarray(normal, float), np.asarray(shear, float))
    phi = math.degrees(math.atan(fit.slope))
    phi_se = math.degrees(fit.stderr / (1.0 + fit.slope**2))
    return MohrCoulomb(phi, phi_se, float(fit.intercept), float(fit.intercept_stderr))


def _scene(bed: Bed, spec: ShearSpec, arch) -> Scene:
    s = bed.spec
    margin = FLANGE * spec.side
    scene = Scene((-margin, -margin, 0.0), (spec.side + margin, spec.side + margin, 1.6 * spec.height),
                  gravity=s.gravity, material=s.material, pair=s.pair, arch=arch)
    scene.add_wall((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), material=s.wall_material, pair=s.wall_pair)
    scene.add_spheres(bed.positions, bed.radii)
    bed.set_pair_history(scene)
    return scene


def _one_stress(bed: Bed, spec: ShearSpec, sigma: float, arch) -> ShearRun:
    start = time.perf_counter()
    s = bed.spec
    side, half = spec.side, 0.5 * spec.height
    scene = _scene(bed, spec, arch)
    material = s.wall_material or STEEL
    cells = max(2, int(math.ceil(side / (2 * s.diameter_max))))
    gap = WALL_THICKNESS + 0.25 * s.diameter_min
    lower_nodes, lower_tri = square_ring(side, 0.0, half, cells, flange=FLANGE * side * 0.9, flange_at="top")
    RigidTool(scene, lower_nodes, lower_tri, WALL_THICKNESS, s.wall_pair, material=material)
    ring_nodes, ring_tri = square_ring(side, half + gap, 1.55 * spec.height, cells)
    ring = RigidTool(scene, ring_nodes, ring_tri, WALL_THICKNESS, s.wall_pair, material=material)
    clearance = 0.25 * s.diameter_min + WALL_THICKNESS
    top = float(np.max(bed.positions[:, 2] + bed.radii)) + WALL_THICKNESS
    cap_side = side - 2 * clearance
    cap_nodes, cap_tri = panel((clearance, clearance, top), (0.0, cap_side, 0.0), (cap_side, 0.0, 0.0), cells, cells)
    cap = RigidTool(scene, cap_nodes, cap_tri, WALL_THICKNESS, s.wall_pair, material=material)
    force = sigma * spec.area
    cap.move((0.0, 0.0, 0.0), free_z=True, force_z=-force)
    dt = scene.time_step
    scene.step(int(math.ceil(spec.consolidation_time / dt)))
    z0 = float(cap.position[2])
    above = scene.positions[:, 2] > half
    plane_extra = float(scene.masses[above].sum()) * s.gravity_magnitude / spec.area
    steps = max(1, int(round(spec.sample_interval / spec.speed / dt)))
    velocity = (spec.speed, 0.0, 0.0)
    ring.move(velocity)
    cap.move(velocity, free_z=True, force_z=-force)
    ring.soil_force()
    cap.soil_force()
    disp, tau, normal, rise = [], [], [], []
    n_samples = int(math.ceil(spec.max_displacement / spec.sample_interval))
    for k in range(n_samples):
        scene.step(steps)
        f_ring, f_cap = ring.soil_force(), cap.soil_force()
        disp.append((k + 0.5) * steps * dt * spec.speed)
        tau.append(-(f_ring[0] + f_cap[0]) / spec.area)
        normal.append(f_cap[2] / spec.area)
        rise.append(float(cap.position[2]) - z0)
    disp, tau, normal, rise = (np.asarray(a) for a in (disp, tau, normal, rise))
    smooth = np.convolve(tau, np.ones(5) / 5, mode="valid")  # centred on disp[2:-2]
    tail = max(1, round(len(tau) / 5))  # the running means of the last fifth of the travel
    at_peak = int(np.argmax(smooth)) + 2
    return ShearRun(sigma, disp, tau, normal, rise, float(smooth.max()), float(smooth[-tail:].mean()),
                    float(normal.mean()), time.perf_counter() - start, float(disp[at_peak]),
                    float(normal.mean()) + plane_extra)


def shear_test(bed_spec: BedSpec, spec: ShearSpec, *, cache_dir=None, arch: str | None = None,
               progress: bool = False) -> ShearResult:
    """Shear the particles of ``bed_spec`` (its material and size range; the box's plan and height replace its
    bin) at every normal stress of ``spec``. Checked before any work: enough particles across the half-height, and
    every stress within what the soft-sphere contact carries (:func:`~.specs.max_normal_stress`)."""
    check_resolution("shear box side", spec.side, bed_spec.diameter_max)
    if spec.height < 4 * bed_spec.diameter_max:
        raise WheelsoilInputError(f"shear box height = {spec.height:g} m holds fewer than two particles of diameter_max = "
                                  f"{bed_spec.diameter_max:g} m in each half (height >= {4 * bed_spec.diameter_max:g} m)")
    d_mean = 0.5 * (bed_spec.diameter_min + bed_spec.diameter_max)
    limit = max_normal_stress(bed_spec.material.youngs_modulus, bed_spec.material.poisson_ratio, d_mean)
    for sigma in spec.normal_stresses:
        if sigma > limit:
            raise WheelsoilInputError(
                f"shear box normal_stresses: {sigma:g} Pa is more than the soft-sphere contact of E = "
                f"{bed_spec.material.youngs_modulus:g} Pa and d = {d_mean:g} m carries ({limit:.3g} Pa, a mean overlap "
                "of 5 % of the radius)")
    spec_bed = dataclasses.replace(bed_spec, length=spec.side, width=spec.side, depth=spec.height, periodic=False)
    bed = prepare_bed(spec_bed, cache_dir=cache_dir, arch=arch, progress=progress)
    runs = []
    bar = None
    if progress:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        bar = Progress(TextColumn("shear box"), BarColumn(), TextColumn("{task.completed}/{task.total} stresses"),
                       TimeElapsedColumn(), transient=True)
        task = bar.add_task("shear", total=len(spec.normal_stresses))
        bar.start()
    try:
        for sigma in spec.normal_stresses:
            runs.append(_one_stress(bed, spec, sigma, arch))
            if bar is not None:
                bar.advance(task)
    finally:
        if bar is not None:
            bar.stop()
    normal = [r.plane_normal for r in runs]
    return ShearResult(tuple(runs), mohr_coulomb(normal, [r.peak for r in runs]),
                       mohr_coulomb(normal, [r.residual for r in runs]), bed.n_particles,
                       bed.packing_fraction * spec_bed.material.density, spec.speed)
