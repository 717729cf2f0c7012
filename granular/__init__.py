"""Soil: a Hertz--Mindlin DEM of polydisperse spheres on Taichi, and regolith-bed preparation.

Public API::

    Scene                    spheres, walls, stepping, NumPy read-back
    Material, PairProperties materials (E, nu, rho) and pair properties (e, mu_s, mu_r)
    LUNAR_SOIL_SIMULANT, SOIL_SOIL, SOIL_STEEL, STEEL   seed-004 Table 1 defaults
    estimate_time_step       Rayleigh / Hertz stable-step estimate
    BedSpec, prepare_bed, load_bed, Bed                 soil-bed preparation with an HDF5 cache
    column_order             particle order for memory locality (prepared beds use it)
"""

from importlib import import_module

from .bed_spec import BedSpec
from .errors import CapacityError, SimulationUnstableError, WheelsoilInputError
from .materials import (
    LUNAR_SOIL_SIMULANT,
    SOIL_SOIL,
    SOIL_STEEL,
    STEEL,
    Material,
    PairProperties,
    effective_mass,
    effective_modulus,
    effective_radius,
    effective_shear_modulus,
    restitution_damping_ratio,
)
from .ordering import column_order
from .timestep import TimeStepEstimate, estimate_time_step

#: The engine's names, imported on first use (PEP 562) so that the plain descriptions above (a bed's spec, the
#: materials, the time step) load without Taichi: a case file is checked before the engine starts.
_ENGINE = {"Bed": ".bed", "BedNotSettledError": ".bed", "load_bed": ".bed", "prepare_bed": ".bed", "init": ".runtime",
           "DeviceState": ".scene", "Interaction": ".interaction", "Scene": ".scene", "Wall": ".scene"}


def __getattr__(name: str):
    if name in _ENGINE:
        value = getattr(import_module(_ENGINE[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "Bed",
    "BedNotSettledError",
    "BedSpec",
    "load_bed",
    "prepare_bed",
    "CapacityError",
    "LUNAR_SOIL_SIMULANT",
    "Material",
    "PairProperties",
    "SOIL_SOIL",
    "SOIL_STEEL",
    "STEEL",
    "DeviceState",
    "Interaction",
    "Scene",
    "SimulationUnstableError",
    "TimeStepEstimate",
    "Wall",
    "WheelsoilInputError",
    "column_order",
    "effective_mass",
    "effective_modulus",
    "effective_radius",
    "effective_shear_modulus",
    "estimate_time_step",
    "init",
    "restitution_damping_ratio",
]
