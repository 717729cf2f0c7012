"""The case's sections as pydantic models: what a case file may say, each key with its unit, allowed range and
default (the smoke steering run, :mod:`wheelsoil.parameters.smoke`). A plain description: reading a file, the
overrides, the solver's cross-checks and writing a case back live in :mod:`.schema`, which re-exports these names;
:mod:`.build` turns a :class:`CaseFile` into the solver's specs.
"""

from __future__ import annotations

import hashlib
import json
import math
from typing import Literal, Optional, Union

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator

from wheelsoil.coupling.rig import DriveStage, TestbedSpec
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import WheelGeometry
from wheelsoil.granular.bed_spec import BedSpec
from wheelsoil.gravity import GRAVITY_PRESETS
from wheelsoil.material import Material, PairProperties
from wheelsoil.parameters import smoke
from wheelsoil.ranges import Range, non_negative

from .units import UnitError, to_unit


class CaseError(WheelsoilInputError):
    """A case file (or override) that does not validate; ``problems`` lists one line per error."""

    def __init__(self, source: str, problems: list[str]) -> None:
        self.source, self.problems = source, list(problems)
        head = f"{source}: " if len(problems) == 1 else f"{source}: {len(problems)} problems:\n  "
        super().__init__(head + "\n  ".join(problems))


def _q(default, unit: str, description: str, rng: Range | None = None):
    """A field with a unit (documented and converted from strings) and the range ``rng`` -- the solver spec's own
    (``TestbedSpec.RANGES``, ``BedSpec.RANGES``, ...), so that the case and the API check the same bounds."""
    limits = rng.limits() if rng is not None else {}
    return Field(default, description=description, json_schema_extra={"unit": unit}, **limits)


_TEST, _BED, _WHEEL, _STAGE = TestbedSpec.RANGES, BedSpec.RANGES, WheelGeometry.RANGES, DriveStage.RANGES
_MATERIAL, _PAIR = Material.RANGES, PairProperties.RANGES
_SOIL_MATERIAL, _SOIL_PAIR, _CONTACT = smoke.SOIL_MATERIAL, smoke.SOIL_SOIL, smoke.CONTACT


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)

    @field_validator("*", mode="before")
    @classmethod
    def _convert_units(cls, value, info: ValidationInfo):
        extra = cls.model_fields[info.field_name].json_schema_extra or {}
        unit = extra.get("unit")
        if unit and isinstance(value, str):
            try:
                return to_unit(value, unit)
            except UnitError as exc:
                raise ValueError(str(exc)) from None
        return value


class CaseInfo(_Section):
    name: Optional[str] = Field(None, description="run name (default: the file name without .toml)",
                                min_length=1, max_length=120, pattern=r"^[A-Za-z0-9._+-]+$")
    description: str = Field("", description="free text kept with the result")
    seed: int = Field(smoke.SEED, description="random seed of the bed's particle radii and packing",
                      **_BED["seed"].limits())


