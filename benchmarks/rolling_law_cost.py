"""What the EPSD rolling law costs against CDT: the same settled bed stepped under each law, alternating.

The EPSD law (``granular/contact.py``) reads and writes a rolling spring torque at every touching contact and carries
it through every neighbour rebuild; CDT touches no such history. Both laws step the same bed (prepared once, CDT,
from the bed cache; the EPSD scene starts with zero rolling springs, which load within a few steps), for ``--rounds``
alternating rounds, each timed after a warm-up; the ratio of the best rounds is reported, and the ratio within every
round (a shared machine's speed drifts between rounds).

Usage::

    python benchmarks/rolling_law_cost.py [--length 0.8 --width 0.5 --depth 0.2] [--steps 1000] [--rounds 3]

Results go to stdout and ``benchmarks/results/rolling_law_cost.json``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

from wheelsoil.benchmarks.common import machine, versions

HERE = Path(__file__).resolve().parent


def timed_steps(bed, law: str, steps: int, warmup: int) -> dict:
    """Particle-steps per second of ``bed`` stepped under the rolling ``law``."""
    spec = bed.spec
    under_law = dataclasses.replace(bed, spec=dataclasses.replace(
        spec, pair=dataclasses.replace(spec.pair, rolling_model=law),
        wall_pair=dataclasses.replace(spec.wall_pair, rolling_model=law)))
    scene = under_law.to_scene(headroom=0.05)
    scene.step(warmup)
    t0 = time.perf_counter()
    scene.step(steps)
    wall = time.perf_counter() - t0
    return {"law": law, "particles": scene.n_particles, "steps": steps, "wall_s": wall,
            "particle_steps_per_s": scene.n_particles * steps / wall, "contacts": scene.contact_count}


def main(argv=None) -> int:
    from wheelsoil.granular import SOIL_SOIL, BedSpec, LUNAR_SOIL_SIMULANT, prepare_bed

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--length", type=float, default=0.8, help="bed length [m]")
    ap.add_argument("--width", type=float, default=0.5, help="bed width [m]")
    ap.add_argument("--depth", type=float, default=0.2, help="bed depth [m]")
    ap.add_argument("--steps", type=int, default=1000, help="timed steps per round")
    ap.add_argument("--warmup", type=int, default=100, help="untimed steps first")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of the two laws")
    ap.add_argument("--cache", default=None, help="bed cache folder")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "rolling_law_cost.json")
    args = ap.parse_args(argv)
    spec = BedSpec(length=args.length, width=args.width, depth=args.depth, diameter_min=0.016, diameter_max=0.024,
                   gravity=(0.0, 0.0, -9.81), wall_material=LUNAR_SOIL_SIMULANT, wall_pair=SOIL_SOIL, seed=1,
                   periodic=False)
    bed = prepare_bed(spec, cache_dir=args.cache)
    rounds = []
    for k in range(args.rounds):
        pair = {law: timed_steps(bed, law, args.steps, args.warmup) for law in ("cdt", "epsd")}
        pair["epsd_over_cdt"] = pair["epsd"]["particle_steps_per_s"] / pair["cdt"]["particle_steps_per_s"]
        rounds.append(pair)
        print(f"round {k + 1}: CDT {pair['cdt']['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s, EPSD "
              f"{pair['epsd']['particle_steps_per_s'] / 1e6:.2f} M, EPSD / CDT {pair['epsd_over_cdt']:.3f}", flush=True)
    best = {law: max(r[law]["particle_steps_per_s"] for r in rounds) for law in ("cdt", "epsd")}
    result = {"particles": rounds[0]["cdt"]["particles"], "rounds": rounds, "best": best,
              "epsd_over_cdt_best": best["epsd"] / best["cdt"], "machine": machine(), "versions": versions()}
    print(f"{result['particles']} particles: EPSD / CDT throughput, best vs best {result['epsd_over_cdt_best']:.3f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
