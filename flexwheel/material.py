"""The wheel structure's materials (linear elastic, small strain in every element's corotated frame).

The class is wheelsoil's one :class:`~wheelsoil.material.Material`; the finite elements need a finite Young's
modulus (a rigid wheel is ``wheel.rigid``, not E = inf), which :class:`~.mesh.StructureMesh` checks.
"""

from wheelsoil.material import Material

#: Wheel material of seed 004 Table 2 (E = 800 MPa, nu = 0.288, rho = 7850 kg/m^3).
SEED004_WHEEL = Material("seed-004 wheel material", youngs_modulus=800e6, poisson_ratio=0.288, density=7850.0)
#: Spring steel, for the ExoMars-like wheel (sheet-metal rim and flexures).
SPRING_STEEL = Material("spring steel", youngs_modulus=200e9, poisson_ratio=0.29, density=7850.0)

__all__ = ["Material", "SEED004_WHEEL", "SPRING_STEEL"]
