"""Uniform-grid neighbour search with Verlet lists that carry contact history across rebuilds.

Particles are binned into cubic cells of edge ``cell_size`` >= 2 r_max + skin by a counting sort
(integer atomics only), then every particle gathers the partners within r_i + r_j + skin from the
27 surrounding cells into its own row of a fixed-width list. Rows are sorted by partner index, which
makes the force summation order -- and hence the result -- independent of the cell size and of the
thread schedule. From the rows, every pair is listed once (owner i < j) in a compact pair list that
holds the pair's tangential history; at a rebuild the history moves from the old pair list to the
new one (a merge of two sorted lists), so contacts survive any number of rebuilds. A reverse index
gives every pair its place in its partner's run of slots (runs by partner, sorted by owner), where
the force pass writes what the pair exerts on the partner (:mod:`.forces`).
"""


import taichi as ti

from wheelsoil.taichi_types import (  # noqa: F401  (re-exported to forces.py, integrator.py, scene.py)
    ivec3,
    mat23,
    nd_f64,
    nd_i32,
    nd_i32_2d,
    nd_mat23,
    nd_vec3,
    nd_vec3_2d,
    vec3,
)


@ti.func
def cell_coords(p: vec3, origin: vec3, inv_cell: ti.f64, dims: ivec3) -> ivec3:
    c = ti.cast(ti.floor((p - origin) * inv_cell), ti.i32)
    return ti.max(ti.min(c, dims - 1), 0)


@ti.kernel
def bin_particles(
    x: nd_vec3, origin: vec3, inv_cell: ti.f64, dims: ivec3, cell_of: nd_i32, cell_count: nd_i32
):
    """Cell index of every particle and the number of particles per cell."""
    for c in cell_count:
        cell_count[c] = 0
    for i in x:
        c = cell_coords(x[i], origin, inv_cell, dims)
        cid = (c[2] * dims[1] + c[1]) * dims[0] + c[0]
        cell_of[i] = cid
        ti.atomic_add(cell_count[cid], 1)


@ti.kernel
def exclusive_scan(cell_count: nd_i32, cell_start: nd_i32) -> ti.i32:
    """cell_start[c] = sum of counts before c; cell_start[n] = total, which is also returned."""
    for _ in range(1):  # one serial task
        acc = 0
        for c in range(cell_count.shape[0]):
            cell_start[c] = acc
            acc += cell_count[c]
        cell_start[cell_count.shape[0]] = acc
    return cell_start[cell_count.shape[0]]


@ti.kernel
def scatter_to_cells(cell_of: nd_i32, cell_start: nd_i32, cell_count: nd_i32, sorted_ids: nd_i32):
    """Write particle ids grouped by cell (consumes ``cell_count``)."""
    for i in cell_of:
        cid = cell_of[i]
        slot = cell_start[cid] + ti.atomic_sub(cell_count[cid], 1) - 1
        sorted_ids[slot] = i


@ti.kernel
def build_neighbor_lists(
    x: nd_vec3,
    radius: nd_f64,
    cell_start: nd_i32,
    sorted_ids: nd_i32,
    origin: vec3,
    inv_cell: ti.f64,
    dims: ivec3,
    skin: ti.f64,
    nbr: nd_i32_2d,
    nbr_count: nd_i32,
) -> ti.i32:
    """Fill each particle's row with partners j != i closer than r_i + r_j + skin, sorted by j.

    Returns the largest number of partners found for one particle; when it exceeds the row width
    the rows are truncated and the caller must widen them and call again.
    """
    width = nbr.shape[1]
    most = 0
    for i in x:
        xi = x[i]
        ri = radius[i]
        c = cell_coords(xi, origin, inv_cell, dims)
        count = 0
        for dz, dy, dx in ti.ndrange((-1, 2), (-1, 2), (-1, 2)):
            cc = c + ivec3(dx, dy, dz)
            if (cc >= 0).all() and (cc < dims).all():
                cid = (cc[2] * dims[1] + cc[1]) * dims[0] + cc[0]
                for s in range(cell_start[cid], cell_start[cid + 1]):
                    j = sorted_ids[s]
                    if j != i:
                        reach = ri + radius[j] + skin
                        if (x[j] - xi).norm_sqr() < reach * reach:
                            if count < width:
                                nbr[i, count] = j
                            count += 1
        kept = ti.min(count, width)
        # insertion sort of the (short) row by partner index
        for a in range(1, kept):
            key = nbr[i, a]
            b = a - 1
            while b >= 0 and nbr[i, b] > key:
                nbr[i, b + 1] = nbr[i, b]
                b -= 1
            nbr[i, b + 1] = key
        nbr_count[i] = kept
        ti.atomic_max(most, count)
    return most


# ---------------------------------------------------------------------------------------------
# Pair list: every listed pair once (owner i < j), stored compactly, with its tangential history,
# and the reverse index that lays the partner slots out by partner.


@ti.kernel
def count_owned(nbr: nd_i32_2d, nbr_count: nd_i32, owned: nd_i32, partnered: nd_i32):
    """owned[i] = number of row entries j > i (rows are sorted, so they are the row's tail);
    partnered[i] = the others (the pairs with an owner j < i)."""
    for i in nbr_count:
        c = 0
        for k in range(nbr_count[i]):
            if nbr[i, k] > i:
                c += 1
        owned[i] = c
        partnered[i] = nbr_count[i] - c


@ti.kernel
def fill_pairs(
    nbr: nd_i32_2d,
    nbr_count: nd_i32,
    pair_start: nd_i32,
    pair_j: nd_i32,
    pair_xi: nd_vec3,
    pair_touching: nd_i32,
    old_start: nd_i32,
    old_j: nd_i32,
    old_xi: nd_vec3,
    old_touching: nd_i32,
    n_old_particles: ti.i32,
):
    """Write the owned pairs of every particle from its sorted row, carrying each pair's history
    and touching flag from the previous pair list (a merge of two sorted lists); new pairs start
    at zero, untouched."""
    for i in nbr_count:
        p = pair_start[i]
        a = 0
        b = 0
        if i < n_old_particles:
            a = old_start[i]
            b = old_start[i + 1]
        for k in range(nbr_count[i]):
            j = nbr[i, k]
            if j > i:
                pair_j[p] = j
                while a < b and old_j[a] < j:
                    a += 1
                if a < b and old_j[a] == j:
                    pair_xi[p] = old_xi[a]
                    pair_touching[p] = old_touching[a]
                else:
                    pair_xi[p] = vec3(0.0, 0.0, 0.0)
                    pair_touching[p] = 0
                p += 1


@ti.kernel
def fill_reverse_index(
    nbr: nd_i32_2d, nbr_count: nd_i32, pair_start: nd_i32, pair_j: nd_i32, rev_start: nd_i32, pair_rev: nd_i32
):
    """pair_rev[p] = the partner slot of pair p: particle j's pairs with owners i < j get the slots
    rev_start[j], rev_start[j] + 1, ... in the order of j's sorted row (pair p of owner i is found by
    binary search in i's sorted pairs). Every pair gets exactly one slot, so no two writes collide."""
    for j in nbr_count:
        e = rev_start[j]
        for k in range(nbr_count[j]):
            i = nbr[j, k]
            if i < j:
                lo = pair_start[i]
                hi = pair_start[i + 1] - 1
                while lo < hi:
                    mid = (lo + hi) // 2
                    if pair_j[mid] < j:
                        lo = mid + 1
                    else:
                        hi = mid
                pair_rev[lo] = e
                e += 1
