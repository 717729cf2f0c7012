"""Uniform-grid neighbour search with Verlet lists that carry contact history across rebuilds.

Particles are binned into cubic cells of edge ``cell_size`` >= 2 r_max + skin by a counting sort
(integer atomics only), then every particle gathers the partners within r_i + r_j + skin from the
27 surrounding cells into its own row of a fixed-width list. Rows are sorted by partner index, which
makes the force summation order -- and hence the result -- independent of the cell size and of the
thread schedule. The tangential history of a contact moves with its partner index from the old list
to the new one (a merge of two sorted rows), so contacts survive any number of rebuilds.
"""


import taichi as ti

vec3 = ti.types.vector(3, ti.f64)
ivec3 = ti.types.vector(3, ti.i32)

nd_vec3 = ti.types.ndarray(dtype=vec3, ndim=1)
nd_vec3_2d = ti.types.ndarray(dtype=vec3, ndim=2)
nd_f64 = ti.types.ndarray(dtype=ti.f64, ndim=1)
nd_i32 = ti.types.ndarray(dtype=ti.i32, ndim=1)
nd_i32_2d = ti.types.ndarray(dtype=ti.i32, ndim=2)


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
def exclusive_scan(cell_count: nd_i32, cell_start: nd_i32):
    """cell_start[c] = sum of counts of cells before c; cell_start[n_cells] = total."""
    for _ in range(1):  # one serial task
        acc = 0
        for c in range(cell_count.shape[0]):
            cell_start[c] = acc
            acc += cell_count[c]
        cell_start[cell_count.shape[0]] = acc


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


@ti.kernel
def carry_history(
    old_nbr: nd_i32_2d,
    old_count: nd_i32,
    old_xi: nd_vec3_2d,
    new_nbr: nd_i32_2d,
    new_count: nd_i32,
    new_xi: nd_vec3_2d,
):
    """Copy each contact's tangential history to its slot in the new (sorted) rows; new pairs start at 0."""
    for i in new_count:
        a = 0
        n_old = old_count[i]
        for k in range(new_count[i]):
            j = new_nbr[i, k]
            while a < n_old and old_nbr[i, a] < j:
                a += 1
            if a < n_old and old_nbr[i, a] == j:
                new_xi[i, k] = old_xi[i, a]
            else:
                new_xi[i, k] = vec3(0.0, 0.0, 0.0)
