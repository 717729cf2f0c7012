"""The ``wheelsoil`` command line.

Exit codes (scripts can trust them):
    0  success
    1  unexpected internal error (a bug: please report it with the traceback), or a benchmark
       regression beyond the tolerance (``bench --smoke --baseline``)
    2  bad input (a parameter out of range, a missing file); the message names the value
    3  the simulation went unstable or did not settle; nothing was written
    4  a sweep ran, but some of its cases failed (the others finished; see its status.json)
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from wheelsoil.gravity import GRAVITY_PRESETS
from wheelsoil.parameters import smoke

from . import soil_lab_command, validate_command
from .units import gravity_argument

EXIT_OK, EXIT_BUG, EXIT_INPUT, EXIT_UNSTABLE, EXIT_SWEEP_FAILED = 0, 1, 2, 3, 4

MAIN_HELP = """\
wheelsoil: a single-wheel terramechanics testbed in software.

Start with the smoke job: the seed-004 lunar-rover wheel (coarse mesh) driven at slip 0.3 and
steering angle 10 deg through a small regolith bed under Earth gravity with W = 3000 N until steady
(about six minutes on two cores, bed preparation included):

    wheelsoil run

a case is a TOML file or a preset; see them, copy one with every key documented, change it:

    wheelsoil case list
    wheelsoil case show smoke-moon-steer > my-case.toml
    wheelsoil run my-case.toml --set test.slip=0.5 --set test.slip_angle=20 --out runs/my-case
    wheelsoil render runs/my-case --animate --out runs/my-case/run.mp4

sweep slip and steering angle (local processes, or --scheduler for a dask cluster):

    wheelsoil batch mini-slip

show how far a case's numbers are from a finer or larger scale (particle size, bed depth and width,
DEM time step, wheel mesh; report in convergence.md):

    wheelsoil convergence mini-1g-steer

hold the semi-empirical model against measured data and name what it misses:

    wheelsoil validate ../shared/data/measured/cmu_3d_terramechanics --holdout slip_angle=60

fit on one dataset, predict another, or hold each steering angle out in turn:

    wheelsoil validate smooth_wheel_trials.csv --test grouser_wheel_trials.csv --report runs/s2g
    wheelsoil predict runs/s2g/model.json grouser_wheel_trials.csv --out runs/s2g-predict
    wheelsoil validate ../shared/data/measured/cmu_3d_terramechanics --cv slip_angle --report runs/cv

run the virtual soil lab on the particles, with the CMU sand's measurements beside (poured, repose, shear,
plate, wheel):

    wheelsoil soil-lab plate --seeds 0 1 2

or prepare your own beds, e.g. a Moon-gravity bed of seed-004 particles:

    wheelsoil prepare-bed --length 1.0 --width 0.5 --depth 0.15 --dmin 0.016 --dmax 0.024 --gravity moon \
        --out moon_bed.h5
    wheelsoil render moon_bed.h5 --out moon_bed.png
