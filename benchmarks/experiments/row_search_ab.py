"""A/B of the neighbour row search: an earlier ``granular/neighbors.py`` against today's, on the same bed, in one process.

The earlier kernel is loaded from a copy of the file. Before the clearance (its signature without ``r_max`` and
``clearance``)::

    git show 0e6337f:granular/neighbors.py > /tmp/neighbors_before.py
    python benchmarks/experiments/row_search_ab.py /tmp/neighbors_before.py \\
        --set soil.diameter_min=0.003072 soil.diameter_max=0.004608

With today's signature (``--same-signature``: the rows, counts and clearances are also compared, to the bit), e.g.
before the block rows were read as runs of columns::

    git show ae3527d:granular/neighbors.py > /tmp/neighbors_cells.py
    python benchmarks/experiments/row_search_ab.py /tmp/neighbors_cells.py --same-signature --set ...

Both kernels fill the same rows of the CMU twin's bed (``cmu-grouser`` with ``--set`` overrides) after 20 steps;
``--rounds`` rounds of five calls each, in alternating order, best and median per call (benchmarks/README.md: the
per-sphere allowance, 1.15-1.17 on the 100,000-sphere bed; the column runs).
"""

from __future__ import annotations

import argparse
import importlib.util

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("before", help="a copy of granular/neighbors.py before the clearance")
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE", help="the case's settings (wheelsoil run --set)")
    ap.add_argument("--rounds", type=int, default=8, help="alternating rounds (default 8)")
    ap.add_argument("--same-signature", action="store_true",
                    help="the earlier kernel takes today's arguments (r_max, clearance); its lists are compared too")
    args = ap.parse_args(argv)

    from wheelsoil import runtime

    runtime.init("cpu")
    from wheelsoil.benchmarks.common import alternating_kernel_times
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.granular import neighbors, prepare_bed

    spec = importlib.util.spec_from_file_location("wheelsoil.granular.neighbors_before", args.before)
    before = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(before)
    scene = prepare_bed(build.bed_spec(load_case("cmu-grouser", args.set))).to_scene(headroom=0.06)
    scene.step(20)
    nl, p = scene.device.neighbor_list, scene.device.particles
    g = nl.grid
    origin, inv_cell, dims = g.kernel_args()

    def today() -> int:
        return neighbors.build_neighbor_lists(p.x, p.r, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims, nl.skin,
                                              nl.r_max, g.period, g.inv_period, nl.nbr, nl.count, nl.clearance)

    def earlier() -> int:
        if args.same_signature:
            return before.build_neighbor_lists(p.x, p.r, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims,
                                               nl.skin, nl.r_max, g.period, g.inv_period, nl.nbr, nl.count,
                                               nl.clearance)
        return before.build_neighbor_lists(p.x, p.r, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims, nl.skin,
                                           g.period, g.inv_period, nl.nbr, nl.count)

    def lists() -> list:
        rows, count = nl.nbr.to_numpy(), nl.count.to_numpy()
        rows[np.arange(rows.shape[1])[None, :] >= count[:, None]] = -1  # slots past a row's end hold stale partners
        return [rows, count, nl.clearance.to_numpy()]

    most = [today()]
    ref = lists()
    most.append(earlier())
    if args.same_signature:
        same = most[0] == most[1] and all(np.array_equal(a, b) for a, b in zip(ref, lists()))
        print(f"the same rows, counts and clearances to the bit: {same}")
    times = alternating_kernel_times({"before": earlier, "today": today}, args.rounds)
    b, t = times["before"], times["today"]
    print(f"{scene.n_particles} spheres, row search: before {1e3 * b.min():.1f} ms best / {1e3 * np.median(b):.1f} "
          f"median, today {1e3 * t.min():.1f} / {1e3 * np.median(t):.1f}; today / before {t.min() / b.min():.2f} best, "
          f"{np.median(t / b):.2f} median of rounds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
