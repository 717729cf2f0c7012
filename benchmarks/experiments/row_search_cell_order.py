"""A/B of the neighbour row search: today's kernel against one that reads a copy of (x, r) laid out in cell order.

Today's ``granular/neighbors.py: build_neighbor_lists`` loops over the spheres in index order and reads each
candidate's position and radius through ``sorted_ids`` (scattered reads). The variant here first gathers (x, r) into
``cell_xr`` in the cells' order (one pass), then loops over the slots in that order, so that a sphere's 27 cells are
read as runs of contiguous memory and neighbouring threads work on neighbouring cells. It fills the same rows and
clearances to the bit (checked here before the timing). The variant kernel is a copy of the row search of then with only its reads changed
(the copy is the point of an A/B); it looks its cells up one by one, as that kernel did, so since the row search reads
each block row as runs of columns (``neighbors.column_runs``, the same evening) "today" here is the faster kernel
and the variant is compared with it on other terms than it was measured on. The CMU twin's bed (``cmu-grouser`` with the settings given)
after 20 steps; eight rounds of five calls each, alternating, best and median per call (benchmarks/README.md, issue
37, 2026-11-29 evening)::

    python benchmarks/experiments/row_search_cell_order.py soil.diameter_min=0.003072 soil.diameter_max=0.004608
"""
import sys

import numpy as np

from wheelsoil import runtime

runtime.init("cpu")
import taichi as ti  # noqa: E402

from wheelsoil.benchmarks.common import alternating_kernel_times  # noqa: E402
from wheelsoil.cases import build  # noqa: E402
from wheelsoil.cases.schema import load_case  # noqa: E402
from wheelsoil.granular import neighbors, prepare_bed  # noqa: E402
from wheelsoil.granular.grid import cell_coords, cell_index  # noqa: E402
from wheelsoil.granular.neighbors import (  # noqa: E402
    block_bound, ivec3, nd_f64, nd_i32, nd_i32_2d, nd_vec3, nd_vec4, nearest_image, sort_row, vec3, vec4,
)


@ti.func
def block_cell(cc: ivec3, dims: ivec3, period: ti.f64) -> ti.i32:
    """Flat index of cell ``cc`` of a searched block, wrapped around along a periodic x; -1 beyond the grid (the
    row search's cell lookup until the column runs of 2026-11-29, ``neighbors.column_runs``)."""
    k = cc
    if period > 0.0:
        k[0] = ((cc[0] % dims[0]) + dims[0]) % dims[0]
    cid = -1
    if (k >= 0).all() and (k < dims).all():
        cid = cell_index(k, dims)
    return cid


@ti.kernel
def gather_cells(x: nd_vec3, radius: nd_f64, sorted_ids: nd_i32, cell_xr: nd_vec4):
    """cell_xr[s] = (x, r) of the sphere in slot s of the cells' order."""
    for s in sorted_ids:
        i = sorted_ids[s]
        p = x[i]
        cell_xr[s] = vec4(p[0], p[1], p[2], radius[i])


@ti.kernel
def rows_sorted(cell_xr: nd_vec4, cell_start: nd_i32, sorted_ids: nd_i32, origin: vec3, inv_cell: ti.f64, dims: ivec3,
                skin: ti.f64, r_max: ti.f64, period: ti.f64, inv_period: ti.f64, nbr: nd_i32_2d, nbr_count: nd_i32,
                clearance: nd_f64) -> ti.i32:
    """:func:`wheelsoil.granular.neighbors.build_neighbor_lists` over the slots in the cells' order, reading
    ``cell_xr`` (the same rows, counts and clearances)."""
    width = nbr.shape[1]
    most = 0
    for s0 in sorted_ids:
        i = sorted_ids[s0]
        pi = cell_xr[s0]
        xi = vec3(pi[0], pi[1], pi[2])
        ri = pi[3]
        c = cell_coords(xi, origin, inv_cell, dims)
        clear = block_bound(xi, c, 1, origin, inv_cell, dims, period, ri + r_max)
        count = 0
        for dz, dy, dx in ti.ndrange((-1, 2), (-1, 2), (-1, 2)):
            cid = block_cell(c + ivec3(dx, dy, dz), dims, period)
            if cid >= 0:
                for s in range(cell_start[cid], cell_start[cid + 1]):
                    j = sorted_ids[s]
                    if j != i:
                        pj = cell_xr[s]
                        touch = ri + pj[3]
                        reach = touch + skin
                        d2 = nearest_image(vec3(pj[0], pj[1], pj[2]) - xi, period, inv_period).norm_sqr()
                        if d2 < reach * reach:
                            if j > i:
                                if count < width:
                                    nbr[i, count] = j
                                count += 1
                        elif d2 < (clear + touch) * (clear + touch):
                            clear = ti.sqrt(d2) - touch
        kept = ti.min(count, width)
        sort_row(nbr, i, 0, kept)
        nbr_count[i] = kept
        clearance[i] = clear
        ti.atomic_max(most, count)
    return most

def main() -> None:
    scene = prepare_bed(build.bed_spec(load_case("cmu-grouser", sys.argv[1:]))).to_scene(headroom=0.06)
    scene.step(20)
    nl, p = scene.device.neighbor_list, scene.device.particles
    g = nl.grid
    origin, inv_cell, dims = g.kernel_args()
    cell_xr = ti.Vector.ndarray(4, ti.f64, shape=scene.n_particles)

    def today() -> int:
        return neighbors.build_neighbor_lists(p.x, p.r, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims, nl.skin,
                                              nl.r_max, g.period, g.inv_period, nl.nbr, nl.count, nl.clearance)

    def cell_order() -> int:
        gather_cells(p.x, p.r, nl.sorted_ids, cell_xr)
        return rows_sorted(cell_xr, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims, nl.skin, nl.r_max, g.period,
                           g.inv_period, nl.nbr, nl.count, nl.clearance)

    def lists() -> tuple:
        rows, count = nl.nbr.to_numpy(), nl.count.to_numpy()
        rows[np.arange(rows.shape[1])[None, :] >= count[:, None]] = -1  # slots past a row's end hold stale partners
        return rows, count, nl.clearance.to_numpy()

    most = today(), cell_order()
    ref = lists() if today() == most[0] else None
    cell_order()
    same = all(np.array_equal(a, b) for a, b in zip(ref, lists()))
    print(f"the same rows, counts and clearances to the bit: {same and most[0] == most[1]}")
    times = alternating_kernel_times({"today": today, "cell order": cell_order}, 8)
    t, c = times["today"], times["cell order"]
    print(f"{scene.n_particles} spheres, row search: today {1e3 * t.min():.1f} ms best / {1e3 * np.median(t):.1f} "
          f"median, cell order (gather included) {1e3 * c.min():.1f} / {1e3 * np.median(c):.1f}; cell order / today "
          f"{c.min() / t.min():.2f} best, {np.median(c / t):.2f} median of rounds")

if __name__ == "__main__":
    main()
