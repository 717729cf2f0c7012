"""The single-wheel testbed: what a terramechanics rig does, on a prepared DEM bed.

Rig kinematics (architecture conventions; seed 004 eqs. 14--16):

* wheel frame: x along the heading, y along the axle, z up; the carriage travels along the bin's +X;
  the wheel is yawed by -beta so that the steering (slip) angle beta lies between heading and travel;
* slip by the measured rigs' convention (architecture; :func:`.kinematics.longitudinal_slip`): driving,
  i = 1 - v_x / (r omega); braking, i = r omega / v_x - 1, so -1 is a wheel dragged without turning. With
  the rig's reference spin omega_0 (``angular_velocity``) the hub spins at omega_0 and the carriage travels
  at v_x = (1 - i) r omega_0 along the heading when driving; when braking the carriage travels at the
  free-rolling v_x = r omega_0 and the hub spins at (1 + i) omega_0 (:func:`.kinematics.rig_command`);
  v_y = v_x tan(beta) across the heading (global speed v_x / cos beta): i and beta are the *commanded* slip
  and slip angle, those of the hub;
* the axle is free vertically under the constant load W: the rig applies W - m g downwards at the hub
  so the total load on the soil is W at any gravity (m: wheel mass including the hub), and a viscous
  damper on the vertical slide (``axle_damping``) keeps the wheel's heave from ringing.

A flexible wheel winds up under torque: the tread lags the hub by a twist that grows with the torque,
and while it grows the tread turns slower than the hub, so the slip the soil sees -- the **tread slip**,
from the tread's own measured rotation (:mod:`.kinematics`) -- is lower than the commanded one. Every
sample records both. A true steady state has the tread turning at the hub's rate again.

Protocol:

1. *lower*: the wheel, its lowest point just above the highest sphere beneath it, is lowered at
   ``lowering_speed`` until the soil carries the load W;
2. *settle*: the axle is released (free vertically under W) and the wheel rests for ``settle_time``;
3. *spin-up*: omega and the carriage speed ramp up together over ``spin_up_time``;
4. *wind-up* (``windup="controller"``): the carriage keeps its speed while the hub's spin follows
   omega_h = omega + K (omega - omega_t) (K = ``windup_gain``, omega_t the tread's spin, filtered over
   ``windup_filter``; omega_h held within omega (1 +- 0.5)), which winds the wheel up to the twist the
   torque needs K + 1 times faster than the constant spin would (the wind-up is a first-order lag of
   time constant c / k_t, c the soil's d torque / d omega_t and k_t the wheel's torsional stiffness;
   with the feedback it is c / ((K + 1) k_t)). It ends when the tread's spin over the last pitch is
   within ``slip_tolerance`` / 3 (in slip) of the commanded one; ``windup="none"``: no wind-up phase;
5. *drive*: the hub spins at exactly omega -- the rig's command -- and the run goes on until a steady
   window of at least ``average_time`` is found at ``steady_checks`` checks in a row, one pitch apart
   (:mod:`.steady`: whole pitches of the tread's rotation; forces, torque, sinkage and tread slip without
   drift; tread slip within ``slip_tolerance`` of the commanded slip), or until ``drive_time`` has passed
   since the spin-up ended (then the summary says the run is not steady, and why). ``stop_when_steady=False``
   drives the whole ``drive_time``.

Every sample also records the wheel's vertical force balance (:mod:`.force_balance`): the soil's vertical force as
the wheel's sub-steps applied it, the rig's load, the slide's damper and reaction, the structural damping's resultant,
the weight, the momentum's rate and the residual of their sum (round-off when the record misses no force).

Measured quantities (wheel frame, from the contact resultant, time-averaged over each sample interval):
drawbar pull DP = F.x (net soil force along the heading), lateral force F.y, vertical force F.z,
driving torque T = -M.y (the torque the motor supplies against the soil's moment about the axle),
sinkage = surface height + r - hub height (hub drop below where the undeformed tread touches the
levelled surface; it includes the wheel's deflection), tread sinkage = surface height - lowest point of
the tread's mid-surface (the depth of the rut the tread presses, without the deflection; grousers reach
deeper), the commanded slip and slip angle from the hub's velocity and spin, and the tread's wind-up,
spin, slip and slip angle.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError
from wheelsoil.flexwheel.geometry import WheelGeometry, build_wheel_mesh
from wheelsoil.flexwheel.structure import Structure
from wheelsoil.granular.bed import Bed

from .contact import WheelContact
from .coupled_state import restore_coupled_state, take_coupled_state
from .force_balance import BALANCE_UNITS, balance_row
from .kinematics import TreadTracker, deformation, rig_command, yaw_matrix
from .patch import MovingPatch
from .placement import wheel_start_centre
from .protocol import advance, protocol_for, running_step
from .protocol_state import ProtocolState
from .rig import (AXLE_DAMPING_TIME, RigPlan, TestbedSpec, batch_rate, batches_per_period, carriage_speed, plan_rig,
                  soil_headroom, stage_spec, statistics_pitch)
from .run_progress import RunProgress
from .run_statistics import detect_from_rows
from .run_summary import SERIES_UNITS
from .sample_row import sample_row
from .steady import SteadyState
from .testbed_result import TestbedResult, testbed_result


class Testbed:
    """A wheel on a prepared bed, driven by the rig.

    Parameters
    ----------
    bed: a prepared :class:`~wheelsoil.granular.Bed` or the path of a bed HDF5 file; it was prepared
        under the gravity the test runs at. A periodic bed (``BedSpec.periodic``) makes a moving soil patch.
    wheel: the wheel geometry (e.g. ``flexwheel.geometry.LUNAR_ROVER.with_element_size(0.05)``).
    spec: the rig settings (:class:`TestbedSpec`).
    arch: Taichi backend.
    plan: instead of ``wheel`` and ``spec``, a rig already checked for this bed (:func:`~.rig.plan_rig`; a case's
        run plan carries one), so the fit checks run once.
    """

    __test__ = False

    def __init__(self, bed: Bed | str | Path, wheel: WheelGeometry | None = None, spec: TestbedSpec | None = None, *,
                 arch: str | None = None, plan: RigPlan | None = None) -> None:
        bed, plan = _bed_and_plan(bed, wheel, spec, plan)
        wheel, spec = plan.wheel, plan.test
        self.bed, self.wheel, self.spec = bed, wheel, spec
        bs = bed.spec
        beta = math.radians(spec.slip_angle)
        outer = wheel.radius + (wheel.grouser_height if wheel.grouser_count else 0.0)
        self.outer_radius = outer
        self.gravity = -float(bs.gravity[2])
        self.enter_stage(0)
        self.periodic = bool(bs.periodic)
        start_x = plan.start_x
        if self.periodic:
            self.patch = MovingPatch(bed, wheel_reach=outer, shift=spec.patch_shift or 0.2 * wheel.radius)
            self.patch.check_start(start_x)
        else:
            self.patch = None
        self.start_x = start_x

        # ---- the wheel, yawed by -beta and placed just above the surface
        mesh, hub_nodes = build_wheel_mesh(wheel)
        self.yaw = yaw_matrix(-beta)
        nodes = mesh.nodes @ self.yaw.T
        center = wheel_start_centre(nodes, bed.positions, bed.radii, start_x, bs.width, bs.diameter_max,
                                    bed.surface_height, gap=0.25 * bs.diameter_min)
        mesh.nodes = nodes + center
        self.mesh = mesh
        tread = mesh.part_names.index("tread") if "tread" in mesh.part_names else None
        facets = mesh.triangles if tread is None else mesh.triangles[mesh.part[: len(mesh.triangles)] == tread]
        #: the tread's nodes (the tread part's, or every surface node of a wheel without one)
        self.tread_nodes = np.unique(facets)
        self.structure = Structure(mesh, hub_nodes=hub_nodes, hub_center=center, hub_mass=wheel.hub_mass,
                                   rigid=spec.rigid, damping=spec.damping, gravity=bs.gravity, arch=arch)
        self.wheel_mass = float(self.structure.mass.sum() + wheel.hub_mass)
        self.axle_damping = spec.axle_damping if spec.axle_damping is not None else self.wheel_mass / AXLE_DAMPING_TIME
        self._slide_damper = 0.0  # the damper's force in the sample being taken [N]
        #: the wheel's weight [N] (3-vector), as its integrator applies it (the force balance's G)
        self.weight = self.structure.gravity_force()
        self.heading = self.yaw[:, 0]
        self.axle = self.yaw[:, 1]
        self.tracker = TreadTracker(mesh.nodes[self.tread_nodes], self.heading, self.axle,
                                    weights=self.structure.mass[self.tread_nodes])
        self.pitch = statistics_pitch(wheel)  # the batch of the steady-state statistics [rad]
        self.period_pitches = batches_per_period(wheel)  # the wheel's whole period in batches

        # ---- the soil and the contact interface
        self.scene = bed.to_scene(headroom=soil_headroom(bs.depth, wheel), arch=arch, periodic_x=False, end_walls=self.patch is None)
        if self.patch is not None:
            self.patch.start(self.scene)
        self.contact = WheelContact(self.structure, bs.material, spec.pair)
        self.scene.add_interaction(self.contact)
        if spec.time_step is not None:
            # the run's own DEM step (the bed was prepared with its stable estimate, so a time-step study
            # tests the same bed)
            self.scene.time_step = spec.time_step
        self.dt = self.scene.time_step
        if spec.sample_interval < self.dt:
            raise WheelsoilInputError(f"output.sample_interval = {spec.sample_interval:.3g} s is shorter than the "
                                      f"run's DEM step {self.dt:.3g} s: a sample averages at least one step")
        self.steps_per_sample = max(1, int(round(spec.sample_interval / self.dt)))
        self.structure.drive_hub(velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0),
                                 free_translation=(False, False, False), free_rotation=(False, False, False))
        self._loop: ProtocolState | None = None
        self.rows: dict | None = None
        self.steady_state: SteadyState | None = None
        #: the rig's protocol, a list of steps (:mod:`.protocol`); the run's state is :attr:`protocol_state`
        self.protocol = protocol_for(spec.n_stages)

    def enter_stage(self, k: int) -> None:
        """Take stage ``k`` of the drive's settings (:func:`~.rig.stage_spec`) as the rig's command: what the
        protocol's steps, the steady-state detector and the summary read (:attr:`stage_spec`)."""
        s, radius = stage_spec(self.spec, k), self.wheel.radius
        #: the running stage's rig settings (the spec itself for the first stage)
        self.stage_spec = s
        # the hub's commanded spin [rad/s] and the carriage's speed along the bin [m/s] (kinematics.rig_command)
        self.spin_command, self.travel_speed = carriage_speed(s, radius)
        #: the commanded speed [m/s] the slip is taken against (spec.slip_speed: along the heading, or the travel)
        self.slip_reference_speed = rig_command(s.slip, s.angular_velocity, radius)[1]
        #: the rate [rad/s] at which the statistics' batches pass: the hub's spin, or for a dragged wheel (no
        #: spin) the angle it would roll through at its travel speed
        self.batch_rate = batch_rate(s.slip, s.angular_velocity, radius)

    # ------------------------------------------------------------------ the rig's commands
    @property
    def carriage_velocity(self) -> float:
        """The carriage's speed along the bin [m/s] at full spin (commanded slip and slip angle)."""
        return self.travel_speed

    def _command(self, hub_spin: float, carriage: float) -> None:
        """Spin the hub at ``hub_spin`` about the axle and move the carriage at ``carriage`` along the bin."""
        self.structure.drive_hub(velocity=(carriage, 0.0, 0.0), angular_velocity=hub_spin * self.axle)

    def release(self) -> None:
        """Free the axle vertically under the load W (the rig applies W - m g downwards)."""
        self.structure.set_hub_state(velocity=(0.0, 0.0, 0.0))
        self.structure.drive_hub(free_translation=(False, False, True))
        self._apply_load(0.0)

    def _apply_load(self, vertical_speed: float) -> None:
        """The rig's force on the released axle: W - m g down, and the damper against the vertical speed."""
        self._slide_damper = -self.axle_damping * vertical_speed
        push = -(self.spec.load - self.wheel_mass * self.gravity) + self._slide_damper
        self.structure.drive_hub(force=(0.0, 0.0, push))

    # ------------------------------------------------------------------ the run
    def run(self, *, progress: bool = False, on_sample=None) -> TestbedResult:
        """Run the protocol (lower, settle, spin up, wind up, drive); returns the series and the summary.

        ``on_sample(testbed)``, if given, is called after every sample (the rows so far are in
        :attr:`rows`); a run restored with :meth:`restore_state` continues where its checkpoint was taken.
        ``progress``: show a progress bar (rich) on the terminal.
        """
        if self._loop is None:
            self._start()
        if self._loop.phase == "done":
            raise WheelsoilInputError("this testbed has finished its run; build a new Testbed to run again")
        wall = time.perf_counter() - self._loop.wall
        bar = RunProgress(self) if progress else None
        try:
            while not self._sample():
                if bar is not None:
                    bar.update()
                if on_sample is not None:
                    self._loop.wall = time.perf_counter() - wall
                    on_sample(self)
        finally:
            if bar is not None:
                bar.stop()
        self.scene.check_health()
        self.structure.check_health()
        self._loop.phase = "done"
        return testbed_result(self, {k: np.asarray(v) for k, v in self.rows.items()}, time.perf_counter() - wall)

    def _start(self) -> None:
        s = self.spec
        self._loop = ProtocolState()
        self.rows = {k: [] for k in SERIES_UNITS}
        self.structure.drive_hub(velocity=(0.0, 0.0, -s.lowering_speed), free_translation=(False, False, False))
        self.contact.mean_resultant(reset=True)

    @property
    def protocol_state(self) -> ProtocolState | None:
        """Where the run's protocol stands (None before :meth:`run`)."""
        return self._loop

    @property
    def phase(self) -> str:
        """Where the protocol is: one of :data:`~.protocol_state.PHASES`."""
        return self._loop.phase if self._loop else "new"

    def _set_drive(self) -> None:
        """The hub's spin and the carriage's speed for the sample about to be taken, from the running step."""
        loop = self._loop
        command = self.protocol[running_step(self.protocol, loop)].command(self, loop, self.scene.time)
        if command is not None:
            loop.hub_spin = command[0]
            self._command(*command)

    def _sample(self) -> bool:
        """Advance one sample interval, record it and move the protocol on; True when the run is over."""
        s, loop, rows = self.spec, self._loop, self.rows
        self._set_drive()
        phase = loop.phase
        self._slide_damper = 0.0
        if phase != "lower" and self.axle_damping > 0.0:
            self._apply_load(float(self.structure.hub_velocity[2]))
        momentum = self.structure.linear_momentum()
        self.structure.reset_impulses()  # the force balance's accounts start with the interval
        self.scene.step(self.steps_per_sample)
        if self.patch is not None:
            self.patch.drop_thrown_out(self.scene)
        interval = self.steps_per_sample * self.dt
        loop.hub_angle += loop.hub_spin * interval
        row = sample_row(self, phase, interval)
        row.update(balance_row(self.structure.take_impulses(), self.structure.linear_momentum() - momentum,
                               self.structure.hub_applied_force, self._slide_damper, self.weight))
        for key, val in row.items():
            rows[key].append(float(val))
        if abs(row["wind_up"]) > s.max_wind_up:
            raise SimulationUnstableError(
                f"the wheel wound up by {math.degrees(row['wind_up']):.1f} deg at t = {row['t']:.3f} s, past "
                f"test.max_wind_up = {s.max_wind_up:g} rad ({math.degrees(s.max_wind_up):.0f} deg): the tread lags "
                f"the hub under {row['torque']:.0f} N m of torque (spokes buckling through?); a stiffer wheel, a "
                "lower load or slip, or a larger test.max_wind_up if the twist is real")
        if self.patch is not None and phase != "lower":
            loop.shift += self.patch.update(self)
        return advance(self.protocol, self, loop, row, self.scene.time)

    def detect(self) -> SteadyState:
        """The steady-state detector's verdict on the running stage's rows so far
        (:func:`~.run_statistics.detect_from_rows`)."""
        s = self.stage_spec
        return detect_from_rows(
            self.rows, slip=s.slip, load=s.load, angular_velocity=s.angular_velocity, average_time=s.average_time,
            steady_tolerance=s.steady_tolerance, slip_tolerance=s.slip_tolerance, radius=self.wheel.radius,
            pitch=self.pitch, mean_diameter=0.5 * (self.bed.spec.diameter_min + self.bed.spec.diameter_max),
            sample_interval=self.steps_per_sample * self.dt, start=self._loop.t_average_from,
            period_pitches=self.period_pitches, drift_confidence=s.steady_drift_confidence)

    # ------------------------------------------------------------------ checkpoints
    def state(self) -> dict:
        """The whole state of a run between two samples: NumPy arrays and scalars, enough to continue it.

        Taking a state also puts the soil in a canonical form (its arrays go back to the host and the
        neighbour lists are rebuilt at the next step; the wheel contact rebuilds its candidates), so a
        run continued from a restored state steps exactly as the run that took the state does.
        """
        if self._loop is None or self._loop.phase == "done":
            raise WheelsoilInputError("a testbed state can only be taken during a run (from on_sample)")
        state = take_coupled_state(self.scene, self.structure, self.contact)
        state["testbed"] = {"loop": self._loop.to_dict(), "rows": {k: np.asarray(v, float) for k, v in self.rows.items()}}
        if self.patch is not None:
            state["patch"] = self.patch.state()
        return state

    def restore_state(self, state: dict) -> None:
        """Continue from a :meth:`state` of a run of the same bed, wheel and rig settings."""
        rows = checkpoint_rows(state["testbed"]["rows"])
        restore_coupled_state(state, self.scene, self.structure, self.contact, same_spheres=self.patch is None)
        if self.patch is not None:
            self.patch.restore_state(state["patch"])
        self._loop = ProtocolState.from_dict(state["testbed"]["loop"])
        self.enter_stage(self._loop.stage)
        self.rows = {k: [float(v) for v in np.asarray(rows[k])] for k in SERIES_UNITS}

    def deformation(self, nodes: np.ndarray | None = None) -> np.ndarray:
        """The wheel's deformation [m] (N, 3): node positions less the wheel's best-fit rigid motion from its
        start pose, the fit weighted by the nodes' lumped masses (:func:`.kinematics.deformation`)."""
        nodes = self.structure.positions() if nodes is None else nodes
        weights = np.maximum(self.structure.mass, 0.0)
        weights[self.structure.hub_nodes] += self.wheel.hub_mass / max(len(self.structure.hub_nodes), 1)
        return deformation(nodes, self.mesh.nodes, weights)


