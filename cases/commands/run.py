"""``wheelsoil run`` (alias ``testbed``): one testbed case, its summary on the terminal."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from . import common

if TYPE_CHECKING:
    from wheelsoil.coupling.run_summary import RunSummary


def add_parser(sub) -> None:
    """The ``run`` command (and its alias ``testbed``) on ``sub``."""
    p = sub.add_parser("run", aliases=["testbed"],
                       help="run a testbed case (a TOML case file or a preset); default: the smoke job",
                       description="Run a testbed case: prepare (or reuse) its bed under the case's gravity, lower "
                                   "the wheel until the soil carries the load W, drive at the commanded slip and "
                                   "steering angle, detect the steady state and average. Writes result.h5 (+ "
                                   "result.xdmf for ParaView), series.csv, summary.json, case.toml (the resolved "
                                   "case), series.png and a render of the last state (final.png) to --out. "
                                   "CASE is a .toml file or a preset ('wheelsoil case list'): smoke-1g-steer (the "
                                   "default; about 6 minutes on 2 cores with the bed, W = 3000 N), smoke-moon-steer "
                                   "(1/6 g, W = 500 N, 5-6 minutes), mini-1g-steer (about 5 minutes), "
                                   "seed004-1g-steer and seed004-moon-steer "
                                   "(full scale, hours). A run killed after a checkpoint continues with --resume. "
                                   "'wheelsoil testbed' is the same command.")
    p.add_argument("case", nargs="?", default="smoke-1g-steer", help="case file (.toml) or preset name "
                                                                     "(default smoke-1g-steer)")
    common.add_set_option(p, "override a case key, e.g. --set test.slip=0.5 --set soil.gravity=moon --set "
                       "'test.drive_time=\"800 ms\"' (repeatable; 'wheelsoil case show' lists the keys)")
    p.add_argument("--slip", type=float, default=None, help="shortcut for --set test.slip=VALUE")
    p.add_argument("--slip-angle", type=float, default=None, help="shortcut for --set test.slip_angle=VALUE [deg]")
    p.add_argument("--load", type=float, default=None, help="shortcut for --set test.load=VALUE [N]")
    p.add_argument("--drive-time", type=float, default=None, help="shortcut for --set test.drive_time=VALUE [s]")
    p.add_argument("--rigid", action="store_true", help="shortcut for --set wheel.rigid=true")
    p.add_argument("--no-render", action="store_true", help="shortcut for --set output.render=false")
    p.add_argument("--resume", action="store_true", help="continue a killed run of the same case from its last "
                                                         "checkpoint in --out")
    p.add_argument("--restart", action="store_true", help="discard the checkpoint of an unfinished run in --out "
                                                          "and start afresh")
    p.add_argument("--out", type=Path, default=None, help="output folder (default wheelsoil-output/<case name>)")
    common.add_arch_option(p)
    p.set_defaults(func=cmd)


def case_from_args(args):
    from ..schema import load_case

    overrides = list(args.set or [])
    for key, value in (("slip", args.slip), ("slip_angle", args.slip_angle), ("load", args.load),
                       ("drive_time", args.drive_time)):
        if value is not None:
            overrides.append(f"test.{key}={value!r}")
    if args.rigid:
        overrides.append("wheel.rigid=true")
    if getattr(args, "no_render", False):
        overrides.append("output.render=false")
    return load_case(args.case, overrides)


def summary_lines(s: RunSummary) -> list[str]:
    """The steady-state summary of a run as terminal lines (rich markup): the verdict, the window, the means
    with their standard errors, and the tread's slip beside the commanded one."""
    span = f"t = {s.window[0]:.2f}-{s.window[1]:.2f} s"
    if s.steady:
        period = s.period_pitches
        periods = f", {s.pitches // period} wheel periods of {period * s.pitch_deg:.0f} deg" if period > 1 else ""
        head = f"[green]steady[/] over {span} ({s.pitches} pitches of {s.pitch_deg:.1f} deg{periods}):"
    else:
        head = f"[yellow]NOT steady[/]: averaged the last window, {span}, for information only:"
    lines = [head]
    for q in ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage", "tread_sinkage"):
        st = s.quantity(q)
        zero = ": zero within its noise, no trend" if st.zero_within_noise else ""
        interval = f", 95 % interval +-{st.ci95:.2g}" if math.isfinite(st.ci95) else ""
        lines.append(f"  {q:16s} {st.mean:10.4g} {st.units:4s} (standard error {st.sem:.2g}{interval}, fluctuation "
                     f"{st.std:.3g}{zero})")
    lines.append(f"  {'tread slip':16s} {s.tread_slip.mean:10.4f}      (commanded {s.commanded_slip:g}; "
                 f"tread slip angle {s.tread_slip_angle.mean:.2f} deg, commanded "
                 f"{s.commanded_slip_angle:g}; wind-up {s.wind_up.mean:.3f} rad)")
    if math.isfinite(s.balance_residual.mean):  # recorded since 2026-11-28 (coupling.force_balance)
        lines.append(f"  {'force balance':16s} soil force as the wheel integrated it "
                     f"{s.vertical_force_applied.mean:.4g} N; residual of the wheel's momentum "
                     f"{s.balance_residual.mean:.1e} N")
    if s.steady:
        lines.append("  (the intervals see the noise within this run; runs on other seeds scatter more: drawbar pull "
                     "and torque about twice as much in the smoke case. 'wheelsoil replicate' measures it: "
                     "docs/replicas.md)")
    for reason in s.reasons:
        lines.append(f"  [yellow]not steady:[/] {reason}")
    return lines


def cmd(args) -> int:
    from ..run import run_case

    console = common.console()
    case = case_from_args(args)
    out = args.out or Path("wheelsoil-output") / case.name
    outcome = run_case(case, out, arch=args.arch, resume=args.resume, restart=args.restart,
                       progress=console.is_terminal, console=console)
    stages = outcome.testbed_result.stages
    for k, s in enumerate(stages):
        if len(stages) > 1:
            console.print(f"[bold]stage {k + 1} of {len(stages)}[/bold] (commanded slip {s.commanded_slip:g})")
        for line in summary_lines(s):
            console.print(line)
    info = outcome.testbed_result.info
    console.print(f"{info['wall_seconds']:.0f} s wall for {info['simulated_seconds']:.2f} s simulated; "
                  f"wrote {outcome.result_path} (+ .xdmf for ParaView), series.csv, summary.json, case.toml, "
                  f"series.png{', final.png' if case.output.render else ''} in {out}")
    return common.EXIT_OK
