"""Gravity similarity: a case carried to another gravity with every dimensionless group of the test kept.

A run of the testbed involves lengths, masses and times only through its parameters (grain sizes, densities, moduli,
friction, the wheel's geometry and material, the rig's speeds and times, the load, gravity). Keep every length and
mass and change gravity from g to g' = g / tau^2: then with time scaled by tau (velocities by 1/tau, accelerations by
1/tau^2) and every force, pressure and modulus by 1/tau^2, Newton's law, the Hertz--Mindlin contact (its force
(4/3) E* sqrt(R) delta^(3/2) and its damping, eq. 11.24 of Johnson's *Contact Mechanics* and Tsuji's dashpot),
Coulomb friction, the rolling torque mu_r R F_n and the shell's elasticity all map one run onto the other: positions
equal at corresponding times, forces in the ratio g'/g. The groups held are the load W / (rho g b r^2), the Froude
number v^2 / (g r), the grain and wheel stiffness E / (rho g r), the damping ratios, restitution and friction. In the
quasi-static limit of rigid grains only the first matters, which is why "equal mass" is the usual way to test at 1/6 g
on Earth (W' = W g'/g): what else differs between the two runs at equal mass -- the Froude number and the stiffness
groups -- is what the reduced-gravity question is about (docs/gravity-terms).

:func:`similar_case` scales every key of a case by its unit (the case schema records each key's unit) with
:data:`TIME_EXPONENT`, plus the two quantities a case leaves to defaults computed at run time (the wheel's modulus from
its preset and the slide damper from the wheel mass), and sets the new gravity. ``keep`` leaves named keys as they
are, which builds the partial transforms that separate one group from another (the moduli kept: stiffer grains and
wheel relative to the load). What the scaling cannot reach is listed in :data:`UNSCALED_CONSTANTS`.
"""

from __future__ import annotations

import math

from wheelsoil.coupling.rig import AXLE_DAMPING_TIME
from wheelsoil.errors import WheelsoilInputError
from wheelsoil.flexwheel.geometry import wheel_mass

from . import build
from .case_model import CaseFile
from .schema import apply_overrides, validate_case

#: The power of the time scale tau by which a key with this unit is multiplied (lengths and masses are kept, so
#: only the unit's dimension of time counts: N = kg m / s^2 -> tau^-2).
TIME_EXPONENT = {
    "1": 0, "m": 0, "kg": 0, "kg/m^3": 0, "deg": 0, "rad": 0,
    "s": 1, "m/s": -1, "rad/s": -1, "1/s": -1, "N s/m": -1, "N": -2, "Pa": -2,
}

#: Constants of the solver that carry a dimension and are not case keys, so :func:`similar_case` cannot scale them,
#: and what each changes. Together they leave the smoke case's similar case within its replicas' spread in drawbar
#: pull, lateral force and torque, and its hub sinkage 1.8 % deeper (3.2 standard errors; docs/gravity-terms).
UNSCALED_CONSTANTS = {
    "bed settling threshold": "the bed counts as settled when its mean grain moves slower than 5 mm/s "
                              "(granular.bed_spec.BedSpec.settle_threshold); a scaled bed stops settling at a "
                              "relatively faster creep, a slightly different packing like another seed's",
    "impact speed of the time-step estimate": "at least 1 m/s (granular.bed), so the Hertz contact time it sets "
                                              "does not stretch by tau: where it binds (smoke-1g-steer carried to "
                                              "1/6 g: 0.263 ms against the Rayleigh step's 0.268) the DEM step is "
                                              "shorter than tau times the original's; set soil.time_step on both "
                                              "for the same step",
    "bin walls": "steel (210 GPa), not scaled: their contact modulus with the grains is the grains' to 2e-4 "
                 "(on the mini testbed, 1e-6 of the load in the first contacts)",
}


def _unit(section: str, key: str) -> str | None:
    field = CaseFile.model_fields[section].annotation.model_fields[key]
    extra = field.json_schema_extra
    return extra.get("unit") if isinstance(extra, dict) else None


def scaled_keys(case: CaseFile) -> dict[str, int]:
    """{"section.key": time exponent} of every key of ``case`` that carries a unit of time (a set value, not None)."""
    out = {}
    data = case.model_dump()
    for section, fields in data.items():
        if section == "protocol" or not isinstance(fields, dict):
            continue
        for key, value in fields.items():
            unit = _unit(section, key)
            if unit is None or value is None:
                continue
            if unit not in TIME_EXPONENT:
                raise WheelsoilInputError(f"{section}.{key}: unit {unit!r} has no time exponent in TIME_EXPONENT")
            if TIME_EXPONENT[unit]:
                out[f"{section}.{key}"] = TIME_EXPONENT[unit]
    return out


def similar_case(base: CaseFile, gravity, *, keep: tuple[str, ...] = (), name: str | None = None) -> CaseFile:
    """``base`` carried to ``gravity`` (a case's gravity value: 'moon', a magnitude or a vector) by the similarity
    above: each key with a unit of time scaled by tau^exponent, tau = sqrt(g_base / g_new), the wheel's modulus (its
    preset's where the case leaves it) and the slide damper (wheel mass / 0.1 s where the case leaves it) too; the
    keys named in ``keep`` ("section.key") as they are. Drive stages ([protocol]) are refused: their times would need
    scaling too."""
    if base.protocol.stages:
        raise WheelsoilInputError("similar_case: a case with [protocol] stages is not supported (scale their times)")
    data = base.model_dump(mode="json")
    probe = validate_case(apply_overrides(data, [(["soil", "gravity"], gravity)]), "similar_case gravity")
    tau = math.sqrt(build.bed_spec(base).gravity_magnitude / build.bed_spec(probe).gravity_magnitude)
    geometry = build.wheel_geometry(base)
    implicit = {}
    if base.wheel.youngs_modulus is None:
        implicit["wheel.youngs_modulus"] = (geometry.material.youngs_modulus, TIME_EXPONENT["Pa"])
    if base.test.axle_damping is None:
        implicit["test.axle_damping"] = (wheel_mass(geometry) / AXLE_DAMPING_TIME, TIME_EXPONENT["N s/m"])
    explicit = scaled_keys(base)
    unknown = [k for k in keep if k not in explicit and k not in implicit]
    if unknown:
        raise WheelsoilInputError(f"similar_case keep={unknown}: not a key that the similarity scales "
                                  f"(those are {sorted(explicit) + sorted(implicit)})")
    overrides = [(["soil", "gravity"], gravity)]
    for dotted, exponent in explicit.items():
        if dotted in keep:
            continue
        section, key = dotted.split(".")
        overrides.append(([section, key], data[section][key] * tau**exponent))
    for dotted, (value, exponent) in implicit.items():
        section, key = dotted.split(".")
        overrides.append(([section, key], value if dotted in keep else value * tau**exponent))
    out = apply_overrides(data, overrides)
    out["case"]["name"] = name or f"{base.name}-similar"
    return validate_case(out, f"{base.name} carried to gravity {gravity!r}")
