"""Contact-force kernel: gathers, for every particle, the Hertz--Mindlin forces of its partners and walls.

Each particle sums the forces that act on it (a gather: no floating-point atomics, no scatter), so
every pair is evaluated from both sides; the two evaluations are mirror images (see
:mod:`.contact`), so action equals reaction to round-off. A two-pass variant that evaluates each
pair once, stores the result per slot and gathers it through a mirror index was measured slower on
CPU (benchmarks/README.md): the extra slot traffic costs more than the halved arithmetic.
"""


import taichi as ti

from .contact import hertz_mindlin
from .neighbors import nd_f64, nd_i32, nd_i32_2d, nd_vec3, nd_vec3_2d, vec3

nd_f64_2d = ti.types.ndarray(dtype=ti.f64, ndim=2)

#: Column layout of the per-wall property table (``wall_props[w, :]``).
WALL_E_EFF, WALL_G_EFF, WALL_BETA, WALL_MU_S, WALL_MU_R = range(5)


@ti.kernel
def contact_forces(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    radius: nd_f64,
    mass: nd_f64,
    inertia: nd_f64,
    nbr: nd_i32_2d,
    nbr_count: nd_i32,
    xi: nd_vec3_2d,
    wall_point: nd_vec3,
    wall_normal: nd_vec3,
    wall_props: nd_f64_2d,
    xi_wall: nd_vec3_2d,
    e_eff: ti.f64,
    g_eff: ti.f64,
    beta: ti.f64,
    mu_s: ti.f64,
    mu_r: ti.f64,
    dt: ti.f64,
    force: nd_vec3,
    torque: nd_vec3,
) -> ti.i32:
    """Write the contact force [N] and torque [N m] on every particle; return the number of contacts.

    Pairs are counted once (i < j); particle--wall contacts once each.
    """
    n_contacts = 0
    for i in x:
        xi_pos = x[i]
        ri = radius[i]
        mi = mass[i]
        ii = inertia[i]
        vi = v[i]
        wi = omega[i]
        f = vec3(0.0, 0.0, 0.0)
        t = vec3(0.0, 0.0, 0.0)
        for k in range(nbr_count[i]):
            j = nbr[i, k]
            d = x[j] - xi_pos
            rj = radius[j]
            reach = ri + rj
            dist2 = d.norm_sqr()
            if dist2 < reach * reach:
                dist = ti.sqrt(dist2)
                n = d / dist
                mj = mass[j]
                ij = inertia[j]
                surf_i = vi + wi.cross(ri * n)
                surf_j = v[j] + omega[j].cross(-rj * n)
                fc, tn, m_roll, xi_new = hertz_mindlin(
                    n,
                    reach - dist,
                    surf_i - surf_j,
                    wi - omega[j],
                    ri * rj / reach,
                    mi * mj / (mi + mj),
                    ii * ij / (ii + ij),
                    e_eff,
                    g_eff,
                    beta,
                    mu_s,
                    mu_r,
                    xi[i, k],
                    dt,
                )
                xi[i, k] = xi_new
                f += fc
                t += ri * tn + m_roll
                if i < j:
                    n_contacts += 1
            else:
                xi[i, k] = vec3(0.0, 0.0, 0.0)
        for w in range(wall_point.shape[0]):
            nw = wall_normal[w]
            gap = (xi_pos - wall_point[w]).dot(nw)
            if gap < ri:
                n = -nw
                fc, tn, m_roll, xi_new = hertz_mindlin(
                    n,
                    ri - gap,
                    vi + wi.cross(ri * n),
                    wi,
                    ri,
                    mi,
                    ii,
                    wall_props[w, WALL_E_EFF],
                    wall_props[w, WALL_G_EFF],
                    wall_props[w, WALL_BETA],
                    wall_props[w, WALL_MU_S],
                    wall_props[w, WALL_MU_R],
                    xi_wall[i, w],
                    dt,
                )
                xi_wall[i, w] = xi_new
                f += fc
                t += ri * tn + m_roll
                n_contacts += 1
            else:
                xi_wall[i, w] = vec3(0.0, 0.0, 0.0)
        force[i] = f
        torque[i] = t
    return n_contacts
