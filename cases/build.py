"""From a validated case to the solver's specs: the one place where case keys become solver inputs.

A case (:class:`~wheelsoil.cases.case_model.CaseFile`) says what a user asked for, section by section; the solver
takes three specs, each of which checks its own ranges (:mod:`wheelsoil.ranges`) and defaults from the same
parameter set (:mod:`wheelsoil.parameters.smoke`):

* :func:`bed_spec` -- ``[soil]`` and ``case.seed`` -> :class:`~wheelsoil.granular.bed.BedSpec`;
* :func:`wheel_geometry` -- ``[wheel]`` over its preset -> :class:`~wheelsoil.flexwheel.geometry.WheelGeometry`;
* :func:`testbed_spec` -- ``[test]``, ``[contact]``, ``[output]``, ``[protocol]``, ``soil.time_step`` and the wheel's
  ``rigid``/``damping`` -> :class:`~wheelsoil.coupling.testbed.TestbedSpec`.

:func:`plan` builds the three once, runs the solver's cross-checks on them (particles against the bin and the
machine's memory, the wheel against the bin, the drive against a static bin: :func:`~wheelsoil.coupling.rig.check_fits`)
and adds the run's size (particles, elements, output bytes): the :class:`RunPlan` that
:func:`~wheelsoil.cases.run.run_case` hands to the bed's preparation and the testbed, so nothing downstream builds or
checks a spec again. The schema (:func:`~wheelsoil.cases.schema.validate_case`) makes a plan when it validates a case,
so those checks run before any work; it keeps the case, not the plan (a case is a plain value that sweeps copy and
change, and its plan is made again, in microseconds, where it runs).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from wheelsoil.coupling.rig import DriveStage, RigPlan, TestbedSpec, plan_rig
from wheelsoil.flexwheel.geometry import SpokeRow, WheelGeometry, estimated_elements, preset
from wheelsoil.granular.bed_spec import BedSpec, estimated_particles
from wheelsoil.material import Material, PairProperties
from wheelsoil.parameters import seed004, smoke

from .case_model import CaseFile
from .cost import longest_simulated_seconds

#: Wheel keys that replace the preset's value when given (None: keep the preset's).
WHEEL_KEYS = ("element_size", "radius", "width", "tread_thickness", "hub_radius", "spokes_per_row", "spoke_thickness",
              "spoke_bow", "spoke_model", "grouser_count", "grouser_height", "grouser_thickness", "grouser_angle",
              "hub_mass", "side_walls")


def bed_spec(case: CaseFile) -> BedSpec:
    """The soil bed of the case's ``[soil]`` section (and ``case.seed``)."""
    s = case.soil
    return BedSpec(
        length=s.length, width=s.width, depth=s.depth, diameter_min=s.diameter_min,
        diameter_max=s.diameter_max, gravity=s.gravity_vector,
        material=Material(smoke.SOIL_MATERIAL.name, s.youngs_modulus, s.poisson_ratio, s.density),
        pair=PairProperties(s.restitution, s.static_friction, s.rolling_friction, s.rolling_model),
        wall_pair=replace(seed004.SOIL_STEEL, rolling_model=s.rolling_model),
        seed=case.case.seed, max_settle_time=s.max_settle_time, periodic=s.periodic,
        pour_friction_factor=s.pour_friction_factor,
    )


def wheel_geometry(case: CaseFile) -> WheelGeometry:
    """The wheel of the case's ``[wheel]`` section: its preset with every given key replaced."""
    w = case.wheel
    base = preset(w.preset)
    changes = {k: getattr(w, k) for k in WHEEL_KEYS if getattr(w, k) is not None}
    if w.spoke_rows is not None:
        changes["spoke_rows"] = tuple(SpokeRow(*row) for row in w.spoke_rows)
    if any(v is not None for v in (w.youngs_modulus, w.poisson_ratio, w.density)):
        m = base.material
        changes["material"] = Material(
            f"{base.name} material (case)",
            youngs_modulus=w.youngs_modulus if w.youngs_modulus is not None else m.youngs_modulus,
            poisson_ratio=w.poisson_ratio if w.poisson_ratio is not None else m.poisson_ratio,
            density=w.density if w.density is not None else m.density)
    return replace(base, **changes)


