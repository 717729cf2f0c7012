"""What one calibration of the semi-empirical model costs, before and after the 2026-11-29 numerics, alternating.

A validation campaign's draw and ``wheelsoil validate`` spend nearly all their time in least-squares fits
(:func:`wheelsoil.validation.calibration.calibrate`), and a fit nearly all of its in the Jacobian. Three variants fit
the same synthetic whole-domain set (the campaigns' design: 210 rows of driving, braking, dragged and 90 deg
conditions; seed ``--seed``, nothing hidden) from the same start (the generic dry sand of
:func:`~wheelsoil.validation.calibration.calibrate_baseline`), the seven baseline parameters free:

* ``before``: the plain 48-node quadrature and scipy's forward differences of the whole prediction;
* ``graded``: the graded 24-node quadrature (:mod:`wheelsoil.validation.quadrature`), forward differences;
* ``now``: the graded quadrature and the Jacobian through the sinkage (:mod:`wheelsoil.validation.fit_jacobian`).

The variants run in turn within each of ``--rounds`` rounds (a shared machine's speed drifts between rounds), in one
process; reported: each fit's wall time, the ratio of ``before`` to each variant within every round, their median
and best against best, and what each fit found (its SSE and its parameters' largest relative difference from
``before``'s), so the gain is shown on fits that land in the same place.

Usage::

    python benchmarks/validation_fit.py [--rounds 3] [--seed 7]

Results go to stdout and ``benchmarks/results/validation_fit.json``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

import numpy as np

from wheelsoil.benchmarks.common import machine, versions
from wheelsoil.validation import calibration as cal
from wheelsoil.validation import synthetic as syn
from wheelsoil.validation.extensions import BASELINE_FREE
from wheelsoil.validation.quadrature import QUADRATURE_POINTS, contact_rule

HERE = Path(__file__).resolve().parent
#: name -> (contact rule (nodes a region, grading power), Jacobian)
VARIANTS = {"before": ((QUADRATURE_POINTS, 1), "difference"), "graded": (None, "difference"), "now": (None, "implicit")}


def fit(data, start, scales, variant: str) -> dict:
    """One fit under ``variant``: its wall time [s], SSE, fitted parameters and function evaluations' outcome."""
    rule, jacobian = VARIANTS[variant]
    t0 = time.perf_counter()
    with nullcontext() if rule is None else contact_rule(*rule):
        result = cal.calibrate(data, start, BASELINE_FREE, responses=cal.RESPONSES, scales=scales, jacobian=jacobian)
    return {"variant": variant, "wall_s": time.perf_counter() - t0, "sse": result.sse, "free": result.free,
            "success": result.success}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds (default 3)")
    ap.add_argument("--seed", type=int, default=7, help="the synthetic set's seed (default 7)")
    ap.add_argument("--out", type=Path, default=HERE / "results" / "validation_fit.json")
    args = ap.parse_args(argv)
    if args.rounds < 1:
        ap.error(f"--rounds {args.rounds}: give at least 1")
    data = syn.synthetic_measurements({}, np.random.default_rng(args.seed), cond=syn.whole_domain_conditions())
    start = replace(syn.TRUE_SOIL, a1=0.2, n0=0.8, friction_angle=30.0, cohesion=100.0, kphi_prime=500.0, kc_prime=20.0)
    scales = cal.response_scales(data, cal.RESPONSES)
    rounds = []
    for k in range(args.rounds):
        runs = {v: fit(data, start, scales, v) for v in VARIANTS}
        rounds.append(runs)
        print(f"round {k + 1}: " + ", ".join(f"{v} {r['wall_s']:.2f} s" for v, r in runs.items()), flush=True)
    best = {v: min(r[v]["wall_s"] for r in rounds) for v in VARIANTS}
    lines = []
    summary = {}
    for v in VARIANTS:
        ratios = [r["before"]["wall_s"] / r[v]["wall_s"] for r in rounds]
        ref, mine = rounds[0]["before"]["free"], rounds[0][v]["free"]
        moved = max(abs(mine[p] - ref[p]) / abs(ref[p]) for p in ref)
        summary[v] = {"best_s": best[v], "speedup_per_round": ratios, "speedup_median": statistics.median(ratios),
                      "speedup_best": best["before"] / best[v], "sse": rounds[0][v]["sse"],
                      "largest_parameter_change_vs_before": moved}
        lines.append(f"{v:7s} best {best[v]:.2f} s; speed-up over before per round "
                     f"{', '.join(f'{x:.2f}' for x in ratios)} (median {statistics.median(ratios):.2f}, best vs best "
                     f"{best['before'] / best[v]:.2f}); SSE {rounds[0][v]['sse']:.6g}; parameters within "
                     f"{moved:.1e} of before's")
    print("\n".join(lines))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"machine": machine(), "versions": versions(), "rows": len(data), "seed": args.seed,
                                    "rounds": rounds, "summary": summary}, indent=2, default=float))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
