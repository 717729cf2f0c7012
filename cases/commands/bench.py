"""``wheelsoil bench``: the benchmark tiers, each in its own process."""

from __future__ import annotations

import sys
from pathlib import Path


def add_parser(sub) -> None:
    """The ``bench`` command on ``sub``."""
    p = sub.add_parser("bench", help="measure solver speed (smoke tier for CI, or the full tier)",
                       description="Benchmarks (benchmarks/README.md). --smoke: a few minutes on 2 cores -- DEM "
                                   "steady stepping on a small dense bed, compile time, peak memory -- each figure "
                                   "also normalised by a NumPy reference workload; with --baseline, a regression "
                                   "beyond --tolerance fails (exit 1) naming the figure. Without --smoke: the full "
                                   "tier (>= 50k-particle bed, LIGGGHTS comparison, seed-004 memory check).")
    p.add_argument("--smoke", action="store_true", help="run the smoke tier")
    p.add_argument("--out", type=Path, default=None, help="JSON to write (default benchmarks/results/<tier>.json)")
    p.add_argument("--baseline", type=Path, default=None, help="smoke: baseline JSON to gate regressions against")
    p.add_argument("--tolerance", type=float, default=0.5, help="smoke: allowed normalised regression (default 0.5)")
    p.add_argument("--record", action="store_true", help="smoke: append the result to benchmarks/history/smoke.jsonl")
    p.add_argument("--no-liggghts", action="store_true", help="full tier: skip the LIGGGHTS comparison")
    p.add_argument("--memory-check", action="store_true", help="full tier: also step a seed-004-size bed")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    """The benchmark tiers run in their own process (``python -m wheelsoil.benchmarks.smoke`` or
    ``.dem_throughput``): their memory and timings are their own, and the case layer does not import the
    benchmarks (they import it). The exit status is theirs (1: a regression beyond the tolerance)."""
    import subprocess

    if args.smoke:
        module = "wheelsoil.benchmarks.smoke"
        argv = ["--tolerance", str(args.tolerance)]
        if args.out:
            argv += ["--out", str(args.out)]
        if args.baseline:
            argv += ["--baseline", str(args.baseline)]
        if args.record:
            argv.append("--record")
    else:
        module = "wheelsoil.benchmarks.dem_throughput"
        argv = (["--out", str(args.out)] if args.out else []) + (["--no-liggghts"] if args.no_liggghts else [])
        argv += ["--memory-check"] if args.memory_check else []
    return subprocess.call([sys.executable, "-m", module, *argv])