def testbed_spec(case: CaseFile) -> TestbedSpec:
    """What the rig does: the case's ``[test]``, ``[contact]`` and ``[output]`` sections, the further stages of its
    drive (``[protocol]``), ``soil.time_step`` and ``wheel.rigid``/``wheel.damping``."""
    t, o, c = case.test, case.output, case.contact
    return TestbedSpec(
        slip=t.slip, slip_angle=t.slip_angle, slip_speed=t.slip_speed, load=t.load,
        angular_velocity=t.angular_velocity,
        lowering_speed=t.lowering_speed, settle_time=t.settle_time, spin_up_time=t.spin_up_time,
        drive_time=t.drive_time, stop_when_steady=t.stop_when_steady, average_time=o.average_time,
        windup=t.windup, windup_gain=t.windup_gain, windup_filter=t.windup_filter, max_wind_up=t.max_wind_up,
        sample_interval=o.sample_interval, steady_tolerance=o.steady_tolerance, slip_tolerance=o.slip_tolerance,
        steady_checks=o.steady_checks, steady_drift_confidence=o.steady_drift_confidence, start_x=t.start_x, time_step=case.soil.time_step, rigid=case.wheel.rigid,
        damping=case.wheel.damping, axle_damping=t.axle_damping,
        pair=PairProperties(c.restitution, c.static_friction, c.rolling_friction, case.soil.rolling_model),
        stages=tuple(DriveStage(st.slip, st.drive_time, st.ramp_time) for st in case.protocol.stages),
    )


def specs(case: CaseFile) -> tuple[BedSpec, WheelGeometry, TestbedSpec]:
    """(bed, wheel, test) of a case: what :class:`~wheelsoil.coupling.testbed.Testbed` is made from."""
    return bed_spec(case), wheel_geometry(case), testbed_spec(case)


@dataclass(frozen=True)
class RunPlan:
    """A case's run, built and checked once (:func:`plan`).

    rig: the bed spec, wheel and rig settings, checked against each other, and the hub's start position.
    particles: spheres in the levelled bed (estimate, :func:`~wheelsoil.granular.bed_spec.estimated_particles`).
    elements: the wheel's elements (estimate, :func:`~wheelsoil.flexwheel.geometry.estimated_elements`).
    output_bytes: upper estimate of the run folder's size [bytes] (:func:`output_bytes`).
    """

    rig: RigPlan
    particles: int
    elements: int
    output_bytes: int

    @property
    def bed(self) -> BedSpec:
        return self.rig.bed

    @property
    def wheel(self) -> WheelGeometry:
        return self.rig.wheel

    @property
    def test(self) -> TestbedSpec:
        return self.rig.test


def output_bytes(case: CaseFile, test: TestbedSpec, particles: int, elements: int) -> int:
    """Upper estimate of a run's files [bytes]: its frames (at most one per sample; per particle position,
    velocity and radius, per wheel element about a node's position and deformation, 8 bytes each) over the
    longest run of the rig ``test`` (lowering allowed 2 s, settle, and every stage's spin-up or ramp and whole drive,
    :func:`~wheelsoil.coupling.rig.stage_spec`), plus two checkpoints."""
    o = case.output
    total = longest_simulated_seconds(test)
    frames = 1 + (int(total / max(o.frame_interval, o.sample_interval)) if o.frame_interval > 0 else 0)
    per_frame = particles * 7 * 8 + elements * 6 * 8
    return frames * per_frame + 2 * particles * 30 * 8


def plan(case: CaseFile) -> RunPlan:
    """The case's :class:`RunPlan`: its specs built once and checked against each other and the machine; errors
    (:class:`~wheelsoil.errors.WheelsoilInputError`) name the case keys and values."""
    rig = plan_rig(*specs(case))
    particles, elements = estimated_particles(rig.bed), estimated_elements(rig.wheel)
    return RunPlan(rig, particles, elements, output_bytes(case, rig.test, particles, elements))
