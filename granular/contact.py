"""The Hertz--Mindlin no-slip contact law with a choice of two rolling-resistance laws.

One Taichi function, :func:`hertz_mindlin`, evaluates the force and torque that a contact partner
exerts on body *i*. It is shared by particle--particle, particle--wall and (in ``coupling``)
particle--wheel contacts, so every contact in the package obeys the same documented law.

Equations (seed 004, section 2.2; same form as EDEM "Hertz-Mindlin (no slip)", LIGGGHTS
``pair_style gran model hertz tangential history rolling_friction cdt|epsd2`` and Chrono DEM-Engine):

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

Rolling resistance acts on omega_r, the relative angular velocity projected on the tangent plane (the
twisting part is left free, as in LIGGGHTS), with the full-mobilisation torque M_m = mu_r F_n^c R*.
Two laws (:data:`ROLLING_MODELS`, chosen per contact pair by ``PairProperties.rolling_model``):

* ``"cdt"``, constant directional torque (Ai et al., Powder Technol. 206 (2011) 269, model A; EDEM's
  "rolling friction"; LIGGGHTS ``cdt``): M_r = -M_m omega_r / |omega_r|. To avoid the well-known chatter
  of CDT at rest, |M_r| is limited to I* |omega_r| / dt, the torque that stops the relative rolling
  within one step. The price: a sphere under a steady torque M below M_m never stops, it rolls at
  omega_r = M dt / I* (``docs/soillab/rolling/creep.md``), so slow loading sees less resistance than
  fast loading and the answer depends on dt.
* ``"epsd"``, elastic--plastic spring--dashpot (Ai et al. 2011, model C, eqs. 14--20, with the rolling
  stiffness of Iwashita & Oda, J. Eng. Mech. 124 (1998) 285, as in LIGGGHTS ``epsd2``):
      k_r = S_t R*^2                                   rolling stiffness [N m / rad]
      M_k <- M_k - k_r omega_r dt,   |M_k| <= M_m       spring torque (the contact's rolling history,
                                                       rotated into the tangent plane like xi)
      M_d = -2 sqrt(5/6) beta sqrt(k_r I*) omega_r      dashpot, off at full mobilisation |M_k| = M_m
      M_r = M_k + M_d
  The dashpot takes the tangential dashpot's form (eq. 6) with k_r and I* in place of S_t and m*, so the
  rolling spring has the same fraction of critical damping as the sliding one (Ai et al. take
  eta_r = 0.3 of critical; here it follows the restitution). A torque below M_m is held at rest
  whatever dt; above it the sphere rolls against M_m, as with CDT.

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

#: The rolling-resistance laws by name, and the code the kernels take for each.
ROLLING_MODELS = {"cdt": 0, "epsd": 1}
ROLLING_CDT = ROLLING_MODELS["cdt"]
ROLLING_EPSD = ROLLING_MODELS["epsd"]


@dataclass(frozen=True)
class ContactParameters:
    """The sphere--sphere pair constants of one soil, computed once from its material and pair properties.

    e_eff, g_eff: E* and G* of two spheres of the material [Pa] (eqs. 10, 12); beta: the damping ratio of the
    restitution (eq. 9); mu_s, mu_r: sliding and rolling friction; rolling: the rolling-resistance law's code
    (:data:`ROLLING_MODELS`).
    """

    e_eff: float
    g_eff: float
    beta: float
    mu_s: float
    mu_r: float
    rolling: int = ROLLING_CDT

    @classmethod
    def of(cls, material: Material, pair: PairProperties) -> "ContactParameters":
        return cls(effective_modulus(material, material), effective_shear_modulus(material, material),
                   pair.damping_ratio, pair.static_friction, pair.rolling_friction, ROLLING_MODELS[pair.rolling_model])


@ti.func
def onto_tangent_plane(h: vec3, n: vec3) -> vec3:
    """A contact's history vector carried into the tangent plane of normal ``n``, its length kept."""
    h_t = h - h.dot(n) * n
    h_t_len2 = h_t.norm_sqr()
    if h_t_len2 > 0.0:
        h_t = h_t * ti.sqrt(h.norm_sqr() / h_t_len2)
    return h_t