def checkpoint_rows(rows: dict) -> dict:
    """A checkpoint's series as this testbed records them (:data:`~.run_summary.SERIES_UNITS`): a checkpoint taken
    before the force balance was recorded (:data:`~.force_balance.BALANCE_UNITS`) has those columns NaN for its
    samples; any other difference is refused."""
    rows = {k: np.asarray(v, float) for k, v in rows.items()}
    if set(rows) - set(SERIES_UNITS) or set(SERIES_UNITS) - set(rows) - set(BALANCE_UNITS):
        raise WheelsoilInputError(f"checkpoint series {sorted(rows)} do not match this testbed's "
                                  f"{sorted(SERIES_UNITS)}")
    for k in set(BALANCE_UNITS) - set(rows):
        rows[k] = np.full(len(rows["t"]), np.nan)
    return rows


def _bed_and_plan(bed: Bed | str | Path, wheel: WheelGeometry | None, spec: TestbedSpec | None,
                  plan: RigPlan | None) -> tuple[Bed, RigPlan]:
    """The bed (loaded where a file is given) and the rig's checked plan: ``plan`` as given, on the bed it was made
    for, or planned here from ``wheel`` and ``spec`` (default :class:`~.rig.TestbedSpec`)."""
    if isinstance(bed, (str, Path)):
        if not Path(bed).is_file():
            raise WheelsoilInputError(f"bed file {str(bed)!r} does not exist; prepare it with 'wheelsoil prepare-bed'")
        bed = Bed.load(bed)
    if not isinstance(bed, Bed):
        raise WheelsoilInputError(f"bed must be a Bed or a bed file path, got {type(bed).__name__}")
    if plan is not None:  # checked already (plan_rig): the plan's wheel and rig, on the bed it was made for
        if wheel is not None or spec is not None:
            raise WheelsoilInputError("give the testbed either a plan or a wheel and spec, not both")
        if plan.bed != bed.spec:
            raise WheelsoilInputError("the bed is not the one the plan was made for: prepare the plan's bed "
                                      "(prepare_bed(plan.bed)) or plan for this one (plan_rig(bed.spec, ...))")
        return bed, plan
    if not isinstance(wheel, WheelGeometry):
        raise WheelsoilInputError(f"wheel must be a WheelGeometry, got {type(wheel).__name__}")
    return bed, plan_rig(bed.spec, wheel, spec or TestbedSpec())
