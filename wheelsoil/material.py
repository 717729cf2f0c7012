"""The one isotropic elastic material of wheelsoil: the soil's grains, the bin's walls and the wheel's structure.

The soil's contact law (``granular``) reads E, nu and rho for the Hertz--Mindlin pair quantities (seed 004
eqs. 10--13), and the wheel's finite elements (``flexwheel``) for their stiffness and mass; one class serves
both, so the wheel's material enters the wheel--soil contact as it is. :class:`PairProperties` holds what a
contact pair adds (restitution, sliding and rolling friction) for soil--soil, soil--wall and soil--wheel pairs.
The named values (seed 004 Tables 1--2 and the others) are in :mod:`wheelsoil.parameters`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import ClassVar

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.ranges import Range, check_ranges, non_negative, positive


#: Stiffest solid there is (diamond, about 1.2e12 Pa): above it a "modulus" is a typo, and its contact step
#: would be too small to run.
MAX_YOUNGS_MODULUS = 1.2e12


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes
    ----------
    name: label used in messages and result files.
    youngs_modulus: Young's modulus E [Pa], in (0, 1.2e12] (``math.inf`` for a rigid body).
    poisson_ratio: Poisson's ratio nu [-], in (-1, 0.5) (0.5 is incompressible, which Hertz contact cannot use).
    density: mass density rho [kg/m^3], > 0.
    """

    name: str
    youngs_modulus: float
    poisson_ratio: float
    density: float

    RANGES: ClassVar[dict[str, Range]] = {
        "youngs_modulus": positive(hi=MAX_YOUNGS_MODULUS, infinite=True),
        "poisson_ratio": Range(-1.0, 0.5, lo_open=True, hi_open=True),
        "density": positive(),
    }
    UNITS: ClassVar[dict[str, str]] = {"youngs_modulus": "Pa", "poisson_ratio": "1", "density": "kg/m^3"}

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, f"material {self.name!r}:", self.UNITS)

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def is_rigid(self) -> bool:
        return math.isinf(self.youngs_modulus)

    def to_dict(self) -> dict:
        return asdict(self)

    @property
    def wave_speed(self) -> float:
        """Plate (plane-stress) longitudinal wave speed sqrt(E / (rho (1 - nu^2))) [m/s]."""
        return math.sqrt(self.youngs_modulus / (self.density * (1.0 - self.poisson_ratio**2)))


@dataclass(frozen=True)
class PairProperties:
    """Interaction properties of a contact pair (soil--soil, soil--wall, soil--wheel).

    Attributes
    ----------
    restitution: coefficient of restitution e [-], in (0, 1] (1 is perfectly elastic).
    static_friction: Coulomb friction coefficient mu_s [-], >= 0.
    rolling_friction: rolling friction coefficient mu_r [-], >= 0 (dimensionless: the torque arm is
        mu_r * R*, as in EDEM and LIGGGHTS ``rolling_friction cdt``).
    rolling_model: the rolling-resistance law, ``"cdt"`` (constant directional torque, the default) or ``"epsd"``
        (elastic--plastic spring--dashpot, which holds a torque below mu_r F_n R* at rest); formulas in
        :mod:`wheelsoil.granular.contact`.
    """

    restitution: float
    static_friction: float
    rolling_friction: float
    rolling_model: str = "cdt"

    #: The rolling-resistance laws (their formulas: :mod:`wheelsoil.granular.contact`).
    ROLLING_MODELS: ClassVar[tuple[str, ...]] = ("cdt", "epsd")

    RANGES: ClassVar[dict[str, Range]] = {
        "restitution": positive(hi=1.0),
        "static_friction": non_negative(),
        "rolling_friction": non_negative(),
    }

    def __post_init__(self) -> None:
        check_ranges(self, self.RANGES, "contact pair")
        if self.rolling_model not in self.ROLLING_MODELS:
            raise WheelsoilInputError(f"contact pair rolling_model = {self.rolling_model!r} is not one of "
                                      f"{', '.join(self.ROLLING_MODELS)}")

    @property
    def damping_ratio(self) -> float:
        """beta of seed 004 eq. (9), returned with the sign that makes damping dissipative (>= 0)."""
        return restitution_damping_ratio(self.restitution)

    def to_dict(self) -> dict:
        d = asdict(self)
        if self.rolling_model == "cdt":  # pairs stored before the choice existed keep their form (and hashes)
            d.pop("rolling_model")
        return d


def restitution_damping_ratio(restitution: float) -> float:
    """beta = -ln e / sqrt(ln^2 e + pi^2)  (seed 004 eq. 9, sign chosen so that beta >= 0).

    With the damping force of eqs. (5)-(6) (stiffness S_n = 2 E* sqrt(R* delta_n)) the coefficient of
    restitution of a binary collision is exactly ``restitution``, independent of impact speed, as long
    as the contact ends when the overlap returns to zero (verified in tests/test_contact_verification.py).
    """
    log_e = math.log(restitution)
    return -log_e / math.sqrt(log_e * log_e + math.pi * math.pi)