"""


#: prepare-bed's defaults without a CASE: the smoke run's bed (the parameter set every layer takes its defaults
#: from), so that ``wheelsoil prepare-bed`` makes the bed ``wheelsoil run`` uses.
BED_DEFAULTS = {"length": smoke.SOIL["length"], "width": smoke.SOIL["width"], "depth": smoke.SOIL["depth"],
                "dmin": smoke.SOIL["diameter_min"], "dmax": smoke.SOIL["diameter_max"],
                "gravity": GRAVITY_PRESETS[smoke.GRAVITY], "seed": smoke.SEED}


def _add_bed_options(p: argparse.ArgumentParser) -> None:
    d = BED_DEFAULTS
    g = p.add_argument_group("soil bed (without a CASE)")
    g.add_argument("--length", type=float, default=None, help=f"bin length along x [m] (default {d['length']})")
    g.add_argument("--width", type=float, default=None, help=f"bin width along y [m] (default {d['width']})")
    g.add_argument("--depth", type=float, default=None, help=f"levelled bed depth [m] (default {d['depth']})")
    g.add_argument("--dmin", type=float, default=None,
                   help=f"smallest particle diameter [m] (default {d['dmin']}; seed 004: 0.016)")
    g.add_argument("--dmax", type=float, default=None,
                   help=f"largest particle diameter [m] (default {d['dmax']}; seed 004: 0.024)")
    g.add_argument("--gravity", type=gravity_argument, default=None,
                   help=f"'earth' (9.81), 'moon' (9.81/6) or a value in m/s^2 (default {smoke.GRAVITY}); "
                        "beds are prepared under the gravity they are tested at")
    g.add_argument("--seed", type=int, default=None, help=f"random seed of radii and packing (default {d['seed']})")
    g.add_argument("--walled", action="store_true",
                   help="end walls instead of a bin periodic along its length (the default, as the smoke run's)")
    p.add_argument("--no-cache", action="store_true", help="prepare afresh even if an identical bed is cached")
    p.add_argument("--arch", default=None, help="Taichi backend: cpu (default), cuda, vulkan, metal")


def _spec_from_args(args):
    from wheelsoil.granular import BedSpec

    given = [k for k in BED_DEFAULTS if getattr(args, k) is not None] + (["walled"] if args.walled else [])
    if getattr(args, "case", None):
        if given:
            raise _InputError(f"--{given[0]} does not go with a CASE: set the case's soil instead, e.g. "
                              f"--set soil.length=1.0 ('wheelsoil case show {args.case}' lists the keys)")
        from . import build
        from .schema import load_case

        return build.bed_spec(load_case(args.case, args.set or []))
    if args.set:
        raise _InputError("--set needs a CASE (e.g. wheelsoil prepare-bed smoke-1g-steer --set soil.gravity=moon)")
    v = {k: (getattr(args, k) if getattr(args, k) is not None else BED_DEFAULTS[k]) for k in BED_DEFAULTS}
    return BedSpec(length=v["length"], width=v["width"], depth=v["depth"], diameter_min=v["dmin"],
                   diameter_max=v["dmax"], gravity=(0.0, 0.0, -v["gravity"]), seed=v["seed"],
                   periodic=not args.walled)


def _add_set_option(p: argparse.ArgumentParser, help: str = "override a case key (repeatable)") -> None:
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", help=help)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="wheelsoil", description=MAIN_HELP,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    from wheelsoil import __version__

    parser.add_argument("--version", action="version", version=f"wheelsoil {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

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
    _add_set_option(p, "override a case key, e.g. --set test.slip=0.5 --set soil.gravity=moon --set "
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
    p.add_argument("--arch", default=None, help="Taichi backend: cpu (default), cuda, vulkan, metal")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("case", help="list the preset cases, show a case with every key, or check a case file",
                       description="'wheelsoil case list' lists the presets; 'wheelsoil case show CASE' prints the "
                                   "resolved case with every key, its unit, range and default (a template to copy); "
                                   "'wheelsoil case check CASE' validates a case file and prints its hash.")
    p.add_argument("action", choices=["list", "show", "check"])
    p.add_argument("case", nargs="?", default=None, help="case file (.toml) or preset name")
    _add_set_option(p)
    p.set_defaults(func=cmd_case)

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
    p.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: the CPU count; a coupled run keeps about one core busy)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="dask.distributed scheduler (e.g. tcp://host:8786) to send the cases to instead; its workers "
                        "need wheelsoil installed and the sweep folder on a shared file system")
    p.add_argument("--timeout", type=float, default=None, help="give up a case after this many seconds (default: none)")
    p.add_argument("--list", action="store_true", help="only list the cases and whether they are finished")
    p.add_argument("--arch", default=None, help="Taichi backend of every case: cpu (default), cuda, ...")
    p.set_defaults(func=cmd_batch)

    p = sub.add_parser("replicate", help="run a case on beds of other particle seeds: the run-to-run spread against "
                                         "the runs' own error bars",
                       description="Run CASE once per --seeds value (a sweep over case.seed in --out: finished replicas "
                                   "are kept) and write replicas.md and replicas.json: per reported quantity the "
                                   "replicas' mean and standard deviation, the runs' own standard errors, the inflation "
                                   "factor (spread over own error, with its 95 %% interval) and how many runs' 95 %% "
                                   "intervals hold the other replicas' mean (cases/replicas.py documents the method).")
    p.add_argument("case", nargs="?", default="smoke-1g-steer", help="case file (.toml) or preset name")
    _add_set_option(p)
    p.add_argument("--seeds", nargs="+", required=True, help="particle seeds, at least two (e.g. 0 1 2 3 4)")
    p.add_argument("--out", type=Path, default=None, help="replica folder (default wheelsoil-output/replicas/<case>)")
    p.add_argument("--workers", type=int, default=1, help="replicas run at once (default 1)")
    p.add_argument("--timeout", type=float, default=None, help="give up a replica after this many seconds")
    p.add_argument("--report-only", action="store_true", help="only rewrite the report from the finished replicas")
    p.add_argument("--arch", default=None, help="Taichi backend of every replica: cpu (default), cuda, ...")
    p.set_defaults(func=cmd_replicate)

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
    _add_set_option(p)
    for factor, levels in (("particle-size", "1,0.8,0.64"), ("depth", "1,2"), ("width", "1,2"),
                           ("time-step", "1,0.5"), ("mesh", "1,0.5")):
        p.add_argument(f"--{factor}-levels", default=None, metavar="SCALES",
                       help=f"scales of {factor.replace('-', ' ')}, reference 1 first (default {levels})")
    p.add_argument("--factors", default="particle_size,depth,width,time_step,mesh",
                   help="factors to study, comma-separated (default: all five)")
    p.add_argument("--threshold", type=float, default=0.10, help="largest relative change called converged "
                                                                 "(default 0.10)")
    p.add_argument("--out", type=Path, default=None, help="study folder (default wheelsoil-output/convergence/<case>)")
    p.add_argument("--level-drive-time", type=float, default=None,
                   help="longest drive of the refined levels in s (default twice the case's test.drive_time; "
                        "a run stops once steady)")
    p.add_argument("--workers", type=int, default=1, help="cases run at once (default 1: a coupled run uses both "
                                                          "cores of a small machine)")
    p.add_argument("--timeout", type=float, default=None, help="give up a case after this many seconds")
    p.add_argument("--report-only", action="store_true", help="only rewrite the report from the finished cases")
    p.add_argument("--particle-step", choices=("common", "own"), default="common",
                   help="DEM step of the particle-size levels: 'common' (default), all at the finest level's, so the "
                        "series changes the particles alone; 'own', each at its own stable step (studies before "
                        "2026-11-26)")
    p.add_argument("--arch", default=None, help="Taichi backend of every case: cpu (default), cuda, ...")
    p.set_defaults(func=cmd_convergence)

    p = sub.add_parser("prepare-bed", help="fill, settle and level a soil bin (a case's, or from options); write it",
                       description="Fill a bin with polydisperse spheres, settle under gravity until the kinetic "
                                   "energy per particle is below the threshold, level at the target depth, and "
                                   "write the bed to HDF5. With a CASE (file or preset, plus --set overrides) the "
                                   "bed is the case's soil, the one 'wheelsoil run CASE' uses; without, the "
                                   "options below describe it. Identical beds are reused from the cache "
                                   "(WHEELSOIL_CACHE, default ~/.cache/wheelsoil).")
    p.add_argument("case", nargs="?", default=None, help="case file (.toml) or preset whose bed to prepare")
    _add_set_option(p)
    _add_bed_options(p)
    p.add_argument("--out", type=Path, default=Path("bed.h5"), help="bed file to write (default bed.h5)")
    p.set_defaults(func=cmd_prepare_bed)

    p = sub.add_parser("render", help="render a result (a frame, or an animation) or a bed file offscreen",
                       description="Render offscreen (no display needed). A result (result.h5 or its run folder): "
                                   "one frame to PNG -- particles coloured by speed (or height), the wheel by its "
                                   "deflection (displacement less the hub's rigid motion) -- or, with --animate, "
                                   "every frame to a GIF or MP4 (the --out suffix picks; MP4 uses imageio-ffmpeg's "
                                   "own ffmpeg). A bed file: its particles coloured by height.")
    p.add_argument("path", type=Path, help="result.h5, a run folder, or a bed file written by prepare-bed")
    p.add_argument("--out", type=Path, default=None,
                   help="file to write (default: frame.png, animation.gif or <bed>.png beside the input)")
    p.add_argument("--frame", type=int, default=-1, help="result frame to render (default -1: the last)")
    p.add_argument("--animate", action="store_true", help="render every frame of a result to --out (.gif or .mp4)")
    p.add_argument("--fps", type=float, default=10.0, help="animation frames per second (default 10)")
    p.add_argument("--color", default="speed", help="particle colour: speed (default) or height")
    p.add_argument("--wheel-color", default="deflection", help="wheel colour: deflection (default) or none")
    p.add_argument("--camera", default="iso", help="camera preset: iso, side, top, front (default iso)")
    p.add_argument("--size", type=int, nargs=2, default=(1200, 800), metavar=("W", "H"), help="image size in pixels")
    p.set_defaults(func=cmd_render)

    p = sub.add_parser("bench", help="measure solver speed (smoke tier for CI, or the full tier)",
                       description="Benchmarks (benchmarks/README.md). --smoke: a few minutes on 2 cores -- DEM "
                                   "steady stepping on a small dense bed, compile time, peak memory -- each figure "
                                   "also normalised by a NumPy reference workload; with --baseline, a regression "
                                   "beyond --tolerance fails (exit 1) naming the figure. Without --smoke: the full "
                                   "tier (>= 50k-particle bed, LIGGGHTS comparison, seed-004 memory check).")
    p.add_argument("--smoke", action="store_true", help="run the smoke tier")
    p.add_argument("--out", type=Path, default=None, help="JSON to write (default benchmarks/results/<tier>.json)")
    p.add_argument("--baseline", type=Path, default=None, help="smoke: baseline JSON to gate regressions against")
    p.add_argument("--tolerance", type=float, default=0.5, help="smoke: allowed normalised regression (default 0.5)")
    p.add_argument("--record", action="store_true", help="smoke: append the result to benchmarks/history/smoke.jsonl")
    p.add_argument("--no-liggghts", action="store_true", help="full tier: skip the LIGGGHTS comparison")
    p.add_argument("--memory-check", action="store_true", help="full tier: also step a seed-004-size bed")
    p.set_defaults(func=cmd_bench)
    p = sub.add_parser("wheel", help="mesh a preset wheel and load-test it against a flat plate",
                       description="Mesh a preset wheel (lunar-rover: seed 004; exomars: seeds 000/001; the CMU rig's "
                                   "cmu-k10-smooth and cmu-k10-grouser), write the "
                                   "mesh as VTU, and measure its radial stiffness: point-load stiffness at angles "
                                   "over one spoke pitch, and the load-deflection curve against a rigid flat plate "
                                   "over the spoke and midway between spokes; and its torsional stiffness (the hub's "
                                   "torque against its twist ahead of the tread, tread clamped and tread loaded, linear "
                                   "and corotational in both directions: how far the wheel winds up under a driving "
                                   "torque). Writes mesh.vtu, load_test.csv, load_test.png, torsion_test.csv, "
                                   "torsion_test.png and summary.json to --out.")
    p.add_argument("preset", help="wheel preset: lunar-rover, exomars, cmu-k10-smooth or cmu-k10-grouser")
    p.add_argument("--element-size", type=float, default=None, help="target element edge [m] (default: the preset's)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default wheelsoil-output/wheel-<preset>)")
    p.add_argument("--points", type=int, default=6, help="load steps of the plate curve (default 6)")
    p.add_argument("--max-load-factor", type=float, default=1.5,
                   help="largest plate load as a multiple of the preset's nominal load (default 1.5)")
    p.add_argument("--torsion", choices=("corotational", "linear", "none"), default="corotational",
                   help="torsion load test: linear only, or also the corotational curves (default; minutes on a fine mesh)")
    p.add_argument("--max-twist", type=float, default=10.0,
                   help="largest twist of the corotational torsion curves [deg] (default 10)")
    p.set_defaults(func=cmd_wheel)

    validate_command.add_parsers(sub)
    soil_lab_command.add_parser(sub)

    return parser


def _load_case_from_args(args):
    from .schema import load_case

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


def summary_lines(s: dict) -> list[str]:
    """The steady-state summary of a run as terminal lines (rich markup): the verdict, the window, the means
    with their standard errors, and the tread's slip beside the commanded one."""
    span = f"t = {s['window'][0]:.2f}-{s['window'][1]:.2f} s"
    if s["steady"]:
        period = s.get("period_pitches", 1)
        periods = f", {s.get('pitches', 0) // period} wheel periods of {period * s.get('pitch_deg', 0):.0f} deg" if period > 1 else ""
        head = f"[green]steady[/] over {span} ({s.get('pitches', 0)} pitches of {s.get('pitch_deg', 0):.1f} deg{periods}):"
    else:
        head = f"[yellow]NOT steady[/]: averaged the last window, {span}, for information only:"
    lines = [head]
    for q in ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage", "tread_sinkage"):
        st = s[q]
        sem, ci = st.get("sem", float("nan")), st.get("ci95", float("nan"))
        zero = ": zero within its noise, no trend" if st.get("zero_within_noise") else ""
        interval = f", 95 % interval +-{ci:.2g}" if math.isfinite(ci) else ""
        lines.append(f"  {q:16s} {st['mean']:10.4g} {st['units']:4s} (standard error {sem:.2g}{interval}, fluctuation "
                     f"{st['std']:.3g}{zero})")
    if "tread_slip" in s:
        lines.append(f"  {'tread slip':16s} {s['tread_slip']['mean']:10.4f}      (commanded {s.get('commanded_slip', float('nan')):g}; "
                     f"tread slip angle {s['tread_slip_angle']['mean']:.2f} deg, commanded "
                     f"{s.get('commanded_slip_angle', float('nan')):g}; wind-up {s['wind_up']['mean']:.3f} rad)")
    for reason in s.get("reasons", []):
        lines.append(f"  [yellow]not steady:[/] {reason}")
    return lines


