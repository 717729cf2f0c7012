"""Taichi kernels of the particle--wheel contact interface (see :mod:`.contact` for the physics).

The candidate lists are rebuilt by :mod:`.candidate_kernels`; here is the work of

* *every step* (:func:`wheel_contacts`, one launch), in phases, each a Taichi function:
  (0) :func:`facet_bounds` -- per facet, its plane and the ball about its centroid that holds it;
  (A) :func:`candidate_geometry` -- per active particle, set aside each candidate that a bound of (0) proves out
  of reach (:func:`surely_apart`), and classify the others by the Voronoi region of their closest point (face,
  edge, vertex); (B) :func:`counted_once` -- keep each physical contact once;
  (C) the Hertz--Mindlin law with the contact's tangential history (:func:`matched_history`), force and
  torque added to the particle, the contact's moment carried by :func:`facet_moment_forces`;
  (D) :func:`node_load` -- per surface node, gather the reactions of the contacts on its facets (a
  gather: no floating-point atomics), with the contacts' normal stiffness lumped to the nodes (the
  structure lets the held force follow the node's motion within its sub-steps, which keeps light
  nodes under stiff contacts stable); then the resultant on the wheel.
"""

import taichi as ti

from wheelsoil.graph_launch import GraphKernel
from wheelsoil.granular.contact import hertz_mindlin
from wheelsoil.taichi_types import nd_f64, nd_f64_2d, nd_i32, nd_i32_2d, nd_vec3, nd_vec3_2d, nd_vec4, vec3, vec4

from .candidate_kernels import corners as _corners
from .closest_point import EDGE_AB, EDGE_CA, FACE, VERTEX_A, closest_point_on_triangle

#: Rows of the resultant array: force and moment of this step, their running sums, sample count.
RES_FORCE, RES_MOMENT, RES_FORCE_SUM, RES_MOMENT_SUM, RES_SAMPLES = range(5)


@ti.func
def _shares_edge(edges: ti.template(), s: ti.i32, edge: ti.i32) -> ti.i32:
    return ti.cast(edges[s, 0] == edge or edges[s, 1] == edge or edges[s, 2] == edge, ti.i32)


@ti.func
def _has_node(tri: ti.template(), s: ti.i32, node: ti.i32) -> ti.i32:
    return ti.cast(tri[s, 0] == node or tri[s, 1] == node or tri[s, 2] == node, ti.i32)


#: A candidate is set aside only when a bound puts it this much [m] beyond reach: far above the round-off of the
#: bounds against the closest point's distance (positions of order 1 m carry about 1e-16 m in f64), so that every
#: candidate set aside is one the closest point would have found apart, and the results do not change.
CULL_SLACK = 1e-9


@ti.func
def facet_bounds(s: ti.i32, xw: ti.template(), tri: ti.template(), plane: ti.template(), ball: ti.template()):
    """Phase 0, facet ``s``: plane[s] = (n, n . a), the unit normal and offset [m] of its mid-surface triangle abc,
    and ball[s] = (c, R), its centroid [m] and the distance R [m] from it to the farthest corner (a ball that holds
    the triangle). A degenerate facet gets a normal of NaNs, which no bound test passes."""
    a, b, c = _corners(xw, tri, s)
    n = (b - a).cross(c - a).normalized()
    cen = (a + b + c) / 3.0
    far = ti.max((a - cen).norm_sqr(), (b - cen).norm_sqr(), (c - cen).norm_sqr())
    plane[s] = vec4(n[0], n[1], n[2], n.dot(a))
    ball[s] = vec4(cen[0], cen[1], cen[2], ti.sqrt(far))


@ti.func
def surely_apart(p: vec3, reach: ti.f64, pl: vec4, bl: vec4) -> ti.i32:
    """Whether a sphere centred at p, within ``reach`` [m] (its radius plus the facet's half thickness) of a
    touching facet, is proved apart from the facet of plane ``pl`` and ball ``bl`` (:func:`facet_bounds`): every
    point of the triangle is at least its plane's distance from p, and at least |p - c| - R."""
    off_plane = ti.abs(pl[0] * p[0] + pl[1] * p[1] + pl[2] * p[2] - pl[3])
    outside = reach + bl[3] + CULL_SLACK
    d = p - vec3(bl[0], bl[1], bl[2])
    return ti.cast(off_plane >= reach + CULL_SLACK, ti.i32) | ti.cast(d.norm_sqr() >= outside * outside, ti.i32)


