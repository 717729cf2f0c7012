"""Two or more variants of the soil's step, timed in alternating separate processes on the DEM benchmark's 53k bed.

A variant is a value of one environment variable that a patched checkout reads at import (each experiment here is
a patch against the commit it names, kept so that its measurement can be repeated; none of them is in the package)::

    git apply benchmarks/experiments/f32-arithmetic.patch
    python benchmarks/experiments/alternate.py --env WHEELSOIL_F32 --values 0 1 --rounds 4 --steps 1000

Each process loads the bed from the bed cache (``benchmarks/dem_throughput.py``'s, prepared once) and times
``--steps`` after 200 untimed, with that benchmark's own stepping; the rounds alternate the variants so that the
machine's drift falls on all of them alike. It prints each process's ms per step and particle-steps per second, and
the ratios of the first variant's time to each other's, per round, their median and best against best.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(steps: int) -> dict:
    """One variant's timing: the DEM benchmark's own stepping (:func:`dem_throughput.run_wheelsoil`, 200 steps of
    warm-up) on its bed."""
    sys.path.insert(0, str(HERE.parent))
    from wheelsoil.runtime import init

    init("cpu")
    import dem_throughput

    from wheelsoil.granular import prepare_bed

    bed = prepare_bed(dem_throughput.bench_spec(argparse.Namespace(length=1.6, width=1.0, depth=0.26)))
    res = dem_throughput.run_wheelsoil(bed, steps, 200)
    return {"ms_per_step": 1e3 * res["wall_s"] / res["steps"], "particle_steps_per_s": res["particle_steps_per_s"]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--env", help="the environment variable the patched code reads")
    ap.add_argument("--values", nargs="+", default=[], help="its values, one per variant (the first is the base)")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.steps)))
        return 0
    if not args.env or len(args.values) < 2 or args.rounds < 1 or args.steps < 1:
        ap.error("give --env, at least two --values, --rounds >= 1 and --steps >= 1")
    times = {v: [] for v in args.values}
    for r in range(args.rounds):
        for v in args.values:
            env = dict(os.environ, **{args.env: v})
            out = subprocess.run([sys.executable, __file__, "--child", "--steps", str(args.steps)], env=env,
                                 capture_output=True, text=True, check=True)
            res = json.loads(out.stdout.strip().splitlines()[-1])
            times[v].append(res["ms_per_step"])
            print(f"round {r + 1} {args.env}={v}: {res['ms_per_step']:.3f} ms/step, "
                  f"{res['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s", flush=True)
    base = args.values[0]
    for v in args.values[1:]:
        per_round = [b / o for b, o in zip(times[base], times[v])]
        print(f"{args.env}={v} against {base}: speed-up per round {', '.join(f'{x:.3f}' for x in per_round)}; "
              f"median {statistics.median(per_round):.3f}; best against best {min(times[base]) / min(times[v]):.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