@ti.func
def rolling_cdt(omega_r: vec3, m_full: ti.f64, inertia_eff: ti.f64, dt: ti.f64) -> vec3:
    """The constant-directional-torque rolling resistance on *i* [N m]: -M_m omega_r / |omega_r|, limited to
    I* |omega_r| / dt (``m_full`` = M_m [N m], ``inertia_eff`` = I* [kg m^2])."""
    m_roll = vec3(0.0, 0.0, 0.0)
    omega_r_len = omega_r.norm()
    if omega_r_len > 0.0:
        inv_len = 1.0 / omega_r_len
        m_roll = -ti.min(m_full * inv_len, inertia_eff / dt) * omega_r
    return m_roll


@ti.func
def rolling_epsd(omega_r: vec3, n: vec3, m_spring: vec3, k_roll: ti.f64, m_full: ti.f64, inertia_eff: ti.f64,
                 beta: ti.f64, dt: ti.f64):
    """The elastic--plastic spring--dashpot rolling resistance (module docstring); returns ``(m_roll, m_spring)``:
    the torque on *i* [N m] and the updated spring torque (the history) [N m]. ``k_roll`` = k_r [N m/rad]."""
    m_k = onto_tangent_plane(m_spring, n) - k_roll * dt * omega_r
    m_k_len2 = m_k.norm_sqr()
    m_roll = m_k
    if m_k_len2 > m_full * m_full:
        m_k = m_k * (m_full / ti.sqrt(m_k_len2))
        m_roll = m_k
    else:
        m_roll = m_k - DAMPING_PREFACTOR * beta * ti.sqrt(k_roll * inertia_eff) * omega_r
    return m_roll, m_k


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
    rolling: ti.i32,
    xi: vec3,
    m_spring: vec3,
    dt: ti.f64,
):
    """Contact force on body *i* and the pieces of the torques; returns ``(force, n_cross_ft, m_roll, xi, m_spring)``.

    * ``force`` [N] acts on *i* (the partner receives ``-force``);
    * ``n_cross_ft`` = n x F_t [N]: the tangential force's torque on a body is ``arm * n_cross_ft``
      for *i* and for the partner alike (``arm`` = distance from the body's centre to the contact);
    * ``m_roll`` [N m] is the rolling-resistance torque on *i* (the partner receives ``-m_roll``);
    * ``xi`` [m] is the updated tangential history;
    * ``m_spring`` [N m] the updated rolling history (the EPSD spring torque; zero under CDT).

    Parameters (SI units): ``n`` unit normal from *i* to the partner; ``overlap`` delta_n > 0 [m];
    ``v_rel`` contact-point velocity of *i* relative to the partner [m/s]; ``omega_rel`` angular
    velocity of *i* minus that of the partner [rad/s]; ``r_eff``, ``m_eff``, ``inertia_eff`` R*, m*,
    I* [m, kg, kg m^2]; ``e_eff``, ``g_eff`` E*, G* [Pa]; ``beta`` damping ratio (eq. 9, >= 0);
    ``mu_s``, ``mu_r`` friction coefficients; ``rolling`` the rolling law (:data:`ROLLING_MODELS`);
    ``xi`` tangential history [m]; ``m_spring`` rolling history [N m]; ``dt`` time step [s].
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

    xi_t = onto_tangent_plane(xi, n) + v_t * dt
    f_t = -s_t * xi_t - gamma_t * v_t  # eqs. 4 and 6
    f_t_len2 = f_t.norm_sqr()
    f_t_max = mu_s * f_elastic
    if f_t_len2 > f_t_max * f_t_max:
        f_t = f_t * (f_t_max / ti.sqrt(f_t_len2))
        if s_t > 0.0:
            xi_t = f_t * (-1.0 / s_t)

    omega_r = omega_rel - omega_rel.dot(n) * n
    m_full = mu_r * f_elastic * r_eff
    m_roll = vec3(0.0, 0.0, 0.0)
    m_k = vec3(0.0, 0.0, 0.0)
    if rolling == ROLLING_EPSD:
        m_roll, m_k = rolling_epsd(omega_r, n, m_spring, s_t * r_eff * r_eff, m_full, inertia_eff, beta, dt)
    else:
        m_roll = rolling_cdt(omega_r, m_full, inertia_eff, dt)
    return -f_normal * n + f_t, n.cross(f_t), m_roll, xi_t, m_k
