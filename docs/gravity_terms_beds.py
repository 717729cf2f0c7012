"""Is the bed's settling threshold what breaks the gravity study's similarity check? (docs/gravity-terms/README.md)

The similarity transform (``wheelsoil.cases.similarity``) cannot reach the bed's settling threshold (5 mm/s of the mean
grain, unscaled: ``UNSCALED_CONSTANTS``). This prepares, for each seed, the bed of ``smoke-1g-steer`` at 1g, the bed of
its similar case at 1/6 g as the study's runs had it, and the same 1/6 g bed with the threshold scaled as the transform
would scale it (kinetic energy / tau^2), and tabulates what the wheel meets: the spheres left after levelling, the
surface, the packing fraction and the settling time (simulated). Two to four minutes a bed on one core; beds are
cached, so a second call only reads them::

    WHEELSOIL_CPU_THREADS=1 python docs/gravity_terms_beds.py --seeds 0 1 2 --cache CACHE --out docs/gravity-terms/beds.md
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time
from pathlib import Path

BASE_CASE = "smoke-1g-steer"
#: tau of the transform from 1g to 1/6 g: times stretch by it, speeds shrink by it
TAU = math.sqrt(6.0)


def bed_specs(seed: int) -> dict:
    """The three beds of one seed: {label: BedSpec}."""
    from wheelsoil.cases import build
    from wheelsoil.cases.schema import load_case
    from wheelsoil.cases.similarity import similar_case

    base = load_case(BASE_CASE, [f"case.seed={seed}"])
    at_1g, at_sixth = build.bed_spec(base), build.bed_spec(similar_case(base, "moon"))
    scaled = dataclasses.replace(at_sixth, kinetic_energy_threshold=at_sixth.settle_threshold / TAU**2)
    return {"1g": at_1g, "1/6 g, threshold as it is": at_sixth, "1/6 g, threshold scaled": scaled}


def table(rows: list[dict]) -> str:
    lines = ["| seed | bed | spheres after levelling | surface [m] | packing fraction | settled in [s] | "
             "settled in, at 1g's time [s] |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        at_1g = r["settled"] / (1.0 if r["bed"] == "1g" else TAU)
        lines.append(f"| {r['seed']} | {r['bed']} | {r['spheres']:,} | {r['surface']:.4f} | {r['packing']:.3f} | "
                     f"{r['settled']:.2f} | {at_1g:.2f} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    ap.add_argument("--cache", default=None, help="bed cache folder (default: wheelsoil's)")
    ap.add_argument("--out", default=None, help="write the table (Markdown) here")
    args = ap.parse_args(argv)
    from wheelsoil.granular import prepare_bed

    rows = []
    for seed in args.seeds:
        for label, spec in bed_specs(seed).items():
            t0 = time.perf_counter()
            bed = prepare_bed(spec, cache_dir=args.cache)
            rows.append({"seed": seed, "bed": label, "spheres": bed.n_particles, "surface": bed.surface_height,
                         "packing": bed.packing_fraction, "settled": bed.settle_time})
            print(f"seed {seed}, {label}: {bed.summary()} ({time.perf_counter() - t0:.0f} s)", flush=True)
    text = table(rows)
    print(text)
    if args.out:
        Path(args.out).write_text(f"`python docs/gravity_terms_beds.py --seeds {' '.join(map(str, args.seeds))}`\n\n"
                                  + text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
