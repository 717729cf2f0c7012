"""A stored convergence study (its ``convergence.json``) asked again with the extrapolated definition of
"converged" (:func:`wheelsoil.cases.convergence_report.extrapolate_levels`): particle size, DEM step and wheel mesh
extrapolated to scale 0 from the levels' stored means and standard errors, no run needed.

Usage (from the repository root)::

    python docs/convergence_extrapolate.py docs/convergence/smoke-1g-steer/convergence.json [--case smoke-1g-steer]
        [--replicas RUNS/replicas/smoke-1g-steer/replicas.json]

``--replicas``: every level's standard error gets the run-to-run excess spread those replicas measured added in
quadrature (:func:`wheelsoil.cases.convergence_report.with_excess`).

Prints a Markdown table: per factor and quantity the extrapolated value +- its standard error, the reference's
error against it (relative, +- one standard error) and whether that error plus two standard errors is within the
study's threshold.
"""

from __future__ import annotations

import argparse
import json
import sys


def main(argv=None) -> int:
    from wheelsoil.cases import convergence as cv
    from wheelsoil.cases import convergence_report as report
    from wheelsoil.cases.schema import load_case

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("study_json")
    parser.add_argument("--case", default=None, help="the study's base case (default: the JSON's 'base')")
    parser.add_argument("--replicas", default=None, help="a replicas.json whose excess spread to add to every level")
    args = parser.parse_args(argv)
    from wheelsoil.cases.replicas import ReplicaSpread
    excess = ReplicaSpread.read(args.replicas, "--replicas").excess if args.replicas else None
    study = json.loads(open(args.study_json).read())
    case = load_case(args.case or study["base"])
    floors = report.relative_floors(case)
    threshold = float(study["threshold"])
    print(f"| factor | levels | quantity | extrapolated | reference | reference's error | converged "
          f"({100 * threshold:.0f} %, 2 SE) |")
    print("|---|---|---|---|---|---|---|")
    for factor in report.REFINED_TOWARDS_ZERO:
        levels = study["levels"].get(factor)
        if not levels or len(levels) < 2:
            continue
        pairs = [(s, report.with_excess(v, excess)) for s, v in report.stored_levels(study, factor)]
        for row in report.extrapolate_levels(factor, pairs, floors, threshold):
            label, unit, scale = cv.QUANTITIES[row["quantity"]]
            scales = ", ".join(f"{s:g}" for s, _ in pairs)
            if "value" not in row:
                print(f"| {factor} | {scales} | {label} | {row['reason']} | | | |")
                continue
            reference = pairs[0][1][row["quantity"]][0]
            print(f"| {factor} | {scales} | {label} [{unit}] | {scale * row['value']:.4g} ± {scale * row['value_se']:.2g} "
                  f"| {scale * reference:.4g} | {100 * row['relative_error']:+.1f} ± {100 * row['relative_error_se']:.1f} % "
                  f"| {'yes' if row['converged'] else '**no**'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
