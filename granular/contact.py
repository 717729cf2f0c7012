"""The Hertz--Mindlin no-slip contact law with constant-directional-torque rolling resistance.

One Taichi function, :func:`hertz_mindlin`, evaluates the force and torque that a contact partner
exerts on body *i*. It is shared by particle--particle, particle--wall and (in ``coupling``)
particle--wheel contacts, so every contact in the package obeys the same documented law.

Equations (seed 004, section 2.2; same form as EDEM "Hertz-Mindlin (no slip)", LIGGGHTS
``pair_style gran model hertz tangential history rolling_friction cdt`` and Chrono DEM-Engine):

* normal elastic force            F_n^c = 4/3 E* sqrt(R*) delta_n^(3/2)                       (eq. 3)
* normal contact stiffness        S_n  = 2 E* sqrt(R* delta_n)       (= dF_n^c / d delta_n)
* normal damping                  F_n^d = 2 sqrt(5/6) beta sqrt(S_n m*) v_n                    (eq. 5)
* tangential stiffness (Mindlin)  S_t  = 8 G* sqrt(R* delta_n)                                 (eq. 8)
* tangential spring + damping     F_t = -S_t xi - 2 sqrt(5/6) beta sqrt(S_t m*) v_t            (eqs. 4, 6)
  where xi is the accumulated tangential displacement (the contact's history), rotated into the
  current tangent plane every step with its length kept, and capped by Coulomb friction:
  |F_t| <= mu_s F_n^c. The cap uses the elastic normal force: the damping part of F_n depends on the
  overlap alone times d(delta_n)/dt, so it integrates to zero over a contact and the sliding impulse
  is exactly mu_s times the normal impulse (rigid-body impact theory); and a contact in the tensile
  tail of its damped unloading carries no friction. While sliding, xi is reset so that the spring
  alone carries the capped force
  (as in LIGGGHTS ``tangential history``; resetting it to carry the force minus the damping term, as
  LAMMPS does, can point the spring against the slip when the damping alone exceeds the cap, which
  reverses the friction force at the start of a fast sliding impact).
* damping ratio                   beta = -ln e / sqrt(ln^2 e + pi^2)                            (eq. 9)
* rolling resistance (CDT)        M_r = -mu_r F_n^c R* omega_r / |omega_r|
  with omega_r the relative angular velocity projected on the tangent plane (the twisting part is
  left free, as in LIGGGHTS ``cdt``). To avoid the well-known chatter of CDT at rest, |M_r| is
  limited to I* |omega_r| / dt, the torque that stops the relative rolling within one step.

Sign conventions: ``n`` is the unit vector from body *i* towards its partner at the contact,
``v_rel`` is the velocity of *i*'s surface point relative to the partner's surface point, so the
normal approach speed is v_n = v_rel . n (> 0 while closing). Each contact is evaluated once; the
partner receives the negated force and rolling torque (see :mod:`.forces`).
"""


import math
from dataclasses import dataclass

import taichi as ti

from .materials import Material, PairProperties, effective_modulus, effective_shear_modulus

vec3 = ti.types.vector(3, ti.f64)

#: 2 sqrt(5/6), the prefactor of the damping forces (eqs. 5-6).
DAMPING_PREFACTOR = 2.0 * math.sqrt(5.0 / 6.0)


@dataclass(frozen=True)
class ContactParameters:
    """The sphere--sphere pair constants of one soil, computed once from its material and pair properties.

    e_eff, g_eff: E* and G* of two spheres of the material [Pa] (eqs. 10, 12); beta: the damping ratio of the
    restitution (eq. 9); mu_s, mu_r: sliding and rolling friction.
    """

    e_eff: float
    g_eff: float
    beta: float
    mu_s: float
    mu_r: float

    @classmethod
    def of(cls, material: Material, pair: PairProperties) -> "ContactParameters":
        return cls(effective_modulus(material, material), effective_shear_modulus(material, material),
                   pair.damping_ratio, pair.static_friction, pair.rolling_friction)


