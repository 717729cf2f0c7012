"""Forces on the wheel's sides when it slides sideways (vectorised NumPy; magnitudes, against the lateral slip).

Two forms of the soil's resistance to a wheel pushed sideways, with the bearing-capacity factors they share:

* Schwanghart's sidewall resistance (seed 003 eqs. 17--19, :func:`sidewall_force`): the bearing capacity of the
  soil against the sidewall's whole depth below the surface, times |sin beta|;
* the CMU lab's side bulldozing (Pavlov, robomechanics/3d-terramechanics ``R_b.m`` and ``forces.m``, after Wong,
  *Theory of Ground Vehicles* 4th ed., 2008, the bulldozing resistance of a blade, :func:`side_bulldozing_force`):
  the soil heaped against the side face, per unit length of the face, at each contact angle theta::

      R_b(theta) = [gamma h_b^2 cot^2 X_c (1 + cot X_c tan phi / 2) / 2 + 2 c h_b cot X_c] |sin beta|,
      X_c = 45 deg - phi / 2 (the failure plane's angle),
      h_b(theta) = min(2 r cos theta, r (cos theta_r - cos theta_f) (sin theta - sin theta_r) / (sin theta_f -
                   sin theta_r) - r (cos theta_r - cos theta))   (the face's depth below the entry--exit line),
      F_b = |sin beta| int_{theta_r}^{theta_f} r cos theta R_b(theta) d theta   (|theta| <= 90 deg),
  so it grows as sin^2 beta where Schwanghart's grows as |sin beta|.

Both take the density and cohesion per condition where they are given (gravity-scaled or compacted).
"""

import numpy as np

from .quadrature import gauss_legendre, gauss_on


def bearing_capacity_factors(friction_angle_deg: float) -> tuple[float, float, float]:
    """Modified Terzaghi factors (N_gamma, N_c, N_q) of seed 003 eq. 18 (Coduto 2001)."""
    phi = np.radians(friction_angle_deg)
    n_q = np.exp((1.5 * np.pi - phi) * np.tan(phi)) / (2.0 * np.cos(np.pi / 4 + phi / 2) ** 2)
    n_gamma = 2.0 * (n_q + 1.0) * np.tan(phi) / (1.0 + 0.4 * np.sin(4.0 * phi))
    n_c = (n_q - 1.0) / np.tan(phi)
    return float(n_gamma), float(n_c), float(n_q)


def soil_state(soil, density, cohesion):
    """Per-condition density [kg/m^3] and cohesion [Pa]: the soil's, unless given (e.g. gravity-scaled or
    compacted by earlier passes, as :func:`.terramechanics.contact_forces` passes them)."""
    rho = soil.density if density is None else np.asarray(density, float)
    c = soil.cohesion if cohesion is None else np.asarray(cohesion, float)
    return rho, c


def sidewall_force(soil, wheel, sinkage, beta, gravity, density=None,
                   cohesion=None) -> np.ndarray:
    """Schwanghart's sidewall resistance (seed 003 eq. 19, surcharge q = 0) [N], magnitude.

    F_s = |sin beta| int_{-r sin theta_f}^{r sin theta_f} (gamma N_gamma f(x) + c N_c) f(x) dx with
    f(x) = sqrt(r^2 - x^2) - r cos theta_f the depth of the sidewall below the surface; ``density`` and
    ``cohesion`` override the soil's per condition.
    """
    rho, c = soil_state(soil, density, cohesion)
    r = wheel.radius
    z = np.asarray(sinkage, float)
    n_gamma, n_c, _ = bearing_capacity_factors(soil.friction_angle)
    theta_f = np.arccos(np.clip(1.0 - z / r, -1.0, 1.0))
    half = r * np.sin(theta_f)
    x, w = gauss_legendre()
    xs = half[:, None] * x[None, :]
    depth = np.clip(np.sqrt(r * r - xs * xs) - r * np.cos(theta_f)[:, None], 0.0, None)
    gamma = rho * np.asarray(gravity, float) * np.ones_like(z)
    c = c * np.ones_like(z)
    integral = np.sum(half[:, None] * w[None, :] * (gamma[:, None] * n_gamma * depth + c[:, None] * n_c) * depth,
                      axis=1)
    return np.abs(np.sin(beta)) * integral


def side_bulldozing_force(soil, wheel, theta_f, theta_r, beta, gravity, density=None, cohesion=None) -> np.ndarray:
    """The CMU lab's side bulldozing force [N], magnitude (module docstring; ``R_b.m`` with the non-Ishigami branch
    of ``forces.m``). ``theta_f``, ``theta_r`` [rad] are the contact's entry and exit angles and ``beta`` the slip
    angle [rad], per condition; the radius is the wheel's rim (``r_s`` of the lab's code)."""
    rho, c = soil_state(soil, density, cohesion)
    r = wheel.radius
    theta_f, theta_r = np.asarray(theta_f, float), np.asarray(theta_r, float)
    phi = np.radians(soil.friction_angle)
    cot_x = 1.0 / np.tan(np.pi / 4.0 - phi / 2.0)
    theta, weight = gauss_on(theta_r, theta_f, *gauss_legendre())
    tf, tr = theta_f[:, None], theta_r[:, None]
    span = np.sin(tf) - np.sin(tr)
    line = np.where(span > 0.0, (np.sin(theta) - np.sin(tr)) / np.where(span > 0.0, span, 1.0), 0.0)
    h_b = np.minimum(2.0 * r * np.cos(theta), line * r * (np.cos(tr) - np.cos(tf)) - r * (np.cos(tr) - np.cos(theta)))
    h_b = np.clip(h_b, 0.0, None)
    gamma = (rho * np.asarray(gravity, float) * np.ones_like(theta_f))[:, None]
    c = (c * np.ones_like(theta_f))[:, None]
    per_length = 0.5 * gamma * h_b**2 * cot_x**2 * (1.0 + cot_x * np.tan(phi) / 2.0) + 2.0 * c * h_b * cot_x
    per_length = np.where(np.abs(theta) <= 0.5 * np.pi, per_length, 0.0)
    sin_beta = np.abs(np.sin(np.asarray(beta, float)))
    return sin_beta**2 * np.sum(weight * r * np.cos(theta) * per_length, axis=1)