def cmd_run(args) -> int:
    from .run import run_case

    console = _console()
    case = _load_case_from_args(args)
    out = args.out or Path("wheelsoil-output") / case.name
    outcome = run_case(case, out, arch=args.arch, resume=args.resume, restart=args.restart,
                       progress=console.is_terminal, console=console)
    s = outcome.testbed_result.summary
    for line in summary_lines(s):
        console.print(line)
    info = outcome.testbed_result.info
    console.print(f"{info['wall_seconds']:.0f} s wall for {info['simulated_seconds']:.2f} s simulated; "
                  f"wrote {outcome.result_path} (+ .xdmf for ParaView), series.csv, summary.json, case.toml, "
                  f"series.png{', final.png' if case.output.render else ''} in {out}")
    return EXIT_OK


def cmd_batch(args) -> int:
    import os

    from .sweep import load_sweep, run_sweep

    console = _console()
    sweep = load_sweep(args.sweep, args.out)
    if args.list:
        for c in sweep.cases:
            print(f"{c.folder.name}  {'finished' if c.finished else 'to run  '}  {c.name}")
        return EXIT_OK
    if args.workers is not None and args.workers < 1:
        raise _InputError(f"--workers {args.workers} must be >= 1")
    if args.timeout is not None and not args.timeout > 0:
        raise _InputError(f"--timeout {args.timeout} must be > 0 seconds")
    workers = args.workers or os.cpu_count() or 1
    status = run_sweep(sweep, workers=workers, scheduler=args.scheduler, arch=args.arch, progress=console.is_terminal,
                       console=console, timeout=args.timeout)
    failed = {k: v for k, v in status.items() if v["status"] == "failed"}
    done = sum(v["status"] == "finished" for v in status.values())
    console.print(f"sweep {sweep.name}: {done} run, {len(status) - done - len(failed)} skipped (finished before), "
                  f"{len(failed)} failed; summary.csv, summary.parquet, figures and status.json in {sweep.out}")
    for key, v in failed.items():
        console.print(f"  [red]failed[/] {key}: {v.get('error')} (log: {sweep.out / 'cases' / key / 'run.log'})")
    return EXIT_SWEEP_FAILED if failed else EXIT_OK


