"""The wheel contact's candidate culling (``WheelContact.cull_far_candidates``) against none, on a run's own state.

Each candidate (sphere, facet) pair whose sphere lies farther than its radius plus the contact margin from the
facet's plane, or from the ball that holds the facet, is set aside before its closest point is sought
(``coupling/kernels.py``: ``facet_bounds``, ``surely_apart``); the result does not change (to the bit,
``tests/test_coupling_contact.py``). What it saves depends on how many candidates the wheel holds, so it is timed
here on a real run's checkpoint (a deep, steered wheel holds most), not on a fresh bed: the testbed is restored from
``RUN/.checkpoint.h5`` and stepped on, in alternating rounds of ``--steps`` DEM steps with the culling on and off
(the order swapped each round, so that the machine's drift falls on both alike), the contact evaluation
(``add_forces``) timed apart from the whole coupled step; then the evaluation alone, repeated on the last state
(``--evaluations`` a round, alternating as well), which stepping's own noise does not reach, and its part without
spheres (the launch, the nodes' loads, the resultant).

Usage (from the repository root; a run folder with its ``case.toml`` and checkpoint, its bed from the cache or
prepared again)::

    WHEELSOIL_CPU_THREADS=1 python -m wheelsoil.benchmarks.contact_culling --run RUN [--steps 300] [--rounds 6] \\
        [--evaluations 40] [--out benchmarks/results/contact-culling.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
from pathlib import Path

from wheelsoil.benchmarks.common import alternating_kernel_times
from wheelsoil.benchmarks.coupled_rounds import _timed


def _stepping(bench, steps: int, cull: bool, totals: dict, contact: list, counts: dict):
    """A call that steps the testbed ``steps`` DEM steps with the culling ``cull``, appending its contact evaluation's
    seconds per step (from ``totals``, :func:`~.coupled_rounds._timed`) to ``contact`` and, culled, the candidates,
    contacts and those set aside to ``counts``."""
    c = bench.contact

    def call():
        c.cull_far_candidates = cull
        c0 = totals["contact"]
        bench.scene.step(steps)
        contact.append((totals["contact"] - c0) / steps)
        if cull:
            counts["set_aside"].append(c.candidates_set_aside)
            counts["candidates"].append(c.candidate_count)
            counts["contacts"].append(c.contact_count)
    return call


def _evaluation(contact, dt: float, cull: bool, spheres: bool = True):
    """A call that evaluates the contact once on the testbed's present state, with the culling ``cull``, and without
    any active sphere unless ``spheres`` (then only the launch, the nodes' loads and the resultant run)."""
    def call():
        contact.cull_far_candidates = cull
        active = contact._n_active
        if not spheres:
            contact._n_active = 0
        contact._launch_contacts(dt)
        contact._n_active = active
    return call


def _ratios(on, off) -> list[float]:
    return [float(b / a) for a, b in zip(on, off)]


def culling_rounds(bench, steps: int, rounds: int, evaluations: int = 40) -> dict:
    """``rounds`` pairs of ``steps`` coupled DEM steps of the testbed ``bench``, the culling on and off in turn; the
    wall per step of each and of its contact evaluation, and the candidates, contacts and those set aside; then
    ``rounds`` rounds of ``evaluations`` contact evaluations on the last state alone, culled, not culled and without
    spheres in turn (:func:`~.common.alternating_kernel_times` times both). Leaves the testbed's spheres with forces
    added many times over: step it no further."""
    c, scene = bench.contact, bench.scene
    totals = {"contact": 0.0}
    _timed(c, "add_forces", totals, "contact")
    for cull in (True, False):  # compile both
        c.cull_far_candidates = cull
        scene.step(10)
    contact = {True: [], False: []}
    counts = {"candidates": [], "contacts": [], "set_aside": []}
    per = alternating_kernel_times({cull: _stepping(bench, steps, cull, totals, contact[cull], counts)
                                    for cull in (True, False)}, rounds, repeats=1)
    per = {cull: per[cull] / steps for cull in per}
    # the evaluation alone, repeated on the last state (it adds its forces again and again to the spheres' external
    # forces: nothing is stepped after it)
    calls = {"cull": _evaluation(c, bench.dt, True), "no_cull": _evaluation(c, bench.dt, False),
             "without_spheres": _evaluation(c, bench.dt, True, spheres=False)}
    frozen = alternating_kernel_times(calls, rounds, repeats=evaluations)
    ratio, ratio_contact = _ratios(per[True], per[False]), _ratios(contact[True], contact[False])
    ratio_frozen = _ratios(frozen["cull"], frozen["no_cull"])
    ms = lambda xs: [1e3 * float(x) for x in xs]  # noqa: E731
    return {
        "steps_per_round": steps, "rounds": rounds,
        "ms_per_step_cull": ms(per[True]), "ms_per_step_no_cull": ms(per[False]),
        "ms_per_step_contact_cull": ms(contact[True]), "ms_per_step_contact_no_cull": ms(contact[False]),
        "step_no_cull_over_cull_median": statistics.median(ratio), "step_no_cull_over_cull": ratio,
        "contact_no_cull_over_cull_median": statistics.median(ratio_contact),
        "contact_no_cull_over_cull": ratio_contact,
        "evaluations_per_round": evaluations,
        "ms_per_evaluation_cull": ms(frozen["cull"]), "ms_per_evaluation_no_cull": ms(frozen["no_cull"]),
        "evaluation_no_cull_over_cull_median": statistics.median(ratio_frozen),
        "evaluation_no_cull_over_cull": ratio_frozen,
        "ms_per_evaluation_without_spheres": ms(frozen["without_spheres"]),
        **{f"{key}_median": statistics.median(v) for key, v in counts.items()},
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--run", type=Path, required=True, help="a run folder with case.toml and .checkpoint.h5")
    ap.add_argument("--steps", type=int, default=300, help="DEM steps per round and setting (>= 10)")
    ap.add_argument("--rounds", type=int, default=6, help="alternating rounds (>= 2)")
    ap.add_argument("--evaluations", type=int, default=40, help="repeated evaluations per round on the last state")
    ap.add_argument("--arch", default=None)
    ap.add_argument("--out", type=Path, default=None, help="write the figures here as JSON")
    args = ap.parse_args(argv)
    from wheelsoil.cases import build
    from wheelsoil.cases.run import CHECKPOINT_NAME
    from wheelsoil.cases.schema import load_case
    from wheelsoil.coupling.testbed import Testbed
    from wheelsoil.errors import WheelsoilInputError
    from wheelsoil.granular.bed import prepare_bed
    from wheelsoil.state_file import load_state

    try:
        if args.steps < 10 or args.rounds < 2 or args.evaluations < 1:
            raise WheelsoilInputError(f"--steps {args.steps} must be >= 10, --rounds {args.rounds} >= 2 and "
                                      f"--evaluations {args.evaluations} >= 1")
        for need in ("case.toml", CHECKPOINT_NAME):
            if not (args.run / need).is_file():
                raise WheelsoilInputError(f"{args.run} has no {need}: give a run folder with a checkpoint")
        case = load_case(args.run / "case.toml")
    except WheelsoilInputError as e:
        print(f"contact_culling: error: {e}", file=sys.stderr)
        return 2
    plan = build.plan(case)
    bed = prepare_bed(plan.bed, arch=args.arch)
    bench = Testbed(bed, plan=plan.rig, arch=args.arch)
    state, meta = load_state(args.run / CHECKPOINT_NAME)
    bench.restore_state(state)
    report = {"run": str(args.run), "case": case.name, "t": float(meta["t"]), "particles": bed.n_particles,
              "facets": bench.contact.surface.n_facets,
              **culling_rounds(bench, args.steps, args.rounds, args.evaluations)}
    print(f"{case.name} from t = {report['t']:.2f} s ({report['particles']} spheres, {report['facets']} facets): "
          f"{report['candidates_median']:.0f} candidates, {report['set_aside_median']:.0f} set aside, "
          f"{report['contacts_median']:.0f} contacts (medians); contact evaluation "
          f"{statistics.median(report['ms_per_step_contact_cull']):.2f} ms culled against "
          f"{statistics.median(report['ms_per_step_contact_no_cull']):.2f} (no cull / cull, median of "
          f"{args.rounds} rounds: {report['contact_no_cull_over_cull_median']:.2f}); coupled step "
          f"{statistics.median(report['ms_per_step_cull']):.2f} ms against "
          f"{statistics.median(report['ms_per_step_no_cull']):.2f} ({report['step_no_cull_over_cull_median']:.2f}); "
          f"the evaluation alone on the last state {statistics.median(report['ms_per_evaluation_cull']):.2f} ms "
          f"against {statistics.median(report['ms_per_evaluation_no_cull']):.2f} "
          f"({report['evaluation_no_cull_over_cull_median']:.2f}), of which "
          f"{statistics.median(report['ms_per_evaluation_without_spheres']):.2f} ms without any sphere")
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps(report, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
