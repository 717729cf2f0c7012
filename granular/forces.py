"""Contact-force kernels: each pair evaluated once by its owner, forces on partners gathered without atomics.

Two passes per step (Newton's third law without floating-point atomics):

1. parallel over particles i (:func:`owner_contacts`): evaluate the Hertz--Mindlin law once for
   every pair i owns (its partners j > i, a contiguous run of the compact pair list), summing the
   force and torque on i in registers, and write what the pair exerts on j -- force and torque --
   into the pair's *partner slot*; then add i's wall contacts and store i's sum;
2. parallel over particles j (:func:`partner_contacts`): add the partner slots of j's pairs with
   owners i < j. The slots are laid out by partner (the reverse index of the pair list), so each
   particle reads one contiguous run.

Both loops live in one kernel (:func:`contact_forces`); :mod:`.fused_step` composes the same two
Taichi functions with the integrator into a one-launch step for scenes without extra interactions.

Slots hold zero while a pair is apart: a pair writes its slot while it touches, and zeros once
when it separates (when its ``touching_flag`` goes from 1 to 0); the slots are zeroed whenever the
pair list is rebuilt. The force on j is the exact negative of the force on i, so action equals
reaction to the bit, and the fixed summation order (owned pairs by partner index, walls, then
partner slots by owner index) makes results deterministic and independent of the thread schedule.

This layout replaced one that stored the force on the owner in a slot per pair and gathered every
slot through an index: the owner's share now stays in registers, and only the partner's share
(48 of 72 bytes per pair) goes through memory, read back in order (benchmarks/README.md).

The particles' state comes from the *contact view* that every drift writes
(:func:`.integrator.write_contact_view`): (x, r), (v, m) and (omega, I) as 4-vectors, so a
partner's state is three 32-byte reads rather than six scattered ones, and the distance check
touches one of them.
"""

import taichi as ti

from wheelsoil.graph_launch import GraphKernel

from .contact import ROLLING_EPSD, hertz_mindlin
from .neighbors import mat23, nd_f64, nearest_image, nd_i32, nd_mat23, nd_vec3, nd_vec3_2d, nd_vec4, vec3

nd_f64_2d = ti.types.ndarray(dtype=ti.f64, ndim=2)

#: Column layout of the per-wall property table (``wall_props[w, :]``); WALL_ROLLING holds the rolling law's code
#: (:data:`.contact.ROLLING_MODELS`) as a float.
WALL_E_EFF, WALL_G_EFF, WALL_BETA, WALL_MU_S, WALL_MU_R, WALL_ROLLING = range(6)


@ti.func
def owner_contacts(
    i,
    x_r: ti.template(),
    v_m: ti.template(),
    w_i: ti.template(),
    pair_start: ti.template(),
    pair_j: ti.template(),
    pair_xi: ti.template(),
    pair_roll: ti.template(),
    pair_rev: ti.template(),
    touching_flag: ti.template(),
    partner_slot: ti.template(),
    wall_point: ti.template(),
    wall_normal: ti.template(),
    wall_props: ti.template(),
    xi_wall: ti.template(),
    roll_wall: ti.template(),
    wall_touching: ti.template(),
    wall_near: ti.template(),
    e_eff,
    g_eff,
    beta,
    mu_s,
    mu_r,
    rolling,
    dt,
    period,
    inv_period,
):
    """Force [N] and torque [N m] on particle ``i`` from the pairs it owns and from the walls, and its
    number of contacts; writes each owned pair's partner slot (force on j [N], torque on j [N m]).

    Per pair, :func:`.contact.hertz_mindlin` gives the force F on i, n x F_t and the rolling torque
    M_r on i. The tangential force acts at distance r from each centre, so i receives
    r_i (n x F_t) + M_r and j receives -F and r_j (n x F_t) - M_r. ``wall_touching[i]`` is a bit
    mask of the walls particle i touched at the last step, so a wall history is cleared once on
    separation rather than every step; ``wall_near[i]`` the mask of the walls within reach since
    the last rebuild (:func:`.neighbors.near_walls`). Only walls in either mask are checked: most
    particles of a bed are far from every wall and skip the loop. ``pair_roll``, ``roll_wall``: the rolling
    history [N m] (the EPSD spring torque), read and written only by contacts under that law (``rolling``, or the
    wall's ``WALL_ROLLING`` column), so the default law costs no memory traffic for it. ``period``, ``inv_period``: the
    periodic length along x and its inverse (0 and 0 without periodicity; :func:`.neighbors.nearest_image`).
    """
    own_x = x_r[i]
    own_v = v_m[i]
    own_w = w_i[i]
    xi_pos = own_x.xyz
    ri = own_x[3]
    vi = own_v.xyz
    mi = own_v[3]
    wi = own_w.xyz
    ii = own_w[3]
    f, t, n_contacts = owned_pairs(i, xi_pos, ri, vi, mi, wi, ii, x_r, v_m, w_i, pair_start, pair_j, pair_xi,
                                   pair_roll, pair_rev, touching_flag, partner_slot, e_eff, g_eff, beta, mu_s, mu_r,
                                   rolling, dt, period, inv_period)
    return wall_contacts(i, xi_pos, ri, vi, mi, wi, ii, f, t, n_contacts, wall_point, wall_normal, wall_props,
                         xi_wall, roll_wall, wall_touching, wall_near, dt)


