"""The one isotropic elastic material of wheelsoil: the soil's grains, the bin's walls and the wheel's structure.

The soil's contact law (``granular``) reads E, nu and rho for the Hertz--Mindlin pair quantities (seed 004
eqs. 10--13), and the wheel's finite elements (``flexwheel``) for their stiffness and mass; one class serves
both, so the wheel's material enters the wheel--soil contact as it is.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from wheelsoil.errors import WheelsoilInputError


def _finite_positive(name: str, value: float, unit: str) -> float:
    value = float(value)
    if not math.isfinite(value) or value <= 0.0:
        raise WheelsoilInputError(f"{name} = {value!r} {unit} is invalid: it must be a finite number > 0")
    return value


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material.

    Attributes
    ----------
    name: label used in messages and result files.
    youngs_modulus: Young's modulus E [Pa], > 0 (``math.inf`` for a rigid body).
    poisson_ratio: Poisson's ratio nu [-], in (-1, 0.5).
    density: mass density rho [kg/m^3], > 0.
    """

    name: str
    youngs_modulus: float
    poisson_ratio: float
    density: float

    def __post_init__(self) -> None:
        E = float(self.youngs_modulus)
        if math.isnan(E) or E <= 0.0:
            raise WheelsoilInputError(
                f"material {self.name!r}: youngs_modulus E = {E!r} Pa is invalid: it must be > 0"
            )
        nu = float(self.poisson_ratio)
        if not (-1.0 < nu < 0.5):
            raise WheelsoilInputError(
                f"material {self.name!r}: poisson_ratio nu = {nu!r} is invalid: "
                "it must lie in (-1, 0.5) (0.5 is incompressible, which Hertz contact cannot use)"
            )
        _finite_positive(f"material {self.name!r}: density", self.density, "kg/m^3")

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
