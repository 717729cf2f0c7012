"""Quantities with units in case files.

A case-file value is a plain number in the key's documented unit (SI, angles in degrees), or a
string "<number> <unit>" in any unit of the same dimension, converted on reading:

    drive_time = 0.6          # s
    drive_time = "600 ms"     # the same
    load = "3 kN"             # 3000 N
    slip = "30 %"             # 0.3

A unit of the wrong dimension ("3 kN" for a time) is an error that names the units allowed.
"""

from __future__ import annotations

import argparse
import math
import re

from wheelsoil.gravity import GRAVITY_PRESETS

#: For each canonical unit of a case key, the units it may be written in and their factor to it.
UNITS: dict[str, dict[str, float]] = {
    "m": {"m": 1.0, "cm": 1e-2, "mm": 1e-3},
    "s": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "N": {"N": 1.0, "kN": 1e3},
    "deg": {"deg": 1.0, "rad": 180.0 / math.pi},
    "Pa": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9},
    "kg": {"kg": 1.0, "g": 1e-3},
    "kg/m^3": {"kg/m^3": 1.0, "g/cm^3": 1e3},
    "m/s": {"m/s": 1.0, "mm/s": 1e-3, "cm/s": 1e-2},
    "m/s^2": {"m/s^2": 1.0},
    "rad/s": {"rad/s": 1.0, "rpm": 2.0 * math.pi / 60.0, "deg/s": math.pi / 180.0},
    "1/s": {"1/s": 1.0},
    "N s/m": {"N s/m": 1.0, "kN s/m": 1e3},
    "1": {"1": 1.0, "%": 1e-2},
}

_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)?\s*$")


class UnitError(ValueError):
    """A value whose unit does not fit its key (the message names the allowed units)."""


def to_unit(value, unit: str):
    """``value`` (a number, or a "<number> <unit>" string) in ``unit``; other values pass unchanged.

    Raises :class:`UnitError` for a string that is not a number with a unit of ``unit``'s dimension.
    """
    if not isinstance(value, str):
        return value
    allowed = UNITS[unit]
    match = _QUANTITY.match(value)
    if match is None:
        if unit == "1":
            raise UnitError(f"{value!r} is not a number (or a percentage such as '30 %')")
        raise UnitError(f"{value!r} is not a number, or a number with a unit ({', '.join(allowed)})")
    number, written = float(match.group(1)), (match.group(2) or unit)
    written = written.replace("²", "^2").replace("³", "^3").replace("·", " ")
    if written not in allowed:
        raise UnitError(f"unit {written!r} does not fit this key; write it in {', '.join(allowed)}")
    factor = allowed[written]
    inverse = 1.0 / factor
    if factor < 1.0 and abs(inverse - round(inverse)) < 1e-9:
        return number / round(inverse)  # "37.5 mm" -> 0.0375 exactly as written in metres
    return number * factor


def gravity_argument(value: str) -> float:
    """A command line's gravity: a preset name of :data:`wheelsoil.gravity.GRAVITY_PRESETS` or a magnitude in
    m/s^2 in (0, 1000) (an ``argparse`` type: bad values raise ``ArgumentTypeError`` naming them)."""
    if value in GRAVITY_PRESETS:
        return GRAVITY_PRESETS[value]
    try:
        g = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"gravity {value!r} is neither a preset {sorted(GRAVITY_PRESETS)} nor a number in m/s^2"
        ) from None
    if not (0 < g < 1000):
        raise argparse.ArgumentTypeError(f"gravity {g} m/s^2 must lie in (0, 1000)")
    return g
