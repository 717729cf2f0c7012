"""Soil: a Hertz--Mindlin DEM of polydisperse spheres on Taichi, and regolith-bed preparation.

Public API::

    Scene                    spheres, walls, stepping, NumPy read-back
    Material, PairProperties materials (E, nu, rho) and pair properties (e, mu_s, mu_r)
    LUNAR_SOIL_SIMULANT, SOIL_SOIL, SOIL_STEEL, STEEL   seed-004 Table 1 defaults
    estimate_time_step       Rayleigh / Hertz stable-step estimate
    BedSpec, prepare_bed, load_bed, Bed                 soil-bed preparation with an HDF5 cache
    column_order             particle order for memory locality (prepared beds use it)
"""

from .bed import Bed, BedNotSettledError, BedSpec, load_bed, prepare_bed
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
from .runtime import init
from .scene import DeviceState, Interaction, Scene, Wall
from .timestep import TimeStepEstimate, estimate_time_step

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
