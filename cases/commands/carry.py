"""``wheelsoil carry``: unfinished runs to another machine, their checkpoints without their frames."""

from __future__ import annotations

from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``carry`` command on ``sub``."""
    p = sub.add_parser("carry", help="carry unfinished runs to another machine: their checkpoints, without frames",
                       description="pack: the checkpoint of every unfinished run under RUNS (a run folder, a sweep, a "
                                   "folder of them) into DIR, compressed, one file a case (<case hash>.carry.h5); "
                                   "unpack: those files back under RUNS on the other machine, where --resume (or the "
                                   "sweep, which resumes any case with a checkpoint) continues each run. The series "
                                   "and summary are those of a run never moved; the result keeps only the frames "
                                   "from the carry on (cases/carry.py).")
    how = p.add_subparsers(dest="action", required=True, metavar="pack|unpack")
    pack = how.add_parser("pack", help="pack the unfinished runs under RUNS into DIR")
    pack.add_argument("runs", type=Path, metavar="RUNS", help="a run folder or a folder of runs")
    pack.add_argument("--to", type=Path, required=True, metavar="DIR", help="the carry folder")
    pack.add_argument("--max-mb", type=float, default=None,
                      help="skip checkpoints larger than this on disk (default 60 MB)")
    pack.add_argument("--finished-in", action="append", default=[], metavar="SUB",
                      help="also pack the finished runs under RUNS/SUB, without their frames (<case hash>.result.h5), "
                           "so that a long sweep's finished cases are not run again on the other machine; repeatable")
    unpack = how.add_parser("unpack", help="put the runs carried in DIR back under RUNS")
    unpack.add_argument("carries", type=Path, metavar="DIR", help="the carry folder")
    unpack.add_argument("--into", type=Path, required=True, metavar="RUNS", help="the runs folder")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    from ..carry import DEFAULT_MAX_MB, pack_runs, unpack_runs

    console = common.console()
    if args.action == "pack":
        done = pack_runs(args.runs, args.to, max_mb=DEFAULT_MAX_MB if args.max_mb is None else args.max_mb,
                         finished_in=tuple(args.finished_in))
        empty = f"no unfinished run with a checkpoint under {args.runs}" + (
            f" and no finished run under {', '.join(args.finished_in)}" if args.finished_in else "")
    else:
        done = unpack_runs(args.carries, args.into)
        empty = f"no carried run in {args.carries}"
    for item in done:
        console.print(item.line(), markup=False, highlight=False)
    if not done:
        console.print(empty)
    return common.EXIT_OK
