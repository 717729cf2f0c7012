"""Soil-bed preparation: fill a bin, settle under the test gravity, level, measure, cache as HDF5.

Protocol (as a lab prepares a soil bin, and as seed 004 section 2.3 prepares its DEM bin):

1. *Fill*: polydisperse spheres (diameters uniform in [d_min, d_max]) on a jittered loose lattice
   above the bin floor, enough for ``overfill`` times the target depth at packing fraction 0.6.
2. *Settle* under the gravity the bed will be tested at (with the sliding and rolling friction of every pair
   multiplied by ``pour_friction_factor``: 1, the default, is a loose pour; below 1 the spheres slide into a
   denser packing, above 1 they lock into a looser one, the DEM's usual way to set a sample's density, e.g.
   Salot, Gotteland & Villard 2009, Granular Matter 11:221), until the kinetic energy per particle
   falls below a threshold (default: that of the mean particle moving at 5 mm/s).
3. *Level*: remove every sphere whose centre lies above the target height, then settle again.
4. *Measure*: surface height (mean over d_max-wide columns of the highest sphere top) and the bulk
   packing fraction in a core region one d_max away from the walls, floor and surface.

The result is cached under a key made from every parameter that shapes the bed; preparing the same
bed again loads the file.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np

from wheelsoil.provenance import atomic_output, provenance

from . import runtime
from .bed_spec import BED_FORMAT_VERSION, BedSpec, check_memory, fill_lattice
from .contact_history import ContactHistory
from .errors import SimulationUnstableError, WheelsoilInputError
from .ordering import column_order
from .scene import Scene


class BedNotSettledError(SimulationUnstableError):
    """The bed did not come to rest within the allowed simulated time."""


@dataclass
class Bed:
    """A prepared soil bed: settled sphere state plus what was measured about it."""

    spec: BedSpec
    positions: np.ndarray
    radii: np.ndarray
    velocities: np.ndarray
    angular_velocities: np.ndarray
    surface_height: float
    packing_fraction: float
    settle_time: float
    meta: dict = field(default_factory=dict)
    #: The settled bed's contact history (:meth:`Scene.contact_history`, renumbered to the bed's order); None for
    #: beds of format 2.
    history: ContactHistory | None = None
    #: (W, 2, 3) the point and normal [m, -] of each wall the history's wall columns belong to.
    wall_planes: np.ndarray | None = None

    @property
    def n_particles(self) -> int:
        return int(self.radii.shape[0])

    def summary(self) -> str:
        s = self.spec
        g = s.gravity_magnitude
        return (
            f"{'periodic ' if s.periodic else ''}bed {s.length:g} x {s.width:g} m, {self.n_particles} particles of {1e3 * s.diameter_min:g}-"
            f"{1e3 * s.diameter_max:g} mm at g = {g:.3g} m/s^2: surface {self.surface_height:.4f} m "
            f"(target {s.depth:g} m), packing fraction {self.packing_fraction:.3f}, "
            f"settled in {self.settle_time:.2f} s simulated"
        )

    # ---------------------------------------------------------------- persistence
    def save(self, path: str | Path) -> Path:
        """Write the bed to HDF5 atomically; returns the path."""
        path = Path(path)
        with atomic_output(path) as tmp, h5py.File(tmp, "w") as f:
            grp = f.create_group("particles")
            grp.create_dataset("position", data=self.positions).attrs["units"] = "m"
            grp.create_dataset("velocity", data=self.velocities).attrs["units"] = "m/s"
            grp.create_dataset("angular_velocity", data=self.angular_velocities).attrs["units"] = "rad/s"
            grp.create_dataset("radius", data=self.radii).attrs["units"] = "m"
            if self.history is not None:
                hist = f.create_group("contacts")
                for key, value in self.history.to_arrays().items():
                    hist.create_dataset(key, data=value)
                hist.create_dataset("wall_point", data=self.wall_planes[:, 0])
                hist.create_dataset("wall_normal", data=self.wall_planes[:, 1])
            f.attrs["kind"] = "wheelsoil soil bed"
            f.attrs["bed_format"] = BED_FORMAT_VERSION
            f.attrs["spec"] = json.dumps(self.spec.to_dict(), sort_keys=True)
            f.attrs["cache_key"] = self.spec.cache_key()
            f.attrs["surface_height"] = self.surface_height
            f.attrs["packing_fraction"] = self.packing_fraction
            f.attrs["settle_time"] = self.settle_time
            f.attrs["seed"] = self.spec.seed
            for k, v in {**provenance(), **self.meta}.items():
                f.attrs[k] = v
        return path

    @classmethod
    def load(cls, path: str | Path) -> Bed:
        """Read a bed written by :meth:`save`."""
        path = Path(path)
        if not path.is_file():
            raise WheelsoilInputError(f"bed file {str(path)!r} does not exist")
        with h5py.File(path, "r") as f:
            if f.attrs.get("kind") != "wheelsoil soil bed":
                raise WheelsoilInputError(f"{str(path)!r} is not a wheelsoil soil-bed file")
            p = f["particles"]
            meta = {k: (v.item() if hasattr(v, "item") else v) for k, v in f.attrs.items()}
            arrays = {k: f["contacts"][k][()] for k in f["contacts"]} if "contacts" in f else None
            return cls(
                spec=BedSpec.from_dict(json.loads(f.attrs["spec"])),
                positions=p["position"][...],
                radii=p["radius"][...],
                velocities=p["velocity"][...],
                angular_velocities=p["angular_velocity"][...],
                surface_height=float(f.attrs["surface_height"]),
                packing_fraction=float(f.attrs["packing_fraction"]),
                settle_time=float(f.attrs["settle_time"]),
                meta={k: meta[k] for k in ("version", "git_rev", "taichi_version", "arch", "created") if k in meta},
                history=None if arrays is None else ContactHistory.from_arrays(arrays),
                wall_planes=None if arrays is None else np.stack([arrays["wall_point"], arrays["wall_normal"]], axis=1),
            )

    def to_scene(self, *, headroom: float | None = None, arch: str | None = None, periodic_x: bool | None = None,
                 end_walls: bool = True, **scene_kwargs) -> Scene:
        """A :class:`Scene` holding this bed in its bin (floor and four side walls; a periodic bed: floor and
        side walls, periodic along x).

        ``headroom`` [m] extends the domain above the surface (default: the bed depth, at least
        0.1 m). ``periodic_x=False`` puts a periodic bed in a bin that is not periodic; ``end_walls=False``
        leaves out the walls at its two ends (a moving soil patch holds the spheres there instead,
        ``wheelsoil.coupling.patch``).
        The scene starts with the bed's contact history (a bed of format 3): pairs and the walls the two bins
        share (floor and side walls; a pair across a periodic end that the end walls separate is dropped).
        """
        s = self.spec
        top = self.surface_height + (headroom if headroom is not None else max(s.depth, 0.1))
        periodic = s.periodic if periodic_x is None else bool(periodic_x) and s.periodic
        scene = Scene(
            (0.0, 0.0, 0.0), (s.length, s.width, top),
            gravity=s.gravity, material=s.material, pair=s.pair, arch=arch, periodic_x=periodic, **scene_kwargs,
        )
        if end_walls or periodic:
            scene.add_box_walls(material=s.wall_material, pair=s.wall_pair)
        else:
            scene.open_ends_x = True
            lo, hi = scene.domain_min, scene.domain_max
            for point, normal in ((lo, (0, 0, 1)), (lo, (0, 1, 0)), (hi, (0, -1, 0))):
                scene.add_wall(point, normal, material=s.wall_material, pair=s.wall_pair)
        x = self.positions
        if s.periodic:  # the stored centres may lie a hair outside the period
            x = x.copy()
            x[:, 0] = np.mod(x[:, 0], s.length)
        scene.add_spheres(x, self.radii, self.velocities, self.angular_velocities,
                          **self.wall_history_for(scene, np.arange(self.n_particles)))
        self.set_pair_history(scene)
        if s.time_step is not None:
            scene.time_step = s.time_step
        return scene


    def set_pair_history(self, scene: Scene) -> None:
        """Give ``scene``'s spheres (this bed's, in its order) the bed's pair contact history."""
        h = self.history
        if h is not None and h.n_pairs:
            scene.set_contact_history(h.pair_i, h.pair_j, h.pair_xi, h.pair_roll)

    def wall_history_for(self, scene: Scene, spheres: np.ndarray) -> dict:
        """The wall contacts of the bed's ``spheres`` in the columns of ``scene``'s walls (matched by point and
        normal; zero for a wall the bed had not), as :meth:`Scene.add_spheres` takes them (empty without a
        history)."""
        h = self.history
        if h is None:
            return {}
        out = {"wall_history": np.zeros((len(spheres), len(scene.walls), 3))}
        out["wall_roll_history"] = out["wall_history"].copy()
        for k, wall in enumerate(scene.walls):
            for b, (point, normal) in enumerate(self.wall_planes):
                if np.allclose(normal, wall.normal) and abs(np.dot(np.asarray(wall.point) - point, normal)) < 1e-12:
                    out["wall_history"][:, k] = h.xi_wall[spheres, b]
                    out["wall_roll_history"][:, k] = h.roll_wall[spheres, b]
        return out