@ti.func
def owned_pairs(i, xi_pos, ri, vi, mi, wi, ii, x_r: ti.template(), v_m: ti.template(), w_i: ti.template(),
                pair_start: ti.template(), pair_j: ti.template(), pair_xi: ti.template(), pair_roll: ti.template(),
                pair_rev: ti.template(), touching_flag: ti.template(), partner_slot: ti.template(), e_eff, g_eff,
                beta, mu_s, mu_r, rolling, dt, period, inv_period):
    """The pairs particle ``i`` owns (its position ``xi_pos``, radius ``ri``, velocity ``vi``, mass ``mi``, spin ``wi``,
    inertia ``ii``): force [N] and torque [N m] on i and the number touching, each pair's history and partner slot
    written (:func:`owner_contacts`)."""
    f = vec3(0.0, 0.0, 0.0)
    t = vec3(0.0, 0.0, 0.0)
    n_contacts = 0
    for p in range(pair_start[i], pair_start[i + 1]):
        j = pair_j[p]
        other_x = x_r[j]
        d = nearest_image(other_x.xyz - xi_pos, period, inv_period)
        rj = other_x[3]
        reach = ri + rj
        dist2 = d.norm_sqr()
        if dist2 < reach * reach:
            dist = ti.sqrt(dist2)
            n = d * (1.0 / dist)
            other_v = v_m[j]
            other_w = w_i[j]
            mj = other_v[3]
            ij = other_w[3]
            wj = other_w.xyz
            roll = vec3(0.0, 0.0, 0.0)
            if rolling == ROLLING_EPSD:
                roll = pair_roll[p]
            fc, tn, m_roll, xi_new, roll_new = hertz_mindlin(
                n,
                reach - dist,
                vi + wi.cross(ri * n) - (other_v.xyz + wj.cross(-rj * n)),
                wi - wj,
                ri * rj / reach,
                mi * mj / (mi + mj),
                ii * ij / (ii + ij),
                e_eff,
                g_eff,
                beta,
                mu_s,
                mu_r,
                rolling,
                pair_xi[p],
                roll,
                dt,
            )
            pair_xi[p] = xi_new
            if rolling == ROLLING_EPSD:
                pair_roll[p] = roll_new
            f += fc
            t += ri * tn + m_roll
            tj = rj * tn - m_roll
            partner_slot[pair_rev[p]] = mat23([[-fc[0], -fc[1], -fc[2]], [tj[0], tj[1], tj[2]]])
            touching_flag[p] = 1
            n_contacts += 1
        elif touching_flag[p] != 0:
            touching_flag[p] = 0
            pair_xi[p] = vec3(0.0, 0.0, 0.0)
            if rolling == ROLLING_EPSD:
                pair_roll[p] = vec3(0.0, 0.0, 0.0)
            partner_slot[pair_rev[p]] = mat23([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    return f, t, n_contacts


@ti.func
def wall_contacts(i, xi_pos, ri, vi, mi, wi, ii, f, t, n_contacts, wall_point: ti.template(),
                  wall_normal: ti.template(), wall_props: ti.template(), xi_wall: ti.template(),
                  roll_wall: ti.template(),
                  wall_touching: ti.template(), wall_near: ti.template(), dt):
    """The walls particle ``i`` touches or is near, added to its force ``f`` [N], torque ``t`` [N m] and contact count
    (in that order after its pairs, so the sums are those of one loop); its wall histories and touching mask kept
    (:func:`owner_contacts`). Returns the three."""
    mask = wall_touching[i]
    candidates = mask | wall_near[i]
    new_mask = 0
    n_walls = 0
    if candidates != 0:
        n_walls = wall_point.shape[0]
    for w in range(n_walls):
        if (candidates >> w) & 1:
            nw = wall_normal[w]
            gap = (xi_pos - wall_point[w]).dot(nw)
            if gap < ri:
                n = -nw
                wall_rolling = ti.cast(wall_props[w, WALL_ROLLING], ti.i32)
                roll = vec3(0.0, 0.0, 0.0)
                if wall_rolling == ROLLING_EPSD:
                    roll = roll_wall[i, w]
                fc, tw, m_roll, xi_new, roll_new = hertz_mindlin(
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
                    wall_rolling,
                    xi_wall[i, w],
                    roll,
                    dt,
                )
                xi_wall[i, w] = xi_new
                if wall_rolling == ROLLING_EPSD:
                    roll_wall[i, w] = roll_new
                f += fc
                t += ri * tw + m_roll
                n_contacts += 1
                new_mask |= 1 << w
            elif (mask >> w) & 1:
                xi_wall[i, w] = vec3(0.0, 0.0, 0.0)
                roll_wall[i, w] = vec3(0.0, 0.0, 0.0)
    if new_mask != mask:
        wall_touching[i] = new_mask
    return f, t, n_contacts


@ti.func
def partner_contacts(j, rev_start: ti.template(), partner_slot: ti.template()):
    """Force [N] and torque [N m] on particle ``j`` from the pairs its partners i < j own: the sum of
    its contiguous run of partner slots (zero for pairs apart)."""
    f = vec3(0.0, 0.0, 0.0)
    t = vec3(0.0, 0.0, 0.0)
    for e in range(rev_start[j], rev_start[j + 1]):
        s = partner_slot[e]
        f += vec3(s[0, 0], s[0, 1], s[0, 2])
        t += vec3(s[1, 0], s[1, 1], s[1, 2])
    return f, t


@ti.func
def add_external(j, force: ti.template(), torque: ti.template(), ext_force: ti.template(), ext_torque: ti.template()):
    """force[j] += ext_force[j], torque[j] += ext_torque[j], and clear the external arrays (interactions add
    into them afresh every step)."""
    force[j] += ext_force[j]
    torque[j] += ext_torque[j]
    ext_force[j] = vec3(0.0, 0.0, 0.0)
    ext_torque[j] = vec3(0.0, 0.0, 0.0)


@ti.kernel
def contact_forces(
    x_r: nd_vec4,
    v_m: nd_vec4,
    w_i: nd_vec4,
    pair_start: nd_i32,
    pair_j: nd_i32,
    pair_xi: nd_vec3,
    pair_roll: nd_vec3,
    pair_rev: nd_i32,
    touching_flag: nd_i32,
    partner_slot: nd_mat23,
    rev_start: nd_i32,
    wall_point: nd_vec3,
    wall_normal: nd_vec3,
    wall_props: nd_f64_2d,
    xi_wall: nd_vec3_2d,
    roll_wall: nd_vec3_2d,
    wall_touching: nd_i32,
    wall_near: nd_i32,
    e_eff: ti.f64,
    g_eff: ti.f64,
    beta: ti.f64,
    mu_s: ti.f64,
    mu_r: ti.f64,
    rolling: ti.i32,
    dt: ti.f64,
    period: ti.f64,
    inv_period: ti.f64,
    external: ti.i32,
    ext_force: nd_vec3,
    ext_torque: nd_vec3,
    force: nd_vec3,
    torque: nd_vec3,
    result: nd_f64,
):
    """Contact force [N] and torque [N m] on every particle; with ``external`` != 0 it adds the external
    contact forces and torques that interactions (a wheel) put into ``ext_force``/``ext_torque`` and clears
    them for the next step. Writes the number of contacts (touching pairs plus particle--wall contacts) to
    ``result[0]`` (it runs as a compute graph,
    :data:`contact_forces_graph`, which cannot return values). Two parallel loops, run one after the other:
    over owners (:func:`owner_contacts`), then over partners (:func:`partner_contacts`).
    """
    n_contacts = 0
    for i in x_r:
        f, t, n = owner_contacts(
            i, x_r, v_m, w_i, pair_start, pair_j, pair_xi, pair_roll, pair_rev, touching_flag,
            partner_slot, wall_point, wall_normal, wall_props, xi_wall, roll_wall, wall_touching, wall_near,
            e_eff, g_eff, beta, mu_s, mu_r, rolling, dt, period, inv_period,
        )
        force[i] = f
        torque[i] = t
        n_contacts += n
    for j in x_r:
        f, t = partner_contacts(j, rev_start, partner_slot)
        force[j] += f
        torque[j] += t
        if external != 0:
            add_external(j, force, torque, ext_force, ext_torque)
    result[0] = n_contacts


#: :func:`contact_forces` as a compute graph (same arguments; :mod:`wheelsoil.graph_launch`).
contact_forces_graph = GraphKernel(contact_forces)
