"""Contact-force kernels: each pair evaluated once, forces gathered per particle without atomics.

Two passes per step (Newton's third law without floating-point atomics):

1. parallel over the compact pair list (owner i < j): evaluate the Hertz--Mindlin law once per
   pair and store the force on i, the tangential moment n x F_t and the rolling torque on i in the
   pair's slot;
2. parallel over particles: sum the slots of each particle's pairs through its gather index (with
   the opposite sign for pairs its partner owns), in sorted row order, then add its wall contacts.

Both loops live in one kernel (:func:`contact_forces`), built from two Taichi functions,
:func:`evaluate_pair` and :func:`sum_particle_contacts`, which :mod:`.fused_step` also composes with
the integrator into a one-launch step for scenes without extra interactions.

The force on j is the exact negative of the force on i, so action equals reaction to the bit, and
the fixed summation order makes results deterministic. The compact slot array (72 bytes per pair)
stays in the last-level cache between the passes; an earlier layout with per-row padded slots did
not, and evaluating every pair from both sides was faster than it (benchmarks/README.md).
"""

import taichi as ti

from .contact import hertz_mindlin
from .neighbors import mat3, nd_f64, nd_i32, nd_mat3, nd_vec3, nd_vec3_2d, vec3

nd_f64_2d = ti.types.ndarray(dtype=ti.f64, ndim=2)

#: Column layout of the per-wall property table (``wall_props[w, :]``).
WALL_E_EFF, WALL_G_EFF, WALL_BETA, WALL_MU_S, WALL_MU_R = range(5)


@ti.func
def evaluate_pair(
    p,
    x: ti.template(),
    v: ti.template(),
    omega: ti.template(),
    radius: ti.template(),
    mass: ti.template(),
    inertia: ti.template(),
    pair_i: ti.template(),
    pair_j: ti.template(),
    pair_xi: ti.template(),
    slot: ti.template(),
    touching_flag: ti.template(),
    e_eff,
    g_eff,
    beta,
    mu_s,
    mu_r,
    dt,
) -> ti.i32:
    """Evaluate pair ``p`` of the pair list once; returns 1 if its spheres touch.

    Slot rows: force on i [N], n x F_t [N], rolling torque on i [N m]; ``touching_flag[p]`` says
    whether the slot holds this step's force (a separated pair only clears its flag and, once, its
    history: no zero slot is written).
    """
    touching = 0
    i = pair_i[p]
    j = pair_j[p]
    d = x[j] - x[i]
    ri = radius[i]
    rj = radius[j]
    reach = ri + rj
    dist2 = d.norm_sqr()
    if dist2 < reach * reach:
        dist = ti.sqrt(dist2)
        n = d * (1.0 / dist)
        mi = mass[i]
        mj = mass[j]
        ii = inertia[i]
        ij = inertia[j]
        surf_i = v[i] + omega[i].cross(ri * n)
        surf_j = v[j] + omega[j].cross(-rj * n)
        fc, tn, m_roll, xi_new = hertz_mindlin(
            n,
            reach - dist,
            surf_i - surf_j,
            omega[i] - omega[j],
            ri * rj / reach,
            mi * mj / (mi + mj),
            ii * ij / (ii + ij),
            e_eff,
            g_eff,
            beta,
            mu_s,
            mu_r,
            pair_xi[p],
            dt,
        )
        pair_xi[p] = xi_new
        slot[p] = mat3([[fc[0], fc[1], fc[2]], [tn[0], tn[1], tn[2]], [m_roll[0], m_roll[1], m_roll[2]]])
        touching_flag[p] = 1
        touching = 1
    elif touching_flag[p] != 0:
        touching_flag[p] = 0
        pair_xi[p] = vec3(0.0, 0.0, 0.0)
    return touching


