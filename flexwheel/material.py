"""The wheel structure's materials (linear elastic, small strain in every element's corotated frame).

The class is wheelsoil's one :class:`~wheelsoil.material.Material`; the finite elements need a finite Young's
modulus (a rigid wheel is ``wheel.rigid``, not E = inf), which :class:`~.mesh.StructureMesh` checks. The named
materials come from their parameter sets (:mod:`wheelsoil.parameters`).
"""

from wheelsoil.material import Material
from wheelsoil.parameters import exomars, seed004

#: Wheel material of seed 004 Table 2 (E = 800 MPa, nu = 0.288, rho = 7850 kg/m^3).
SEED004_WHEEL = seed004.WHEEL_MATERIAL
#: Spring steel, for the ExoMars-like wheel (sheet-metal rim and flexures).
SPRING_STEEL = exomars.SPRING_STEEL

__all__ = ["Material", "SEED004_WHEEL", "SPRING_STEEL"]
