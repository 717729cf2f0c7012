"""What the rig does, before any of it runs: the test's specification (:class:`TestbedSpec`), the carriage's
speeds, the wheel's period and the statistics' pitch, and the checks that a bed and a wheel fit the machine and the
drive (:func:`check_fits`). No Taichi: a case file is checked with these before the engine starts
(:mod:`.testbed` runs the rig).

Conventions (architecture; seed 004 eqs. 14--16; the measured rigs' slip): see :mod:`.testbed`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from typing import ClassVar

from wheelsoil.bearing import rectangular_footing
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import WheelGeometry, check_mesh_memory
from wheelsoil.granular.bed_spec import BedSpec, check_memory, machine_memory
from wheelsoil.granular.materials import PairProperties, effective_modulus
from wheelsoil.granular.timestep import estimate_time_step
from wheelsoil.parameters import smoke
from wheelsoil.ranges import Range, check_ranges, non_negative, positive

from .kinematics import rig_command
from .patch_geometry import PatchGeometry

#: What the slip may be taken against (:class:`TestbedSpec` ``slip_speed``).
SLIP_SPEEDS = ("heading", "travel")

#: The default slide damper's decay time [s]: axle_damping = wheel mass / AXLE_DAMPING_TIME (a free heave decays in it).
AXLE_DAMPING_TIME = 0.1


def _check(key: str, value, ok: bool, allowed: str) -> None:
    if not ok:
        raise WheelsoilInputError(f"testbed {key} = {value!r} is out of range: allowed {allowed}")


@dataclass(frozen=True)
class DriveStage:
    """A further stage of the drive, after the first (which runs at the spec's own ``slip``): the carriage and the
    hub ramp from the previous stage's command to this stage's over ``ramp_time``, a flexible wheel winds up again,
    and the wheel drives until steady (or for ``drive_time``), each stage with its own steady window and summary. A
    list of stages is a slip ramp on one bed and one lowering (:func:`stage_spec`).

    slip: the stage's commanded slip, in [-1, 1) as :attr:`TestbedSpec.slip`.
    drive_time: the stage's longest drive after its ramp [s] (None: the spec's ``drive_time``).
    ramp_time: the time over which the command moves to the stage's [s] (None: the spec's ``spin_up_time``).
    """

    __test__ = False

    slip: float
    drive_time: float | None = None
    ramp_time: float | None = None

    RANGES: ClassVar[dict[str, Range]] = {"slip": Range(-1.0, 1.0, hi_open=True), "drive_time": positive(),
                                          "ramp_time": non_negative()}

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "protocol stage", {"drive_time": "s", "ramp_time": "s"})

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class TestbedSpec:
    """What the rig does (SI units, angles in degrees).

    slip: commanded longitudinal slip in [-1, 1): driving (>= 0) i = 1 - v_x / (r omega); braking (< 0)
        i = r omega / v_x - 1, -1 a wheel dragged without turning (the measured rigs' convention).
    slip_angle: steering angle beta between heading and travel [deg], in (-90, 90]; 90 (the wheel ploughing
        sideways) only with ``slip_speed = "travel"``.
    slip_speed: the travel speed v the slip is taken against: ``"heading"`` (the architecture's v_x, the
        travel velocity's component along the heading; the carriage then moves at v_x / cos beta) or
        ``"travel"`` (the measured rigs': the carriage's whole horizontal speed V, as the CMU rig reports slip:
        at 60 deg a rim speed of 20 mm/s against a 10 mm/s carriage is i = 0.5; its model's v_jt.m takes
        r omega >= V as the slip condition). Equal at beta = 0.
    load: vertical load W on the soil, wheel weight included [N], > 0.
    angular_velocity: the rig's reference spin omega_0 [rad/s], > 0 (seed 004: r omega = 0.6 m/s): the hub's
        spin when driving; when braking the carriage travels at r omega_0 and the hub spins at (1 + i) omega_0.
    lowering_speed: speed [m/s] at which the rig lowers the wheel onto the soil until the soil carries W.
    settle_time: time the wheel then rests, free vertically under W, before driving [s].
    spin_up_time: time over which omega (and the carriage speed) rise linearly [s].
    drive_time: longest drive after the spin-up [s]; the run ends sooner once steady (``stop_when_steady``).
    stop_when_steady: end the run at the first steady window of ``average_time``.
    average_time: shortest averaging window once steady [s] (rounded up to whole pitches of the tread, at
        least three, and to two whole periods of the wheel: :func:`statistics_pitch`, :func:`wheel_period`).
    windup: ``"controller"`` (wind the wheel up by tread-speed feedback on the hub, then hold omega) or
        ``"none"`` (hold omega from the spin-up on).
    windup_gain: feedback gain K of the wind-up controller (> 0).
    windup_filter: time constant [s] of the filter on the tread's measured spin in the controller.
    max_wind_up: the twist [rad] beyond which the run stops with an error (spokes buckling through).
    sample_interval: averaging interval of one sample of the time series [s].
    steady_tolerance: largest drift over the window allowed for a steady quantity, relative to
        max(|mean|, floor) (floors: 5 % of W for forces, 5 % of W r for the torque, half a mean particle
        diameter for the sinkage).
    slip_tolerance: largest difference between the tread slip and the commanded slip in a steady window.
    steady_checks: consecutive checks, one period of the tread apart, that must find the run steady before it
        stops and is reported steady. The detector is asked again every period, so one lucky window would let
        a drift comparable to its noise through sooner or later; two in a row cut that several-fold for a
        period's more driving (``docs/steady-detector.md``).
    steady_drift_confidence: standard errors of each quantity's drift (and of the change between the window's
        halves) added to it before it is held to ``steady_tolerance`` (0: the estimate alone; 0.5 or 1: a window
        too short to tell its drift from the tolerance is not called steady; ``docs/steady-drift-confidence.md``).
    start_x: initial hub position along the bin [m] (default: one wheel radius plus 0.1 m from the start;
        on a periodic bed, as near the start as the moving patch allows).
    rigid: use the rigid wheel with the same surface instead of the flexible one.
    damping: mass-proportional structural damping of the flexible wheel [1/s], relative to the hub.
    axle_damping: viscous damper on the rig's vertical slide [N s/m], acting on the hub's vertical speed
        once the axle is released (like the damper or heavy carriage of a real rig). It has no mean force
        in a steady state, so the load on the soil stays W, but it stops the wheel's heave on the soil's
        stiffness from ringing through the run; its force is updated every sample interval. None: wheel
        mass / 0.1 s (a free heave decays in 0.1 s; roughly 0.4 of critical damping for the smoke case's
        heave on the soil); 0: no damper.
    stages: further stages of the drive (:class:`DriveStage`), each after the one before has ended (steady, or at
        its ``drive_time``): a slip ramp on one bed and one lowering. Empty (the default): one drive at ``slip``.
    patch_shift: on a periodic bed, the moving soil patch re-centres the wheel whenever it has travelled
        this far [m] (:mod:`.patch`); None: a fifth of the wheel radius.
    time_step: DEM time step of the run [s] (None: the bed's stable estimate); the bed is prepared with its own,
        so a time-step study tests the same bed. A step above the stable estimate is refused.
    pair: soil--wheel contact properties (default seed 004 Table 1 soil--steel).
    """

    __test__ = False  # not a pytest class

    slip: float = smoke.TEST["slip"]
    slip_angle: float = smoke.TEST["slip_angle"]
    slip_speed: str = "heading"
    load: float = smoke.TEST["load"]
    angular_velocity: float = smoke.TEST["angular_velocity"]
    lowering_speed: float = smoke.TEST["lowering_speed"]
    settle_time: float = smoke.TEST["settle_time"]
    spin_up_time: float = smoke.TEST["spin_up_time"]
    drive_time: float = smoke.TEST["drive_time"]
    stop_when_steady: bool = smoke.TEST["stop_when_steady"]
    average_time: float = smoke.OUTPUT["average_time"]
    windup: str = smoke.TEST["windup"]
    windup_gain: float = smoke.TEST["windup_gain"]
    windup_filter: float = smoke.TEST["windup_filter"]
    max_wind_up: float = smoke.TEST["max_wind_up"]
    sample_interval: float = smoke.OUTPUT["sample_interval"]
    steady_tolerance: float = smoke.OUTPUT["steady_tolerance"]
    slip_tolerance: float = smoke.OUTPUT["slip_tolerance"]
    steady_checks: int = smoke.OUTPUT["steady_checks"]
    steady_drift_confidence: float = smoke.OUTPUT["steady_drift_confidence"]
    start_x: float | None = None
    rigid: bool = smoke.WHEEL["rigid"]
    damping: float = smoke.WHEEL["damping"]
    axle_damping: float | None = None
    patch_shift: float | None = None
    time_step: float | None = None
    pair: PairProperties = smoke.CONTACT
    stages: tuple[DriveStage, ...] = ()

    #: Allowed range of every scalar input (None: "use the default" where a default is computed). The case
    #: schema's [test], [output] and wheel.damping fields take their bounds from here.
    RANGES: ClassVar[dict[str, Range]] = {
        "slip": Range(-1.0, 1.0, hi_open=True),
        "slip_angle": Range(-90.0, 90.0, lo_open=True),
        "load": positive(),
        "angular_velocity": positive(),
        "lowering_speed": positive(),
        "settle_time": positive(),
        "spin_up_time": non_negative(),
        "drive_time": positive(),
        "average_time": positive(),
        "windup_gain": positive(hi=50.0),
        "windup_filter": positive(),
        "max_wind_up": positive(hi=math.pi / 2),
        "sample_interval": positive(),
        "steady_tolerance": positive(hi=1.0),
        "slip_tolerance": positive(hi=0.5),
        "steady_checks": Range(1, 10, integer=True),
        "steady_drift_confidence": Range(0.0, 3.0),
        "start_x": positive(),
        "damping": non_negative(),
        "axle_damping": non_negative(),
        "patch_shift": positive(),
        "time_step": positive(),
    }
    UNITS: ClassVar[dict[str, str]] = {
        "slip_angle": "deg", "load": "N", "angular_velocity": "rad/s", "lowering_speed": "m/s", "settle_time": "s",
        "spin_up_time": "s", "drive_time": "s", "average_time": "s", "windup_filter": "s", "max_wind_up": "rad",
        "sample_interval": "s", "start_x": "m", "damping": "1/s", "axle_damping": "N s/m", "patch_shift": "m",
        "time_step": "s",
    }

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "testbed", self.UNITS)
        _check("windup", self.windup, self.windup in ("controller", "none"), "'controller' or 'none'")
        _check("slip_speed", self.slip_speed, self.slip_speed in SLIP_SPEEDS, " or ".join(map(repr, SLIP_SPEEDS)))
        _check("slip_angle", self.slip_angle, abs(self.slip_angle) < 90.0 or self.slip_speed == "travel",
               "-90 < slip_angle < 90 deg with slip_speed = 'heading' (at 90 deg the heading speed is zero: take "
               "the slip against the travel, slip_speed = 'travel', the measured rigs' convention)")
        _check("average_time", self.average_time, self.average_time < self.drive_time,
               f"average_time < drive_time = {self.drive_time} s")
        _check("sample_interval", self.sample_interval, self.sample_interval <= 0.25 * self.average_time,
               f"sample_interval <= average_time / 4 = {0.25 * self.average_time:g} s")
        if not isinstance(self.pair, PairProperties):
            raise WheelsoilInputError(f"testbed pair must be a PairProperties, got {type(self.pair).__name__}")
        if not isinstance(self.stages, tuple) or not all(isinstance(st, DriveStage) for st in self.stages):
            raise WheelsoilInputError("testbed stages must be a tuple of DriveStage")
        for k, st in enumerate(self.stages):
            if st.drive_time is not None:
                _check(f"stages[{k}].drive_time", st.drive_time, self.average_time < st.drive_time,
                       f"more than average_time = {self.average_time} s")

    @property
    def n_stages(self) -> int:
        """The drive's stages: the first, at ``slip``, and the further :attr:`stages`."""
        return 1 + len(self.stages)

    def to_dict(self) -> dict:
        """Plain values (``stages`` only where there are further stages, so a one-stage spec reads as before)."""
        d = asdict(self)
        d["pair"] = self.pair.to_dict()
        d.pop("stages")
        if self.stages:
            d["stages"] = [st.to_dict() for st in self.stages]
        return d


def stage_spec(spec: TestbedSpec, k: int) -> TestbedSpec:
    """The rig's settings during stage ``k`` of the drive (0: ``spec`` itself; k >= 1: its ``stages[k - 1]``'s slip,
    drive time and ramp time in place of ``slip``, ``drive_time`` and ``spin_up_time``, without further stages)."""
    if k == 0:
        return spec
    if not 1 <= k <= len(spec.stages):
        raise ValueError(f"the drive has stages 0 to {len(spec.stages)}, not {k}")
    st = spec.stages[k - 1]
    return replace(spec, slip=st.slip, stages=(),
                   drive_time=st.drive_time if st.drive_time is not None else spec.drive_time,
                   spin_up_time=st.ramp_time if st.ramp_time is not None else spec.spin_up_time)


def carriage_speed(spec: TestbedSpec, radius: float) -> tuple[float, float]:
    """The hub's commanded spin [rad/s] and the carriage's speed along the bin [m/s] that give the commanded
    slip (:func:`.kinematics.rig_command`) against the speed ``spec.slip_speed`` names: the speed along the
    heading is v cos beta when the carriage moves at v, so with ``"heading"`` the carriage moves at v_x / cos beta,
    with ``"travel"`` at V itself (velocity components, never through tan beta: 90 deg is a wheel ploughing
    sideways)."""
    spin, speed = rig_command(spec.slip, spec.angular_velocity, radius)
    if spec.slip_speed == "heading":
        speed /= math.cos(math.radians(spec.slip_angle))
    return spin, speed


def soil_headroom(bed_depth: float, wheel: WheelGeometry) -> float:
    """How far [m] the soil's domain reaches above the bed surface: above the wheel's top when it stands on the
    surface (2 (r + grouser height) + 0.1 m), and at least the bed depth. Grains that ride up in the grouser
    pockets or on a steered wheel's berm stay in the domain. (At 0.25 m, a 20-deg steering run at smoke scale
    stopped at 6.1 s with a grain carried up at 0.5 m/s; grains launched higher are counted, not fatal:
    :meth:`~wheelsoil.granular.Scene.check_health`.)"""
    return max(bed_depth, 2.0 * (wheel.radius + wheel.grouser_height) + 0.1)


def wheel_period(wheel: WheelGeometry) -> float:
    """The angle [rad] after which the wheel repeats itself: the smallest rotation that maps the grousers onto
    the grousers and the spokes onto the spokes, 2 pi / gcd(grousers, spokes around) (the spoke pitch for a
    smooth wheel). The forces of a spoked wheel ride on its periodic stiffness (seed 000 eq. 19) as well as on
    the grousers, so the steady-state windows span whole periods."""
    spokes = int(round(360.0 / wheel.spoke_pitch))
    return 2.0 * math.pi / (math.gcd(wheel.grouser_count, spokes) if wheel.grouser_count else spokes)


def statistics_pitch(wheel: WheelGeometry) -> float:
    """The batch angle [rad] of the steady-state statistics: the whole period (:func:`wheel_period`) when the
    grouser and spoke pitches are whole multiples one of the other (the 24 grousers and 12 spokes of seed 004's
    wheel: 30 deg), else the grouser pitch (8 grousers and 6 spokes: 45 deg, four to the 180-deg period),
    which keeps a batch short enough for several per second of driving."""
    spoke = math.radians(wheel.spoke_pitch)
    if not wheel.grouser_count:
        return spoke
    grouser = 2.0 * math.pi / wheel.grouser_count
    for small, large in ((grouser, spoke), (spoke, grouser)):
        ratio = large / small
        if abs(ratio - round(ratio)) < 1e-9:
            return large
    return grouser


def batches_per_period(wheel: WheelGeometry) -> int:
    """The wheel's whole period (:func:`wheel_period`) in batches of the statistics (:func:`statistics_pitch`)."""
    return int(round(wheel_period(wheel) / statistics_pitch(wheel)))


@dataclass(frozen=True)
class RigPlan:
    """A rig checked against its bed and wheel (:func:`plan_rig`): what :class:`~.testbed.Testbed` is made from
    without checking it again. ``start_x``: the hub's start position along the bin [m]."""

    bed: BedSpec
    wheel: WheelGeometry
    test: TestbedSpec
    start_x: float


def plan_rig(bed: BedSpec, wheel: WheelGeometry, test: TestbedSpec) -> RigPlan:
    """The rig of ``test`` for ``wheel`` on a bed of ``bed``, checked once (:func:`check_fits`)."""
    return RigPlan(bed, wheel, test, check_fits(bed, wheel, test))


#: The soil of :func:`load_bound`: the densest random packing of equal spheres (a poured bed of any size spread is
#: looser) and the top of the bearing formulas' friction angles (a cohesionless granular bed's peak angle is below
#: it: the soil lab's beds give 34-42 deg), so that no bed the case can make is stronger.
BOUND_PACKING, BOUND_FRICTION_ANGLE = 0.64, 49.0


def load_bound(bed: BedSpec, wheel: WheelGeometry) -> tuple[float, float, float]:
    """An upper bound [N] of the vertical load the bed can carry under the wheel while it is lowered, with the
    footprint's length and depth [m]: the lowering stops a run once the rim is half its radius deep
    (``coupling.protocol.Lower``), so the bound is Meyerhof's ultimate bearing pressure
    (:func:`wheelsoil.bearing.rectangular_footing`) at that depth on the footprint there, the wheel's width times the
    chord of its outer (grouser-tip) circle, for the strongest soil of :data:`BOUND_PACKING` and
    :data:`BOUND_FRICTION_ANGLE` (no cohesion: the DEM has none) under the bed's gravity. It is generous (for the CMU
    wheels about twenty times the most the measured sand carried when they were pressed to that depth,
    ``force_displacement/wheel_sinkage.csv``), so it refuses only a load no bed of the case could carry, before any
    work: a load in the wrong unit or another rig's."""
    sink = 0.5 * wheel.radius
    outer = wheel.radius + (wheel.grouser_height if wheel.grouser_count else 0.0)
    length = 2.0 * math.sqrt(outer ** 2 - (wheel.radius - sink) ** 2)
    depth = sink + (outer - wheel.radius)
    unit_weight = BOUND_PACKING * bed.material.density * abs(float(bed.gravity[2]))
    pressure = rectangular_footing(wheel.width, length, depth, BOUND_FRICTION_ANGLE, 0.0, unit_weight)
    return pressure * wheel.width * length, length, depth


def check_fits(bed: BedSpec, wheel: WheelGeometry, spec: TestbedSpec) -> float:
    """Check, before any bed is prepared, that the bed and the wheel mesh fit the machine's memory, that the
    time step and the load are ones the contact model can take, that the bed could carry the load at all
    (:func:`load_bound`), that the wheel fits the bin and that the bin
    (or the moving patch on a periodic bin) holds the drive; returns the hub's start position along the bin
    [m]. The errors name the case keys and values."""
    check_memory(bed)
    check_mesh_memory(wheel, machine_memory())
    if spec.time_step is not None:
        # the soil pairs alone bound the stable step from above (walls and the wheel only shorten it): a step
        # beyond it is refused now, not after the bed is prepared
        est = estimate_time_step(0.5 * bed.diameter_min, bed.material)
        if spec.time_step > est.stable:
            raise WheelsoilInputError(f"soil.time_step = {spec.time_step:.3g} s exceeds the stable time step of "
                                      f"the particle pairs: {est.describe()}")
    # a lower bound of the run's DEM step: the smallest possible radius, and the walls' and the wheel's contacts
    # beside the pairs (the scene's estimate uses the spheres' actual smallest radius, never below it)
    moduli = (effective_modulus(bed.material, bed.wall_material),
              effective_modulus(bed.material, wheel.material))
    shortest = spec.time_step or estimate_time_step(0.5 * bed.diameter_min, bed.material, wall_moduli=moduli).stable
    if spec.sample_interval < shortest:
        raise WheelsoilInputError(f"output.sample_interval = {spec.sample_interval:.3g} s is shorter than the "
                                  f"run's DEM step (at least {shortest:.3g} s): a sample averages at least one step")
    pressure = spec.load / (wheel.width * wheel.radius)
    if pressure > 0.05 * bed.material.youngs_modulus:
        # a nominal pressure p over a contact of about one radius: Hertz overlaps grow as (p / E)^(2/3) of the
        # radius, past ~10 % when p > 5 % of E -- beyond what a soft-sphere contact model represents
        raise WheelsoilInputError(
            f"test.load = {spec.load:.4g} N on a wheel of width {wheel.width:g} m and radius {wheel.radius:g} m is a "
            f"nominal pressure W / (b r) = {pressure:.3g} Pa, more than 5 % of the soil's Young's modulus "
            f"({bed.material.youngs_modulus:.3g} Pa): the particles would overlap by more than about a tenth of "
            f"their radius; lower the load (at most {0.05 * bed.material.youngs_modulus * wheel.width * wheel.radius:.3g} N)"
            " or stiffen the soil (soil.youngs_modulus)")
    bound, length, depth = load_bound(bed, wheel)
    if spec.load > bound:
        raise WheelsoilInputError(
            f"test.load = {spec.load:.4g} N is more than this bed can carry under wheel {wheel.name!r}: the lowering "
            f"stops a run once the rim is half its radius deep, and there even the strongest soil of these particles "
            f"(packing {BOUND_PACKING}, friction angle {BOUND_FRICTION_ANGLE:g} deg, no cohesion, gravity "
            f"{abs(float(bed.gravity[2])):.3g} m/s^2) carries at most {bound:.4g} N on the footprint "
            f"({wheel.width:g} m x {length:.3g} m, {depth:.3g} m deep; Meyerhof's bearing capacity); lower the load "
            "(is it in newtons, for this gravity?) or use a larger wheel")
    beta = math.radians(spec.slip_angle)
    outer = wheel.radius + (wheel.grouser_height if wheel.grouser_count else 0.0)
    # footprint across the bin: the width turned by beta plus a contact length of about one radius
    footprint = wheel.width * math.cos(beta) + wheel.radius * abs(math.sin(beta))
    if wheel.width >= bed.width or footprint >= bed.width - 2 * bed.diameter_max:
        raise WheelsoilInputError(
            f"wheel {wheel.name!r} (width {wheel.width} m, footprint {footprint:.3f} m across the bin at "
            f"slip_angle {spec.slip_angle} deg) does not fit the bed width {bed.width} m "
            f"(allowed footprint < {bed.width - 2 * bed.diameter_max:.3f} m)"
        )
    if bed.periodic:
        shift = spec.patch_shift or 0.2 * wheel.radius
        return PatchGeometry.for_wheel(bed.length, outer, shift, bed.diameter_max).check(spec.start_x)
    # every stage's longest drive and ramp at that stage's carriage speed (the ramp's at the faster of its ends)
    stages = [stage_spec(spec, k) for k in range(spec.n_stages)]
    speeds = [abs(carriage_speed(st, wheel.radius)[1]) for st in stages]
    speed = max(speeds)
    travel = sum(v * st.drive_time + max(v, before) * st.spin_up_time
                 for st, v, before in zip(stages, speeds, speeds[:1] + speeds[:-1]))
    start_x = spec.start_x if spec.start_x is not None else outer + 0.1
    if start_x - outer < 0 or start_x + travel + outer > bed.length:
        raise WheelsoilInputError(
            f"the bin (soil.length = {bed.length} m) is too short for test.drive_time = {spec.drive_time} s"
            f"{f' and its further stages (protocol.stages)' if spec.stages else ''}: "
            f"the wheel (outer radius {outer:.3f} m) starts at x = {start_x:.3f} m and may travel "
            f"{travel:.3f} m at up to {speed:.3f} m/s; shorten drive_time, use a longer bin, or a "
            "periodic bed (soil.periodic = true: a moving soil patch holds any drive)"
        )
    return start_x


def batch_rate(slip: float, reference_spin: float, radius: float) -> float:
    """The rate [rad/s] at which the steady-state statistics' batches (pitches) pass under the rig's command:
    the hub's commanded spin (:func:`.kinematics.rig_command`), or for a wheel dragged without turning (i = -1)
    the angle it would roll through at its travel speed, v_x / r."""
    spin, heading_speed = rig_command(slip, reference_spin, radius)
    return spin if spin > 0.0 else heading_speed / radius