def cmd_replicate(args) -> int:
    from .replicas import make_replicas, write_report
    from .schema import load_case
    from .sweep import run_sweep

    console = _console()
    case = load_case(args.case, list(args.set or []))
    if args.workers < 1:
        raise _InputError(f"--workers {args.workers} must be >= 1")
    if args.timeout is not None and not args.timeout > 0:
        raise _InputError(f"--timeout {args.timeout} must be > 0 seconds")
    out = args.out or Path("wheelsoil-output") / "replicas" / case.name
    sweep = make_replicas(case, args.seeds, out)
    if not args.report_only:
        run_sweep(sweep, workers=args.workers, arch=args.arch, timeout=args.timeout, progress=console.is_terminal,
                  console=console)
    paths = write_report(sweep, case)
    console.print(paths[1].read_text())
    console.print(f"wrote {', '.join(p.name for p in paths)} in {out}")
    return EXIT_OK


def cmd_convergence(args) -> int:
    from .convergence import DEFAULT_LEVELS, make_study, parse_levels, plan, resolve_time_step_levels, run_study
    from .convergence_report import write_report
    from .schema import load_case

    console = _console()
    case = load_case(args.case, list(args.set or []))
    factors = [f.strip() for f in args.factors.split(",") if f.strip()]
    unknown = [f for f in factors if f not in DEFAULT_LEVELS]
    if unknown or not factors:
        raise _InputError(f"--factors {args.factors!r}: choose from {', '.join(DEFAULT_LEVELS)}")
    if args.workers < 1:
        raise _InputError(f"--workers {args.workers} must be >= 1")
    if args.timeout is not None and not args.timeout > 0:
        raise _InputError(f"--timeout {args.timeout} must be > 0 seconds")
    levels = {f: parse_levels(getattr(args, f"{f}_levels"), f) for f in factors}
    out = args.out or Path("wheelsoil-output") / "convergence" / case.name
    if args.level_drive_time is not None and not args.level_drive_time > 0:
        raise _InputError(f"--level-drive-time {args.level_drive_time} must be > 0 seconds")
    study = make_study(case, out, levels, args.threshold, level_drive_time=args.level_drive_time,
                       particle_step=args.particle_step)
    if args.report_only:
        paths = write_report(study)
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
        write_report(study)
        paths = [out / n for n in ("convergence.md", "convergence.csv", "convergence.json", "convergence.png")]
    console.print((out / "convergence.md").read_text() if (out / "convergence.md").is_file() else "")
    console.print(f"wrote {', '.join(p.name for p in paths)} in {out}")
    return EXIT_OK


