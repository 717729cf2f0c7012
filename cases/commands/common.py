"""What the commands share: exit codes, the input error they raise for a bad option, the console and progress bar,
and the options declared the same way everywhere (``--set``, ``--arch``, ``--workers``/``--timeout`` checks)."""

from __future__ import annotations

import argparse

EXIT_OK, EXIT_BUG, EXIT_INPUT, EXIT_UNSTABLE, EXIT_SWEEP_FAILED = 0, 1, 2, 3, 4


class InputError(ValueError):
    """A command-line option out of range (exit code 2, the message names the option and the value)."""


def add_set_option(p: argparse.ArgumentParser, help: str = "override a case key (repeatable)") -> None:
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help=help)


def add_arch_option(p: argparse.ArgumentParser, what: str = "") -> None:
    """``--arch``: the Taichi backend (``what``: whose, e.g. "of every case")."""
    p.add_argument("--arch", default=None, help=f"Taichi backend{' ' + what if what else ''}: cpu (default), cuda, "
                                                "vulkan, metal, or gpu (the first of cuda and vulkan found)")


def add_pool_options(p: argparse.ArgumentParser, unit: str, workers_default: int | None, workers_help: str) -> None:
    """``--workers``, ``--timeout`` and ``--arch`` of a command that runs many ``unit``s (cases, replicas)."""
    p.add_argument("--workers", type=int, default=workers_default, help=workers_help)
    p.add_argument("--timeout", type=float, default=None, help=f"give up a {unit} after this many seconds (default: none)")
    add_arch_option(p, f"of every {unit}")


def check_workers_and_timeout(workers: int | None, timeout: float | None) -> None:
    """``--workers`` at least 1 and ``--timeout`` positive, where given."""
    if workers is not None and workers < 1:
        raise InputError(f"--workers {workers} must be >= 1")
    if timeout is not None and not timeout > 0:
        raise InputError(f"--timeout {timeout} must be > 0 seconds")


def console():
    from rich.console import Console

    return Console(stderr=False)


def progress(console):
    """A transient rich progress bar with counts and the time remaining."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                    TimeRemainingColumn(), console=console, transient=True)


def budget_said(sweep, budget_hours: float | None, what: str = "cases", *, same_case: bool = False) -> str:
    """The wall time the sweep's unfinished runs will take on this machine, checked against ``budget_hours``
    (:func:`wheelsoil.cases.cost.check_budget`: a budget that cannot hold them is refused here, before any run). With
    ``same_case`` (replicas: one case on other seeds) the finished runs' mean wall time is the estimate where there
    are any; otherwise each run's size gives its range."""
    from ..build import plan
    from ..cost import check_budget, run_cost
    from ..results import load_result

    todo = [c for c in sweep.cases if not c.finished]
    if not todo:
        return f"all {what} have finished; nothing to run"
    if same_case:
        walls = [load_result(c.folder).info.get("wall_seconds") for c in sweep.cases if c.finished]
        costs = [run_cost(plan(todo[0].case), finished_walls=walls)] * len(todo)
    else:
        costs = [run_cost(plan(c.case)) for c in todo]
    return check_budget(costs, budget_hours, what)
