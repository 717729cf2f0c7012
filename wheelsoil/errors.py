"""Exceptions raised by wheelsoil's solvers and input checks.

Every error names the offending quantity, its value and what would have been accepted, so that a
user can fix the input without reading a traceback.
"""


class WheelsoilInputError(ValueError):
    """Bad user input: a parameter outside its allowed range, NaN in an array, a shape mismatch."""


class SimulationUnstableError(RuntimeError):
    """A run went unstable (NaN, energy blow-up, particles escaping the domain) and was stopped."""


class CapacityError(RuntimeError):
    """A fixed-size buffer (e.g. the per-particle neighbour list) overflowed."""