class Soil(_Section):
    length: float = _q(smoke.SOIL["length"], "m", "bin length along the travel direction", _BED["length"])
    width: float = _q(smoke.SOIL["width"], "m", "bin width across the travel direction", _BED["width"])
    depth: float = _q(smoke.SOIL["depth"], "m", "levelled bed depth", _BED["depth"])
    diameter_min: float = _q(smoke.SOIL["diameter_min"], "m", "smallest particle diameter (uniform distribution)",
                             _BED["diameter_min"])
    diameter_max: float = _q(smoke.SOIL["diameter_max"], "m", "largest particle diameter", _BED["diameter_max"])
    gravity: Union[float, tuple[float, float, float], str] = Field(
        smoke.GRAVITY, description="'earth' (9.81 m/s^2), 'moon' (9.81/6), a magnitude in m/s^2, or a vector "
                             "[gx, gy, gz] with gz < 0; the bed is prepared under the gravity it is tested at")
    youngs_modulus: float = _q(_SOIL_MATERIAL.youngs_modulus, "Pa", "particle Young's modulus (seed 004 Table 1); "
                               "at most 1.2e12 Pa (diamond)", _MATERIAL["youngs_modulus"])
    poisson_ratio: float = _q(_SOIL_MATERIAL.poisson_ratio, "1", "particle Poisson's ratio", _MATERIAL["poisson_ratio"])
    density: float = _q(_SOIL_MATERIAL.density, "kg/m^3", "particle density", _MATERIAL["density"])
    restitution: float = _q(_SOIL_PAIR.restitution, "1", "soil--soil coefficient of restitution", _PAIR["restitution"])
    static_friction: float = _q(_SOIL_PAIR.static_friction, "1", "soil--soil Coulomb friction coefficient",
                                _PAIR["static_friction"])
    rolling_friction: float = _q(_SOIL_PAIR.rolling_friction, "1", "soil--soil rolling friction coefficient",
                                 _PAIR["rolling_friction"])
    periodic: bool = Field(smoke.SOIL["periodic"], description="prepare the bin periodic along its length: a moving soil patch keeps "
                                              "fresh soil ahead of the wheel for any drive (the bin need not grow "
                                              "with test.drive_time)")
    time_step: Optional[float] = _q(None, "s", "DEM time step of the run (default: the stable Hertz/Rayleigh "
                                                "estimate); the bed is prepared with that estimate either way",
                                       _TEST["time_step"])
    max_settle_time: float = _q(smoke.SOIL["max_settle_time"], "s", "give up preparing the bed after this much "
                                "settling", _BED["max_settle_time"])
    pour_friction_factor: float = _q(1.0, "1", "sliding and rolling friction are multiplied by this while the bed is "
                                     "poured: 1 a loose pour, 0 frictionless spheres, the densest bed, above 1 "
                                     "looser; the run uses the friction above", _BED["pour_friction_factor"])
    rolling_model: Literal["cdt", "epsd"] = Field(
        "cdt", description="the rolling-resistance law of every soil contact (soil--soil, bin walls, wheel): 'cdt' "
                           "constant directional torque, or 'epsd' elastic--plastic spring--dashpot, which holds a "
                           "torque below mu_r F_n R* at rest (CDT creeps under it at a rate proportional to the time "
                           "step); formulas in wheelsoil.granular.contact")

    @field_validator("gravity")
    @classmethod
    def _gravity(cls, value):
        if isinstance(value, str):
            if value not in GRAVITY_PRESETS:
                raise ValueError("gravity is 'earth', 'moon', a magnitude in m/s^2 or a vector [gx, gy, gz]")
            return value
        if isinstance(value, (int, float)):
            if not (math.isfinite(value) and 0 < value < 1000):
                raise ValueError("a gravity magnitude must lie in (0, 1000) m/s^2")
            return float(value)
        if not all(math.isfinite(v) for v in value) or value[2] >= 0:
            raise ValueError("a gravity vector must be finite and point down (gz < 0)")
        return tuple(float(v) for v in value)

    @property
    def gravity_vector(self) -> tuple[float, float, float]:
        g = self.gravity
        if isinstance(g, str):
            return (0.0, 0.0, -GRAVITY_PRESETS[g])
        if isinstance(g, float):
            return (0.0, 0.0, -g)
        return tuple(g)


WHEEL_PRESETS = ("lunar-rover", "exomars", "cmu-k10-smooth", "cmu-k10-grouser")


