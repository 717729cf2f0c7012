"""Taichi kernels that rebuild the particle--wheel candidate lists (when particles or the wheel have moved far
enough; :mod:`.contact`): bin the contact facets into the scene's uniform grid (:mod:`wheelsoil.granular.grid`, the
cells the soil's neighbour search uses), list for every particle the facets within its reach plus a skin (its
*candidates*, sorted by facet so that results do not depend on thread scheduling) and its gap to the facets it does
not list, compact the particles that have candidates into an *active* list, and transpose the candidate list per
facet. The every-step contact evaluation is :mod:`.kernels`.
"""

import taichi as ti

from wheelsoil.granular.grid import cell_coords, cell_index
from wheelsoil.granular.neighbors import sort_run
from wheelsoil.taichi_types import ivec3, nd_f64, nd_i32, nd_i32_2d, nd_ivec3, nd_vec3, vec3

from .closest_point import closest_point_on_triangle


@ti.func
def corners(xw: ti.template(), tri: ti.template(), s: ti.i32):
    return xw[tri[s, 0]], xw[tri[s, 1]], xw[tri[s, 2]]


@ti.func
def grown_cell_range(xw: ti.template(), tri: ti.template(), half_t: ti.template(), s: ti.i32, pad: ti.f64, origin: vec3,
                     inv_cell: ti.f64, dims: ivec3):
    """The first and last cell coordinates that facet s's box grown by ``pad`` [m] + its half thickness meets
    (clamped to the grid); an empty range (first > last) when the box misses the grid."""
    a, b, c = corners(xw, tri, s)
    grow = pad + half_t[s]
    mn = ti.min(a, b, c) - grow
    mx = ti.max(a, b, c) + grow
    top = origin + ti.cast(dims, ti.f64) / inv_cell
    lo = ivec3(1, 1, 1)
    hi = ivec3(0, 0, 0)
    if (mx >= origin).all() and (mn <= top).all():
        lo = cell_coords(mn, origin, inv_cell, dims)
        hi = cell_coords(mx, origin, inv_cell, dims)
    return lo, hi


@ti.kernel
def facet_cell_ranges(
    xw: nd_vec3, tri: nd_i32_2d, half_t: nd_f64, n_facets: ti.i32, pad: ti.f64, origin: vec3, inv_cell: ti.f64,
    dims: ivec3, lo: nd_ivec3, hi: nd_ivec3, cell_count: nd_i32,
):
    """Cell range of every facet's box grown by ``pad`` + half thickness; count facets per cell."""
    for c in cell_count:
        cell_count[c] = 0
    for s in range(n_facets):
        l, h = grown_cell_range(xw, tri, half_t, s, pad, origin, inv_cell, dims)
        for i, j, k in ti.ndrange((l[0], h[0] + 1), (l[1], h[1] + 1), (l[2], h[2] + 1)):
            ti.atomic_add(cell_count[cell_index(ivec3(i, j, k), dims)], 1)
        lo[s] = l
        hi[s] = h


@ti.kernel
def fill_facet_cells(
    n_facets: ti.i32, dims: ivec3, lo: nd_ivec3, hi: nd_ivec3, cell_start: nd_i32, cell_fill: nd_i32,
    cell_facets: nd_i32,
):
    for c in cell_fill:
        cell_fill[c] = 0
    for s in range(n_facets):
        l = lo[s]
        h = hi[s]
        for i, j, k in ti.ndrange((l[0], h[0] + 1), (l[1], h[1] + 1), (l[2], h[2] + 1)):
            c = cell_index(ivec3(i, j, k), dims)
            cell_facets[cell_start[c] + ti.atomic_add(cell_fill[c], 1)] = s


@ti.func
def _distance2(p: vec3, xw: ti.template(), tri: ti.template(), s: ti.i32) -> ti.f64:
    """Squared distance [m^2] from p to facet s's mid-surface triangle."""
    a, b, c = corners(xw, tri, s)
    bary, _ = closest_point_on_triangle(p, a, b, c)
    q = bary[0] * a + bary[1] * b + bary[2] * c
    return (p - q).norm_sqr()


@ti.func
def _within_reach(p: vec3, reach: ti.f64, xw: ti.template(), tri: ti.template(), s: ti.i32) -> ti.i32:
    return ti.cast(_distance2(p, xw, tri, s) < reach * reach, ti.i32)


@ti.kernel
def mark_near_cells(
    xw: nd_vec3, tri: nd_i32_2d, half_t: nd_f64, n_facets: ti.i32, pad: ti.f64, origin: vec3, inv_cell: ti.f64,
    dims: ivec3, near: nd_i32,
):
    """near[c] = 1 for every cell that some facet's box grown by ``pad`` [m] + half thickness meets, 0 elsewhere:
    a sphere inside a cell left at 0 is at least ``pad`` plus its distance to the cell's faces from every facet's
    mid-surface box (:func:`count_candidates`). Plain stores of the same value: no atomics needed."""
    for c in near:
        near[c] = 0
    for s in range(n_facets):
        lo, hi = grown_cell_range(xw, tri, half_t, s, pad, origin, inv_cell, dims)
        for i, j, k in ti.ndrange((lo[0], hi[0] + 1), (lo[1], hi[1] + 1), (lo[2], hi[2] + 1)):
            near[cell_index(ivec3(i, j, k), dims)] = 1


