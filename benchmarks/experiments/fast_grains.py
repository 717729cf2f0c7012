"""Which sphere sets the neighbour-rebuild rate of a coupled run: the CMU twin's protocol, then the fastest spheres.

The soil's neighbour list was rebuilt whenever any sphere had moved half the skin since the last build, so one fast
grain set the whole bed's rebuild rate (since 2026-11-29 each sphere has its own allowance, half its clearance within
a cap: :func:`wheelsoil.granular.neighbors.displacement_allowance`, which thrown grains were the reason for).
This runs ``cmu-grouser`` (with ``--set`` overrides, e.g. finer particles)
through its protocol with a short drive, then steps on in chunks and prints, per chunk, the rebuilds so far and the
fastest sphere (speed, position, radius) and how many move faster than 0.5 and 1 m/s::

    python benchmarks/experiments/fast_grains.py --set soil.diameter_min=0.003072 soil.diameter_max=0.004608 \\
        --chunks 12 --steps 5 [--watch-protocol]

(2026-11-29, benchmarks/README.md: at about 100,000 spheres a grain rising at 4.0 m/s beside the wheel forced a
rebuild every five steps; at the twin's 21,485, a grain falling inside the open drum at 0.3 m/s, one every 70.)
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE",
                    help="the case's settings (wheelsoil run --set)")
    ap.add_argument("--drive-time", type=float, default=0.3, help="the protocol's drive [s] (default 0.3)")
    ap.add_argument("--chunks", type=int, default=20, help="chunks stepped after the protocol (default 20)")
    ap.add_argument("--steps", type=int, default=10, help="DEM steps a chunk (default 10)")
    ap.add_argument("--who-rebuilds", type=int, default=0, metavar="STEPS",
                    help="after the chunks, step STEPS single steps and print, for each neighbour rebuild, the sphere "
                         "that asked for it (displacement over allowance, speed, clearance, place)")
    ap.add_argument("--watch-protocol", action="store_true",
                    help="also print, after every sample of the protocol, its phase, the fastest sphere and the "
                         "neighbour rebuilds in the sample (where a grain is thrown)")
    args = ap.parse_args(argv)

    from wheelsoil import runtime

    runtime.init()
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.granular import prepare_bed

    case = load_case("cmu-grouser", [*args.set, f"test.drive_time={args.drive_time!r}", "test.stop_when_steady=false",
                                     "output.average_time=0.1", "output.render=false"])
    bed = prepare_bed(build.bed_spec(case))
    bench = Testbed(bed, build.wheel_geometry(case), build.testbed_spec(case))
    scene = bench.scene
    seen = {"rebuilds": 0}

    def watch(tb) -> None:
        print(f"{tb.phase:8s} t = {scene.time:.4f} s: {fastest(scene)[0]}, rebuilds in the sample "
              f"{scene.neighbor_rebuilds - seen['rebuilds']}, hub at {np.round(1e3 * tb.structure.hub_position, 1)} mm",
              flush=True)
        seen["rebuilds"] = scene.neighbor_rebuilds

    t0 = time.perf_counter()
    bench.run(on_sample=watch if args.watch_protocol else None)
    print(f"protocol {time.perf_counter() - t0:.0f} s; {scene.n_particles} spheres, skin "
          f"{1e3 * scene.device.neighbor_list.skin:.3f} mm, DEM step {scene.time_step:.3e} s", flush=True)
    start = scene.neighbor_rebuilds
    for k in range(args.chunks):
        scene.step(args.steps)
        text, speed = fastest(scene)
        print(f"chunk {k}: rebuilds {scene.neighbor_rebuilds - start}, {text}, {int((speed > 0.5).sum())} above "
              f"0.5 m/s, {int((speed > 1.0).sum())} above 1 m/s", flush=True)
    if args.who_rebuilds:
        who_rebuilds(scene, bench, args.who_rebuilds)
    return 0


def fastest(scene) -> tuple[str, np.ndarray]:
    """The fastest sphere, described (speed, place, radius), and every sphere's speed [m/s]."""
    speed = np.linalg.norm(scene.velocities, axis=1)
    i = int(np.argmax(speed))
    return (f"fastest {speed[i]:.3f} m/s at {np.round(1e3 * scene.positions[i], 1)} mm (radius "
            f"{1e3 * scene.radii[i]:.2f} mm)"), speed


def who_rebuilds(scene, bench, steps: int) -> None:
    """Single steps; before each, the sphere furthest past its allowance after the step's drift (|x + v dt - x_ref|^2
    / a^2, read back from the device), printed whenever the step rebuilds the lists (below 1: the wheel asked)."""
    nl, p = scene.device.neighbor_list, scene.device.particles
    asked: dict[str, int] = {}
    for _ in range(steps):
        # the allowances and clearances of the lists in use (the step's rebuild replaces them)
        allowance = 1.0 / np.sqrt(nl.allowance_inv2.to_numpy())
        clearance = nl.clearance.to_numpy()
        drifted = p.x.to_numpy() + scene.time_step * p.v.to_numpy()
        ratio = ((drifted - p.x_ref.to_numpy()) ** 2).sum(axis=1) / allowance**2
        before = scene.neighbor_rebuilds
        scene.step(1)
        if scene.neighbor_rebuilds == before:
            continue
        i = int(np.argmax(ratio))
        if ratio[i] <= 1.0:
            asked["the wheel"] = asked.get("the wheel", 0) + 1
            continue
        speed = float(np.linalg.norm(scene.velocities[i]))
        hub = np.asarray(bench.structure.hub_position)
        where = "far" if np.linalg.norm(scene.positions[i] - hub) > 1.5 * bench.wheel.radius else "near the wheel"
        # held: its allowance below half its clearance (the wheel's gap to it, or a cap); own: half its clearance
        kind = "held by the wheel" if allowance[i] < 0.5 * clearance[i] * (1 - 1e-9) else "own"
        asked[f"{where}, {kind}"] = asked.get(f"{where}, {kind}", 0) + 1
        print(f"step {scene.steps_taken}: sphere {i} asked ({ratio[i]:.2f} of its allowance before the step), "
              f"{speed:.3f} m/s, allowance {1e3 * allowance[i]:.3f} mm, clearance {1e3 * clearance[i]:.3f} mm (skin "
              f"{1e3 * nl.skin:.3f}), at {np.round(1e3 * scene.positions[i], 1)} mm, {where}, {kind}", flush=True)
    print(f"who asked, over {steps} steps: {asked}", flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