@ti.func
def hertz_mindlin(
    n: vec3,
    overlap: ti.f64,
    v_rel: vec3,
    omega_rel: vec3,
    r_eff: ti.f64,
    m_eff: ti.f64,
    inertia_eff: ti.f64,
    e_eff: ti.f64,
    g_eff: ti.f64,
    beta: ti.f64,
    mu_s: ti.f64,
    mu_r: ti.f64,
    xi: vec3,
    dt: ti.f64,
):
    """Contact force on body *i* and the pieces of the torques; returns ``(force, n_cross_ft, m_roll, xi)``.

    * ``force`` [N] acts on *i* (the partner receives ``-force``);
    * ``n_cross_ft`` = n x F_t [N]: the tangential force's torque on a body is ``arm * n_cross_ft``
      for *i* and for the partner alike (``arm`` = distance from the body's centre to the contact);
    * ``m_roll`` [N m] is the rolling-resistance torque on *i* (the partner receives ``-m_roll``);
    * ``xi`` [m] is the updated tangential history.

    Parameters (SI units): ``n`` unit normal from *i* to the partner; ``overlap`` delta_n > 0 [m];
    ``v_rel`` contact-point velocity of *i* relative to the partner [m/s]; ``omega_rel`` angular
    velocity of *i* minus that of the partner [rad/s]; ``r_eff``, ``m_eff``, ``inertia_eff`` R*, m*,
    I* [m, kg, kg m^2]; ``e_eff``, ``g_eff`` E*, G* [Pa]; ``beta`` damping ratio (eq. 9, >= 0);
    ``mu_s``, ``mu_r`` friction coefficients; ``xi`` tangential history [m]; ``dt`` time step [s].
    """
    sqrt_rd = ti.sqrt(r_eff * overlap)
    f_elastic = (4.0 / 3.0) * e_eff * sqrt_rd * overlap  # eq. 3
    s_n = 2.0 * e_eff * sqrt_rd
    s_t = 8.0 * g_eff * sqrt_rd  # eq. 8
    gamma_n = DAMPING_PREFACTOR * beta * ti.sqrt(s_n * m_eff)  # eq. 5
    gamma_t = gamma_n * ti.sqrt(4.0 * g_eff / e_eff)  # eq. 6: sqrt(S_t m*) = sqrt(S_n m*) sqrt(S_t / S_n)

    v_n = v_rel.dot(n)
    f_normal = f_elastic + gamma_n * v_n  # magnitude along -n (repulsive when > 0)
    v_t = v_rel - v_n * n

    # Carry the history into the current tangent plane, keeping its length.
    xi_t = xi - xi.dot(n) * n
    xi_t_len2 = xi_t.norm_sqr()
    if xi_t_len2 > 0.0:
        xi_t = xi_t * ti.sqrt(xi.norm_sqr() / xi_t_len2)
    xi_t += v_t * dt

    f_t = -s_t * xi_t - gamma_t * v_t  # eqs. 4 and 6
    f_t_len2 = f_t.norm_sqr()
    f_t_max = mu_s * f_elastic
    if f_t_len2 > f_t_max * f_t_max:
        f_t = f_t * (f_t_max / ti.sqrt(f_t_len2))
        if s_t > 0.0:
            xi_t = f_t * (-1.0 / s_t)

    # Rolling resistance of the constant-directional-torque type.
    m_roll = vec3(0.0, 0.0, 0.0)
    omega_r = omega_rel - omega_rel.dot(n) * n
    omega_r_len = omega_r.norm()
    if omega_r_len > 0.0:
        inv_len = 1.0 / omega_r_len
        m_roll = -ti.min(mu_r * f_elastic * r_eff * inv_len, inertia_eff / dt) * omega_r
    return -f_normal * n + f_t, n.cross(f_t), m_roll, xi_t
