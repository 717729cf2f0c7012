"""Materials and contact-pair properties, and the effective quantities of a Hertz--Mindlin pair.

Equation numbers refer to seed 004 (DEM--FEM steering of a flexible metal wheel), section 2.2.
Defaults are its Table 1 lunar soil simulant.

Note on eqs. (10) and (12): the seed prints a minus sign between the two bodies' compliances;
Hertz theory (Johnson, *Contact Mechanics*, eq. 4.22) and Mindlin's tangential compliance add
them. The sum is what is implemented here, as in EDEM, LIGGGHTS and Chrono DEM-Engine.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from wheelsoil.material import Material

from .errors import WheelsoilInputError


@dataclass(frozen=True)
class PairProperties:
    """Interaction properties of a contact pair (soil--soil, soil--wall, soil--wheel).

    Attributes
    ----------
    restitution: coefficient of restitution e [-], in (0, 1].
    static_friction: Coulomb friction coefficient mu_s [-], >= 0.
    rolling_friction: rolling friction coefficient mu_r [-], >= 0 (dimensionless: the torque arm is
        mu_r * R*, as in EDEM and LIGGGHTS ``rolling_friction cdt``).
    """

    restitution: float
    static_friction: float
    rolling_friction: float

    def __post_init__(self) -> None:
        e = float(self.restitution)
        if not (0.0 < e <= 1.0):
            raise WheelsoilInputError(
                f"restitution e = {e!r} is invalid: it must lie in (0, 1] (1 is perfectly elastic)"
            )
        for name in ("static_friction", "rolling_friction"):
            value = float(getattr(self, name))
            if not math.isfinite(value) or value < 0.0:
                raise WheelsoilInputError(f"{name} = {value!r} is invalid: it must be a finite number >= 0")

    @property
    def damping_ratio(self) -> float:
        """beta of seed 004 eq. (9), returned with the sign that makes damping dissipative (>= 0)."""
        return restitution_damping_ratio(self.restitution)

    def to_dict(self) -> dict:
        return asdict(self)


def restitution_damping_ratio(restitution: float) -> float:
    """beta = -ln e / sqrt(ln^2 e + pi^2)  (seed 004 eq. 9, sign chosen so that beta >= 0).

    With the damping force of eqs. (5)-(6) (stiffness S_n = 2 E* sqrt(R* delta_n)) the coefficient of
    restitution of a binary collision is exactly ``restitution``, independent of impact speed, as long
    as the contact ends when the overlap returns to zero (verified in tests/test_contact_verification.py).
    """
    log_e = math.log(restitution)
    return -log_e / math.sqrt(log_e * log_e + math.pi * math.pi)


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


# ---- defaults: seed 004 Table 1 ---------------------------------------------------------------
LUNAR_SOIL_SIMULANT = Material("lunar soil simulant", youngs_modulus=50e6, poisson_ratio=0.3, density=3200.0)
"""Seed 004 Table 1: rho = 3200 kg/m^3, E = 50 MPa, nu = 0.3."""

STEEL = Material("steel", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
"""Structural steel for bin walls."""

SOIL_SOIL = PairProperties(restitution=0.5, static_friction=0.42, rolling_friction=0.11)
"""Seed 004 Table 1: lunar soil simulant -- lunar soil simulant."""

SOIL_STEEL = PairProperties(restitution=0.5, static_friction=0.39, rolling_friction=0.15)
"""Seed 004 Table 1: lunar soil simulant -- steel."""