class Wheel(_Section):
    preset: Literal["lunar-rover", "exomars", "cmu-k10-smooth", "cmu-k10-grouser"] = Field(
        smoke.WHEEL_PRESET, description="base wheel: lunar-rover (seed 004, r = 0.6 m), exomars (seeds 000/001) or "
                                   "the CMU rig's K10-mini, cmu-k10-smooth or cmu-k10-grouser (r = 0.058 m); the "
                                   "keys below replace its dimensions")
    element_size: Optional[float] = _q(smoke.WHEEL["element_size"], "m", "target element edge of the mesh "
                                       "(preset's own: 0.018 m lunar-rover, 0.006 m exomars)", _WHEEL["element_size"])
    rigid: bool = Field(smoke.WHEEL["rigid"], description="use the rigid wheel with the same surface")
    damping: float = _q(smoke.WHEEL["damping"], "1/s", "mass-proportional structural damping, relative to the hub",
                        _TEST["damping"])
    radius: Optional[float] = _q(None, "m", "outer tread radius (without grousers)", _WHEEL["radius"])
    width: Optional[float] = _q(None, "m", "tread width", _WHEEL["width"])
    tread_thickness: Optional[float] = _q(None, "m", "tread sheet thickness", _WHEEL["tread_thickness"])
    hub_radius: Optional[float] = _q(None, "m", "hub radius", _WHEEL["hub_radius"])
    spokes_per_row: Optional[int] = Field(None, description="spokes in each spoke row",
                                          **_WHEEL["spokes_per_row"].limits())
    spoke_thickness: Optional[float] = _q(None, "m", "spoke sheet thickness", _WHEEL["spoke_thickness"])
    spoke_bow: Optional[float] = _q(None, "1", "spoke bow as a fraction of its length", _WHEEL["spoke_bow"])
    spoke_model: Optional[Literal["shell", "beam"]] = Field(None, description="spokes as shells or beams")
    spoke_rows: Optional[list[tuple[float, float, float]]] = Field(
        None, description="spoke rows as [y_min, y_max, angle]: band of the width (fractions, -0.5..0.5) "
                          "and angle of the first spoke [deg]")
    grouser_count: Optional[int] = Field(None, description="grousers around the tread (0: smooth)",
                                         **_WHEEL["grouser_count"].limits())
    grouser_height: Optional[float] = _q(None, "m", "grouser height", _WHEEL["grouser_height"])
    grouser_thickness: Optional[float] = _q(None, "m", "grouser sheet thickness", _WHEEL["grouser_thickness"])
    grouser_angle: Optional[float] = _q(None, "deg", "grouser angle to the axle (chevron half-angle)",
                                        _WHEEL["grouser_angle"])
    hub_mass: Optional[float] = _q(None, "kg", "hub mass (with the rig's moving parts)", _WHEEL["hub_mass"])
    side_walls: Optional[bool] = Field(None, description="close the wheel with a flat disc on each side, from the "
                                                         "tread to the hub (an open wheel driven deep fills with soil "
                                                         "through its sides); every preset's own is open")
    youngs_modulus: Optional[float] = _q(None, "Pa", "wheel material Young's modulus; at most 1.2e12 Pa (diamond)",
                                         _MATERIAL["youngs_modulus"])
    poisson_ratio: Optional[float] = _q(None, "1", "wheel material Poisson's ratio", _MATERIAL["poisson_ratio"])
    density: Optional[float] = _q(None, "kg/m^3", "wheel material density", _MATERIAL["density"])


class Contact(_Section):
    restitution: float = _q(_CONTACT.restitution, "1", "soil--wheel coefficient of restitution (seed 004 "
                            "soil--steel)", _PAIR["restitution"])
    static_friction: float = _q(_CONTACT.static_friction, "1", "soil--wheel Coulomb friction coefficient",
                                _PAIR["static_friction"])
    rolling_friction: float = _q(_CONTACT.rolling_friction, "1", "soil--wheel rolling friction coefficient",
                                 _PAIR["rolling_friction"])


