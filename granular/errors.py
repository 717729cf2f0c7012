"""Exceptions of the soil solver (shared with the rest of the package; defined in ``wheelsoil.errors``)."""

from wheelsoil.errors import CapacityError, SimulationUnstableError, WheelsoilInputError

__all__ = ["CapacityError", "SimulationUnstableError", "WheelsoilInputError"]