@ti.func
def candidate_geometry(e: ti.i32, p: vec3, ri: ti.f64, cand: ti.template(), xw: ti.template(), tri: ti.template(),
                       half_t: ti.template(), code: ti.template(), overlap: ti.template(), normal: ti.template(),
                       bary: ti.template(), cull: ti.i32, plane: ti.template(), ball: ti.template()) -> ti.i32:
    """Phase A, candidate entry ``e`` of a sphere (centre p, radius ri): the closest feature of its facet
    (face, edge or vertex; ``code`` -1 when they do not touch), the normal from the sphere towards the wheel
    (the facet normal on the sphere's side, or along the separation) and the overlap r + h - distance. With
    ``cull``, a candidate :func:`surely_apart` gets ``code`` -1 alone (nothing reads the rest of an entry that does
    not touch); of the CMU twin's closed wheel at 75 deg, 85 % of 37,518 candidates (``benchmarks/README.md``).
    Returns 1 for a candidate set aside so, else 0."""
    s = cand[e]
    apart = 0
    if cull > 0:
        apart = surely_apart(p, ri + half_t[s], plane[s], ball[s])
    if apart:
        code[e] = -1
    else:
        _closest_feature(e, s, p, ri, xw, tri, half_t, code, overlap, normal, bary)
    return apart


@ti.func
def _closest_feature(e: ti.i32, s: ti.i32, p: vec3, ri: ti.f64, xw: ti.template(), tri: ti.template(),
                     half_t: ti.template(), code: ti.template(), overlap: ti.template(), normal: ti.template(),
                     bary: ti.template()):
    """Phase A's closest point, feature, normal and overlap of entry ``e`` (facet ``s``), as
    :func:`candidate_geometry` describes."""
    ca, cb, cc = _corners(xw, tri, s)
    w, feature = closest_point_on_triangle(p, ca, cb, cc)
    d = p - (w[0] * ca + w[1] * cb + w[2] * cc)
    reach = ri + half_t[s]
    n = vec3(0.0, 0.0, 1.0)
    depth = 0.0
    if feature == FACE:
        nf = (cb - ca).cross(cc - ca).normalized()
        sd = d.dot(nf)
        n = -nf if sd >= 0.0 else nf
        depth = reach - ti.abs(sd)
    else:
        dist = d.norm()
        if dist > 0.0:
            n = -d / dist
        depth = reach - dist
    code[e] = feature if depth > 0.0 else -1
    overlap[e] = depth
    normal[e] = n
    for k in ti.static(range(3)):
        bary[e, k] = w[k]


@ti.func
def counted_once(e: ti.i32, e0: ti.i32, e1: ti.i32, code: ti.template(), cand: ti.template(), edges: ti.template(),
                 tri: ti.template()) -> ti.i32:
    """Phase B: whether entry ``e`` is a physical contact of its own where facets share an edge or a vertex
    (Kremmer & Favier 2001): a face contact always; an edge contact unless a facet with that edge has a face
    contact or an earlier entry gave the same edge; a vertex contact unless a face or edge contact involves
    that vertex or an earlier entry gave it."""
    kept = 0
    kind = code[e]
    if kind == FACE:
        kept = 1
    elif kind >= EDGE_AB and kind <= EDGE_CA:
        edge = edges[cand[e], kind - EDGE_AB]
        kept = 1
        for e2 in range(e0, e1):
            k2 = code[e2]
            s2 = cand[e2]
            if k2 == FACE and _shares_edge(edges, s2, edge):
                kept = 0
            elif e2 < e and k2 >= EDGE_AB and k2 <= EDGE_CA and edges[s2, k2 - EDGE_AB] == edge:
                kept = 0
    elif kind >= VERTEX_A:
        node = tri[cand[e], kind - VERTEX_A]
        kept = 1
        for e2 in range(e0, e1):
            k2 = code[e2]
            s2 = cand[e2]
            if k2 == FACE and _has_node(tri, s2, node):
                kept = 0
            elif k2 >= EDGE_AB and k2 <= EDGE_CA:
                j = k2 - EDGE_AB
                if tri[s2, j] == node or tri[s2, (j + 1) % 3] == node:
                    kept = 0
            elif e2 < e and k2 >= VERTEX_A and tri[s2, k2 - VERTEX_A] == node:
                kept = 0
    return kept


