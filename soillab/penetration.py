"""Plate sinkage and static wheel sinkage: a rigid plate or wheel pressed into a prepared bed at constant speed, the
soil's vertical reaction recorded against sinkage (the CMU lab's force--displacement tests).

Protocol: the bed (:func:`wheelsoil.granular.prepare_bed`, cached) in its walled bin; the tool placed centred over
the bin, a quarter of the smallest particle above the highest sphere beneath it; moved down at ``speed``; one
sample every ``sample_interval`` of travel, each the mean soil force over the DEM steps in it. Sinkage is measured
from the bed's surface under the tool (the mean over d_max-wide columns of the highest sphere tops inside the
footprint): on sand of real grains the lab's zero, the first contact of the plate, is that surface to within about
0.7 mm (data README); on coarse spheres the first contact would sit up to a particle radius higher.
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wheelsoil.coupling.coupled_state import restore_coupled_state, take_coupled_state
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import WheelGeometry, build_wheel_mesh, from_parameters
from wheelsoil.granular.bed import Bed, prepare_bed
from wheelsoil.granular.bed_spec import BedSpec
from wheelsoil.granular.materials import STEEL, PairProperties
from wheelsoil.parameters import cmu_k10
from wheelsoil.state_file import load_state, save_state

from .measured import LoadCurve, plate_area
from .rigid import RigidTool
from .shapes import disc
from .specs import PlateSpec, WheelPressSpec, check_plate_fits, check_resolution, inertial_number


@dataclass
class PenetrationResult:
    """A simulated pressing test: the curve, where it ran and what it cost.

    curve: force against sinkage (:class:`~.measured.LoadCurve`); surface: the zero of sinkage [m]; top_offset: how
    far the highest sphere top under the footprint stands above it [m] (the tool touches the first sphere at
    sinkage -top_offset; on coarse spheres about a diameter);
    bulk_density: the bed's [kg/m^3]; packing_fraction; gravity: its magnitude [m/s^2]; particles; inertial_number at the deepest sample (the
    flow is quasi-static below about 1e-3); wall_seconds; steps; time_step [s]; bed_seconds: preparing the bed
    (0 when it came from the cache).
    """

    curve: LoadCurve
    surface: float
    top_offset: float
    bulk_density: float
    packing_fraction: float
    particles: int
    inertial_number: float
    wall_seconds: float
    steps: int
    time_step: float
    gravity: float
    bed_seconds: float = 0.0
    meta: dict = field(default_factory=dict)


def footprint_surface(bed: Bed, center_xy, half_x: float, half_y: float) -> tuple[float, float]:
    """(mean surface, highest sphere top) [m] inside the rectangle ``center_xy`` +- (half_x, half_y): the surface
    is the mean over d_max-wide columns of each column's highest sphere top."""
    x, r = bed.positions, bed.radii
    d = bed.spec.diameter_max
    lo = np.asarray(center_xy, float) - (half_x, half_y)
    inside = np.all((x[:, :2] >= lo) & (x[:, :2] <= lo + (2 * half_x, 2 * half_y)), axis=1)
    if not inside.any():
        raise WheelsoilInputError("no sphere lies under the tool's footprint: the bed is empty there")
    top = x[inside, 2] + r[inside]
    cols = np.floor((x[inside, :2] - lo) / d).astype(np.int64)
    _, column = np.unique(cols, axis=0, return_inverse=True)
    highest = np.full(int(column.max()) + 1, -math.inf)
    np.maximum.at(highest, column.ravel(), top)
    return float(highest.mean()), float(top.max())


@dataclass(frozen=True)
class PressCheckpoint:
    """Where and how often a pressing test keeps the state to continue from (for tests of hours, e.g. a plate in a
    box of 300,000 spheres).

    path: the checkpoint file; a run that finds one there written for the same test (``key``) continues from it,
    and the file is removed once the test has finished. key: what the test is (bed, tool, speeds, contact), so that
    a file of another test is never continued. every: samples between two checkpoints (>= 1).

    Taking a state rebuilds the neighbour lists at the next step, so a test with checkpoints follows another
    trajectory than one without (at round-off, then chaotically); with the same ``every`` the trajectory, and the
    curve, are the same bit for bit whether or not the run was interrupted."""

    path: Path
    key: str
    every: int = 10

    def __post_init__(self) -> None:
        if int(self.every) != self.every or self.every < 1:
            raise WheelsoilInputError(f"checkpoint every = {self.every!r} samples: give a whole number >= 1")


