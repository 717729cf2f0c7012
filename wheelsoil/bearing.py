"""Ultimate bearing pressure of a footing on a soil's friction angle and cohesion: the check that a plate's pressure in
the virtual lab is of the size soil mechanics predicts (:func:`circular_footing`), and the bound on the load a bed can
carry under a wheel, checked before a run prepares anything (:func:`rectangular_footing`, used by
``coupling.rig.check_fits``). Plain arithmetic: no solver, no Taichi.

Meyerhof (1963), "Some recent research on the bearing capacity of foundations", Can. Geotech. J. 1(1):

    q_u = c N_c s_c d_c + q N_q s_q d_q + 0.5 gamma B N_gamma s_gamma d_gamma,
    N_q = exp(pi tan phi) tan^2(45 deg + phi/2),  N_c = (N_q - 1) cot phi,  N_gamma = (N_q - 1) tan(1.4 phi),
    K_p = tan^2(45 deg + phi/2); a B x L rectangle (B <= L): s_c = 1 + 0.2 K_p B/L, s_q = s_gamma = 1 + 0.1 K_p B/L
    (phi > 10 deg), a circle of diameter B as B/L = 1; depth D: d_c = 1 + 0.2 sqrt(K_p) D/B,
    d_q = d_gamma = 1 + 0.1 sqrt(K_p) D/B (phi > 10 deg),

and Terzaghi's circular footing (Terzaghi 1943, general shear): q_u = 1.3 c N_c + q N_q + 0.3 gamma B N_gamma,
with Terzaghi's N_q = a^2 / (2 cos^2(45 deg + phi/2)), a = exp((0.75 pi - phi/2) tan phi), N_c = (N_q - 1) cot phi
and N_gamma from Kumbhojkar's (1993) fit 2 (N_q + 1) tan phi / (1 + 0.4 sin 4 phi) (Coduto's form).
q = gamma D is the overburden at the footing's depth D, gamma = rho_bulk g the unit weight [N/m^3].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from wheelsoil.errors import WheelsoilInputError


@dataclass(frozen=True)
class BearingCapacity:
    """Ultimate bearing pressure [Pa] by Meyerhof and by Terzaghi, and the factors used."""

    meyerhof: float
    terzaghi: float
    n_q: float
    n_c: float
    n_gamma: float


def _check(friction_angle_deg: float, sizes: tuple[float, ...], depth: float, cohesion: float,
           unit_weight: float) -> None:
    if not (10.0 < friction_angle_deg < 50.0):
        raise WheelsoilInputError(f"friction_angle = {friction_angle_deg!r} deg is outside the bearing-capacity "
                                  "formulas' range: 10 < friction_angle < 50 deg")
    if min(sizes) <= 0 or depth < 0 or cohesion < 0 or unit_weight <= 0:
        raise WheelsoilInputError(f"bearing capacity needs footing sizes > 0, depth >= 0, cohesion >= 0, unit weight "
                                  f"> 0; got {sizes!r} m, {depth!r} m, {cohesion!r} Pa, {unit_weight!r} N/m^3")


def _meyerhof(width: float, length: float, depth: float, phi: float, cohesion: float,
              unit_weight: float) -> tuple[float, float, float, float]:
    """Meyerhof's q_u [Pa] of a ``width`` x ``length`` rectangle (width <= length) at ``depth``, and N_q, N_c, N_gamma
    (the module's formulas; phi in radians)."""
    k_p = math.tan(math.pi / 4 + phi / 2) ** 2
    n_q = math.exp(math.pi * math.tan(phi)) * k_p
    n_c = (n_q - 1.0) / math.tan(phi)
    n_gamma = (n_q - 1.0) * math.tan(1.4 * phi)
    q = unit_weight * depth
    ratio, aspect = depth / width, width / length
    s_c, s_q = 1.0 + 0.2 * k_p * aspect, 1.0 + 0.1 * k_p * aspect
    d_c, d_q = 1.0 + 0.2 * math.sqrt(k_p) * ratio, 1.0 + 0.1 * math.sqrt(k_p) * ratio
    q_u = cohesion * n_c * s_c * d_c + q * n_q * s_q * d_q + 0.5 * unit_weight * width * n_gamma * s_q * d_q
    return q_u, n_q, n_c, n_gamma


def rectangular_footing(width: float, length: float, depth: float, friction_angle_deg: float, cohesion: float,
                        unit_weight: float) -> float:
    """Meyerhof's q_u [Pa] of a rectangular footing ``width`` x ``length`` [m] (either order: B is the shorter) at
    ``depth`` [m] below the surface, on a soil of friction angle [deg], cohesion [Pa] and unit weight [N/m^3]."""
    _check(friction_angle_deg, (width, length), depth, cohesion, unit_weight)
    short, long = sorted((width, length))
    return _meyerhof(short, long, depth, math.radians(friction_angle_deg), cohesion, unit_weight)[0]


def circular_footing(diameter: float, depth: float, friction_angle_deg: float, cohesion: float,
                     unit_weight: float) -> BearingCapacity:
    """q_u [Pa] of a circular footing of ``diameter`` [m] at ``depth`` [m] below the surface, on a soil of friction
    angle [deg], cohesion [Pa] and unit weight [N/m^3]."""
    _check(friction_angle_deg, (diameter,), depth, cohesion, unit_weight)
    phi = math.radians(friction_angle_deg)
    meyerhof, n_q, n_c, n_gamma = _meyerhof(diameter, diameter, depth, phi, cohesion, unit_weight)
    q = unit_weight * depth
    a = math.exp((0.75 * math.pi - phi / 2) * math.tan(phi))
    n_q_t = a * a / (2.0 * math.cos(math.pi / 4 + phi / 2) ** 2)
    n_c_t = (n_q_t - 1.0) / math.tan(phi)
    n_g_t = 2.0 * (n_q_t + 1.0) * math.tan(phi) / (1.0 + 0.4 * math.sin(4.0 * phi))
    terzaghi = 1.3 * cohesion * n_c_t + q * n_q_t + 0.3 * unit_weight * diameter * n_g_t
    return BearingCapacity(meyerhof, terzaghi, n_q, n_c, n_gamma)