@ti.func
def matched_history(i: ti.i32, n: vec3, is_face: ti.i32, n_old: ti.i32, claimed: ti.i32, hist_n: ti.template()) -> ti.i32:
    """Phase C, history matching: the unclaimed history slot of sphere ``i`` whose normal is closest to n
    (within 60 deg; a face contact matches either side), or -1 for a new contact."""
    best = -1
    best_score = 0.5  # cos 60 deg: a contact's normal turns far less in one step
    for k in range(n_old):
        if ((claimed >> k) & 1) == 0:
            score = n.dot(hist_n[i, k])
            if is_face:
                score = ti.abs(score)
            if score > best_score:
                best_score = score
                best = k
    return best


@ti.func
def facet_moment_forces(s: ti.i32, xw: ti.template(), tri: ti.template(), moment: vec3) -> vec3:
    """The vector lam whose nodal forces f_k = lam x s_k (s_k: corner k about the facet centroid) add up to
    no force and to the moment ``moment``: J lam = M with J = sum_k (|s_k|^2 I - s_k s_k^T)."""
    centroid = (xw[tri[s, 0]] + xw[tri[s, 1]] + xw[tri[s, 2]]) / 3.0
    jac = ti.Matrix.zero(ti.f64, 3, 3)
    for q in ti.static(range(3)):
        sk = xw[tri[s, q]] - centroid
        jac += sk.dot(sk) * ti.Matrix.identity(ti.f64, 3) - sk.outer_product(sk)
    return jac.inverse() @ moment


@ti.func
def node_load(u: ti.i32, nodes: ti.template(), corner_start: ti.template(), corners: ti.template(),
              facet_start: ti.template(), facet_entries: ti.template(), keep: ti.template(), bary: ti.template(),
              f_wheel: ti.template(), m_wheel: ti.template(), stiffness: ti.template(), xw: ti.template(),
              vw: ti.template(), tri: ti.template(), f_ext: ti.template(), k_ext: ti.template(),
              x_anchor: ti.template(), anchor_lead: ti.f64):
    """Phase D, surface node ``u``: gather the reactions of the kept contacts on its facets (barycentric share
    of the force, plus the moment's nodal force lam x arm) and their lumped normal stiffness; a gather, so
    no two threads write one node.

    The structure feels f - k (x - x_anchor) over its sub-steps (:func:`wheelsoil.flexwheel.integrator.node_update`).
    The anchor is the node's position carried ``anchor_lead`` seconds ahead at its present velocity, the mean of the
    positions at which the n sub-steps of the next interval evaluate the force (Delta t (n - 1) / (2 n)): so a node
    moving steadily receives exactly f on average, the force the spheres received the reaction of. Anchored at the
    present position instead, a node moving down into the soil received f plus k v Delta t (n - 1) / (2 n): the
    wheel was held up by more than the soil's reported force (issue 35: F_z below W at 1/6 g)."""
    node = nodes[u]
    f = vec3(0.0)
    stiff = 0.0
    for q in range(corner_start[u], corner_start[u + 1]):
        s = corners[q] // 3
        k = corners[q] % 3
        arm = xw[node] - (xw[tri[s, 0]] + xw[tri[s, 1]] + xw[tri[s, 2]]) / 3.0
        for j in range(facet_start[s], facet_start[s + 1]):
            e = facet_entries[j]
            if keep[e]:
                f += bary[e, k] * f_wheel[e] + m_wheel[e].cross(arm)
                stiff += bary[e, k] * stiffness[e]
    f_ext[node] = f
    k_ext[node] = stiff
    x_anchor[node] = xw[node] + anchor_lead * vw[node]