@ti.func
def sum_particle_contacts(
    i,
    x: ti.template(),
    v: ti.template(),
    omega: ti.template(),
    radius: ti.template(),
    mass: ti.template(),
    inertia: ti.template(),
    slot: ti.template(),
    touching_flag: ti.template(),
    gather_start: ti.template(),
    gather: ti.template(),
    wall_point: ti.template(),
    wall_normal: ti.template(),
    wall_props: ti.template(),
    xi_wall: ti.template(),
    wall_touching: ti.template(),
    dt,
):
    """Contact force [N] and torque [N m] on particle ``i`` and its number of wall contacts.

    Sums the slots of the particle's pairs through its gather index (negated for pairs its partner
    owns: the tangential force acts at distance r from each centre, so both bodies receive
    r (n x F_t); the rolling torque is +M on the owner and -M on the partner), then adds its wall
    contacts. ``wall_touching[i]`` is a bit mask of the walls particle i touched at the last step,
    so a wall history is cleared once on separation rather than every step.
    """
    ri = radius[i]
    f = vec3(0.0, 0.0, 0.0)
    tn = vec3(0.0, 0.0, 0.0)
    roll = vec3(0.0, 0.0, 0.0)
    for e in range(gather_start[i], gather_start[i + 1]):
        q = gather[e]
        if touching_flag[q >> 1] != 0:
            s = slot[q >> 1]
            sign = 1.0 - 2.0 * ti.cast(q & 1, ti.f64)
            f += sign * vec3(s[0, 0], s[0, 1], s[0, 2])
            tn += vec3(s[1, 0], s[1, 1], s[1, 2])
            roll += sign * vec3(s[2, 0], s[2, 1], s[2, 2])
    t = ri * tn + roll
    xi_pos = x[i]
    mask = wall_touching[i]
    new_mask = 0
    n_walls = 0
    for w in range(wall_point.shape[0]):
        nw = wall_normal[w]
        gap = (xi_pos - wall_point[w]).dot(nw)
        if gap < ri:
            n = -nw
            fc, tw, m_roll, xi_new = hertz_mindlin(
                n,
                ri - gap,
                v[i] + omega[i].cross(ri * n),
                omega[i],
                ri,
                mass[i],
                inertia[i],
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
            t += ri * tw + m_roll
            n_walls += 1
            new_mask |= 1 << w
        elif (mask >> w) & 1:
            xi_wall[i, w] = vec3(0.0, 0.0, 0.0)
    if new_mask != mask:
        wall_touching[i] = new_mask
    return f, t, n_walls


@ti.kernel
def contact_forces(
    x: nd_vec3,
    v: nd_vec3,
    omega: nd_vec3,
    radius: nd_f64,
    mass: nd_f64,
    inertia: nd_f64,
    pair_i: nd_i32,
    pair_j: nd_i32,
    pair_xi: nd_vec3,
    n_pairs: ti.i32,
    slot: nd_mat3,
    touching_flag: nd_i32,
    gather_start: nd_i32,
    gather: nd_i32,
    wall_point: nd_vec3,
    wall_normal: nd_vec3,
    wall_props: nd_f64_2d,
    xi_wall: nd_vec3_2d,
    wall_touching: nd_i32,
    e_eff: ti.f64,
    g_eff: ti.f64,
    beta: ti.f64,
    mu_s: ti.f64,
    mu_r: ti.f64,
    dt: ti.f64,
    force: nd_vec3,
    torque: nd_vec3,
) -> ti.i32:
    """Contact force [N] and torque [N m] on every particle; returns the number of contacts
    (touching pairs plus particle--wall contacts). Two parallel loops, run one after the other:
    over the pair list (:func:`evaluate_pair`), then over particles (:func:`sum_particle_contacts`).
    """
    n_contacts = 0
    for p in range(n_pairs):
        n_contacts += evaluate_pair(
            p, x, v, omega, radius, mass, inertia, pair_i, pair_j, pair_xi, slot, touching_flag,
            e_eff, g_eff, beta, mu_s, mu_r, dt,
        )
    for i in x:
        f, t, n_walls = sum_particle_contacts(
            i, x, v, omega, radius, mass, inertia, slot, touching_flag, gather_start, gather,
            wall_point, wall_normal, wall_props, xi_wall, wall_touching, dt,
        )
        force[i] = f
        torque[i] = t
        n_contacts += n_walls
    return n_contacts
