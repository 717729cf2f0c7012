"""Linear-elastic material of the wheel structure (small strain in every element's corotated frame)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class ElasticMaterial:
    """Isotropic linear-elastic material.

    Attributes
    ----------
    youngs_modulus: E [Pa], > 0.
    poisson_ratio: nu [-], in (-1, 0.5).
    density: rho [kg/m^3], > 0.
    """

    youngs_modulus: float
    poisson_ratio: float
    density: float
    name: str = "material"

    def __post_init__(self) -> None:
        e, nu, rho = self.youngs_modulus, self.poisson_ratio, self.density
        if not (math.isfinite(e) and e > 0):
            raise WheelsoilInputError(f"{self.name}: youngs_modulus={e!r} Pa must be finite and > 0")
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise WheelsoilInputError(f"{self.name}: poisson_ratio={nu!r} must lie in (-1, 0.5)")
        if not (math.isfinite(rho) and rho > 0):
            raise WheelsoilInputError(f"{self.name}: density={rho!r} kg/m^3 must be finite and > 0")

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) [Pa]."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def wave_speed(self) -> float:
        """Plate (plane-stress) longitudinal wave speed sqrt(E / (rho (1 - nu^2))) [m/s]."""
        return math.sqrt(self.youngs_modulus / (self.density * (1.0 - self.poisson_ratio**2)))


#: Wheel material of seed 004 Table 2 (E = 800 MPa, nu = 0.288, rho = 7850 kg/m^3).
SEED004_WHEEL = ElasticMaterial(800e6, 0.288, 7850.0, name="seed-004 wheel material")
#: Spring steel, for the ExoMars-like wheel (sheet-metal rim and flexures).
SPRING_STEEL = ElasticMaterial(200e9, 0.29, 7850.0, name="spring steel")
