"""Uniform-grid neighbour search with Verlet lists that carry contact history across rebuilds.

Particles are binned into the cells of the scene's :class:`~.grid.UniformGrid` (edge ``cell_size`` >= 2 r_max +
skin) by a counting sort
(integer atomics only), then every particle gathers the partners j > i within r_i + r_j + skin from
the 27 surrounding cells into its own row of a fixed-width list (each pair once: its owner is the
lower index). Rows are sorted by partner index, which makes the force summation order -- and hence
the result -- independent of the cell size and of the thread schedule. The rows become a compact
pair list that holds each pair's tangential history; at a rebuild the history moves from the old
pair list to the new one (a merge of two sorted lists), so contacts survive any number of rebuilds.
A reverse index gives every pair its place in its partner's run of slots (runs by partner, sorted
by owner), where the force pass writes what the pair exerts on the partner (:mod:`.forces`).
Walls get a list of their own at each rebuild: a bit mask per particle of the walls within reach
(:func:`near_walls`). Each sphere also gets its clearance to whatever it does not list, from which its displacement
allowance until the next rebuild follows (:func:`displacement_allowance`; a grain in the air searches further:
:func:`widen_clearance`).
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
    nd_vec4,
    vec3,
    vec4,
)

from .grid import cell_coords, cell_index

#: Six integers: the three runs of columns of a block row (:func:`column_runs`).
ivec6 = ti.types.vector(6, ti.i32)


@ti.func
def nearest_image(d: vec3, period: ti.f64, inv_period: ti.f64) -> vec3:
    """The separation d [m] taken to the nearest periodic image along x (minimum-image convention,
    Allen & Tildesley, *Computer Simulation of Liquids*, sec. 1.5.2): d_x - L round(d_x / L). With
    period = inv_period = 0 (no periodicity) it returns d unchanged, to the bit."""
    return vec3(d[0] - period * ti.round(d[0] * inv_period), d[1], d[2])


@ti.func
def column_runs(cx: ti.i32, cells: ti.i32, nx: ti.i32, period: ti.f64) -> ivec6:
    """The columns cx - ``cells`` .. cx + ``cells`` of a row of ``nx`` cells along x, as three runs of consecutive
    columns (first, last) side by side, each empty when its first exceeds its last: those within the grid, and along a
    periodic x (``period`` > 0) those that wrap around from the row's far end and from its near end, each column once.
    The cells of a row are consecutive in the flat index (:func:`.grid.cell_index`, x fastest), and so are their
    spheres in the cell-sorted order, so a block's row is read as at most three runs of slots (:func:`row_slots`)
    instead of cell by cell (the two integer remainders of a wrapped cell index took half the row search's time)."""
    lo = ti.max(cx - cells, 0)
    hi = ti.min(cx + cells, nx - 1)
    a1, b1, a2, b2 = 0, -1, 0, -1
    if period > 0.0:
        if cx - cells < 0:
            a1, b1 = ti.max(nx + cx - cells, hi + 1), nx - 1
        if cx + cells > nx - 1:
            a2, b2 = 0, ti.min(cx + cells - nx, lo - 1)
    return ivec6(lo, hi, a1, b1, a2, b2)


@ti.func
def row_slots(cy: ti.i32, cz: ti.i32, first: ti.i32, last: ti.i32, dims: ivec3, cell_start: ti.template()):
    """The slots [s0, s1) of the spheres in columns ``first`` .. ``last`` of the row (cy, cz): an empty range where
    first > last or the row lies beyond the grid."""
    s0, s1 = 0, 0
    if first <= last and cy >= 0 and cy < dims[1] and cz >= 0 and cz < dims[2]:
        base = cell_index(ivec3(0, cy, cz), dims)
        s0, s1 = cell_start[base + first], cell_start[base + last + 1]
    return s0, s1


#: Where no face of a searched block bounds a sphere's clearance (the block holds every cell) [m].
UNBOUNDED = 1e30


@ti.func
def block_bound(xi: vec3, c: ivec3, cells: ti.i32, origin: vec3, inv_cell: ti.f64, dims: ivec3, period: ti.f64,
                radii: ti.f64) -> ti.f64:
    """A lower bound [m] on the gap from the sphere at ``xi`` (in cell ``c``, clamped to the grid) to every sphere
    outside the block of cells c - ``cells`` .. c + ``cells`` (the grid's cells within it): the distance from xi to
    the block's nearest face, less ``radii`` (r_i + r_max), and at least 0.

    A face on or beyond the grid's boundary does not count: a sphere beyond the grid is binned into the boundary
    layer (:func:`.grid.cell_coords`), which the block holds on that side, so a sphere outside the block lies beyond
    one of the block's other faces along that axis (whether or not it was clamped). Along a periodic x (``period``
    > 0) the cells wrap, and the x faces count unless the block holds every column. So a grain thrown above the
    grid's top is bounded by the faces below and beside it only. :data:`UNBOUNDED` where no face counts."""
    u = (xi - origin) * inv_cell - ti.cast(c, ti.f64)  # xi's place in its cell [cells] (outside [0, 1) if clamped)
    nearest = UNBOUNDED * inv_cell
    for k in ti.static(range(3)):
        wraps = period > 0.0 and k == 0
        if (wraps and 2 * cells + 1 < dims[0]) or (not wraps and c[k] - cells > 0):
            nearest = ti.min(nearest, u[k] + cells)
        if (wraps and 2 * cells + 1 < dims[0]) or (not wraps and c[k] + cells < dims[k] - 1):
            nearest = ti.min(nearest, cells + 1.0 - u[k])
    return ti.min(ti.max(nearest / inv_cell - radii, 0.0), UNBOUNDED)


@ti.kernel
def wrap_positions(x: nd_vec3, x_r: nd_vec4, origin_x: ti.f64, period: ti.f64):
    """Bring every centre back into [origin_x, origin_x + period) along x (periodic domain), in the
    positions and in the contact view."""
    for i in x:
        u = x[i][0] - origin_x
        u -= period * ti.floor(u / period)
        if u >= period:  # round-off of a centre a hair below the origin
            u -= period
        x[i][0] = origin_x + u
        x_r[i][0] = origin_x + u


@ti.kernel
def bin_particles(
    x: nd_vec3, origin: vec3, inv_cell: ti.f64, dims: ivec3, cell_of: nd_i32, cell_count: nd_i32
):
    """Cell index of every particle and the number of particles per cell."""
    for c in cell_count:
        cell_count[c] = 0
    for i in x:
        cid = cell_index(cell_coords(x[i], origin, inv_cell, dims), dims)
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
    r_max: ti.f64,
    period: ti.f64,
    inv_period: ti.f64,
    nbr: nd_i32_2d,
    nbr_count: nd_i32,
    clearance: nd_f64,
) -> ti.i32:
    """Fill each particle's row with the partners j > i closer than r_i + r_j + skin, sorted by j, and
    ``clearance[i]`` [m] with a lower bound on the gap d_ij - r_i - r_j from i to every sphere listed with it by
    neither row (j > i in i's row, j < i in j's row): the least such gap among the spheres of the 27 cells searched,
    and for those beyond them :func:`block_bound`. It is at least ``skin``: a sphere beyond the grid (a grain thrown
    above its top) is clamped into a boundary cell, and the block's faces on the grid's boundary do not bound it.

    ``period`` > 0 makes the domain periodic along x with that length (``inv_period`` = 1 / period;
    both 0 otherwise): the cells wrap around in x (the grid must have at least 3 cells along x and a
    cell edge of period / cells) and distances are taken to the nearest image (:func:`nearest_image`).
    Returns the largest number of partners found for one particle; when it exceeds the row width
    the rows are truncated and the caller must widen them and call again.
    """
    width = nbr.shape[1]
    most = 0
    for i in x:
        xi = x[i]
        ri = radius[i]
        c = cell_coords(xi, origin, inv_cell, dims)
        clear = block_bound(xi, c, 1, origin, inv_cell, dims, period, ri + r_max)
        count = 0
        runs = column_runs(c[0], 1, dims[0], period)
        for dz, dy in ti.ndrange((-1, 2), (-1, 2)):
            for run in ti.static(range(3)):  # each block row as runs of consecutive cells
                s0, s1 = row_slots(c[1] + dy, c[2] + dz, runs[2 * run], runs[2 * run + 1], dims, cell_start)
                for s in range(s0, s1):
                    j = sorted_ids[s]
                    if j != i:
                        touch = ri + radius[j]
                        reach = touch + skin
                        d2 = nearest_image(x[j] - xi, period, inv_period).norm_sqr()
                        if d2 < reach * reach:
                            if j > i:
                                if count < width:
                                    nbr[i, count] = j
                                count += 1
                        elif d2 < (clear + touch) * (clear + touch):
                            clear = ti.sqrt(d2) - touch
        kept = ti.min(count, width)
        sort_row(nbr, i, 0, kept)  # by partner index
        nbr_count[i] = kept
        clearance[i] = clear
        ti.atomic_max(most, count)
    return most


