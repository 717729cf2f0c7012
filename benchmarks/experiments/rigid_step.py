"""The CMU twin's rigid wheel (``cmu-grouser``; ``--closed``: with its side walls, the `closed-wheel` candidate's) stepped
alone at the twin's DEM step under random nodal loads, its hub free and spinning: the best of five rounds of 1000
single steps [ms a step], and a checksum of the state (to compare two checkouts bit for bit, ``--save FILE.npy``).

Before and after a change, in two checkouts, in alternating processes::

    for r in 1 2 3; do (cd OLD && python benchmarks/experiments/rigid_step.py); python benchmarks/experiments/rigid_step.py; done
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--closed", action="store_true", help="the wheel with side walls (wheel.side_walls = true)")
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--save", help="write the final node state (positions, velocities, spins, rotations) here")
    args = ap.parse_args(argv)
    from wheelsoil import runtime

    runtime.init("cpu")
    from wheelsoil.cases.build import wheel_geometry
    from wheelsoil.cases.schema import load_case
    from wheelsoil.flexwheel.geometry import build_wheel_mesh
    from wheelsoil.flexwheel.structure import Structure

    case = load_case("cmu-grouser", ["wheel.side_walls=true"] if args.closed else [])
    geometry = wheel_geometry(case)
    mesh, hub = build_wheel_mesh(geometry)
    rng = np.random.default_rng(0)
    wheel = Structure(mesh, hub_nodes=hub, hub_center=np.zeros(3), hub_mass=geometry.hub_mass, rigid=True,
                      damping=case.wheel.damping)
    wheel.set_external(rng.normal(size=(mesh.n_nodes, 3)), 1e-3 * rng.normal(size=(mesh.n_nodes, 3)))
    wheel.drive_hub(free_translation=(True, True, True), free_rotation=(True, True, True),
                    angular_velocity=(0.0, case.test.angular_velocity, 0.0))
    dt = 2e-5  # the twin's DEM step
    wheel.step(10, dt)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(args.steps):
            wheel.step(1, dt)
        best = min(best, (time.perf_counter() - t0) / args.steps)
    state = np.concatenate([wheel.positions(), wheel.velocities(), wheel.angular_velocities(),
                            wheel.rotations().reshape(-1, 3)])
    if args.save:
        np.save(args.save, state)
    print(json.dumps({"nodes": mesh.n_nodes, "ms_per_step": 1e3 * best, "checksum": float(np.abs(state).sum())}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
