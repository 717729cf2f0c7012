"""The contact arc's quadrature error and cost: the graded rule against the plain one, measured on the semi-empirical
model's forces, written to docs/validation/quadrature.md.

Every force of :func:`wheelsoil.validation.terramechanics.contact_forces` is an integral over the contact arc in two
regions; the normal stress vanishes at both outer ends as a power n of the distance (the sinkage exponent), so the
plain Gauss--Legendre rule converges slowly there (:mod:`wheelsoil.validation.quadrature`). For each sinkage exponent
n (0.5--2, with n1 = 0.2 on top: the slip-dependent exponent), a rear region (c3 = 0.2) and both shear forms, over the
campaigns' whole-domain conditions (driving, braking, dragged and 90 deg rows, both gravities; 210 rows): the
sinkage of vertical equilibrium is solved once with the reference rule (400 nodes a region, power 3), and the forces
at that sinkage are evaluated with each rule. The error of a response is its largest absolute difference from the
reference over the rows, relative to its largest magnitude over the rows. The reference is checked against 400 nodes
of power 2 (the line "reference vs power 2"). The cost is the best of ``--repeat`` cold solves of
:func:`~wheelsoil.validation.terramechanics.predict` over the 210 rows (sinkage and forces), in one process, the
rules alternated.

Usage (from the repository root; about a minute)::

    python docs/validation_quadrature.py [--repeat 5] [--out docs/validation/quadrature.md]
"""

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from wheelsoil.validation import synthetic as syn
from wheelsoil.validation.quadrature import CONTACT_POINTS, GRADING_POWER, QUADRATURE_POINTS, contact_rule
from wheelsoil.validation.terramechanics import CheckedConditions, forces_at_sinkage, predict

RESPONSES = ("drawbar_pull", "lateral_force", "vertical_force", "torque")
REFERENCE = (400, 3)
#: (nodes a region, power): the plain rule used before (48, 1), and graded ones.
RULES = ((48, 1), (96, 1), (16, 2), (24, 2), (32, 2), (16, 3), (24, 3), (32, 3))
EXPONENTS = (0.5, 0.7, 1.0, 1.1, 1.5, 2.0)


def soils():
    """The soils measured: the synthetic campaigns' true soil with each exponent, a rear region, both shear forms."""
    for n0 in EXPONENTS:
        for shear_form in ("independent", "resultant"):
            yield f"n0 {n0:g} + 0.2 |i|, {shear_form}", replace(syn.TRUE_SOIL, n0=n0, n1=0.2, c3=0.2,
                                                                 shear_form=shear_form)


def conditions() -> dict:
    cond = syn.whole_domain_conditions()
    return {k: np.asarray(cond[k], float) for k in ("slip", "slip_angle", "load", "gravity", "passes", "travel_slip")
            if k in cond}


def forces_at(soil, wheel, sinkage, cond, rule) -> dict:
    with contact_rule(*rule):
        return forces_at_sinkage(soil, wheel, sinkage, CheckedConditions.of(**cond))


def braking_rows(cond: dict) -> np.ndarray:
    """Rows braking (-1 < travel slip < 0): the only ones whose shear changes sign inside the contact, where the
    integrands have a kink (the independent form) or a jump (the resultant form, whose direction follows the slip
    velocity), so every rule converges there only algebraically."""
    return (cond["travel_slip"] > -1.0) & (cond["travel_slip"] < 0.0)


def relative_error(out: dict, ref: dict, rows: np.ndarray) -> float:
    """The largest error over the responses and ``rows``, each relative to the response's largest magnitude over
    all rows."""
    return max(float(np.max(np.abs(out[q][rows] - ref[q][rows])) / np.max(np.abs(ref[q]))) for q in RESPONSES)