@ti.kernel
def count_candidates(
    x: nd_vec3, radius: nd_f64, skin: ti.f64, pad: ti.f64, far_pad: ti.f64, origin: vec3, inv_cell: ti.f64,
    dims: ivec3, cell_start: nd_i32, cell_facets: nd_i32, near: nd_i32, xw: nd_vec3, tri: nd_i32_2d, half_t: nd_f64,
    count: nd_i32, hist_count: nd_i32, wheel_gap: nd_f64,
) -> ti.i32:
    """Number of facets within radius + half thickness + ``skin`` of each particle (its candidates); returns the
    largest. A particle with no candidates forgets its wheel-contact history (it has left the wheel).

    ``wheel_gap[i]`` [m]: a lower bound on the gap from particle i to every facet it does not list, r_i and the
    facet's half thickness off the distance to its mid-surface: the least such gap among the facets binned into its
    cell (their boxes grown by ``pad``, :func:`facet_cell_ranges`), and ``pad`` + e_i - r_i for the rest, or
    ``far_pad`` + e_i - r_i where no facet's box grown by ``far_pad`` meets the cell (``near``,
    :func:`mark_near_cells`); e_i is the distance from x_i to its cell's nearest face. (A box grown by g that misses
    the cell is more than g beyond one of the cell's faces along that face's axis, so more than g + e_i from x_i.)
    A particle outside the grid (clamped into a boundary cell) gets ``skin``, the candidates' own margin."""
    most = 0
    for i in x:
        xi = x[i]
        ri = radius[i]
        cc = cell_coords(xi, origin, inv_cell, dims)
        c = cell_index(cc, dims)
        u = (xi - origin) * inv_cell - ti.cast(cc, ti.f64)
        gap = skin
        if (u >= 0.0).all() and (u <= 1.0).all():
            e = ti.min(u.min(), (1.0 - u).min()) / inv_cell
            gap = (far_pad if near[c] == 0 else pad) + e - ri
        k = 0
        for q in range(cell_start[c], cell_start[c + 1]):
            s = cell_facets[q]
            d2 = _distance2(xi, xw, tri, s)
            reach = ri + half_t[s] + skin
            if d2 < reach * reach:
                k += 1
            else:
                gap = ti.min(gap, ti.sqrt(d2) - ri - half_t[s])
        count[i] = k
        wheel_gap[i] = gap
        if k == 0:
            hist_count[i] = 0
        ti.atomic_max(most, k)
    return most


@ti.kernel
def fill_candidates(
    x: nd_vec3, radius: nd_f64, skin: ti.f64, origin: vec3, inv_cell: ti.f64, dims: ivec3, cell_start: nd_i32,
    cell_facets: nd_i32, xw: nd_vec3, tri: nd_i32_2d, half_t: nd_f64, start: nd_i32, cand: nd_i32,
):
    """Write each particle's candidate facets, sorted ascending (:func:`wheelsoil.granular.neighbors.sort_run`)."""
    for i in x:
        e0 = start[i]
        e1 = start[i + 1]
        if e1 > e0:
            c = cell_index(cell_coords(x[i], origin, inv_cell, dims), dims)
            k = e0
            for q in range(cell_start[c], cell_start[c + 1]):
                s = cell_facets[q]
                if _within_reach(x[i], radius[i] + half_t[s] + skin, xw, tri, s):
                    cand[k] = s
                    k += 1
            sort_run(cand, e0, e1)


@ti.kernel
def index_active(
    count: nd_i32, start: nd_i32, active: nd_i32, n_facets: ti.i32, cand: nd_i32, facet_start: nd_i32,
    facet_fill: nd_i32, facet_entries: nd_i32,
) -> ti.i32:
    """Compact the particles with candidates into ``active`` and list every facet's candidate entries
    (serial: the order is deterministic). Returns the number of active particles."""
    n_active = 0
    ti.loop_config(serialize=True)
    for _ in range(1):
        for s in range(n_facets + 1):
            facet_start[s] = 0
        for i in range(count.shape[0]):
            if count[i] > 0:
                active[n_active] = i
                n_active += 1
                for e in range(start[i], start[i + 1]):
                    facet_start[cand[e] + 1] += 1
        for s in range(n_facets):
            facet_start[s + 1] += facet_start[s]
            facet_fill[s] = facet_start[s]
        for a in range(n_active):
            i = active[a]
            for e in range(start[i], start[i + 1]):
                s = cand[e]
                facet_entries[facet_fill[s]] = e
                facet_fill[s] += 1
    return n_active


@ti.kernel
def copy_node_positions(xw: nd_vec3, nodes: nd_i32, ref: nd_vec3):
    for u in nodes:
        ref[u] = xw[nodes[u]]