def cmd_case(args) -> int:
    import os

    os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "0")  # stdout is the case text: no Taichi banner
    from .schema import case_to_toml, load_case, preset_names, preset_text

    if args.action == "list":
        for name in preset_names():
            first = next((ln for ln in preset_text(name).splitlines() if ln.startswith("description")), "")
            print(f"{name:22s} {first.split('=', 1)[-1].strip().strip(chr(34))}")
        return EXIT_OK
    if not args.case:
        raise _InputError("give a case file or preset name ('wheelsoil case list' shows the presets)")
    case = load_case(args.case, args.set or [])
    if args.action == "show":
        print(case_to_toml(case, template=True), end="")
    else:  # check
        print(f"{args.case}: valid; case {case.name}, hash {case.case_hash()}")
    return EXIT_OK


def cmd_wheel(args) -> int:
    import json

    import numpy as np

    from wheelsoil.flexwheel.geometry import build_wheel_mesh, preset
    from wheelsoil.flexwheel.loadtest import plate_load_curve, point_load_stiffness
    from wheelsoil.provenance import atomic_output, provenance

    console = _console()
    geometry = preset(args.preset)
    if args.element_size is not None:
        geometry = geometry.with_element_size(args.element_size)
    if args.points < 2:
        raise _InputError(f"--points={args.points} must be >= 2")
    if not (args.max_load_factor > 0):
        raise _InputError(f"--max-load-factor={args.max_load_factor} must be > 0")
    out = args.out or Path("wheelsoil-output") / f"wheel-{geometry.name}"
    mesh, hub = build_wheel_mesh(geometry)
    mesh.write(out / "mesh.vtu")
    console.print(f"[bold]{geometry.name}[/]: {mesh.n_nodes} nodes, {len(mesh.triangles)} facets, {len(mesh.beams)} beams, "
                  f"{len(hub)} hub nodes, structure mass {mesh.total_mass:.3g} kg -> {out / 'mesh.vtu'}")
    pitch = geometry.spoke_pitch
    angles = np.linspace(0.0, pitch, 5)
    with _progress(console) as bar:
        task = bar.add_task("point-load stiffness", total=len(angles))
        point = []
        for a in angles:
            point.append(point_load_stiffness(geometry, a))
            bar.advance(task)
        k_ref = min(point)
        top = min(args.max_load_factor * max(geometry.nominal_load, 1.0) / k_ref, 0.2 * geometry.radius)
        deflections = np.linspace(top / args.points, top, args.points)
        curves = []
        for a in (0.0, pitch / 2):
            task = bar.add_task(f"plate curve at {a:g} deg", total=len(deflections))
            curves.append(plate_load_curve(geometry, deflections, a, progress=lambda k, n, t=task: bar.update(t, completed=k)))
    rows = ["angle_deg,deflection_m,force_N,contact_nodes"]
    for c in curves:
        rows += [f"{c.angle:g},{d:.6g},{f:.6g},{n}" for d, f, n in zip(c.deflection, c.force, c.contact_nodes)]
    with atomic_output(out / "load_test.csv") as tmp:
        tmp.write_text("\n".join(rows) + "\n")
    nominal = {}
    for c in curves:
        if geometry.nominal_load and c.force[0] <= geometry.nominal_load <= c.force[-1]:
            nominal[f"{c.angle:g}"] = c.stiffness_at(geometry.nominal_load)
    summary = {
        "preset": geometry.name,
        "element_size_m": geometry.element_size,
        "nodes": mesh.n_nodes,
        "facets": int(len(mesh.triangles)),
        "beams": int(len(mesh.beams)),
        "structure_mass_kg": mesh.total_mass,
        "spoke_pitch_deg": pitch,
        "point_load_stiffness_N_per_m": {f"{a:g}": k for a, k in zip(angles, point)},
        "point_load_stiffness_mean_N_per_m": float(np.mean(point)),
        "nominal_load_N": geometry.nominal_load,
        "plate_secant_stiffness_at_nominal_N_per_m": nominal,
        "provenance": provenance(),
    }
    if args.torsion != "none":
        summary["torsion"] = _torsion_tests(geometry, mesh, args, out, console)
    with atomic_output(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    _plot_load_curves(curves, geometry, out / "load_test.png")
    console.print(f"point-load radial stiffness over one spoke pitch ({pitch:g} deg): "
                  + ", ".join(f"{a:g} deg: {k / 1e3:.2f} kN/m" for a, k in zip(angles, point))
                  + f"; mean {np.mean(point) / 1e3:.2f} kN/m")
    for key, k in nominal.items():
        console.print(f"plate secant stiffness at the nominal {geometry.nominal_load:g} N, wheel at {key} deg: {k / 1e3:.2f} kN/m")
    torsion = f", {out / 'torsion_test.csv'}, {out / 'torsion_test.png'}" if args.torsion != "none" else ""
    console.print(f"wrote {out / 'load_test.csv'}, {out / 'load_test.png'}{torsion}, {out / 'summary.json'}")
    return EXIT_OK


def _torsion_tests(geometry, mesh, args, out, console) -> dict:
    """The torsion load tests of ``wheelsoil wheel``: torsion_test.csv, torsion_test.png and the summary entries."""
    import math

    import numpy as np

    from wheelsoil.flexwheel.torsion import torsion_test
    from wheelsoil.provenance import atomic_output

    if not (0 < args.max_twist <= 45):
        raise _InputError(f"--max-twist={args.max_twist} deg must lie in (0, 45]")
    linear = {hold: torsion_test(geometry, method="linear", hold=hold) for hold in ("tread", "free")}
    curves = list(linear.values())
    twists = np.radians([-args.max_twist, -args.max_twist / 2, -1.0, 1.0, args.max_twist / 2, args.max_twist])
    if args.torsion == "corotational":
        with _progress(console) as bar:
            task = bar.add_task("torsion, tread clamped", total=len(twists))
            curves.append(torsion_test(geometry, twists, method="corotational", hold="tread",
                                       progress=lambda k, n: bar.update(task, completed=k)))
            task = bar.add_task("torsion, torque on the tread", total=len(twists))
            curves.append(torsion_test(geometry, method="corotational", hold="free",
                                       torques=linear["free"].stiffness * twists,
                                       progress=lambda k, n: bar.update(task, completed=k)))
    rows = ["hold,method,twist_deg,torque_N_m,secant_stiffness_N_m_per_rad"]
    for c in curves:
        rows += [f"{c.hold},{c.method},{math.degrees(t):.6g},{q:.6g},{q / t:.6g}" for t, q in zip(c.twist, c.torque)]
    with atomic_output(out / "torsion_test.csv") as tmp:
        tmp.write_text("\n".join(rows) + "\n")
    # the torsion mode of the tread on its spokes, hub held: f = sqrt(k_t / I) / 2 pi, I the tread's and grousers'
    # inertia about the axle (their nodes beyond the spokes' reach)
    mass, _ = mesh.lumped_mass()
    outer = np.flatnonzero(np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 2]) >= geometry.tread_mid_radius - 1e-9)
    inertia = float(np.sum(mass[outer] * (mesh.nodes[outer, 0] ** 2 + mesh.nodes[outer, 2] ** 2)))
    frequency = math.sqrt(linear["free"].stiffness / inertia) / (2 * math.pi)
    result = {"linear_tread_clamped_N_m_per_rad": linear["tread"].stiffness,
              "linear_torque_on_tread_N_m_per_rad": linear["free"].stiffness,
              "tread_inertia_kg_m2": inertia, "torsion_mode_hub_held_Hz": frequency}
    for c in curves[2:]:
        result[f"corotational_{c.hold}"] = {"twist_deg": np.degrees(c.twist).tolist(), "torque_N_m": c.torque.tolist()}
    _plot_torsion(curves, out / "torsion_test.png", geometry.name)
    console.print(f"torsional stiffness (linear): {linear['tread'].stiffness / 1e3:.2f} kN m/rad with the tread clamped, "
                  f"{linear['free'].stiffness / 1e3:.2f} kN m/rad with the torque on the tread; torsion mode of the "
                  f"tread (hub held) {frequency:.2f} Hz")
    for c in curves[2:]:
        k = c.secant_stiffness()
        console.print(f"  corotational, {'tread clamped' if c.hold == 'tread' else 'torque on the tread'}: "
                      + ", ".join(f"{math.degrees(t):+.1f} deg: {q / 1e3:.2f}" for t, q in zip(c.twist, k)) + " kN m/rad")
    return result