@ti.func
def kept_contact(e: ti.i32, i: ti.i32, p: vec3, ri: ti.f64, n_old: ti.i32, claimed: ti.i32, v: ti.template(),
                 omega: ti.template(), mass: ti.template(), inertia: ti.template(), cand: ti.template(),
                 code: ti.template(), bary: ti.template(), normal: ti.template(), overlap: ti.template(),
                 f_wheel: ti.template(), m_wheel: ti.template(), xi_new: ti.template(), roll_new: ti.template(),
                 stiffness: ti.template(), hist_n: ti.template(), hist_xi: ti.template(), hist_roll: ti.template(),
                 xw: ti.template(), vw: ti.template(), ww: ti.template(), inv_mass_w: ti.template(),
                 tri: ti.template(), half_t: ti.template(), e_eff: ti.f64, g_eff: ti.f64, beta: ti.f64, mu_s: ti.f64,
                 mu_r: ti.f64, rolling: ti.i32, dt: ti.f64):
    """Phase C, kept entry ``e`` of sphere ``i`` (centre p, radius ri): the Hertz--Mindlin law with the history matched
    by normal (:func:`matched_history`; ``claimed`` the slots taken so far), the reaction and its moment for the
    wheel's nodes, the normal stiffness and the new history written at ``e``. Returns the force on the sphere, n x its
    tangential force and the rolling torque (:func:`wheelsoil.granular.contact.hertz_mindlin`'s), and ``claimed`` with
    this contact's slot."""
    s = cand[e]
    n = normal[e]
    depth = overlap[e]
    best = matched_history(i, n, ti.cast(code[e] == FACE, ti.i32), n_old, claimed, hist_n)
    xi = vec3(0.0)
    roll = vec3(0.0)
    if best >= 0:
        claimed |= 1 << best
        xi = hist_xi[i, best]
        roll = hist_roll[i, best]
        if code[e] == FACE and n.dot(hist_n[i, best]) < 0.0:
            # the contact stays on the side of the shell it began on (no tunnelling)
            n = -n
            depth = 2.0 * (ri + half_t[s]) - depth
    i0 = tri[s, 0]
    i1 = tri[s, 1]
    i2 = tri[s, 2]
    b0 = bary[e, 0]
    b1 = bary[e, 1]
    b2 = bary[e, 2]
    point = b0 * xw[i0] + b1 * xw[i1] + b2 * xw[i2]
    v_wheel = b0 * vw[i0] + b1 * vw[i1] + b2 * vw[i2]
    w_wheel = b0 * ww[i0] + b1 * ww[i1] + b2 * ww[i2]
    # effective mass (eq. 13) with the wheel's apparent mass at the contact point: a force F
    # at c moves the lumped nodes by b_k F / m_k, so 1/m_c = sum b_k^2 / m_k (tied nodes: 0)
    inv_mc = b0 * b0 * inv_mass_w[i0] + b1 * b1 * inv_mass_w[i1] + b2 * b2 * inv_mass_w[i2]
    m_eff = 1.0 / (1.0 / mass[i] + inv_mc)
    fc, tn, m_roll, xi_out, roll_out = hertz_mindlin(
        n, depth, v[i] + omega[i].cross(ri * n) - v_wheel, omega[i] - w_wheel,
        ri, m_eff, inertia[i], e_eff, g_eff, beta, mu_s, mu_r, rolling, xi, roll, dt,
    )
    f_wheel[e] = -fc
    stiffness[e] = 2.0 * e_eff * ti.sqrt(ri * depth)  # S_n = dF_n/d(delta_n)
    # The moment the wheel must also receive for angular momentum to balance exactly: the
    # particle's torque about the origin is (p + r n) x F + M_roll, the wheel receives -F at
    # ``point``; it goes to the facet's nodes as a self-equilibrated set of forces (no nodal
    # moments: a shell node's small rotary inertia would make them stiff).
    m_wheel[e] = facet_moment_forces(s, xw, tri, -m_roll - (p + ri * n - point).cross(fc))
    normal[e] = n
    xi_new[e] = xi_out
    roll_new[e] = roll_out
    return fc, tn, m_roll, claimed


