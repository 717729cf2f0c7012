"""Corotational 3-D Euler-Bernoulli beam: set-up (NumPy) and internal forces (Taichi).

Same EICR recipe as the shell (see ``shell.py``), after Crisfield (1990), CMAME 81, 131-150:

* current frame: e1 along the chord x_1 - x_0; e2, e3 from the reference section axes carried by the
  mean nodal rotation R_m = R_0 exp(1/2 log(R_0^T R_1));
* deformational rotations theta_a = log(T^T R_a T0); axial stretch u = (l^2 - L^2) / (l + L);
* local small-strain beam (Przemieniecki, *Theory of Matrix Structural Analysis*, sec. 5.6):
      N = EA u / L,  M_x = GJ (theta_1x - theta_0x) / L,
      [M_0y, M_1y] = EI_y / L [[4, 2], [2, 4]] [theta_0y, theta_1y]   (same for z with EI_z);
* moments through H(theta_a)^T and the projector P = I - Psi G with the spin-lever
      omega_z = (v_1 - v_0) / l,  omega_y = -(w_1 - w_0) / l,  omega_x = (theta_0x + theta_1x) / 2,
  which supplies the shear forces (M_0 + M_1) / l that balance the end moments.
"""


import taichi as ti

from wheelsoil.taichi_types import nd_f64, nd_ivec2, nd_mat3, nd_vec3, nd_vec4, vec3

from .rotation import exp_so3, log_so3, spin_jacobian_inverse


@ti.func
def beam_element(
    e: ti.i32, x: ti.template(), rot: ti.template(), ends: ti.template(), frame0: ti.template(),
    length0: ti.template(), rigidity: ti.template(), slot_f: ti.template(), slot_m: ti.template(),
    slot_base: ti.i32, write: ti.i32,
) -> ti.f64:
    """Internal forces of beam e into its two slots (if ``write``); returns its strain energy [J]."""
    n0, n1 = ends[e][0], ends[e][1]
    d = x[n1] - x[n0]
    l = d.norm()
    e1 = d / l
    r0, r1 = rot[n0], rot[n1]
    rm = r0 @ exp_so3(0.5 * log_so3(r0.transpose() @ r1))
    q = rm @ ti.Vector([frame0[e][0, 1], frame0[e][1, 1], frame0[e][2, 1]])
    e3 = e1.cross(q).normalized()
    t = ti.Matrix.cols([e1, e3.cross(e1), e3])
    tt = t.transpose()
    th0 = log_so3(tt @ r0 @ frame0[e])
    th1 = log_so3(tt @ r1 @ frame0[e])
    big_l = length0[e]
    k = rigidity[e] / big_l  # EA/L, GJ/L, EIy/L, EIz/L
    u = (l * l - big_l * big_l) / (l + big_l)
    n_ax = k[0] * u
    mx = k[1] * (th1[0] - th0[0])
    my0 = k[2] * (4.0 * th0[1] + 2.0 * th1[1])
    my1 = k[2] * (2.0 * th0[1] + 4.0 * th1[1])
    mz0 = k[3] * (4.0 * th0[2] + 2.0 * th1[2])
    mz1 = k[3] * (2.0 * th0[2] + 4.0 * th1[2])
    energy = 0.5 * (n_ax * u + mx * (th1[0] - th0[0]) + my0 * th0[1] + my1 * th1[1] + mz0 * th0[2] + mz1 * th1[2])
    if write:
        m0 = spin_jacobian_inverse(th0).transpose() @ vec3(-mx, my0, mz0)
        m1 = spin_jacobian_inverse(th1).transpose() @ vec3(mx, my1, mz1)
        mtot = m0 + m1  # the axial forces are collinear with the chord: no moment
        f0 = vec3(-n_ax, mtot[2] / l, -mtot[1] / l)
        f1 = vec3(n_ax, -mtot[2] / l, mtot[1] / l)
        m0 -= vec3(0.5 * mtot[0], 0.0, 0.0)
        m1 -= vec3(0.5 * mtot[0], 0.0, 0.0)
        slot_f[slot_base + 2 * e] = -(t @ f0)
        slot_f[slot_base + 2 * e + 1] = -(t @ f1)
        slot_m[slot_base + 2 * e] = -(t @ m0)
        slot_m[slot_base + 2 * e + 1] = -(t @ m1)
    return energy


@ti.kernel
def beam_forces(
    x: nd_vec3, rot: nd_mat3, ends: nd_ivec2, frame0: nd_mat3, length0: nd_f64, rigidity: nd_vec4,
    slot_f: nd_vec3, slot_m: nd_vec3, slot_base: ti.i32,
):
    """Internal nodal forces and moments of every beam (one slot per beam end)."""
    for e in ends:
        beam_element(e, x, rot, ends, frame0, length0, rigidity, slot_f, slot_m, slot_base, 1)


@ti.kernel
def beam_energies(
    x: nd_vec3, rot: nd_mat3, ends: nd_ivec2, frame0: nd_mat3, length0: nd_f64, rigidity: nd_vec4,
    slot_f: nd_vec3, slot_m: nd_vec3, energy: nd_f64,
):
    """Strain energy of every beam [J]."""
    for e in ends:
        energy[e] = beam_element(e, x, rot, ends, frame0, length0, rigidity, slot_f, slot_m, 0, 0)