def _plot_torsion(curves, path, name):
    import numpy as np

    from wheelsoil.plotting import pyplot
    from wheelsoil.provenance import atomic_output

    plt = pyplot()

    fig, ax = plt.subplots(figsize=(5.5, 4))
    span = max(abs(float(np.max(np.abs(c.twist)))) for c in curves)
    for c in curves:
        label = f"{'tread clamped' if c.hold == 'tread' else 'torque on the tread'}, {c.method}"
        if c.method == "linear":
            tw = np.linspace(-span, span, 3)
            ax.plot(np.degrees(tw), c.stiffness * tw, "--", lw=1, label=label)
        else:
            ax.plot(np.degrees(c.twist), c.torque, "o-", label=label)
    ax.axhline(0, color="0.7", lw=0.5)
    ax.axvline(0, color="0.7", lw=0.5)
    ax.set_xlabel("twist: hub ahead of the tread [deg] (+: drive)")
    ax.set_ylabel("torque on the hub [N m]")
    ax.set_title(f"{name}: torsion load test")
    ax.legend(fontsize=7)
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def _progress(console):
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                    TimeRemainingColumn(), console=console, transient=True)


def _plot_load_curves(curves, geometry, path):
    import numpy as np

    from wheelsoil.plotting import pyplot
    from wheelsoil.provenance import atomic_output

    plt = pyplot()

    fig, ax = plt.subplots(figsize=(5.5, 4))
    for c in curves:
        ax.plot(1e3 * np.concatenate([[0], c.deflection]), np.concatenate([[0], c.force]), "o-",
                label=f"wheel turned {c.angle:g} deg")
    if geometry.nominal_load:
        ax.axhline(geometry.nominal_load, color="0.5", ls="--", lw=0.8, label=f"nominal {geometry.nominal_load:g} N")
    ax.set_xlabel("plate deflection [mm]")
    ax.set_ylabel("plate force [N]")
    ax.set_title(f"{geometry.name}: radial load against a flat plate")
    ax.legend()
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def _console():
    from rich.console import Console

    return Console(stderr=False)


