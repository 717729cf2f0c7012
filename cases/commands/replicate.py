"""``wheelsoil replicate``: a case on beds of other particle seeds, the run-to-run spread."""

from __future__ import annotations

from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``replicate`` command on ``sub``."""
    p = sub.add_parser("replicate", help="run a case on beds of other particle seeds: the run-to-run spread against "
                                         "the runs' own error bars",
                       description="Run CASE once per --seeds value (a sweep over case.seed in --out: finished replicas "
                                   "are kept) and write replicas.md and replicas.json: per reported quantity the "
                                   "replicas' mean and standard deviation, the runs' own standard errors, the inflation "
                                   "factor (spread over own error, with its 95 %% interval) and how many runs' 95 %% "
                                   "intervals hold the other replicas' mean (cases/replicas.py documents the method).")
    p.add_argument("case", nargs="?", default="smoke-1g-steer", help="case file (.toml) or preset name")
    common.add_set_option(p)
    p.add_argument("--seeds", nargs="+", required=True, help="particle seeds, at least two (e.g. 0 1 2 3 4)")
    p.add_argument("--out", type=Path, default=None, help="replica folder (default wheelsoil-output/replicas/<case>)")
    common.add_pool_options(p, "replica", 1, "replicas run at once (default 1)")
    p.add_argument("--report-only", action="store_true", help="only rewrite the report from the finished replicas")
    p.add_argument("--budget", type=float, default=None, metavar="HOURS",
                   help="wall hours the replicas still to run may take: refused before any run when even the fast "
                        "end of their estimate (cases/cost.py) cannot be held, said when the slow end cannot")
    p.add_argument("--widen-by", type=Path, default=None, metavar="REPLICAS_JSON",
                   help="also check the runs' 95 %% intervals widened to t(n_f - 1) f sem, with f = max(1, inflation) "
                        "as another replica set of n_f runs measured it (its replicas.json)")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    from ..replicas import ReplicaSpread, make_replicas, write_report
    from ..schema import load_case
    from ..sweep import run_sweep

    console = common.console()
    case = load_case(args.case, list(args.set or []))
    common.check_workers_and_timeout(args.workers, args.timeout)
    out = args.out or Path("wheelsoil-output") / "replicas" / case.name
    sweep = make_replicas(case, args.seeds, out)
    if args.widen_by is not None:
        ReplicaSpread.read(args.widen_by)  # a bad file is refused before any run
    if not args.report_only:
        console.print(common.budget_said(sweep, args.budget, "replicas", same_case=True))
        run_sweep(sweep, workers=args.workers, arch=args.arch, timeout=args.timeout, progress=console.is_terminal,
                  console=console)
    paths = write_report(sweep, case, args.widen_by)
    console.print(paths[1].read_text(), markup=False)  # "[mm]" is a unit, not markup
    console.print(f"wrote {', '.join(p.name for p in paths)} in {out}")
    return common.EXIT_OK
