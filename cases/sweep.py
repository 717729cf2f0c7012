"""Batch sweeps: a base case and lists to combine, run by local processes or a dask.distributed cluster.

A sweep file (TOML)::

    [sweep]
    name = "smoke-slip"            # default: the file name
    base = "smoke-1g-steer"        # a preset or a case file (relative to the sweep file)
    set = { "output.render" = false }          # overrides for every case (optional)

    [sweep.grid]                   # every combination (cartesian product)
    "test.slip" = [0.1, 0.3, 0.5]
    "test.slip_angle" = [0, 10, 20]

    [[sweep.rows]]                 # explicit rows; with a grid, each row is combined with every grid point
    "soil.gravity" = "earth"
    "test.load" = 3000
    [[sweep.rows]]
    "soil.gravity" = "moon"
    "test.load" = 500

Each case runs in its own process (``wheelsoil run`` on the case's resolved TOML) and writes its
run folder under ``<out>/cases/<case hash>/``; a case whose folder holds a finished result is
skipped when the sweep runs again, a failed one is retried, and one failing case never stops the
others: its error is in ``status.json`` and its ``run.log``. At the end ``summary.csv`` and
``summary.parquet`` hold one row per finished case (the swept keys, the main rig settings, the
steady-state means and standard deviations), and ``figure_*.png`` plot sinkage, drawbar pull and
lateral force against slip, one panel per steering angle, one line per gravity and load (seed 004
Figs. 6--8).
"""

from __future__ import annotations

import itertools
import json
import os
import socket
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.provenance import atomic_output
from wheelsoil.runtime import CPU_THREADS_VAR

from . import build
from .run import RESULT_NAME
from .schema import (CaseError, CaseFile, apply_overrides, case_to_toml, load_case, parse_toml, read_toml_text,
                     validate_case)


class SweepSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    name: Optional[str] = Field(None, pattern=r"^[A-Za-z0-9._+-]+$", description="sweep name (default: file name)")
    base: str = Field(..., description="base case: a preset name or a case file relative to the sweep file")
    set: dict[str, Any] = Field(default_factory=dict, description="overrides for every case")
    grid: dict[str, list[Any]] = Field(default_factory=dict, description="keys to combine: every combination")
    rows: list[dict[str, Any]] = Field(default_factory=list, description="explicit rows of overrides")


@dataclass
class SweepCase:
    """One case of a sweep: its swept values, the validated case and where it runs."""

    values: dict
    case: CaseFile
    folder: Path

    @property
    def name(self) -> str:
        return self.case.name

    @property
    def finished(self) -> bool:
        return (self.folder / RESULT_NAME).is_file()


@dataclass
class Sweep:
    name: str
    cases: list[SweepCase]
    out: Path
    swept_keys: list[str] = field(default_factory=list)


def _flatten(table: dict, prefix: str = "") -> dict:
    """{"test": {"slip": [..]}} or {"test.slip": [..]} -> {"test.slip": [..]}."""
    out = {}
    for key, value in table.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict) and "." not in key and not prefix:
            out.update(_flatten(value, f"{path}."))
        else:
            out[path] = value
    return out


def _label(value) -> str:
    """A swept value as part of a case name: numbers short, lists joined by "x" (none: "none"), tables (a drive
    stage) as key and value joined by "+"."""
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "x".join(_label(v) for v in value) if value else "none"
    if isinstance(value, dict):
        return "+".join(f"{k}{_label(v)}" for k, v in value.items())
    return str(value).replace(" ", "")