def press_key(*parts) -> str:
    """A short digest of the test's description (dataclasses of specs, numbers): a checkpoint's ``key``."""
    return hashlib.sha256(repr(parts).encode()).hexdigest()[:16]


def _take_state(tool: RigidTool, sinkage: list, force: list) -> dict:
    state = take_coupled_state(tool.scene, tool.structure, tool.contact)
    state["press"] = {"sinkage": np.asarray(sinkage, float), "force": np.asarray(force, float)}
    return state


def _restore(tool: RigidTool, checkpoint: PressCheckpoint) -> tuple[list, list] | None:
    """The samples so far from ``checkpoint``'s file, with the tool and soil restored; None without a file of it."""
    if not checkpoint.path.is_file():
        return None
    state, meta = load_state(checkpoint.path)
    if meta.get("key") != checkpoint.key:
        raise WheelsoilInputError(f"{checkpoint.path} is the checkpoint of another test (key {meta.get('key')}, this "
                                  f"test {checkpoint.key}): remove it, or run the test it was written for")
    restore_coupled_state(state, tool.scene, tool.structure, tool.contact)
    press = state["press"]
    return [float(v) for v in np.atleast_1d(press["sinkage"])], [float(v) for v in np.atleast_1d(press["force"])]


def _press(tool: RigidTool, bottom_offset: float, surface: float, speed: float, max_sinkage: float,
           sample_interval: float, progress: bool, label: str,
           checkpoint: PressCheckpoint | None = None) -> tuple[np.ndarray, np.ndarray, int]:
    """Move ``tool`` down at ``speed`` until its lowest point is ``max_sinkage`` below ``surface``; returns the
    sinkage [m] and the soil's vertical force [N] of every sample and the steps taken. With ``checkpoint`` the state
    is kept every ``checkpoint.every`` samples and a kept state of the same test is continued."""
    scene = tool.scene
    dt = scene.time_step
    steps = max(1, int(round(sample_interval / speed / dt)))
    sinkage, force = [], []
    resumed = _restore(tool, checkpoint) if checkpoint is not None else None
    if resumed is not None:
        sinkage, force = resumed
    tool.move((0.0, 0.0, -speed))
    tool.soil_force()
    depth_at = lambda: surface - (tool.position[2] + bottom_offset)  # noqa: E731
    total = max_sinkage - depth_at()
    bar = _Bar(label, total) if progress else None
    try:
        while depth_at() < max_sinkage:
            scene.step(steps)
            sinkage.append(depth_at() - 0.5 * steps * dt * speed)  # the sample's mean position
            force.append(float(tool.soil_force()[2]))
            if bar is not None:
                bar.advance(steps * dt * speed)
            if checkpoint is not None and len(sinkage) % checkpoint.every == 0 and depth_at() < max_sinkage:
                save_state(checkpoint.path, _take_state(tool, sinkage, force),
                           {"key": checkpoint.key, "samples": len(sinkage), "t": scene.time})
    finally:
        if bar is not None:
            bar.stop()
    tool.hold()
    if checkpoint is not None:
        checkpoint.path.unlink(missing_ok=True)
    return np.asarray(sinkage), np.asarray(force), len(sinkage) * steps


class _Bar:
    """A rich progress bar over the tool's travel [m]."""

    def __init__(self, label: str, total: float) -> None:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        self.progress = Progress(TextColumn(label), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                                 TimeElapsedColumn(), TimeRemainingColumn(), transient=True)
        self.task = self.progress.add_task(label, total=max(total, 1e-9))
        self.progress.start()

    def advance(self, amount: float) -> None:
        self.progress.advance(self.task, amount)

    def stop(self) -> None:
        self.progress.stop()


def _bed(bed_spec: BedSpec, cache_dir, arch) -> tuple[Bed, float]:
    start = time.perf_counter()
    bed = prepare_bed(bed_spec, cache_dir=cache_dir, arch=arch)
    return bed, (0.0 if bed.meta.get("from_cache") else time.perf_counter() - start)


