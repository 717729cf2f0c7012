"""``wheelsoil batch``: a sweep of cases on local processes or a dask cluster."""

from __future__ import annotations

from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``batch`` command on ``sub``."""
    p = sub.add_parser("batch", help="run a sweep of cases (local processes or a dask cluster); summary and figures",
                       description="Run a sweep file: a base case plus lists to combine (grid) or explicit rows "
                                   "(cases/sweep.py documents the format; 'wheelsoil batch mini-slip' is a small "
                                   "preset, smoke-figures and smoke-flexible-rigid the smoke-scale trends, "
                                   "seed004-figures the paper's 90 cases). Each case runs in its own process "
                                   "and writes <out>/cases/<case hash>/; finished cases are skipped when the sweep "
                                   "runs again, failed ones retried; one failing case never stops the others. Writes "
                                   "status.json, summary.csv, summary.parquet and figure_{sinkage,drawbar_pull,"
                                   "lateral_force}.png (seed 004 Figs. 6-8). Exit code 4 when some cases failed.")
    p.add_argument("sweep", help="sweep file (.toml) or preset (mini-slip, smoke-figures, smoke-flexible-rigid, "
                                 "seed004-figures)")
    p.add_argument("--out", type=Path, default=None, help="sweep folder (default wheelsoil-output/sweeps/<name>)")
    common.add_pool_options(p, "case", None, "local worker processes (default: the CPU count; a coupled run keeps "
                                             "about one core busy)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="dask.distributed scheduler (e.g. tcp://host:8786) to send the cases to instead; its workers "
                        "need wheelsoil installed and the sweep folder on a shared file system")
    p.add_argument("--list", action="store_true", help="only list the cases and whether they are finished")
    p.add_argument("--budget", type=float, default=None, metavar="HOURS",
                   help="wall hours the unfinished cases may take on this machine: refused before any run when even "
                        "the fast end of their estimate (cases/cost.py) cannot be held, said when the slow end cannot "
                        "(not with --scheduler: a cluster's speed is not this machine's)")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    import os

    from ..sweep import load_sweep, run_sweep

    console = common.console()
    sweep = load_sweep(args.sweep, args.out)
    if args.list:
        for c in sweep.cases:
            print(f"{c.folder.name}  {'finished' if c.finished else 'to run  '}  {c.name}")
        return common.EXIT_OK
    common.check_workers_and_timeout(args.workers, args.timeout)
    if args.scheduler is None:
        console.print(common.budget_said(sweep, args.budget))
    elif args.budget is not None:
        raise common.InputError("--budget is for runs on this machine; a --scheduler's workers have their own speed")
    workers = args.workers or os.cpu_count() or 1
    status = run_sweep(sweep, workers=workers, scheduler=args.scheduler, arch=args.arch, progress=console.is_terminal,
                       console=console, timeout=args.timeout)
    failed = {k: v for k, v in status.items() if v["status"] == "failed"}
    done = sum(v["status"] == "finished" for v in status.values())
    console.print(f"sweep {sweep.name}: {done} run, {len(status) - done - len(failed)} skipped (finished before), "
                  f"{len(failed)} failed; summary.csv, summary.parquet, figures and status.json in {sweep.out}")
    for key, v in failed.items():
        console.print(f"  [red]failed[/] {key}: {v.get('error')} (log: {sweep.out / 'cases' / key / 'run.log'})")
    return common.EXIT_SWEEP_FAILED if failed else common.EXIT_OK