def _prepare(args, console):
    from wheelsoil.granular import prepare_bed

    spec = _spec_from_args(args)
    bed = prepare_bed(spec, use_cache=not args.no_cache, progress=console.is_terminal, arch=args.arch)
    origin = "reused from cache" if bed.meta.get("from_cache") else f"prepared in {bed.meta['prepare_seconds']:.1f} s"
    console.print(f"[bold]{bed.summary()}[/bold] ({origin})")
    return bed


def cmd_prepare_bed(args) -> int:
    console = _console()
    bed = _prepare(args, console)
    console.print(f"wrote {bed.save(args.out)}")
    return EXIT_OK


def cmd_render(args) -> int:
    import h5py

    from .render import CAMERA_PRESETS, PARTICLE_COLORS

    if args.camera not in CAMERA_PRESETS:
        raise _InputError(f"--camera {args.camera!r} is not a preset; choose one of {sorted(CAMERA_PRESETS)}")
    if args.color not in PARTICLE_COLORS:
        raise _InputError(f"--color {args.color!r}; choose one of {sorted(PARTICLE_COLORS)}")
    if args.wheel_color not in ("deflection", "none"):
        raise _InputError(f"--wheel-color {args.wheel_color!r}; choose deflection or none")
    if any(v < 16 or v > 8192 for v in args.size):
        raise _InputError(f"--size {args.size[0]} {args.size[1]}: each side must lie in [16, 8192] pixels")
    if not (0 < args.fps <= 120):
        raise _InputError(f"--fps {args.fps} must lie in (0, 120]")
    console = _console()
    path = args.path / "result.h5" if args.path.is_dir() else args.path
    is_result = False
    if path.is_file():
        try:
            with h5py.File(path, "r") as f:
                is_result = "case_toml" in f.attrs
        except OSError:
            raise _InputError(f"{path} is not an HDF5 file (a result or a bed)") from None
    size = tuple(args.size)
    if is_result:
        from wheelsoil.provenance import writable_file

        from .render import render_animation, render_result_frame
        from .results import load_result

        result = load_result(path)
        wheel = None if args.wheel_color == "none" else "deflection"
        if args.animate:
            out = args.out or path.parent / "animation.gif"
            if out.suffix.lower() not in (".gif", ".mp4"):
                raise _InputError(f"--out {out}: an animation is a .gif or .mp4 file")
            writable_file(out)
            with _progress(console) as bar:
                task = bar.add_task("rendering frames", total=len(result.frame_times))
                render_animation(result, out, fps=args.fps, color=args.color, wheel_color=wheel, camera=args.camera,
                                 size=size, progress=lambda k, n: bar.update(task, completed=k))
        else:
            out = writable_file(args.out or path.parent / "frame.png")
            render_result_frame(result, out, frame=args.frame, color=args.color, wheel_color=wheel,
                                camera=args.camera, size=size)
        console.print(f"wrote {out}")
        return EXIT_OK
    if args.animate:
        raise _InputError(f"--animate needs a result file; {path} is not one")
    from wheelsoil.provenance import writable_file
    from wheelsoil.granular import load_bed

    from .render import render_bed

    out = writable_file(args.out or path.with_suffix(".png"))
    bed = load_bed(path)
    console.print(f"wrote {render_bed(bed, out, camera=args.camera, size=size)}")
    return EXIT_OK


