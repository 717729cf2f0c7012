"""The single-wheel testbed: what a terramechanics rig does, on a prepared DEM bed.

Rig kinematics (architecture conventions; seed 004 eqs. 14--16):

* wheel frame: x along the heading, y along the axle, z up; the carriage travels along the bin's +X;
  the wheel is yawed by -beta so that the steering (slip) angle beta lies between heading and travel;
* prescribed wheel spin omega about the axle; travel speed from the commanded slip,
  v_x = (1 - i) r omega along the heading and v_y = v_x tan(beta) across it (global speed v_x / cos beta);
* the axle is free vertically under the constant load W: the rig applies W - m g downwards at the hub
  so the total load on the soil is W at any gravity (m: wheel mass including the hub), and a viscous
  damper on the vertical slide (``axle_damping``) keeps the wheel's heave from ringing.

Protocol: place the wheel with its lowest point just above the highest sphere beneath it; lower it at
``lowering_speed`` until the soil carries the load W, then release the axle (free vertically under W)
and let it settle (``settle_time``); spin up to omega and drive (``drive_time``); detect the steady
state and average over it.

Measured quantities (wheel frame, from the contact resultant, time-averaged over each sample interval):
drawbar pull DP = F.x (net soil force along the heading), lateral force F.y, vertical force F.z,
driving torque T = -M.y (the torque the motor supplies against the soil's moment about the axle),
sinkage = surface height + r - hub height (hub drop below where the undeformed tread touches the
levelled surface; it includes the wheel's deflection), tread sinkage = surface height - lowest point of
the tread's mid-surface (the depth of the rut the tread presses, without the deflection; grousers reach
deeper), achieved slip and slip angle from the hub's velocity.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError
from wheelsoil.flexwheel.geometry import WheelGeometry, build_wheel_mesh
from wheelsoil.flexwheel.mesh import StructureMesh
from wheelsoil.flexwheel.structure import Structure
from wheelsoil.granular.bed import Bed
from wheelsoil.granular.materials import SOIL_STEEL, PairProperties

from .contact import WheelContact

#: Series recorded at every sample, with units.
SERIES_UNITS = {
    "t": "s",
    "drawbar_pull": "N",
    "lateral_force": "N",
    "vertical_force": "N",
    "torque": "N m",
    "sinkage": "m",
    "tread_sinkage": "m",
    "slip": "1",
    "slip_angle": "deg",
    "load": "N",
    "omega": "rad/s",
    "hub_x": "m",
    "hub_y": "m",
    "hub_z": "m",
    "contacts": "1",
}
#: Quantities averaged over the steady state.
STEADY_QUANTITIES = ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage", "tread_sinkage", "slip",
                     "slip_angle")


def _check(key: str, value, ok: bool, allowed: str) -> None:
    if not ok:
        raise WheelsoilInputError(f"testbed {key} = {value!r} is out of range: allowed {allowed}")


@dataclass(frozen=True)
class TestbedSpec:
    """What the rig does (SI units, angles in degrees).

    slip: longitudinal slip i = 1 - v_x / (r omega), in [-1, 1) (negative: braking).
    slip_angle: steering angle beta between heading and travel [deg], in (-90, 90).
    load: vertical load W on the soil, wheel weight included [N], > 0.
    angular_velocity: wheel spin omega [rad/s], > 0 (seed 004: r omega = 0.6 m/s).
    lowering_speed: speed [m/s] at which the rig lowers the wheel onto the soil until the soil carries W.
    settle_time: time the wheel then rests, free vertically under W, before driving [s].
    spin_up_time: time over which omega (and the carriage speed) rise linearly [s].
    drive_time: time driven at constant omega [s].
    sample_interval: averaging interval of one sample of the time series [s].
    steady_window: shortest span [s] compared when detecting the steady state.
    steady_tolerance: relative change allowed between the two halves of the steady span.
    start_x: initial hub position along the bin [m] (default: one wheel radius plus 0.1 m from the start).
    rigid: use the rigid wheel with the same surface instead of the flexible one.
    damping: mass-proportional structural damping of the flexible wheel [1/s], relative to the hub.
    axle_damping: viscous damper on the rig's vertical slide [N s/m], acting on the hub's vertical speed
        once the axle is released (like the damper or heavy carriage of a real rig). It has no mean force
        in a steady state, so the load on the soil stays W, but it stops the wheel's heave on the soil's
        stiffness from ringing through the run; its force is updated every sample interval. None: wheel
        mass / 0.1 s (a free heave decays in 0.1 s; roughly 0.4 of critical damping for the smoke case's
        heave on the soil); 0: no damper.
    pair: soil--wheel contact properties (default seed 004 Table 1 soil--steel).
    """

    __test__ = False  # not a pytest class

    slip: float = 0.2
    slip_angle: float = 0.0
    load: float = 3000.0
    angular_velocity: float = 1.0
    lowering_speed: float = 0.3
    settle_time: float = 0.1
    spin_up_time: float = 0.05
    drive_time: float = 1.0
    sample_interval: float = 0.005
    steady_window: float = 0.15
    steady_tolerance: float = 0.15
    start_x: float | None = None
    rigid: bool = False
    damping: float = 10.0
    axle_damping: float | None = None
    pair: PairProperties = field(default_factory=lambda: SOIL_STEEL)

    def __post_init__(self) -> None:
        fin = lambda v: isinstance(v, (int, float)) and math.isfinite(v)  # noqa: E731
        _check("slip", self.slip, fin(self.slip) and -1.0 <= self.slip < 1.0, "-1 <= slip < 1")
        _check("slip_angle", self.slip_angle, fin(self.slip_angle) and -90.0 < self.slip_angle < 90.0,
               "-90 < slip_angle < 90 deg")
        _check("load", self.load, fin(self.load) and self.load > 0.0, "load > 0 N")
        _check("angular_velocity", self.angular_velocity, fin(self.angular_velocity) and self.angular_velocity > 0.0,
               "angular_velocity > 0 rad/s")
        for key in ("lowering_speed", "settle_time", "drive_time", "sample_interval", "steady_window",
                    "steady_tolerance"):
            v = getattr(self, key)
            _check(key, v, fin(v) and v > 0.0, f"{key} > 0")
        for key in ("spin_up_time", "damping"):
            v = getattr(self, key)
            _check(key, v, fin(v) and v >= 0.0, f"{key} >= 0")
        _check("spin_up_time", self.spin_up_time, self.spin_up_time < self.drive_time,
               f"spin_up_time < drive_time = {self.drive_time}")
        if self.axle_damping is not None:
            _check("axle_damping", self.axle_damping, fin(self.axle_damping) and self.axle_damping >= 0.0,
                   "axle_damping >= 0 N s/m, or None for wheel mass / 0.1 s")
        if self.start_x is not None:
            _check("start_x", self.start_x, fin(self.start_x) and self.start_x > 0.0, "start_x > 0 m")
        if not isinstance(self.pair, PairProperties):
            raise WheelsoilInputError(f"testbed pair must be a PairProperties, got {type(self.pair).__name__}")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["pair"] = self.pair.to_dict()
        return d


def yaw_matrix(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass
class TestbedResult:
    """Time series (NumPy arrays, units in :data:`SERIES_UNITS`) and the steady-state summary."""

    __test__ = False

    series: dict
    summary: dict
    spec: TestbedSpec
    wheel: WheelGeometry
    bed_summary: str
    info: dict = field(default_factory=dict)
    final_particles: dict = field(default_factory=dict)
    final_wheel_nodes: np.ndarray | None = None
    mesh: StructureMesh | None = None

    def steady(self, name: str) -> float:
        """Steady-state mean of a quantity (see :data:`STEADY_QUANTITIES`)."""
        return float(self.summary[name]["mean"])


def detect_steady_state(t: np.ndarray, values: dict, *, start: float, window: float, tolerance: float,
                        scales: dict) -> tuple[int, bool]:
    """First sample index from which every series in ``values`` is stationary.

    A span [t_k, t_end] (at least two ``window``s long, beginning at or after ``start``) is steady
    when, for every series, the means of its first and second halves differ by at most
    ``tolerance`` x max(|mean|, scale). Candidates are tried from ``start`` onwards in steps of half a
    window; returns (index, True) for the first steady span, or (index of the last half of the drive,
    False) when none is.
    """
    t = np.asarray(t)
    end = t[-1]
    candidates = np.arange(start, end - 2 * window + 1e-12, 0.5 * window)
    for t0 in candidates:
        k0 = int(np.searchsorted(t, t0))
        mid = k0 + (len(t) - k0) // 2
        ok = True
        for name, y in values.items():
            a, b = np.mean(y[k0:mid]), np.mean(y[mid:])
            scale = max(abs(np.mean(y[k0:])), scales.get(name, 0.0))
            if abs(a - b) > tolerance * scale:
                ok = False
                break
        if ok:
            return k0, True
    k_start = int(np.searchsorted(t, start))
    return k_start + (len(t) - k_start) // 2, False


class Testbed:
    """A wheel on a prepared bed, driven by the rig.

    Parameters
    ----------
    bed: a prepared :class:`~wheelsoil.granular.Bed` or the path of a bed HDF5 file; it was prepared
        under the gravity the test runs at.
    wheel: the wheel geometry (e.g. ``flexwheel.geometry.LUNAR_ROVER.with_element_size(0.05)``).
    spec: the rig settings (:class:`TestbedSpec`).
    arch: Taichi backend.
    """

    __test__ = False

    def __init__(self, bed: Bed | str | Path, wheel: WheelGeometry, spec: TestbedSpec | None = None, *,
                 arch: str | None = None) -> None:
        if isinstance(bed, (str, Path)):
            if not Path(bed).is_file():
                raise WheelsoilInputError(f"bed file {str(bed)!r} does not exist; prepare it with 'wheelsoil prepare-bed'")
            bed = Bed.load(bed)
        if not isinstance(bed, Bed):
            raise WheelsoilInputError(f"bed must be a Bed or a bed file path, got {type(bed).__name__}")
        if not isinstance(wheel, WheelGeometry):
            raise WheelsoilInputError(f"wheel must be a WheelGeometry, got {type(wheel).__name__}")
        spec = spec or TestbedSpec()
        self.bed, self.wheel, self.spec = bed, wheel, spec
        bs = bed.spec
        beta = math.radians(spec.slip_angle)
        outer = wheel.radius + (wheel.grouser_height if wheel.grouser_count else 0.0)
        # footprint across the bin: the width turned by beta plus a contact length of about one radius
        footprint = wheel.width * math.cos(beta) + wheel.radius * abs(math.sin(beta))
        if wheel.width >= bs.width or footprint >= bs.width - 2 * bs.diameter_max:
            raise WheelsoilInputError(
                f"wheel {wheel.name!r} (width {wheel.width} m, footprint {footprint:.3f} m across the bin at "
                f"slip_angle {spec.slip_angle} deg) does not fit the bed width {bs.width} m "
                f"(allowed footprint < {bs.width - 2 * bs.diameter_max:.3f} m)"
            )
        g = -float(bs.gravity[2])
        self.gravity = g
        v_x = (1.0 - spec.slip) * wheel.radius * spec.angular_velocity
        self.travel_speed = v_x / math.cos(beta)  # along the bin
        travel = abs(self.travel_speed) * spec.drive_time
        start_x = spec.start_x if spec.start_x is not None else outer + 0.1
        end_x = start_x + travel + outer
        if start_x - outer < 0 or end_x > bs.length:
            raise WheelsoilInputError(
                f"the bin (length {bs.length} m) is too short: the wheel (outer radius {outer:.3f} m) starts at "
                f"x = {start_x:.3f} m and travels {travel:.3f} m in drive_time = {spec.drive_time} s "
                f"at {self.travel_speed:.3f} m/s; shorten drive_time or use a longer bed"
            )

        # ---- the wheel, yawed by -beta and placed just above the surface
        mesh, hub_nodes = build_wheel_mesh(wheel)
        self.yaw = yaw_matrix(-beta)
        gap = 0.25 * bs.diameter_min
        nodes = mesh.nodes @ self.yaw.T
        center = np.array([start_x, 0.5 * bs.width, 0.0])
        # lowest point of the wheel just above the highest sphere beneath it (not the mean surface:
        # spheres stand proud of it by up to a radius, and a deep first overlap would kick the tread)
        lo, hi = (nodes + center)[:, :2].min(axis=0), (nodes + center)[:, :2].max(axis=0)
        below = np.all((bed.positions[:, :2] >= lo - bs.diameter_max) & (bed.positions[:, :2] <= hi + bs.diameter_max), axis=1)
        top = float(np.max(bed.positions[below, 2] + bed.radii[below])) if below.any() else bed.surface_height
        center[2] = top - nodes[:, 2].min() + gap
        mesh.nodes = nodes + center
        self.mesh = mesh
        tread = mesh.part_names.index("tread") if "tread" in mesh.part_names else None
        facets = mesh.triangles if tread is None else mesh.triangles[mesh.part[: len(mesh.triangles)] == tread]
        self._tread_nodes = np.unique(facets)
        self.structure = Structure(mesh, hub_nodes=hub_nodes, hub_center=center, hub_mass=wheel.hub_mass,
                                   rigid=spec.rigid, damping=spec.damping, gravity=bs.gravity, arch=arch)
        self.wheel_mass = float(self.structure.mass.sum() + wheel.hub_mass)
        self.axle_damping = spec.axle_damping if spec.axle_damping is not None else self.wheel_mass / 0.1
        self.heading = self.yaw[:, 0]
        self.axle = self.yaw[:, 1]

        # ---- the soil and the contact interface
        headroom = max(bs.depth, 0.25)
        self.scene = bed.to_scene(headroom=headroom, arch=arch)
        self.contact = WheelContact(self.structure, bs.material, spec.pair)
        self.scene.add_interaction(self.contact)
        self.dt = self.scene.time_step
        self.steps_per_sample = max(1, int(round(spec.sample_interval / self.dt)))
        self.structure.drive_hub(velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                                 free_translation=(False, False, False), free_rotation=(False, False, False))
        self._loop: dict | None = None
        self.rows: dict | None = None

    # ------------------------------------------------------------------ the run
    def _drive(self, omega: float) -> None:
        """Spin omega about the axle and the carriage speed that gives the commanded slip."""
        v = (1.0 - self.spec.slip) * self.wheel.radius * omega / math.cos(math.radians(self.spec.slip_angle))
        self.structure.drive_hub(velocity=(v, 0.0, 0.0), angular_velocity=omega * self.axle)

    def _release(self) -> None:
        """Free the axle vertically under the load W (the rig applies W - m g downwards)."""
        self.structure.set_hub_state(velocity=(0.0, 0.0, 0.0))
        self.structure.drive_hub(free_translation=(False, False, True))
        self._apply_load(0.0)

    def _apply_load(self, vertical_speed: float) -> None:
        """The rig's force on the released axle: W - m g down, and the damper against the vertical speed."""
        push = -(self.spec.load - self.wheel_mass * self.gravity) - self.axle_damping * vertical_speed
        self.structure.drive_hub(force=(0.0, 0.0, push))

    def run(self, *, progress: bool = False, on_sample=None) -> TestbedResult:
        """Run the protocol (lower, settle, drive); returns the time series and the steady-state summary.

        ``on_sample(testbed)``, if given, is called after every sample (the rows so far are in
        :attr:`rows`); a run restored with :meth:`restore_state` continues where its checkpoint was taken.
        """
        s = self.spec
        sample = self.steps_per_sample * self.dt
        if self._loop is None:
            self._loop = {"phase": "lower", "t_drive": math.inf, "t_settled": math.inf, "wall": 0.0}
            self.rows = {k: [] for k in SERIES_UNITS}
            self.structure.drive_hub(velocity=(0.0, 0.0, -s.lowering_speed), free_translation=(False, False, False))
            self.contact.mean_resultant(reset=True)
        loop, rows = self._loop, self.rows
        if loop["phase"] == "done":
            raise WheelsoilInputError("this testbed has finished its run; build a new Testbed to run again")
        surface = self.bed.surface_height
        max_sinkage = 0.5 * self.wheel.radius
        wall = time.perf_counter() - loop["wall"]
        bar = task = None
        if progress:
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

            bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                           TimeElapsedColumn(), TimeRemainingColumn(), transient=True)
            bar.start()
            total = None
            if loop["phase"] != "lower":
                total = int(math.ceil((loop["t_settled"] + s.drive_time - self.scene.time) / sample)) + len(rows["t"])
            task = bar.add_task("testbed", total=total, completed=len(rows["t"]))
        try:
            while True:
                phase = loop["phase"]
                t = self.scene.time
                if phase == "drive":
                    ramp = min(1.0, (t - loop["t_drive"]) / s.spin_up_time) if s.spin_up_time > 0 else 1.0
                    self._drive(s.angular_velocity * ramp)
                if phase != "lower" and self.axle_damping > 0.0:
                    self._apply_load(float(self.structure.hub_velocity[2]))
                self.scene.step(self.steps_per_sample)
                force, moment, _ = self.contact.mean_resultant(reset=True)
                hub = self.structure.hub_position
                vel = self.structure.hub_velocity
                vx, vy = float(vel @ self.heading), float(vel @ self.axle)
                spin = self.structure.hub_angular_velocity @ self.axle
                row = {
                    "t": self.scene.time,
                    "drawbar_pull": force @ self.heading,
                    "lateral_force": force @ self.axle,
                    "vertical_force": force[2],
                    "torque": -(moment @ self.axle),
                    "sinkage": surface + self.wheel.radius - hub[2],
                    "tread_sinkage": surface - float(self.structure.positions()[self._tread_nodes, 2].min()),
                    "slip": 1.0 - vx / (self.wheel.radius * spin) if spin > 0 else 0.0,
                    "slip_angle": math.degrees(math.atan2(vy, vx)) if abs(vx) > 1e-12 else 0.0,
                    "load": s.load if phase != "lower" else 0.0,
                    "omega": spin,
                    "hub_x": hub[0], "hub_y": hub[1], "hub_z": hub[2],
                    "contacts": self.contact.contact_count,
                }
                for key, val in row.items():
                    rows[key].append(float(val))
                finished = False
                if phase == "lower":
                    if force[2] >= s.load:
                        self._release()
                        loop["phase"], loop["t_settled"] = "settle", self.scene.time + s.settle_time
                        if bar is not None:
                            bar.update(task, total=int(math.ceil((s.settle_time + s.drive_time) / sample)) + len(rows["t"]))
                    elif row["sinkage"] > max_sinkage:
                        raise SimulationUnstableError(
                            f"the bed does not carry the load {s.load} N: the wheel sank {row['sinkage']:.3f} m "
                            f"(more than half its radius) while lowered, with the soil carrying {force[2]:.1f} N"
                        )
                elif phase == "settle" and self.scene.time >= loop["t_settled"] - 1e-12:
                    loop["phase"], loop["t_drive"] = "drive", self.scene.time
                elif phase == "drive" and self.scene.time >= loop["t_drive"] + s.drive_time - 1e-12:
                    finished = True
                if bar is not None:
                    bar.update(task, advance=1, description=(
                        f"{phase:6s} t = {self.scene.time:.3f} s  DP {row['drawbar_pull']:8.1f} N  "
                        f"Fz {row['vertical_force']:8.1f} N  sinkage {1e3 * row['sinkage']:6.1f} mm"))
                if finished:
                    break
                if on_sample is not None:
                    loop["wall"] = time.perf_counter() - wall
                    on_sample(self)
        finally:
            if bar is not None:
                bar.stop()
        self.scene.check_health()
        self.structure.check_health()
        loop["phase"] = "done"
        self.phase_times = {"released": loop["t_settled"] - s.settle_time, "drive_start": loop["t_drive"]}
        return self._result({k: np.asarray(v) for k, v in rows.items()}, time.perf_counter() - wall)

    # ------------------------------------------------------------------ checkpoints
    @property
    def samples_taken(self) -> int:
        return len(self.rows["t"]) if self.rows else 0

    @property
    def phase(self) -> str:
        """Where the protocol is: 'new', 'lower', 'settle', 'drive' or 'done'."""
        return self._loop["phase"] if self._loop else "new"

    def state(self) -> dict:
        """The whole state of a run between two samples: NumPy arrays and scalars, enough to continue it.

        Taking a state also puts the soil in a canonical form (its arrays go back to the host and the
        neighbour lists are rebuilt at the next step; the wheel contact rebuilds its candidates), so a
        run continued from a restored state steps exactly as the run that took the state does.
        """
        if self._loop is None or self._loop["phase"] == "done":
            raise WheelsoilInputError("a testbed state can only be taken during a run (from on_sample)")
        state = {"scene": self.scene.state(), "structure": self.structure.state(), "contact": self.contact.state()}
        self.contact.invalidate()
        loop = dict(self._loop)
        state["testbed"] = {"loop": loop, "rows": {k: np.asarray(v, float) for k, v in self.rows.items()}}
        return state

    def restore_state(self, state: dict) -> None:
        """Continue from a :meth:`state` of a run of the same bed, wheel and rig settings."""
        rows = state["testbed"]["rows"]
        if set(rows) != set(SERIES_UNITS):
            raise WheelsoilInputError(f"checkpoint series {sorted(rows)} do not match this testbed's {sorted(SERIES_UNITS)}")
        self.scene.restore_state(state["scene"])
        self.structure.restore_state(state["structure"])
        self.contact.restore_state(self.scene, state["contact"])
        self._loop = dict(state["testbed"]["loop"])
        self.rows = {k: [float(v) for v in np.asarray(rows[k])] for k in SERIES_UNITS}

    def _result(self, rows: dict, wall: float) -> TestbedResult:
        s = self.spec
        t = rows["t"]
        drive_start = self.phase_times["drive_start"] + s.spin_up_time
        d_mean = 0.5 * (self.bed.spec.diameter_min + self.bed.spec.diameter_max)
        k0, steady = detect_steady_state(
            t, {q: rows[q] for q in ("drawbar_pull", "vertical_force", "torque", "sinkage")},
            start=drive_start, window=s.steady_window, tolerance=s.steady_tolerance,
            scales={"drawbar_pull": 0.05 * s.load, "vertical_force": 0.05 * s.load,
                    "torque": 0.05 * s.load * self.wheel.radius, "sinkage": 0.5 * d_mean},
        )
        summary = {"window": [float(t[k0]), float(t[-1])], "steady": bool(steady), "samples": int(len(t) - k0)}
        for q in STEADY_QUANTITIES:
            y = rows[q][k0:]
            summary[q] = {"mean": float(np.mean(y)), "std": float(np.std(y)), "units": SERIES_UNITS[q]}
        particles = {"position": self.scene.positions, "velocity": self.scene.velocities, "radius": self.scene.radii}
        info = {
            "wall_seconds": wall,
            "simulated_seconds": float(t[-1]),
            "dem_steps": self.scene.steps_taken,
            "dem_time_step": self.dt,
            "fe_substeps": self.contact.structure_substeps,
            "fe_time_step": self.structure.stable_time_step,
            "particles": self.scene.n_particles,
            "fe_elements": int(self.mesh.n_elements),
            "contact_facets": int(self.contact.surface.n_facets),
            "wheel_mass": self.wheel_mass,
            "contact_rebuilds": self.contact.rebuilds,
            "seconds_per_simulated_second": wall / max(float(t[-1]), 1e-12),
            **{f"t_{k}": v for k, v in self.phase_times.items()},
        }
        return TestbedResult(series=rows, summary=summary, spec=s, wheel=self.wheel, bed_summary=self.bed.summary(),
                             info=info, final_particles=particles, final_wheel_nodes=self.structure.positions(),
                             mesh=self.mesh)