#: How far the widened search of :func:`widen_clearance` looks, in cells either side of the sphere's own.
WIDE_CELLS = 3


@ti.kernel
def widen_clearance(
    x: nd_vec3,
    v: nd_vec3,
    radius: nd_f64,
    cell_start: nd_i32,
    sorted_ids: nd_i32,
    origin: vec3,
    inv_cell: ti.f64,
    dims: ivec3,
    skin: ti.f64,
    r_max: ti.f64,
    period: ti.f64,
    inv_period: ti.f64,
    horizon: ti.f64,
    clearance: nd_f64,
) -> ti.i32:
    """Search the block of (2 :data:`WIDE_CELLS` + 1)^3 cells for the spheres the 27 cells could not bound and that
    need it: those whose clearance (from :func:`build_neighbor_lists`) is the 27-cell block's bound itself (no
    unlisted sphere nearer in it: a grain in the air) and which, at their speed |v_i| [m/s], would cross their
    allowance (half that clearance) within ``horizon`` [s]. For them ``clearance[i]`` [m] becomes the least gap to an
    unlisted sphere in the wide block, or the wide block's bound (:func:`block_bound`) if less, which is again a
    lower bound on the gap to every unlisted sphere. A grain thrown up no longer asks for a rebuild every few steps;
    a sphere in the bed keeps its 27-cell clearance (searching 343 cells for each would cost more than the row
    search). Returns the number of spheres widened."""
    widened = 0
    for i in x:
        xi = x[i]
        ri = radius[i]
        c = cell_coords(xi, origin, inv_cell, dims)
        clear = clearance[i]
        if clear >= block_bound(xi, c, 1, origin, inv_cell, dims, period, ri + r_max) and (
            v[i].norm() * horizon > 0.5 * ti.max(skin, clear)
        ):
            wide = block_bound(xi, c, WIDE_CELLS, origin, inv_cell, dims, period, ri + r_max)
            runs = column_runs(c[0], WIDE_CELLS, dims[0], period)
            for dz, dy in ti.ndrange((-WIDE_CELLS, WIDE_CELLS + 1), (-WIDE_CELLS, WIDE_CELLS + 1)):
                for run in ti.static(range(3)):
                    s0, s1 = row_slots(c[1] + dy, c[2] + dz, runs[2 * run], runs[2 * run + 1], dims, cell_start)
                    for s in range(s0, s1):
                        j = sorted_ids[s]
                        if j != i:
                            touch = ri + radius[j]
                            reach = touch + skin
                            d2 = nearest_image(x[j] - xi, period, inv_period).norm_sqr()
                            if d2 >= reach * reach and d2 < (wide + touch) * (wide + touch):
                                wide = ti.sqrt(d2) - touch
            clearance[i] = wide
            ti.atomic_add(widened, 1)
    return widened