# ---------------------------------------------------------------------- preparation
def initial_packing(spec: BedSpec) -> tuple[np.ndarray, np.ndarray, float]:
    """Jittered loose lattice of spheres filling the bin; returns positions, radii, fill-top height."""
    rng = np.random.default_rng(spec.seed)
    r_max = 0.5 * spec.diameter_max
    nx, ny, layers, spacing_x, spacing = fill_lattice(spec)
    ix, iy, iz = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(layers), indexing="ij")
    # centre the lattice in the bin
    x0 = 0.5 * (spec.length - (nx - 1) * spacing_x)
    y0 = 0.5 * (spec.width - (ny - 1) * spacing)
    pos = np.stack([x0 + ix * spacing_x, y0 + iy * spacing, r_max * 1.05 + iz * spacing], -1).reshape(-1, 3)
    # column by column (memory locality for the force pass; see .ordering)
    pos = pos[column_order(pos, spacing)]
    diam = rng.uniform(spec.diameter_min, spec.diameter_max, len(pos))
    slack = 0.5 * (spacing - diam)[:, None] * 0.9
    pos = pos + rng.uniform(-1.0, 1.0, pos.shape) * slack
    return pos, 0.5 * diam, float(pos[:, 2].max() + r_max)


def measure_surface(positions: np.ndarray, radii: np.ndarray, spec: BedSpec) -> float:
    """Mean over d_max-wide columns (away from the walls) of the highest sphere top [m]."""
    d = spec.diameter_max
    margin_x = 0.0 if spec.periodic else d  # a periodic bin has no end walls
    nx = max(1, int((spec.length - 2 * margin_x) // d))
    ny = max(1, int((spec.width - 2 * d) // d))
    ix = np.floor((positions[:, 0] - margin_x) / d).astype(int)
    iy = np.floor((positions[:, 1] - d) / d).astype(int)
    inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    tops = np.full(nx * ny, -np.inf)
    np.maximum.at(tops, ix[inside] * ny + iy[inside], (positions[:, 2] + radii)[inside])
    tops = tops[np.isfinite(tops)]
    return float(tops.mean()) if tops.size else float((positions[:, 2] + radii).max())


def measure_packing_fraction(positions: np.ndarray, radii: np.ndarray, spec: BedSpec, surface: float) -> float:
    """Solid volume fraction in the core region [d_max, L - d_max] x [d_max, W - d_max] x [d_max, surface - d_max].

    Spheres whose centres lie inside the region's horizontal extent count with their exact volume
    between the region's bottom and top (a sphere cut by two planes: pi [r^2 u - u^3 / 3] between
    the planes' heights u relative to the centre), so the estimate stays unbiased and smooth even
    when the region is only a diameter or so tall, as in small test beds.
    """
    d = spec.diameter_max
    margin_x = 0.0 if spec.periodic else d  # a periodic bin has no end walls
    lo = np.array([margin_x, d, d])
    hi = np.array([spec.length - margin_x, spec.width - d, surface - d])
    if np.any(hi <= lo):
        lo, hi = np.zeros(3), np.array([spec.length, spec.width, surface])
    inside = np.all((positions[:, :2] >= lo[:2]) & (positions[:, :2] <= hi[:2]), axis=1)
    r = radii[inside]
    z = positions[inside, 2]
    u_lo = np.clip(lo[2] - z, -r, r)
    u_hi = np.clip(hi[2] - z, -r, r)
    volume = np.pi * ((r**2 * u_hi - u_hi**3 / 3.0) - (r**2 * u_lo - u_lo**3 / 3.0))
    return float(np.sum(volume) / np.prod(hi - lo))


def settle(scene: Scene, spec: BedSpec, *, label: str, min_time: float = 0.0, progress=None) -> float:
    """Step until the kinetic energy per particle is below ``spec.settle_threshold``; return the time taken."""
    threshold = spec.settle_threshold
    start = scene.time
    chunk = max(1, int(round(0.01 / scene.time_step)))  # check every 10 ms of simulated time
    task = progress.add_task(label, total=None) if progress is not None else None
    while True:
        scene.step(chunk)
        health = scene.check_health()
        per_particle = health["kinetic_energy"] / scene.n_particles
        elapsed = scene.time - start
        if progress is not None:
            progress.update(
                task, description=f"{label}: t = {elapsed:.2f} s, KE/particle = {per_particle:.2e} J "
                f"(target {threshold:.1e} J)"
            )
        if per_particle < threshold and elapsed >= min_time:
            break
        if elapsed > spec.max_settle_time:
            raise BedNotSettledError(
                f"{label}: the bed did not settle within max_settle_time = {spec.max_settle_time} s "
                f"(kinetic energy per particle {per_particle:.3e} J, threshold {threshold:.3e} J); "
                "raise max_settle_time or kinetic_energy_threshold"
            )
    if progress is not None:
        progress.remove_task(task)
    return scene.time - start


def default_bed_cache() -> Path:
    return runtime.default_cache_dir() / "beds"


def bed_cache_path(spec: BedSpec, cache_dir: str | Path | None = None) -> Path:
    folder = Path(cache_dir) if cache_dir is not None else default_bed_cache()
    return folder / f"bed-{spec.cache_key()[:20]}.h5"


def prepare_bed(
    spec: BedSpec | None = None,
    *,
    cache_dir: str | Path | None = None,
    use_cache: bool = True,
    progress: bool = False,
    arch: str | None = None,
) -> Bed:
    """Prepare (or load from the cache) the soil bed described by ``spec``.

    Returns a :class:`Bed`; ``bed.meta["cache_path"]`` is the cached file, ``bed.meta["from_cache"]``
    tells whether it was reused.
    """
    spec = spec or BedSpec()
    path = bed_cache_path(spec, cache_dir)
    if use_cache and path.is_file():
        bed = Bed.load(path)
        bed.meta.update(cache_path=str(path), from_cache=True)
        return bed

    check_memory(spec)
    runtime.init(arch)
    wall_clock = time.perf_counter()
    positions, radii, fill_top = initial_packing(spec)
    scene = Scene(
        (0.0, 0.0, 0.0),
        (spec.length, spec.width, max(fill_top, spec.depth) + spec.diameter_max * 2),
        gravity=spec.gravity, material=spec.material, pair=spec.pour_pair(spec.pair), arch=arch,
        impact_speed=max(1.0, math.sqrt(2 * spec.gravity_magnitude * fill_top)), periodic_x=spec.periodic,
    )
    scene.add_box_walls(material=spec.wall_material, pair=spec.pour_pair(spec.wall_pair))
    scene.add_spheres(positions, radii)
    if spec.time_step is not None:
        scene.time_step = spec.time_step
    fall_time = math.sqrt(2.0 * fill_top / spec.gravity_magnitude)

    bar = None
    if progress:
        from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

        bar = Progress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(), transient=True)
        bar.start()
    try:
        t_settle = settle(scene, spec, label="settling", min_time=fall_time, progress=bar)
        x = scene.positions
        filled = measure_surface(x, scene.radii, spec)
        if filled < spec.depth:
            raise WheelsoilInputError(
                f"the settled fill reaches only {filled:.4f} m, below the target depth {spec.depth} m; "
                f"raise overfill (now {spec.overfill})"
            )
        scene.keep_spheres(x[:, 2] <= spec.depth)
        t_level = settle(scene, spec, label="levelled, re-settling", progress=bar)
    finally:
        if bar is not None:
            bar.stop()
    # Settling moves spheres by less than a diameter, so they stay nearly in column order: sort them
    # exactly into the columns of the settled positions.
    order = column_order(scene.positions, spec.diameter_max)
    x, r = scene.positions[order], scene.radii[order]
    if spec.periodic:
        x[:, 0] = np.mod(x[:, 0], spec.length)
    surface = measure_surface(x, r, spec)
    bed = Bed(
        spec=spec,
        positions=x,
        radii=r,
        velocities=scene.velocities[order],
        angular_velocities=scene.angular_velocities[order],
        surface_height=surface,
        packing_fraction=measure_packing_fraction(x, r, spec, surface),
        settle_time=t_settle + t_level,
        meta={"prepare_seconds": time.perf_counter() - wall_clock, "time_step": scene.time_step},
        history=scene.contact_history().in_order(order),
        wall_planes=np.array([[w.point, w.normal] for w in scene.walls], float).reshape(-1, 2, 3),
    )
    if use_cache:
        bed.save(path)
    bed.meta.update(cache_path=str(path) if use_cache else "", from_cache=False)
    return bed


def load_bed(path: str | Path) -> Bed:
    """Read a bed HDF5 file (see :meth:`Bed.save`)."""
    return Bed.load(path)
