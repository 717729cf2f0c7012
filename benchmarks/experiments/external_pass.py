"""What the soil's step pays for taking interactions' forces: the CMU twin's bed stepped alone, once plain and once
with an interaction that adds nothing, alternating.

With an interaction the one-launch step (``granular/fused_step.py``) adds every sphere's external force and torque to
its contact sums and clears them (``granular/forces.py: add_external``), 96 bytes a sphere a step, whether a body
touched it or not; without one it skips that. Both scenes are the same bed (``cmu-grouser``'s, from the bed cache) at
the twin's step; ``--rounds`` rounds of ``--steps`` steps each, in turn. Prints each round's ms per step and the
ratio of the two, with its median.

    python benchmarks/experiments/external_pass.py [--steps 500] [--rounds 6]
"""

import argparse
import statistics
import time

from wheelsoil.cases import build
from wheelsoil.cases.schema import load_case
from wheelsoil.coupling.rig import soil_headroom
from wheelsoil.granular import prepare_bed


class Nothing:
    """An interaction that adds no force (the scene then steps with its external arrays)."""

    contact_moduli = ()

    def after_drift(self, scene, dt):
        pass

    def add_forces(self, scene, dt):
        return 0


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=500)
    ap.add_argument("--rounds", type=int, default=6)
    args = ap.parse_args(argv)
    case = load_case("cmu-grouser", [])
    bed = prepare_bed(build.bed_spec(case))
    headroom = soil_headroom(bed.spec.depth, build.wheel_geometry(case))
    plain, external = bed.to_scene(headroom=headroom), bed.to_scene(headroom=headroom)
    external.add_interaction(Nothing())
    for scene in (plain, external):
        scene.time_step = 0.995 * scene.stable_time_step().stable
        scene.step(50)
    ratios = []
    for k in range(args.rounds):
        times = []
        for scene in (plain, external):
            t0 = time.perf_counter()
            scene.step(args.steps)
            times.append((time.perf_counter() - t0) / args.steps)
        ratios.append(times[1] / times[0])
        print(f"round {k + 1}: plain {1e3 * times[0]:.3f} ms, with an interaction {1e3 * times[1]:.3f} ms, "
              f"ratio {ratios[-1]:.3f}", flush=True)
    print(f"{plain.n_particles} particles; ratio median {statistics.median(ratios):.3f} "
          f"({min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()