@ti.kernel
def near_walls(x: nd_vec3, radius: nd_f64, wall_point: nd_vec3, wall_normal: nd_vec3, skin: ti.f64, wall_near: nd_i32,
               clearance: nd_f64):
    """wall_near[i] = bit mask of the planar walls w whose signed distance to particle i's centre,
    (x_i - p_w) . n_w, is below r_i + skin: the only walls i can touch before the next rebuild, since
    no particle moves its gap to a wall it does not list in between (walls do not move;
    :func:`displacement_allowance`). The gap to each wall not listed lowers ``clearance[i]`` [m] (from
    :func:`build_neighbor_lists`). The force pass checks just these instead of every wall for every
    particle."""
    for i in x:
        xi = x[i]
        reach = radius[i] + skin
        mask = 0
        clear = clearance[i]
        for w in range(wall_point.shape[0]):
            above = (xi - wall_point[w]).dot(wall_normal[w])
            if above < reach:
                mask |= 1 << w
            else:
                clear = ti.min(clear, above - radius[i])
        wall_near[i] = mask
        clearance[i] = clear


@ti.kernel
def displacement_allowance(clearance: nd_f64, skin: ti.f64, cap: ti.f64, allowance_inv2: nd_f64):
    """Each sphere's displacement allowance a_i until the next rebuild, stored as 1 / a_i^2 [1/m^2]:

        a_i = min(max(skin, c_i) / 2, cap),   c_i = ``clearance[i]``.

    The lists stay complete while every sphere keeps within its allowance: a pair (i, j) listed by neither had a
    gap g_ij >= max(skin, c_i, c_j) at the rebuild, and a_i + a_j <= max(skin, c_i) / 2 + max(skin, c_j) / 2 <=
    g_ij, so the pair cannot have closed it; a wall w not listed by i had a gap >= c_i >= 2 a_i. This is the
    Verlet test (rebuild once any sphere has moved half the skin; Allen & Tildesley, *Computer Simulation of
    Liquids*, sec. 5.3.1) with each sphere's own clearance in place of the skin: a grain thrown clear of the bed,
    whose nearest sphere is far, no longer sets the whole bed's rebuild rate. ``cap`` [m] bounds every allowance for
    what else relies on it (an interaction's candidate lists: :meth:`~.scene.Scene.displacement_cap`)."""
    for i in clearance:
        a = ti.min(0.5 * ti.max(skin, clearance[i]), cap)
        allowance_inv2[i] = 1.0 / (a * a)