def _result(bed: Bed, curve: LoadCurve, surface: float, highest: float, speed: float, footprint: float,
            loaded_area: float,
            tool: RigidTool, steps: int, wall: float, bed_seconds: float) -> PenetrationResult:
    """The result record; the inertial number at the deepest sample, with the strain rate speed / footprint and the
    pressure the force over ``loaded_area`` [m^2] (at least the overburden of one particle layer)."""
    s = bed.spec
    d_mean = 0.5 * (s.diameter_min + s.diameter_max)
    bulk = bed.packing_fraction * s.material.density
    deepest = max(float(curve.force[-1]), 1e-9) / loaded_area
    rate = speed / footprint
    inertial = inertial_number(rate, d_mean, max(deepest, bulk * s.gravity_magnitude * d_mean), s.material.density)
    return PenetrationResult(curve, surface, highest - surface, bulk, bed.packing_fraction, bed.n_particles, inertial, wall, steps,
                             tool.scene.time_step, s.gravity_magnitude, bed_seconds)


def plate_test(bed_spec: BedSpec, plate: PlateSpec, *, pair: PairProperties | None = None, cache_dir=None,
               arch: str | None = None, progress: bool = False,
               checkpoint: str | Path | None = None, checkpoint_every: int = 10) -> PenetrationResult:
    """Press a rigid circular plate into the bed of ``bed_spec`` (checked before any work: the plate inside the
    box, enough particles across it). ``checkpoint``: a file to keep the state in every ``checkpoint_every``
    samples, continued when the same test runs again after an interruption (:class:`PressCheckpoint`)."""
    check_plate_fits("plate diameter", plate.diameter, bed_spec.length, bed_spec.width)
    check_resolution("plate diameter", plate.diameter, bed_spec.diameter_max)
    bed, bed_seconds = _bed(bed_spec, cache_dir, arch)
    start = time.perf_counter()
    center = np.array([0.5 * bed_spec.length, 0.5 * bed_spec.width])
    radius = 0.5 * plate.diameter
    surface, highest = footprint_surface(bed, center, radius, radius)
    nodes, tri = disc(radius, plate.rings)
    gap = 0.25 * bed_spec.diameter_min
    z0 = highest + 0.5 * plate.thickness + gap
    scene = bed.to_scene(headroom=max(plate.max_sinkage, 0.05), arch=arch)
    tool = RigidTool(scene, nodes + (center[0], center[1], z0), tri, plate.thickness,
                     pair or bed_spec.wall_pair, material=bed_spec.wall_material or STEEL)
    keep = None if checkpoint is None else PressCheckpoint(
        Path(checkpoint), press_key("plate", bed_spec, plate, pair, checkpoint_every), checkpoint_every)
    sinkage, force, steps = _press(tool, -0.5 * plate.thickness, surface, plate.speed, plate.max_sinkage,
                                   plate.sample_interval, progress, f"plate {1e3 * plate.diameter:g} mm", keep)
    curve = LoadCurve("plate", plate.diameter, f"DEM, {1e3 * plate.diameter:g} mm plate, seed {bed_spec.seed}",
                      sinkage, force, area=plate_area(plate.diameter))
    return _result(bed, curve, surface, highest, plate.speed, plate.diameter, plate.area, tool, steps,
                   time.perf_counter() - start, bed_seconds)


def cmu_wheel(name: str, element_size: float | None = None) -> WheelGeometry:
    """The CMU K10-mini wheel ``"smooth"`` or ``"grouser"`` (:data:`wheelsoil.parameters.cmu_k10.K10_MINI_WHEELS`)."""
    values = dict(cmu_k10.K10_MINI_WHEELS[name])
    if element_size is not None:
        values["element_size"] = element_size
    return from_parameters(values)