def cmd_bench(args) -> int:
    """The benchmark tiers run in their own process (``python -m wheelsoil.benchmarks.smoke`` or
    ``.dem_throughput``): their memory and timings are their own, and the case layer does not import the
    benchmarks (they import it). The exit status is theirs (1: a regression beyond the tolerance)."""
    import subprocess

    if args.smoke:
        module = "wheelsoil.benchmarks.smoke"
        argv = ["--tolerance", str(args.tolerance)]
        if args.out:
            argv += ["--out", str(args.out)]
        if args.baseline:
            argv += ["--baseline", str(args.baseline)]
        if args.record:
            argv.append("--record")
    else:
        module = "wheelsoil.benchmarks.dem_throughput"
        argv = (["--out", str(args.out)] if args.out else []) + (["--no-liggghts"] if args.no_liggghts else [])
        argv += ["--memory-check"] if args.memory_check else []
    return subprocess.call([sys.executable, "-m", module, *argv])


class _InputError(ValueError):
    pass


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_INPUT
    from wheelsoil.errors import SimulationUnstableError, WheelsoilInputError

    try:
        return args.func(args)
    except (WheelsoilInputError, _InputError) as exc:
        print(f"wheelsoil {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except SimulationUnstableError as exc:
        print(f"wheelsoil {args.command}: simulation stopped: {exc}", file=sys.stderr)
        return EXIT_UNSTABLE
    except KeyboardInterrupt:
        print(f"wheelsoil {args.command}: interrupted; no file that looks finished was written (a run with a "
              "checkpoint continues with --resume)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
