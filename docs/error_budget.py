"""The smoke case's error budget (issue 35 item 3): every source of error of a reported number, from the stored
studies, no run needed.

Per quantity:
* **run to run**: the replicas' spread s, relative to the reference value. It is one run's error on its own, and
  the replicas' mean carries t(n - 1) s / sqrt(n) instead.
* **particle size, DEM step, mesh**: the reference's error against the value extrapolated to scale 0
  (:func:`wheelsoil.cases.convergence_report.extrapolate_levels`). Each level's standard error has the replicas'
  excess spread added in quadrature (:func:`~wheelsoil.cases.convergence_report.with_excess`).
* **depth x2, width x2**: the reference's error against the doubled bin, (q_ref - q_2x) / q_2x. The errors are
  again widened by the excess spread.

A bias e_k with standard error u_k from each of the five scale factors is not corrected for: each is an estimate
from one or two refinements. The budget combines them as sqrt(sum_k (e_k^2 + u_k^2)), root-sum-square of each bias
and its uncertainty, the usual treatment of an uncorrected bias, GUM F.2.4.5. With the run-to-run spread added in
quadrature, this is the error of one run at the smoke scale against the converged answer.

Usage (from the repository root; seconds)::

    python docs/error_budget.py [--study docs/convergence/smoke-1g-steer/convergence.json]
        [--depth docs/convergence/smoke-1g-steer/depth-10s/convergence.json]
        [--replicas docs/replicas/smoke-1g-steer/replicas.json]

Prints a Markdown table (percent of the reference value; a factor whose levels did not all reach a steady state
is named instead of a number).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

STUDY = "docs/convergence/smoke-1g-steer/convergence.json"
DEPTH = "docs/convergence/smoke-1g-steer/depth-10s/convergence.json"
REPLICAS = "docs/replicas/smoke-1g-steer/replicas.json"
REFINED = ("particle_size", "time_step", "mesh")
DOUBLED = ("depth", "width")


def budget(study: dict, depth_study: dict | None, excess: dict, spread: dict, floors: dict, threshold: float) -> dict:
    """Per quantity: the reference value, each source as (relative error, its standard error) or a reason, the
    combined scale error and the one-run total (relative)."""
    from wheelsoil.cases import convergence as cv
    from wheelsoil.cases import convergence_report as report

    out = {}
    sources = {}
    for factor in REFINED:
        levels = [(s, report.with_excess(v, excess)) for s, v in report.stored_levels(study, factor)]
        sources[factor] = {r["quantity"]: r for r in report.extrapolate_levels(factor, levels, floors, threshold)}
    for factor in DOUBLED:
        source = depth_study if factor == "depth" and depth_study is not None else study
        levels = [(s, report.with_excess(v, excess)) for s, v in report.stored_levels(source, factor)]
        sources[factor] = {}
        (_, ref), (_, doubled) = levels[0], levels[-1]
        for q in cv.QUANTITIES:
            if ref is None or doubled is None or not (ref["steady"] and doubled["steady"]):
                sources[factor][q] = {"reason": "not every level reached a steady state"}
                continue
            scale = max(abs(doubled[q][0]), floors[q])
            sources[factor][q] = {"relative_error": (ref[q][0] - doubled[q][0]) / scale,
                                  "relative_error_se": math.hypot(ref[q][1], doubled[q][1]) / scale}
    reference = report.stored_levels(study, "particle_size")[0][1]
    for q in cv.QUANTITIES:
        value = reference[q][0]
        scale = max(abs(value), floors[q])
        row = {"value": value, "run_to_run": spread[q] / scale, "sources": {}}
        squares, known = 0.0, True
        for factor in REFINED + DOUBLED:
            r = sources[factor][q]
            if "relative_error" not in r:
                row["sources"][factor] = r.get("reason", "not run")
                known = False
                continue
            e, u = r["relative_error"], r["relative_error_se"]
            row["sources"][factor] = (e, u)
            squares += e * e + u * u
        row["scale_error"] = math.sqrt(squares) if known else math.nan
        row["one_run"] = math.hypot(row["scale_error"], row["run_to_run"]) if known else math.nan
        out[q] = row
    return out


def main(argv=None) -> int:
    from wheelsoil.cases import convergence as cv
    from wheelsoil.cases import convergence_report as report
    from wheelsoil.cases.replicas import ReplicaSpread
    from wheelsoil.cases.schema import load_case

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--study", default=STUDY)
    parser.add_argument("--depth", default=DEPTH, help="a depth study that replaces the main study's depth levels")
    parser.add_argument("--replicas", default=REPLICAS)
    args = parser.parse_args(argv)
    study = json.loads(open(args.study).read())
    depth_study = json.loads(open(args.depth).read()) if args.depth else None
    replicas = ReplicaSpread.read(args.replicas, "--replicas")
    floors = report.relative_floors(load_case(study["base"]))
    rows = budget(study, depth_study, replicas.excess, replicas.spread, floors, float(study["threshold"]))

    def cell(x):
        return x if isinstance(x, str) else f"{100 * x[0]:+.1f} ± {100 * x[1]:.1f}"

    print("| quantity | reference | run to run (one run) | particle size | DEM step | mesh | depth ×2 | width ×2 "
          "| scale error | one run's error |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for q, r in rows.items():
        label, unit, scale = cv.QUANTITIES[q]
        cells = " | ".join(cell(r["sources"][f]) for f in REFINED + DOUBLED)
        print(f"| {label} [{unit}] | {scale * r['value']:.4g} | {100 * r['run_to_run']:.1f} | {cells} | "
              f"{100 * r['scale_error']:.0f} | {100 * r['one_run']:.0f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