def wheel_press_test(bed_spec: BedSpec, press: WheelPressSpec, *, pair: PairProperties | None = None,
                     cache_dir=None, arch: str | None = None, progress: bool = False,
                     checkpoint: str | Path | None = None, checkpoint_every: int = 10) -> PenetrationResult:
    """Press a rigid CMU wheel, axle along y, straight down into the bed of ``bed_spec`` (``checkpoint``: as
    :func:`plate_test`'s)."""
    wheel = cmu_wheel(press.wheel, press.element_size)
    outer = wheel.radius + wheel.grouser_height
    check_plate_fits("wheel diameter", 2 * outer, bed_spec.length, bed_spec.length)
    check_plate_fits("wheel width", wheel.width, bed_spec.width, bed_spec.width)
    check_resolution("wheel width", wheel.width, bed_spec.diameter_max)
    bed, bed_seconds = _bed(bed_spec, cache_dir, arch)
    start = time.perf_counter()
    mesh, _ = build_wheel_mesh(wheel)
    surface_facets = mesh.surface if mesh.surface is not None else np.arange(len(mesh.triangles))
    center = np.array([0.5 * bed_spec.length, 0.5 * bed_spec.width])
    chord = math.sqrt(max(outer**2 - (outer - press.max_sinkage) ** 2, 0.0))
    surface, _ = footprint_surface(bed, center, max(chord, bed_spec.diameter_max), 0.5 * wheel.width)
    _, highest = footprint_surface(bed, center, outer, 0.5 * wheel.width)
    gap = 0.25 * bed_spec.diameter_min
    lowest = float(mesh.nodes[:, 2].min()) - 0.5 * wheel.grouser_thickness if wheel.grouser_count else \
        float(mesh.nodes[:, 2].min()) - 0.5 * wheel.tread_thickness
    z0 = highest - lowest + gap
    scene = bed.to_scene(headroom=2 * outer, arch=arch)
    tri = mesh.triangles[surface_facets]
    used = np.unique(tri)
    renumber = np.full(len(mesh.nodes), -1, np.int64)
    renumber[used] = np.arange(used.size)
    thickness = np.asarray(mesh.thickness)[surface_facets] if np.ndim(mesh.thickness) else mesh.thickness
    tool = RigidTool(scene, mesh.nodes[used] + (center[0], center[1], z0), renumber[tri], thickness,
                     pair or bed_spec.wall_pair, material=bed_spec.wall_material or STEEL,
                     center=(center[0], center[1], z0))
    keep = None if checkpoint is None else PressCheckpoint(
        Path(checkpoint), press_key("wheel", bed_spec, press, pair, checkpoint_every), checkpoint_every)
    sinkage, force, steps = _press(tool, lowest, surface, press.speed, press.max_sinkage, press.sample_interval,
                                   progress, f"{press.wheel} wheel", keep)
    curve = LoadCurve("wheel", wheel.radius, f"DEM, {press.wheel} wheel, seed {bed_spec.seed}", sinkage, force,
                      wheel=press.wheel)
    return _result(bed, curve, surface, highest, press.speed, wheel.width, 2 * chord * wheel.width, tool, steps,
                   time.perf_counter() - start, bed_seconds)


@dataclass(frozen=True)
class RestingPlate:
    """A plate left to rest on the bed under gravity: its weight [N], the soil's mean vertical force on it over the
    last quarter of the rest [N], how far it sank [m] and its vertical speed at the end [m/s]."""

    weight: float
    soil_force: float
    settlement: float
    final_speed: float


def resting_plate(bed_spec: BedSpec, plate: PlateSpec, *, mass: float, rest_time: float = 0.25,
                  pair: PairProperties | None = None, cache_dir=None, arch: str | None = None) -> RestingPlate:
    """Lay a plate of ``mass`` [kg] on the bed, free to sink under gravity, and hold its weight against the soil's
    force (the check that the soil carries what rests on it: equal to within the rest's remaining motion). A plate
    dropped on a loose bed of coarse spheres sinks a particle diameter or so and comes to rest within about 0.1 s.
    """
    check_plate_fits("plate diameter", plate.diameter, bed_spec.length, bed_spec.width)
    check_resolution("plate diameter", plate.diameter, bed_spec.diameter_max)
    bed, _ = _bed(bed_spec, cache_dir, arch)
    center = np.array([0.5 * bed_spec.length, 0.5 * bed_spec.width])
    radius = 0.5 * plate.diameter
    _, highest = footprint_surface(bed, center, radius, radius)
    nodes, tri = disc(radius, plate.rings)
    z0 = highest + 0.5 * plate.thickness + 0.1 * bed_spec.diameter_min
    scene = bed.to_scene(headroom=0.05, arch=arch)
    tool = RigidTool(scene, nodes + (center[0], center[1], z0), tri, plate.thickness, pair or bed_spec.wall_pair,
                     material=bed_spec.wall_material or STEEL, gravity=bed_spec.gravity, mass=mass)
    tool.move((0.0, 0.0, 0.0), free_z=True)
    steps = int(math.ceil(0.25 * rest_time / scene.time_step))
    scene.step(3 * steps)
    tool.soil_force()
    scene.step(steps)
    weight = tool.mass * bed_spec.gravity_magnitude
    return RestingPlate(weight, float(tool.soil_force()[2]), z0 - float(tool.position[2]), float(tool.velocity[2]))