def measure(repeat: int) -> tuple[dict, dict, list]:
    """Errors per rule: {rule: [(error over the rows whose shear keeps its sign, over the braking rows)] per soil};
    the best predict time per rule [s]; the soils' names with the reference's check against power 2."""
    wheel, cond = syn.TEST_WHEEL, conditions()
    braking = braking_rows(cond)
    errors: dict = {rule: [] for rule in RULES}
    checks = []
    for name, soil in soils():
        with contact_rule(*REFERENCE):
            sinkage = predict(soil, wheel, **cond)["sinkage"]
        ref = forces_at(soil, wheel, sinkage, cond, REFERENCE)
        power_2 = forces_at(soil, wheel, sinkage, cond, (REFERENCE[0], 2))
        checks.append((name, relative_error(power_2, ref, ~braking), relative_error(power_2, ref, braking)))
        for rule in RULES:
            out = forces_at(soil, wheel, sinkage, cond, rule)
            errors[rule].append((relative_error(out, ref, ~braking), relative_error(out, ref, braking)))
    soil = replace(syn.TRUE_SOIL, n0=0.8, n1=0.2, c3=0.2)
    seconds: dict = {rule: [] for rule in RULES}
    for _ in range(repeat):
        for rule in RULES:
            with contact_rule(*rule):
                t0 = time.perf_counter()
                predict(soil, wheel, **cond)
                seconds[rule].append(time.perf_counter() - t0)
    return errors, {rule: min(v) for rule, v in seconds.items()}, checks


def report(errors: dict, seconds: dict, checks: list, command: str) -> str:
    n_braking = int(braking_rows(conditions()).sum())
    lines = [
        "# The contact arc's quadrature: error and cost",
        "",
        f"Generated by `{command}` (the method: the script's docstring). Error: the largest difference from the "
        f"reference rule ({REFERENCE[0]} nodes a region, power {REFERENCE[1]}) over the rows and the four forces, "
        f"relative to each force's largest magnitude over the 210 whole-domain rows, at the reference's sinkage; worst "
        f"over the {len(checks)} soils (sinkage exponents {', '.join(f'{n:g}' for n in EXPONENTS)} plus 0.2 |i|, a "
        f"rear region, both shear forms). Apart: the {n_braking} braking rows, whose shear changes sign inside the "
        f"contact (a kink or a jump in the integrand, where every rule converges slowly), and the other "
        f"{210 - n_braking}. Cost: the best cold `predict` over the 210 rows (sinkage solve and forces), beside other "
        f"jobs on the machine. The package uses {CONTACT_POINTS} nodes a region of power {GRADING_POWER}; before "
        f"2026-11-29 it used the plain rule with {QUADRATURE_POINTS}.",
        "",
        "| nodes a region | power | worst error, shear of one sign | worst error, braking rows | predict [ms] | "
        "cost / plain 48 |",
        "|---|---|---|---|---|---|",
    ]
    base = seconds[(48, 1)]
    for rule in RULES:
        e = np.asarray(errors[rule])
        lines.append(f"| {rule[0]} | {rule[1]}{' (plain)' if rule[1] == 1 else ''} | {e[:, 0].max():.1e} | "
                     f"{e[:, 1].max():.1e} | {seconds[rule] * 1e3:.1f} | {seconds[rule] / base:.2f} |")
    lines += ["", f"The reference against power 2 at {REFERENCE[0]} nodes: worst {max(c[1] for c in checks):.1e} "
              f"(shear of one sign), {max(c[2] for c in checks):.1e} (braking rows): on braking rows the reference is "
              "itself uncertain by that much (the integrand's kink or jump where the shear reverses, which no rule "
              "resolves without a node there), so errors below it are not resolved.", "",
              f"By soil, plain 48 against graded {CONTACT_POINTS} of power {GRADING_POWER} (shear of one sign; "
              "braking rows):", ""]
    chosen = (CONTACT_POINTS, GRADING_POWER)
    for k, (name, _, _) in enumerate(checks):
        old = errors[(48, 1)][k]
        new = errors[chosen][k] if chosen in errors else (np.nan, np.nan)
        lines.append(f"- {name}: {old[0]:.1e} → {new[0]:.1e}; {old[1]:.1e} → {new[1]:.1e}")
    return "\n".join(lines) + "\n"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="cold predicts timed per rule (best taken)")
    parser.add_argument("--out", type=Path, default=Path("docs/validation/quadrature.md"))
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat}: give at least 1")
    errors, seconds, checks = measure(args.repeat)
    text = report(errors, seconds, checks, f"python docs/validation_quadrature.py --repeat {args.repeat}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text)
    print(text)


if __name__ == "__main__":
    main()