class Test(_Section):
    __test__ = False  # not a pytest class

    slip: float = _q(smoke.TEST["slip"], "1", "longitudinal slip: driving i = 1 - v_x / (r omega); braking (< 0) "
                     "i = r omega / v_x - 1, -1 a wheel dragged without turning",
                     _TEST["slip"])
    slip_speed: Literal["heading", "travel"] = Field(
        "heading", description="the travel speed the slip is taken against: 'heading' (v_x, along the wheel's "
                               "heading) or 'travel' (the carriage's whole speed, as the measured rigs report slip; "
                               "needed at slip_angle = 90)")
    slip_angle: float = _q(smoke.TEST["slip_angle"], "deg", "steering (slip) angle beta between heading and travel",
                           _TEST["slip_angle"])
    load: float = _q(smoke.TEST["load"], "N", "vertical load W on the soil, wheel weight included", _TEST["load"])

    angular_velocity: float = _q(smoke.TEST["angular_velocity"], "rad/s", "reference spin omega_0: the hub's spin when "
                                 "driving; braking, the carriage travels at r omega_0 and the hub spins at (1 + i) omega_0",
                                 _TEST["angular_velocity"])
    lowering_speed: float = _q(smoke.TEST["lowering_speed"], "m/s", "speed at which the rig lowers the wheel until "
                               "the soil carries W", _TEST["lowering_speed"])
    settle_time: float = _q(smoke.TEST["settle_time"], "s", "rest, free vertically under W, before driving",
                            _TEST["settle_time"])
    spin_up_time: float = _q(smoke.TEST["spin_up_time"], "s", "time over which omega and the carriage speed ramp up",
                             _TEST["spin_up_time"])
    drive_time: float = _q(smoke.TEST["drive_time"], "s", "longest drive after the spin-up; the run ends sooner once "
                           "it is steady (stop_when_steady)", _TEST["drive_time"])
    stop_when_steady: bool = Field(smoke.TEST["stop_when_steady"], description="end the run at the first steady "
                                   "window of output.average_time (false: drive the whole drive_time)")
    windup: Literal["controller", "none"] = Field(
        smoke.TEST["windup"], description="'controller': after the spin-up the hub's spin follows the tread's "
                                          "(feedback) until the wheel has wound up to the tread slip commanded, then "
                                          "holds omega; 'none': hold omega from the spin-up on")
    windup_gain: float = _q(smoke.TEST["windup_gain"], "1", "feedback gain of the wind-up controller",
                            _TEST["windup_gain"])
    windup_filter: float = _q(smoke.TEST["windup_filter"], "s", "time constant of the filter on the tread's measured "
                              "spin in the wind-up controller", _TEST["windup_filter"])
    max_wind_up: float = _q(smoke.TEST["max_wind_up"], "rad", "stop the run when the tread lags the hub by more than "
                            "this", _TEST["max_wind_up"])
    start_x: Optional[float] = _q(None, "m", "initial hub position along the bin (default: radius + 0.1 m; the "
                                             "middle of a periodic bin)", _TEST["start_x"])
    axle_damping: Optional[float] = _q(None, "N s/m", "damper on the rig's vertical slide (default: wheel "
                                                      "mass / 0.1 s)", _TEST["axle_damping"])

    @field_validator("slip_angle")
    @classmethod
    def _sideways_needs_travel(cls, value, info: ValidationInfo):
        if info.data.get("slip_speed") == "heading" and abs(value) >= 90.0:
            raise ValueError("needs slip_speed = 'travel': at 90 deg the speed along the heading is zero, so the "
                             "slip is taken against the carriage's whole speed")
        return value