@ti.kernel
def wheel_contacts(
    # particles
    x: nd_vec3, v: nd_vec3, omega: nd_vec3, radius: nd_f64, mass: nd_f64, inertia: nd_f64,
    ext_force: nd_vec3, ext_torque: nd_vec3,
    # candidates
    n_active: ti.i32, active: nd_i32, start: nd_i32, cand: nd_i32,
    # per-entry scratch
    code: nd_i32, keep: nd_i32, bary: nd_f64_2d, normal: nd_vec3, overlap: nd_f64, f_wheel: nd_vec3,
    m_wheel: nd_vec3, xi_new: nd_vec3, roll_new: nd_vec3, stiffness: nd_f64,
    # contact history per particle
    hist_n: nd_vec3_2d, hist_xi: nd_vec3_2d, hist_roll: nd_vec3_2d, hist_count: nd_i32,
    # wheel
    xw: nd_vec3, vw: nd_vec3, ww: nd_vec3, inv_mass_w: nd_f64, tri: nd_i32_2d, edges: nd_i32_2d, half_t: nd_f64,
    n_cull: ti.i32, facet_plane: nd_vec4, facet_ball: nd_vec4,
    nodes: nd_i32, corner_start: nd_i32, corners: nd_i32, facet_start: nd_i32, facet_entries: nd_i32,
    f_ext: nd_vec3, k_ext: nd_f64, x_anchor: nd_vec3, node_ref: nd_vec3, hub: nd_vec3, resultant: nd_vec3,
    # contact law
    e_eff: ti.f64, g_eff: ti.f64, beta: ti.f64, mu_s: ti.f64, mu_r: ti.f64, rolling: ti.i32, dt: ti.f64,
    anchor_lead: ti.f64, stats: nd_f64,
):
    """One evaluation of every particle--wheel contact (phases A--D above, then the resultant).

    Writes to ``stats``: [0] the largest squared displacement of a surface node since the last rebuild,
    [1] the number of contacts, [2] the candidates set aside by their bounds (it runs as a compute graph, which
    cannot return values). The resultant's
    moment is taken about the hub centre, read from ``hub`` (row 0; zeros for a structure without a hub).
    ``n_cull``: the number of facets (candidates set aside by their bounds, :func:`surely_apart`), or 0 (every
    candidate's closest point found; the results are the same).
    """
    for s in range(n_cull):
        facet_bounds(s, xw, tri, facet_plane, facet_ball)
    n_contacts = 0
    n_apart = 0
    for a in range(n_active):
        i = active[a]
        p = x[i]
        ri = radius[i]
        e0 = start[i]
        e1 = start[i + 1]
        apart_here = 0
        for e in range(e0, e1):
            apart_here += candidate_geometry(e, p, ri, cand, xw, tri, half_t, code, overlap, normal, bary, n_cull,
                                             facet_plane, facet_ball)
        n_apart += apart_here
        for e in range(e0, e1):
            keep[e] = counted_once(e, e0, e1, code, cand, edges, tri)
        # (C) Hertz--Mindlin on each kept contact, history matched by contact normal
        f_total = vec3(0.0)
        t_total = vec3(0.0)
        n_old = hist_count[i]
        claimed = 0
        n_kept = 0
        for e in range(e0, e1):
            if keep[e]:
                fc, tn, m_roll, claimed = kept_contact(e, i, p, ri, n_old, claimed, v, omega, mass, inertia, cand, code,
                                                   bary, normal, overlap, f_wheel, m_wheel, xi_new, roll_new,
                                                   stiffness, hist_n, hist_xi, hist_roll, xw, vw, ww, inv_mass_w, tri,
                                                   half_t, e_eff, g_eff, beta, mu_s, mu_r, rolling, dt)
                f_total += fc
                t_total += ri * tn + m_roll
                n_kept += 1
        n_contacts += n_kept
        # the history of this step's contacts
        slots = 0
        for e in range(e0, e1):
            if keep[e] and slots < hist_n.shape[1]:
                hist_n[i, slots] = normal[e]
                hist_xi[i, slots] = xi_new[e]
                hist_roll[i, slots] = roll_new[e]
                slots += 1
        hist_count[i] = slots
        ext_force[i] += f_total
        ext_torque[i] += t_total
    largest = 0.0
    for u in nodes:
        node_load(u, nodes, corner_start, corners, facet_start, facet_entries, keep, bary, f_wheel, m_wheel,
                  stiffness, xw, vw, tri, f_ext, k_ext, x_anchor, anchor_lead)
        ti.atomic_max(largest, (xw[nodes[u]] - node_ref[u]).norm_sqr())
    # resultant on the wheel: force and moment about the hub centre (serial sum: deterministic)
    ti.loop_config(serialize=True)
    for _ in range(1):
        center = hub[0]
        f = vec3(0.0)
        m = vec3(0.0)
        for u in range(nodes.shape[0]):
            node = nodes[u]
            f += f_ext[node]
            m += (xw[node] - center).cross(f_ext[node])
        resultant[RES_FORCE] = f
        resultant[RES_MOMENT] = m
        resultant[RES_FORCE_SUM] += f
        resultant[RES_MOMENT_SUM] += m
        resultant[RES_SAMPLES] += vec3(1.0, 0.0, 0.0)
        stats[0] = largest
        stats[1] = n_contacts
        stats[2] = n_apart


#: :func:`wheel_contacts` as a compute graph (same arguments; :mod:`wheelsoil.graph_launch`).
wheel_contacts_graph = GraphKernel(wheel_contacts)
