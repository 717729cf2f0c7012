"""A/B of the neighbour row search: an earlier ``granular/neighbors.py`` against today's, on the same bed, in one process.

The earlier kernel is loaded from a copy of the file (its signature before the clearance: no ``r_max``, no
``clearance``)::

    git show 0e6337f:granular/neighbors.py > /tmp/neighbors_before.py
    python benchmarks/experiments/row_search_ab.py /tmp/neighbors_before.py \\
        --set soil.diameter_min=0.003072 soil.diameter_max=0.004608

Both kernels fill the same rows of the CMU twin's bed (``cmu-grouser`` with ``--set`` overrides) after 20 steps;
eight rounds of five calls each, in alternating order, best and median per call (benchmarks/README.md, the per-sphere
allowance: 1.15-1.17 on the 100,000-sphere bed).
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
        return before.build_neighbor_lists(p.x, p.r, nl.cell_start, nl.sorted_ids, origin, inv_cell, dims, nl.skin,
                                           g.period, g.inv_period, nl.nbr, nl.count)

    today(), earlier()  # compile
    times = alternating_kernel_times({"before": earlier, "today": today}, args.rounds)
    b, t = times["before"], times["today"]
    print(f"{scene.n_particles} spheres, row search: before {1e3 * b.min():.1f} ms best / {1e3 * np.median(b):.1f} "
          f"median, today {1e3 * t.min():.1f} / {1e3 * np.median(t):.1f}; today / before {t.min() / b.min():.2f} best, "
          f"{np.median(t / b):.2f} median of rounds")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