class Output(_Section):
    sample_interval: float = _q(smoke.OUTPUT["sample_interval"], "s", "averaging interval of one time-series sample",
                                _TEST["sample_interval"])
    average_time: float = _q(smoke.OUTPUT["average_time"], "s", "shortest averaging window once steady (whole "
                             "pitches of the tread)", _TEST["average_time"])
    steady_tolerance: float = _q(smoke.OUTPUT["steady_tolerance"], "1", "largest drift over the averaging window, "
                                 "relative to the mean (or a floor: 5 % of W for forces)", _TEST["steady_tolerance"])
    slip_tolerance: float = _q(smoke.OUTPUT["slip_tolerance"], "1", "largest difference between tread slip and "
                               "commanded slip when steady", _TEST["slip_tolerance"])
    steady_checks: int = Field(smoke.OUTPUT["steady_checks"], description="consecutive checks, one period of the "
                               "tread apart, that must find the run steady before it stops and is reported steady",
                               **_TEST["steady_checks"].limits())
    steady_drift_confidence: float = _q(smoke.OUTPUT["steady_drift_confidence"], "1", "standard errors of a "
                                        "quantity's drift added to it before it is held to steady_tolerance (0: the "
                                        "estimate alone)", _TEST["steady_drift_confidence"])
    # what a run keeps (cases.run's own: no solver spec carries these two)
    frame_interval: float = _q(smoke.OUTPUT["frame_interval"], "s", "simulated time between frames (particles, "
                               "wheel nodes) kept in the result; 0: the last frame only", non_negative())
    checkpoint_interval: float = _q(smoke.OUTPUT["checkpoint_interval"], "s", "simulated time between checkpoints a "
                                    "killed run resumes from (--resume); 0: none", non_negative())
    render: bool = Field(smoke.OUTPUT["render"], description="render the last state to final.png")


class Stage(_Section):
    """One further stage of the drive (``[protocol]`` ``stages``; :class:`~wheelsoil.coupling.rig.DriveStage`)."""

    slip: float = _q(..., "1", "the stage's commanded slip (as test.slip)", _STAGE["slip"])
    drive_time: Optional[float] = _q(None, "s", "the stage's longest drive after its ramp (default: test.drive_time)",
                                     _STAGE["drive_time"])
    ramp_time: Optional[float] = _q(None, "s", "time over which the hub's spin and the carriage's speed move from the "
                                               "previous stage's command to this one's (default: test.spin_up_time)",
                                    _STAGE["ramp_time"])


class Protocol(_Section):
    stages: tuple[Stage, ...] = Field(
        (), description="further stages of the drive, after the first at test.slip, e.g. stages = [{slip = 0.3}, "
                        "{slip = 0.5, drive_time = 6.0}]: each ramps to its slip, winds up and drives until steady "
                        "(or for its drive_time), with its own summary (a slip ramp on one bed and one lowering)")


SECTIONS: dict[str, type[_Section]] = {
    "case": CaseInfo, "soil": Soil, "wheel": Wheel, "contact": Contact, "test": Test, "output": Output,
    "protocol": Protocol,
}


class CaseFile(BaseModel):
    """A validated case: one testbed run."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    case: CaseInfo = Field(default_factory=CaseInfo)
    soil: Soil = Field(default_factory=Soil)
    wheel: Wheel = Field(default_factory=Wheel)
    contact: Contact = Field(default_factory=Contact)
    test: Test = Field(default_factory=Test)
    output: Output = Field(default_factory=Output)
    protocol: Protocol = Field(default_factory=Protocol)

    @property
    def name(self) -> str:
        return self.case.name or "case"

    def case_hash(self) -> str:
        """16 hex digits of SHA-256 over everything that shapes the result (not the name or description)."""
        data = self.model_dump(mode="json")
        data["case"].pop("name")
        data["case"].pop("description")
        # keys added after cases were stored leave a case's hash as it was while they hold their default
        if data["test"]["slip_speed"] == "heading":
            data["test"].pop("slip_speed")
        if data["soil"]["pour_friction_factor"] == 1.0:
            data["soil"].pop("pour_friction_factor")
        if data["soil"]["rolling_model"] == "cdt":
            data["soil"].pop("rolling_model")
        if data["output"]["steady_drift_confidence"] == 0.0:
            data["output"].pop("steady_drift_confidence")
        if not data["protocol"]["stages"]:
            data.pop("protocol")
        if data["wheel"]["side_walls"] is None:
            data["wheel"].pop("side_walls")
        if data["test"]["windup_filter"] == smoke.TEST["windup_filter"]:
            data["test"].pop("windup_filter")
        return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]
