"""``wheelsoil convergence``: a case at refined levels of each scale factor, and the report."""

from __future__ import annotations

from pathlib import Path

from . import common


def add_parser(sub) -> None:
    """The ``convergence`` command on ``sub``."""
    p = sub.add_parser("convergence", help="convergence study of a case: particle size, bed depth and width, time "
                                           "step, wheel mesh; report of the changes",
                       description="Run a case at its reference scale and at refined levels of each factor "
                                   "(particle size x 1, 0.8, 0.64; bed depth and width x 1, 2; DEM time step and wheel "
                                   "element size x 1, 0.5 by default), as a sweep in --out (finished cases are kept), "
                                   "and write convergence.md, convergence.csv, convergence.json and convergence.png: "
                                   "every reported quantity's change between neighbouring levels with its standard "
                                   "error; particle size, DEM step and mesh extrapolated to scale 0, converged where "
                                   "the reference's error against that, plus two standard errors, is within "
                                   "--threshold; depth and width converged from the level whose doubling changes "
                                   "every quantity by less than it (cases/convergence.py documents the method).")
    p.add_argument("case", nargs="?", default="smoke-1g-steer", help="case file (.toml) or preset name")
    common.add_set_option(p)
    for factor, levels in (("particle-size", "1,0.8,0.64"), ("depth", "1,2"), ("width", "1,2"),
                           ("time-step", "1,0.5"), ("mesh", "1,0.5"), ("length", "1,2")):
        p.add_argument(f"--{factor}-levels", default=None, metavar="SCALES",
                       help=f"scales of {factor.replace('-', ' ')}, reference 1 first (default {levels})")
    p.add_argument("--factors", default="particle_size,depth,width,time_step,mesh",
                   help="factors to study, comma-separated (default: all five; 'length', the bin along the travel, "
                        "on request: for a wheel ploughing sideways)")
    p.add_argument("--threshold", type=float, default=0.10, help="largest relative change called converged "
                                                                 "(default 0.10)")
    p.add_argument("--out", type=Path, default=None, help="study folder (default wheelsoil-output/convergence/<case>)")
    p.add_argument("--level-drive-time", type=float, default=None,
                   help="longest drive of the refined levels in s (default twice the case's test.drive_time; "
                        "a run stops once steady)")
    common.add_pool_options(p, "case", 1, "cases run at once (default 1: a coupled run uses both cores of a small "
                                          "machine)")
    p.add_argument("--report-only", action="store_true", help="only rewrite the report from the finished cases")
    p.add_argument("--particle-step", choices=("common", "own"), default="common",
                   help="DEM step of the particle-size levels: 'common' (default), all at the finest level's, so the "
                        "series changes the particles alone; 'own', each at its own stable step (studies before "
                        "2026-11-26)")
    p.add_argument("--replicas", type=Path, default=None, metavar="REPLICAS_JSON",
                   help="add the run-to-run excess spread that replicas of the case measured ('wheelsoil replicate': "
                        "its replicas.json) to every level's standard error")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    from ..convergence import DEFAULT_LEVELS, make_study, parse_levels, plan, resolve_time_step_levels, run_study
    from ..convergence_report import write_report
    from ..replicas import ReplicaSpread
    from ..schema import load_case

    console = common.console()
    case = load_case(args.case, list(args.set or []))
    factors = [f.strip() for f in args.factors.split(",") if f.strip()]
    unknown = [f for f in factors if f not in DEFAULT_LEVELS]
    if unknown or not factors:
        raise common.InputError(f"--factors {args.factors!r}: choose from {', '.join(DEFAULT_LEVELS)}")
    common.check_workers_and_timeout(args.workers, args.timeout)
    levels = {f: parse_levels(getattr(args, f"{f}_levels"), f) for f in factors}
    out = args.out or Path("wheelsoil-output") / "convergence" / case.name
    if args.level_drive_time is not None and not args.level_drive_time > 0:
        raise common.InputError(f"--level-drive-time {args.level_drive_time} must be > 0 seconds")
    replicas = ReplicaSpread.read(args.replicas, "--replicas") if args.replicas is not None else None
    study = make_study(case, out, levels, args.threshold, level_drive_time=args.level_drive_time,
                       particle_step=args.particle_step)
    if args.report_only:
        paths = write_report(study, replicas)
    else:
        resolve_time_step_levels(study)  # with the others when the reference has already run
        console.print(f"convergence study of {case.name}: {len(study.cases())} cases "
                      f"(+ {sum(lv.case is None for lvs in study.levels.values() for lv in lvs)} levels that need "
                      "the reference's DEM step, after it) "
                      f"in {out}; estimated soil cost per simulated second against the reference:")
        for row in plan(study):
            console.print(f"  {row['factor']:>13s} x {row['scale']:<5g} ~{row['particles']:>9,} particles, "
                          f"soil cost x {row['relative_soil_cost']:.2g}, drive up to {row['drive_time']:g} s")
        run_study(study, workers=args.workers, arch=args.arch, timeout=args.timeout, progress=console.is_terminal,
                  console=console)
        write_report(study, replicas)
        paths = [out / n for n in ("convergence.md", "convergence.csv", "convergence.json", "convergence.png")]
    console.print((out / "convergence.md").read_text() if (out / "convergence.md").is_file() else "", markup=False)
    console.print(f"wrote {', '.join(p.name for p in paths)} in {out}")
    return common.EXIT_OK
