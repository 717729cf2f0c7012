"""Allowed ranges of input values, declared once and checked in one place.

Every spec of the solver (:class:`~wheelsoil.material.Material`, :class:`~wheelsoil.material.PairProperties`,
``BedSpec``, ``WheelGeometry``, ``TestbedSpec``) declares the range of each of its scalar inputs as a
:class:`Range` in a ``RANGES`` table and checks itself with :func:`check_ranges` when it is made. The case
schema (``wheelsoil.cases.schema``) does not restate them: its fields take their pydantic bounds from the same
``Range`` (:meth:`Range.limits`), so ``wheelsoil case show``, a case file's error message and an API call
name the same range, and a range changes in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class Range:
    """An interval of allowed values: ``lo`` < or <= value < or <= ``hi`` (None: unbounded on that side).

    ``integer``: the value must be a whole number. ``infinite``: ``math.inf`` is allowed beyond ``hi`` in the
    API (a rigid wall's Young's modulus; not in a case file, see :meth:`limits`). Values must be finite numbers
    otherwise (NaN never passes).
    """

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False
    infinite: bool = False

    def contains(self, value) -> bool:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return False
        if self.integer and (not float(value).is_integer()):
            return False
        v = float(value)
        if self.infinite and v == math.inf:
            return True
        if not math.isfinite(v):
            return False
        if self.lo is not None and (v <= self.lo if self.lo_open else v < self.lo):
            return False
        if self.hi is not None and (v >= self.hi if self.hi_open else v > self.hi):
            return False
        return True

    def describe(self, key: str) -> str:
        """The range as text, e.g. ``-1 <= slip < 1``, ``an integer 1 <= steady_checks <= 10``."""
        left = "" if self.lo is None else f"{self.lo:g} {'<' if self.lo_open else '<='} "
        right = "" if self.hi is None else f" {'<' if self.hi_open else '<='} {self.hi:g}"
        text = f"{left}{key}{right}" if (left or right) else f"{key} finite"
        if self.integer:
            text = f"an integer {text}"
        if self.infinite:
            text += " (or inf)"
        return text

    def check(self, owner: str, key: str, value, unit: str = "") -> None:
        """Raise :class:`WheelsoilInputError` naming ``owner``, ``key``, the value and the range unless the
        value lies in it."""
        if not self.contains(value):
            unit_text = f" {unit}" if unit and unit != "1" else ""
            in_unit = f" ({unit})" if unit_text else ""
            raise WheelsoilInputError(
                f"{owner} {key} = {value!r}{unit_text} is out of range: allowed {self.describe(key)}{in_unit}")

    def limits(self) -> dict:
        """The bounds as pydantic ``Field`` keywords (gt/ge/lt/le)."""
        out = {}
        if self.lo is not None:
            out["gt" if self.lo_open else "ge"] = self.lo
        if self.hi is not None:  # a case never takes inf (a rigid wheel is wheel.rigid)
            out["lt" if self.hi_open else "le"] = self.hi
        return out


def positive(**kw) -> Range:
    """0 < value."""
    return Range(lo=0.0, lo_open=True, **kw)


def non_negative(**kw) -> Range:
    """0 <= value."""
    return Range(lo=0.0, **kw)


def check_ranges(obj, ranges: dict[str, Range], owner: str, units: dict[str, str] | None = None) -> None:
    """Check every attribute of ``obj`` named in ``ranges`` (None values are skipped: "use the default")."""
    units = units or {}
    for key, rng in ranges.items():
        value = getattr(obj, key)
        if value is not None:
            rng.check(owner, key, value, units.get(key, ""))
