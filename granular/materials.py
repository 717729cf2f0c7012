"""Materials and contact-pair properties, and the effective quantities of a Hertz--Mindlin pair.

Equation numbers refer to seed 004 (DEM--FEM steering of a flexible metal wheel), section 2.2.
The classes live in :mod:`wheelsoil.material`, the named values (its Table 1) in
:mod:`wheelsoil.parameters.seed004`; both are re-exported here.

Note on eqs. (10) and (12): the seed prints a minus sign between the two bodies' compliances;
Hertz theory (Johnson, *Contact Mechanics*, eq. 4.22) and Mindlin's tangential compliance add
them. The sum is what is implemented here, as in EDEM, LIGGGHTS and Chrono DEM-Engine.
"""

from __future__ import annotations

from wheelsoil.material import Material, PairProperties, restitution_damping_ratio
from wheelsoil.parameters import seed004

__all__ = ["Material", "PairProperties", "restitution_damping_ratio", "effective_modulus", "effective_shear_modulus",
           "effective_radius", "effective_mass", "LUNAR_SOIL_SIMULANT", "STEEL", "SOIL_SOIL", "SOIL_STEEL"]


def effective_modulus(a: Material, b: Material | None) -> float:
    """E* from 1/E* = (1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b [Pa] (seed 004 eq. 10; ``b=None`` is rigid)."""
    compliance = (1.0 - a.poisson_ratio**2) / a.youngs_modulus
    if b is not None and not b.is_rigid:
        compliance += (1.0 - b.poisson_ratio**2) / b.youngs_modulus
    return 1.0 / compliance


def effective_shear_modulus(a: Material, b: Material | None) -> float:
    """G* from 1/G* = (2 - nu_a)/G_a + (2 - nu_b)/G_b [Pa] (seed 004 eq. 12; ``b=None`` is rigid)."""
    compliance = (2.0 - a.poisson_ratio) / a.shear_modulus
    if b is not None and not b.is_rigid:
        compliance += (2.0 - b.poisson_ratio) / b.shear_modulus
    return 1.0 / compliance


def effective_radius(r_a: float, r_b: float | None) -> float:
    """R* from 1/R* = 1/R_a + 1/R_b [m] (seed 004 eq. 11; ``r_b=None`` is a flat wall, R* = R_a)."""
    return r_a if r_b is None else r_a * r_b / (r_a + r_b)


def effective_mass(m_a: float, m_b: float | None) -> float:
    """m* from 1/m* = 1/m_a + 1/m_b [kg] (seed 004 eq. 13; ``m_b=None`` is an immovable wall)."""
    return m_a if m_b is None else m_a * m_b / (m_a + m_b)


# ---- the named values, from their parameter set (seed 004 Table 1; re-exported for the granular API)
LUNAR_SOIL_SIMULANT = seed004.SOIL
STEEL = seed004.BIN_WALLS
SOIL_SOIL = seed004.SOIL_SOIL
SOIL_STEEL = seed004.SOIL_STEEL