def load_sweep(path: str | Path, out: str | Path | None = None) -> Sweep:
    """Read and validate a sweep file and every case it makes (errors name the file, row and key)."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        from importlib import resources

        packaged = resources.files("wheelsoil.cases") / "presets" / "sweeps" / f"{path.name}.toml"
        if path.suffix or not packaged.is_file():
            raise WheelsoilInputError(f"sweep file {source!r} does not exist")
        text, source, stem, base_dir = packaged.read_text(), f"sweep preset {path.name}", path.name, Path.cwd()
    else:
        text, stem, base_dir = read_toml_text(path), path.stem, path.parent
    data = parse_toml(text, source)
    if set(data) != {"sweep"}:
        raise CaseError(source, [f"a sweep file has one table, [sweep]; found {sorted(data)}"])
    try:
        spec = SweepSpec.model_validate(data["sweep"])
    except ValidationError as exc:
        raise CaseError(source, [f"sweep.{'.'.join(str(p) for p in e['loc'])}: {e['msg']}" for e in exc.errors()]) from None
    name = spec.name or stem
    base_path = base_dir / spec.base
    base = str(base_path) if spec.base.endswith(".toml") else spec.base
    common = _flatten(spec.set)
    grid = _flatten(spec.grid)
    for key, values in grid.items():
        if not values:
            raise CaseError(source, [f"sweep.grid.{key} is empty"])
    rows = [_flatten(r) for r in spec.rows] or [{}]
    points = [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())] if grid else [{}]
    swept = list(dict.fromkeys(list(grid) + [k for r in rows for k in r]))
    base_case = load_case(base)  # validates the base alone first: its errors name the base file
    base_data = base_case.model_dump(mode="json")
    out = Path(out) if out is not None else Path("wheelsoil-output") / "sweeps" / name
    cases, seen = [], {}
    for k, (row, point) in enumerate(itertools.product(rows, points)):
        values = {**row, **point}
        overrides = [(key.split("."), value) for key, value in {**common, **values}.items()]
        where = f"{source}, case {k} ({', '.join(f'{a}={_label(b)}' for a, b in values.items()) or 'base'})"
        for path_, _ in overrides:
            if len(path_) != 2:
                raise CaseError(where, [f"{'.'.join(path_)} is not section.key"])
        label = "-".join(f"{key.split('.')[-1]}{_label(v)}" for key, v in values.items())
        case_data = apply_overrides(base_data, overrides)
        case_data["case"]["name"] = f"{name}-{label}" if label else name
        case = validate_case(case_data, where)
        h = case.case_hash()
        if h in seen:
            raise CaseError(source, [f"cases {seen[h]} and {k} are the same case; remove the duplicate row"])
        seen[h] = k
        cases.append(SweepCase(values=values, case=case, folder=out / "cases" / h))
    return Sweep(name=name, cases=cases, out=out, swept_keys=swept)


# -------------------------------------------------------------------- running
def _check_reachable(scheduler: str, wait: float = 5.0) -> None:
    """Refuse at once a TCP scheduler address that nothing listens on (dask itself retries for its whole
    connect timeout before it says so); other schemes are left to dask."""
    from urllib.parse import urlsplit

    parts = urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}")
    if parts.scheme != "tcp":
        return
    try:
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise WheelsoilInputError(f"--scheduler {scheduler!r} is not an address such as tcp://host:8786 ({exc})") from None
    if not host or port is None:
        raise WheelsoilInputError(f"--scheduler {scheduler!r} is not an address such as tcp://host:8786")
    try:
        socket.create_connection((host, port), timeout=wait).close()
    except OSError as exc:
        raise WheelsoilInputError(f"cannot reach the dask scheduler {scheduler!r}: {exc}") from None


def execute_case(case_toml: str, folder: str, arch: str | None = None, timeout: float | None = None,
                 cpu_threads: int | None = None) -> dict:
    """Run one case in a fresh ``wheelsoil run`` process; never raises. Returns its status.

    This is what local workers and dask workers call: the case is written to ``folder/case.toml``
    and its output to ``folder``; the process's output goes to ``folder/run.log``. ``cpu_threads``: the CPU
    backend's worker threads of that process (``WHEELSOIL_CPU_THREADS``; None: as the environment says).
    """
    folder_path = Path(folder)
    folder_path.mkdir(parents=True, exist_ok=True)
    (folder_path / "case.toml").write_text(case_toml)
    cmd = [sys.executable, "-m", "wheelsoil.cases.cli", "run", str(folder_path / "case.toml"), "--out", str(folder_path)]
    if arch:
        cmd += ["--arch", arch]
    if (folder_path / ".checkpoint.h5").is_file():
        cmd.append("--resume")  # a case killed with its sweep continues from its checkpoint
    t0 = time.perf_counter()
    env = {**os.environ, "COLUMNS": "100"}
    if cpu_threads is not None:
        env[CPU_THREADS_VAR] = str(cpu_threads)
    try:
        with open(folder_path / "run.log", "w") as log:
            done = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, timeout=timeout, env=env)
        code = done.returncode
    except subprocess.TimeoutExpired:
        code = -1
    wall = time.perf_counter() - t0
    if code == 0 and (folder_path / RESULT_NAME).is_file():
        return {"status": "finished", "wall_seconds": wall}
    text = (folder_path / "run.log").read_text(errors="replace").strip().splitlines()
    errors = [ln for ln in text if "error" in ln.lower() or "stopped" in ln.lower()]
    message = (errors or text or ["no output"])[-1]
    if code == -1:
        message = f"timed out after {timeout} s"
    return {"status": "failed", "exit_code": code, "error": message, "wall_seconds": wall}


def worker_threads(workers: int) -> int | None:
    """The CPU threads each of ``workers`` local workers' runs gets: the cores shared out, at least one
    (``WHEELSOIL_CPU_THREADS`` set by the user wins: None). Two runs on two cores step 1.18-1.26 times faster in all
    with one thread each than with a thread per core each, and the thread count does not change a run's result
    (``benchmarks/README.md``, "Several runs sharing the cores")."""
    if os.environ.get(CPU_THREADS_VAR, "").strip():
        return None
    return max(1, (os.cpu_count() or 1) // workers)


def run_sweep(sweep: Sweep, *, workers: int | None = None, scheduler: str | None = None, arch: str | None = None,
              progress: bool = False, console=None, timeout: float | None = None) -> dict:
    """Run every unfinished case; returns {case hash: status}. Writes status.json and the summary."""
    say = console.print if console is not None else (lambda *a, **k: None)
    sweep.out.mkdir(parents=True, exist_ok=True)
    status: dict[str, dict] = {}
    todo = []
    for c in sweep.cases:
        key = c.folder.name
        if c.finished:
            status[key] = {"status": "skipped (finished before)"}
        else:
            todo.append(c)
    say(f"sweep {sweep.name}: {len(sweep.cases)} cases, {len(sweep.cases) - len(todo)} finished before, "
        f"{len(todo)} to run {'on ' + scheduler if scheduler else f'with {workers or 1} local workers'}")
    jobs = [(c, case_to_toml(c.case), str(c.folder)) for c in todo]
    bar = task = None
    if progress and jobs:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

        bar = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                       TimeRemainingColumn(), console=console, transient=True)
        bar.start()
        task = bar.add_task(f"sweep {sweep.name}", total=len(jobs))

    def record(c: SweepCase, result: dict) -> None:
        status[c.folder.name] = result
        mark = "[green]finished[/]" if result["status"] == "finished" else f"[red]failed[/]: {result.get('error')}"
        say(f"  {c.name}: {mark} ({result.get('wall_seconds', 0):.0f} s)")
        _write_status(sweep, status)
        if result["status"] == "finished":  # the tables and figures follow each finished case: a sweep of hours
            write_summary(sweep)            # killed half-way keeps what it has (summary.csv for validate --model)
        if bar is not None:
            bar.advance(task)

    try:
        if scheduler:
            try:
                from distributed import Client, as_completed as dask_completed
            except ImportError:
                raise WheelsoilInputError("--scheduler needs dask.distributed: pip install 'wheelsoil[cluster]'") from None
            _check_reachable(scheduler)
            try:
                client = Client(scheduler, timeout="20s")
            except (OSError, TimeoutError) as exc:
                raise WheelsoilInputError(f"cannot reach the dask scheduler {scheduler!r}: {exc}") from None
            with client:
                futures = {client.submit(execute_case, text, folder, arch, timeout, pure=False): c
                           for c, text, folder in jobs}
                for fut in dask_completed(futures):
                    c = futures[fut]
                    try:
                        result = fut.result()
                    except Exception as exc:  # the worker died: report it as this case's failure
                        result = {"status": "failed", "error": f"dask worker: {exc}"}
                    record(c, result)
        else:
            threads = worker_threads(max(1, workers or 1))
            with ThreadPoolExecutor(max_workers=max(1, workers or 1)) as pool:
                futures = {pool.submit(execute_case, text, folder, arch, timeout, threads): c
                           for c, text, folder in jobs}
                for fut in as_completed(futures):
                    record(futures[fut], fut.result())
    finally:
        if bar is not None:
            bar.stop()
    _write_status(sweep, status)
    write_summary(sweep)
    return status


def _write_status(sweep: Sweep, status: dict) -> None:
    rows = {c.folder.name: {"case": c.name, "values": c.values, **status.get(c.folder.name, {"status": "pending"})}
            for c in sweep.cases}
    with atomic_output(sweep.out / "status.json") as tmp:
        tmp.write_text(json.dumps(rows, indent=2, default=str))


# -------------------------------------------------------------------- summary
def summary_table(sweep: Sweep):
    """A pandas DataFrame: one row per finished case with its swept values, rig settings and wheel, and the
    steady means and standard deviations (SI: N, m, N m; angles in degrees; gravity in m/s^2). A case whose drive
    has several stages (``[[protocol.stages]]``, a slip ramp) gives one row per stage, its ``slip_set`` the stage's
    commanded slip, with a ``stage`` column (0: the first) in every row of the table."""
    import pandas as pd

    from .results import load_result

    rows, staged = [], False
    for c in sweep.cases:
        if not c.finished:
            continue
        r = load_result(c.folder / RESULT_NAME)
        t = c.case.test
        head = {"case": c.name, "case_hash": c.folder.name}
        head.update({k: (_label(v) if isinstance(v, (list, tuple)) else v) for k, v in c.values.items()})
        wheel = build.wheel_geometry(c.case)
        head.update({"slip_set": t.slip, "slip_angle_set": t.slip_angle, "slip_speed": t.slip_speed,
                     "load_set": t.load, "gravity": -c.case.soil.gravity_vector[2], "rigid": c.case.wheel.rigid,
                     "wheel_radius": wheel.radius, "wheel_width": wheel.width, "grouser_count": wheel.grouser_count,
                     "grouser_height": wheel.grouser_height if wheel.grouser_count else 0.0})
        if len(r.stages) == 1:
            rows.append({**head, **{k: v for k, v in r.summary_row().items() if k not in ("case", "case_hash")}})
            continue
        staged = True
        for k in range(len(r.stages)):
            stage = {key: v for key, v in r.summary_row(k).items() if key not in ("case", "case_hash")}
            rows.append({**head, "slip_set": stage.pop("commanded_slip"), **stage})
    table = pd.DataFrame(rows)
    if staged:
        table["stage"] = table["stage"].fillna(0).astype(int)
    return table


def write_summary(sweep: Sweep) -> list[Path]:
    """summary.csv, summary.parquet and the seed-004-style figures of the finished cases."""
    table = summary_table(sweep)
    written = []
    if table.empty:
        return written
    with atomic_output(sweep.out / "summary.csv") as tmp:
        table.to_csv(tmp, index=False)
    written.append(sweep.out / "summary.csv")
    with atomic_output(sweep.out / "summary.parquet") as tmp:
        table.to_parquet(tmp, index=False)
    written.append(sweep.out / "summary.parquet")
    from .plots import plot_sweep

    written += plot_sweep(table, sweep.out, sweep.name)
    return written
