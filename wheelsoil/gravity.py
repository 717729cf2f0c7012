"""The gravity levels wheelsoil names, in one place (every layer takes them from here).

Seed 004 tests its wheel at Earth gravity and at one sixth of it (the Moon, 1.635 m/s^2 with g = 9.81), with
the load scaled so that the wheel's mass is the same; cases, plots, sweeps and the validation reports all name
a gravity by :func:`gravity_name`.
"""

from __future__ import annotations

#: Standard gravity as the seeds use it [m/s^2].
EARTH_GRAVITY = 9.81
#: Seed 004's Moon gravity, one sixth of Earth's [m/s^2].
MOON_GRAVITY = EARTH_GRAVITY / 6.0
#: Names a case file or the command line accepts for a gravity magnitude.
GRAVITY_PRESETS = {"earth": EARTH_GRAVITY, "moon": MOON_GRAVITY}
#: Short labels of the named levels in tables and plots.
GRAVITY_LABELS = {"earth": "1g", "moon": "1/6 g"}


def gravity_name(g: float, tolerance: float = 0.05) -> str | None:
    """``"earth"`` or ``"moon"`` when the magnitude ``g`` [m/s^2] is within ``tolerance`` of that level, else
    None."""
    for name, value in GRAVITY_PRESETS.items():
        if abs(abs(float(g)) - value) < tolerance:
            return name
    return None


def gravity_label(g: float, *, moon: str | None = None, other: str = "{g:.3g} m/s²") -> str:
    """A short label of the magnitude ``g``: "1g", "1/6 g" (or ``moon``) for the named levels, else ``other``
    formatted with ``g``."""
    name = gravity_name(g)
    if name is None:
        return other.format(g=abs(float(g)))
    return moon if (name == "moon" and moon is not None) else GRAVITY_LABELS[name]