@ti.kernel
def limit_allowance(gap: nd_f64, less: ti.f64, allowance_inv2: nd_f64):
    """Lower each sphere's allowance to ``gap[i]`` - ``less`` [m] where that is less (``allowance_inv2`` holds
    1 / a_i^2 [1/m^2]): a body that listed the spheres near it gives each one the gap [m] to what it did not list,
    and ``less`` [m] is how far the body itself may move before it lists them again
    (:meth:`~.scene.Scene.limit_allowances`)."""
    for i in allowance_inv2:
        a = gap[i] - less
        allowance_inv2[i] = ti.max(allowance_inv2[i], 1.0 / (a * a))


@ti.func
def sort_row(values: ti.template(), row, lo, hi):
    """Sort ``values[row, lo:hi]`` (a 2-D integer array; a 1-D one, ``values[lo:hi]``, with ``row`` ignored)
    ascending in place: an insertion sort, for the short runs of a neighbour or candidate list (stable, no
    scratch memory, one thread per run)."""
    for a in range(lo + 1, hi):
        key = _at(values, row, a)
        b = a - 1
        while b >= lo and _at(values, row, b) > key:
            _put(values, row, b + 1, _at(values, row, b))
            b -= 1
        _put(values, row, b + 1, key)


@ti.func
def sort_run(values: ti.template(), lo, hi):
    """Sort ``values[lo:hi]`` (a 1-D integer array) ascending in place (:func:`sort_row`)."""
    sort_row(values, 0, lo, hi)


@ti.func
def _at(values: ti.template(), row, k):
    out = 0
    if ti.static(len(values.shape) == 2):
        out = values[row, k]
    else:
        out = values[k]
    return out


@ti.func
def _put(values: ti.template(), row, k, value):
    if ti.static(len(values.shape) == 2):
        values[row, k] = value
    else:
        values[k] = value


# ---------------------------------------------------------------------------------------------
# Pair list: every listed pair once (owner i < j), stored compactly, with its tangential history,
# and the reverse index that lays the partner slots out by partner.


@ti.kernel
def fill_pairs(
    nbr: nd_i32_2d,
    nbr_count: nd_i32,
    pair_start: nd_i32,
    pair_j: nd_i32,
    pair_xi: nd_vec3,
    pair_roll: nd_vec3,
    pair_touching: nd_i32,
    old_start: nd_i32,
    old_j: nd_i32,
    old_xi: nd_vec3,
    old_roll: nd_vec3,
    old_touching: nd_i32,
    n_old_particles: ti.i32,
):
    """Write the pairs of every particle (its sorted row of partners j > i) into the pair list,
    carrying each pair's history (tangential and rolling) and touching flag from the previous pair list (a merge of two
    sorted lists); new pairs start at zero, untouched."""
    for i in nbr_count:
        p = pair_start[i]
        a = 0
        b = 0
        if i < n_old_particles:
            a = old_start[i]
            b = old_start[i + 1]
        for k in range(nbr_count[i]):
            j = nbr[i, k]
            pair_j[p] = j
            while a < b and old_j[a] < j:
                a += 1
            if a < b and old_j[a] == j:
                pair_xi[p] = old_xi[a]
                pair_roll[p] = old_roll[a]
                pair_touching[p] = old_touching[a]
            else:
                pair_xi[p] = vec3(0.0, 0.0, 0.0)
                pair_roll[p] = vec3(0.0, 0.0, 0.0)
                pair_touching[p] = 0
            p += 1


@ti.kernel
def count_partners(pair_j: nd_i32, n_pairs: ti.i32, partnered: nd_i32):
    """partnered[j] = number of pairs with partner j (owners i < j)."""
    for j in partnered:
        partnered[j] = 0
    for p in range(n_pairs):
        ti.atomic_add(partnered[pair_j[p]], 1)


@ti.kernel
def fill_reverse_index(
    pair_j: nd_i32, n_pairs: ti.i32, rev_start: nd_i32, cursor: nd_i32, rev_pair: nd_i32, pair_rev: nd_i32
):
    """pair_rev[p] = the partner slot of pair p: the pairs with partner j get the slots rev_start[j],
    rev_start[j] + 1, ... in the order of their owners. Pairs are listed by owner, so that is
    ascending p: each run is filled in any order (integer atomics on ``cursor``) and then sorted,
    which makes the index independent of the thread schedule. ``rev_pair`` is the inverse map."""
    for j in cursor:
        cursor[j] = 0
    for p in range(n_pairs):
        j = pair_j[p]
        rev_pair[rev_start[j] + ti.atomic_add(cursor[j], 1)] = p
    for j in cursor:
        lo = rev_start[j]
        hi = rev_start[j + 1]
        sort_run(rev_pair, lo, hi)
        for e in range(lo, hi):
            pair_rev[rev_pair[e]] = e
