"""The ``wheelsoil`` command line.

Exit codes (scripts can trust them):
    0  success
    1  unexpected internal error (a bug: please report it with the traceback), or a benchmark
       regression beyond the tolerance (``bench --smoke --baseline``)
    2  bad input (a parameter out of range, a missing file); the message names the value
    3  the simulation went unstable or did not settle; nothing was written
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

EXIT_OK, EXIT_BUG, EXIT_INPUT, EXIT_UNSTABLE = 0, 1, 2, 3

GRAVITY_PRESETS = {"earth": 9.81, "moon": 9.81 / 6.0}

MAIN_HELP = """\
wheelsoil: a single-wheel terramechanics testbed in software.

Start with the smoke job: the seed-004 lunar-rover wheel (coarse mesh) driven at slip 0.3 and
steering angle 10 deg through a small regolith bed under Earth gravity with W = 3000 N (about
three minutes on two cores, bed preparation included):

    wheelsoil run

the same wheel at Moon gravity with W = 500 N (equal wheel mass), or other rig settings:

    wheelsoil run smoke-moon-steer
    wheelsoil run smoke-1g-steer --slip 0.5 --slip-angle 20 --rigid --out runs/rigid

hold the semi-empirical model against measured data and name what it misses:

    wheelsoil validate ../shared/data/measured/cmu_3d_terramechanics --holdout slip_angle=60

or prepare your own beds, e.g. a Moon-gravity bed of seed-004 particles:

    wheelsoil prepare-bed --length 1.0 --width 0.5 --depth 0.15 --gravity moon --out moon_bed.h5
    wheelsoil render moon_bed.h5 --out moon_bed.png
"""


def _gravity(value: str) -> float:
    if value in GRAVITY_PRESETS:
        return GRAVITY_PRESETS[value]
    try:
        g = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"gravity {value!r} is neither a preset {sorted(GRAVITY_PRESETS)} nor a number in m/s^2"
        ) from None
    if not (0 < g < 1000):
        raise argparse.ArgumentTypeError(f"gravity {g} m/s^2 must lie in (0, 1000)")
    return g


def _add_bed_options(p: argparse.ArgumentParser, *, length=0.5, width=0.25, depth=0.1) -> None:
    g = p.add_argument_group("soil bed")
    g.add_argument("--length", type=float, default=length, help=f"bin length along x [m] (default {length})")
    g.add_argument("--width", type=float, default=width, help=f"bin width along y [m] (default {width})")
    g.add_argument("--depth", type=float, default=depth, help=f"levelled bed depth [m] (default {depth})")
    g.add_argument("--dmin", type=float, default=0.016, help="smallest particle diameter [m] (default 0.016, seed 004)")
    g.add_argument("--dmax", type=float, default=0.024, help="largest particle diameter [m] (default 0.024, seed 004)")
    g.add_argument("--gravity", type=_gravity, default=GRAVITY_PRESETS["earth"],
                   help="'earth' (9.81), 'moon' (9.81/6) or a value in m/s^2 (default earth); "
                        "beds are prepared under the gravity they are tested at")
    g.add_argument("--seed", type=int, default=0, help="random seed of radii and packing (default 0)")
    g.add_argument("--no-cache", action="store_true", help="prepare afresh even if an identical bed is cached")
    p.add_argument("--arch", default=None, help="Taichi backend: cpu (default), cuda, vulkan, metal")


def _spec_from_args(args):
    from wheelsoil.granular import BedSpec

    return BedSpec(length=args.length, width=args.width, depth=args.depth, diameter_min=args.dmin,
                   diameter_max=args.dmax, gravity=(0.0, 0.0, -args.gravity), seed=args.seed)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="wheelsoil", description=MAIN_HELP,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    from wheelsoil import __version__

    parser.add_argument("--version", action="version", version=f"wheelsoil {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser("run", aliases=["testbed"],
                       help="drive a wheel through a prepared bed (single-wheel testbed); default: the smoke job",
                       description="Run a testbed case: prepare (or reuse) its bed under the case's gravity, lower "
                                   "the wheel until the soil carries the load W, drive at the commanded slip and "
                                   "steering angle, detect the steady state and average. Writes series.csv, "
                                   "summary.json, series.png and a render of the last state (final.png) to --out. "
                                   "Cases: smoke-1g-steer (the default; about 3 minutes on 2 cores with the bed, "
                                   "W = 3000 N), smoke-moon-steer (1/6 g, W = 500 N), seed004-1g-steer and "
                                   "seed004-moon-steer (full scale, hours). 'wheelsoil testbed' is the same command.")
    p.add_argument("case", nargs="?", default="smoke-1g-steer",
                   help="case name (smoke-1g-steer [default], smoke-moon-steer, seed004-1g-steer, seed004-moon-steer)")
    p.add_argument("--slip", type=float, default=None, help="longitudinal slip i in [-1, 1) (default: the case's)")
    p.add_argument("--slip-angle", type=float, default=None, help="steering angle beta [deg] in (-90, 90)")
    p.add_argument("--load", type=float, default=None, help="vertical load W [N] > 0, wheel weight included")
    p.add_argument("--drive-time", type=float, default=None, help="driving time [s]")
    p.add_argument("--rigid", action="store_true", help="use the rigid wheel with the same surface")
    p.add_argument("--no-render", action="store_true", help="skip the render of the last state")
    p.add_argument("--out", type=Path, default=None, help="output folder (default wheelsoil-output/<case>)")
    p.add_argument("--arch", default=None, help="Taichi backend: cpu (default), cuda, vulkan, metal")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("prepare-bed", help="fill, settle and level a soil bin; write it to HDF5",
                       description="Fill a bin with polydisperse spheres, settle under gravity until the kinetic "
                                   "energy per particle is below the threshold, level at the target depth, and "
                                   "write the bed to HDF5. Identical beds are reused from the cache "
                                   "(WHEELSOIL_CACHE, default ~/.cache/wheelsoil).")
    _add_bed_options(p)
    p.add_argument("--out", type=Path, default=Path("bed.h5"), help="bed file to write (default bed.h5)")
    p.set_defaults(func=cmd_prepare_bed)

    p = sub.add_parser("render", help="render a bed file to PNG offscreen",
                       description="Render the particles of a bed HDF5 file to a PNG, coloured by height.")
    p.add_argument("bed", type=Path, help="bed file written by prepare-bed or run")
    p.add_argument("--out", type=Path, default=None, help="PNG to write (default: next to the bed file)")
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
                       description="Mesh a preset wheel (lunar-rover: seed 004; exomars: seeds 000/001), write the "
                                   "mesh as VTU, and measure its radial stiffness: point-load stiffness at angles "
                                   "over one spoke pitch, and the load-deflection curve against a rigid flat plate "
                                   "over the spoke and midway between spokes. Writes mesh.vtu, load_test.csv, "
                                   "load_test.png and summary.json to --out.")
    p.add_argument("preset", help="wheel preset: lunar-rover or exomars")
    p.add_argument("--element-size", type=float, default=None, help="target element edge [m] (default: the preset's)")
    p.add_argument("--out", type=Path, default=None, help="output folder (default wheelsoil-output/wheel-<preset>)")
    p.add_argument("--points", type=int, default=6, help="load steps of the plate curve (default 6)")
    p.add_argument("--max-load-factor", type=float, default=1.5,
                   help="largest plate load as a multiple of the preset's nominal load (default 1.5)")
    p.set_defaults(func=cmd_wheel)

    p = sub.add_parser("validate", help="hold the semi-empirical model against measured data; name what it misses",
                       description="Calibrate the classical wheel-soil model (Wong-Reece, Janosi-Hanamoto, lateral "
                                   "shear) on training conditions, diagnose its residuals, fit every candidate "
                                   "mechanism the data can show (slip-sinkage, theta_m moving with slip, soil flow, "
                                   "sidewall, grousers, surrogate radius, gravity-scaled cohesion), rank them by "
                                   "held-out error and BIC, and write report.md, findings.json and plots to "
                                   "--report. DATA: a folder of CMU trial files, the digitised single-wheel CSV, a "
                                   "CSV in wheelsoil's format (slip, vertical_load_N, wheel_radius_m, "
                                   "wheel_width_m, drawbar_pull_N, ...), or 'synthetic' (a hidden mechanism, "
                                   "revealed at the end of the report).")
    p.add_argument("data", help="measured data (folder or CSV), or 'synthetic'")
    p.add_argument("--model", choices=["semi-empirical"], default="semi-empirical",
                   help="model to hold against the data (default semi-empirical)")
    p.add_argument("--report", type=Path, default=Path("wheelsoil-output/validation"), help="report folder")
    p.add_argument("--holdout", default=None,
                   help="CONDITION=VALUE: hold out one level, e.g. slip_angle=45 or group=smooth "
                        "(default: a random 30 %% of the conditions)")
    p.add_argument("--responses", nargs="+", default=None,
                   help="responses to fit: drawbar_pull lateral_force sinkage torque (default: those measured)")
    p.add_argument("--hidden", default=None, help="synthetic only: mechanism to hide, or 'none' (default: random)")
    p.add_argument("--seed", type=int, default=0, help="random seed of the hold-out split and synthetic data")
    p.add_argument("--group", default=None,
                   help="keep the rows whose group starts with this (e.g. ding2011: one rig and soil of the "
                        "digitised set; grouser or smooth in the CMU set)")
    p.set_defaults(func=cmd_validate)
    return parser


def cmd_validate(args) -> int:
    from wheelsoil.validation.workflow import main_validate

    return main_validate(args)


def cmd_run(args) -> int:
    import json

    from wheelsoil.coupling.presets import preset_case
    from wheelsoil.coupling.testbed import SERIES_UNITS, Testbed
    from wheelsoil.granular import prepare_bed
    from wheelsoil.provenance import atomic_output, provenance

    console = _console()
    overrides = {k: v for k, v in (("slip", args.slip), ("slip_angle", args.slip_angle), ("load", args.load),
                                   ("drive_time", args.drive_time)) if v is not None}
    if args.rigid:
        overrides["rigid"] = True
    case = preset_case(args.case, **overrides)
    out = args.out or Path("wheelsoil-output") / case.name
    bed = prepare_bed(case.bed, progress=console.is_terminal, arch=args.arch)
    console.print(f"[bold]{bed.summary()}[/bold] ({'reused from cache' if bed.meta.get('from_cache') else 'prepared'})")
    bench = Testbed(bed, case.wheel, case.testbed, arch=args.arch)
    console.print(f"wheel {case.wheel.name}: {bench.mesh.n_elements} elements, {bench.wheel_mass:.1f} kg, "
                  f"{'rigid' if case.testbed.rigid else 'flexible'}; DEM step {bench.dt:.3g} s; "
                  f"slip {case.testbed.slip:g}, steering {case.testbed.slip_angle:g} deg, W = {case.testbed.load:g} N")
    result = bench.run(progress=console.is_terminal)
    names = list(SERIES_UNITS)
    rows = [",".join(f"{n}[{SERIES_UNITS[n]}]" for n in names)]
    rows += [",".join(f"{result.series[n][k]:.9g}" for n in names) for k in range(len(result.series["t"]))]
    with atomic_output(out / "series.csv") as tmp:
        tmp.write_text("\n".join(rows) + "\n")
    summary = {"case": case.name, "testbed": case.testbed.to_dict(), "bed": case.bed.to_dict(),
               "wheel": case.wheel.name, "element_size_m": case.wheel.element_size, "summary": result.summary,
               "run": result.info, "provenance": provenance()}
    with atomic_output(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2, default=str))
    _plot_series(result, out / "series.png", case.name)
    written = [out / "series.csv", out / "summary.json", out / "series.png"]
    if not args.no_render:
        from .render import render_testbed

        with atomic_output(out / "final.png") as tmp:
            image = tmp.with_suffix(".png")  # the renderer picks the format from the suffix
            try:
                render_testbed(result, image, title=f"{case.name}: end of the run")
                image.replace(tmp)
            finally:
                image.unlink(missing_ok=True)
        written.append(out / "final.png")
    s = result.summary
    console.print(("steady state" if s["steady"] else "[yellow]no steady state detected; averaged the last half[/]")
                  + f" over t = {s['window'][0]:.2f}-{s['window'][1]:.2f} s:")
    for q in ("drawbar_pull", "lateral_force", "vertical_force", "torque", "sinkage", "tread_sinkage"):
        console.print(f"  {q:15s} {s[q]['mean']:10.4g} +- {s[q]['std']:.3g} {s[q]['units']}")
    console.print(f"{result.info['wall_seconds']:.0f} s wall for {result.info['simulated_seconds']:.2f} s simulated; "
                  f"wrote {', '.join(str(w) for w in written)}")
    return EXIT_OK


def _plot_series(result, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wheelsoil.provenance import atomic_output

    s, t = result.series, result.series["t"]
    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for name in ("drawbar_pull", "lateral_force", "vertical_force"):
        axes[0].plot(t, s[name], label=name.replace("_", " "))
    axes[0].axhline(result.spec.load, color="0.5", ls="--", lw=0.8, label="load W")
    axes[0].set_ylabel("force on the wheel [N]")
    axes[1].plot(t, s["torque"], color="C3")
    axes[1].set_ylabel("driving torque [N m]")
    axes[2].plot(t, 1e3 * s["sinkage"], color="C4", label="hub (with deflection)")
    axes[2].plot(t, 1e3 * s["tread_sinkage"], color="C5", label="tread")
    axes[2].set_ylabel("sinkage [mm]")
    axes[2].legend(fontsize=8)
    axes[2].set_xlabel("time [s]")
    t0, t1 = result.summary["window"]
    for ax in axes:
        ax.axvspan(t0, t1, color="0.9", zorder=0)
    axes[0].legend(fontsize=8, ncol=2)
    axes[0].set_title(f"{title} (shaded: averaging window)")
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


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
    with atomic_output(out / "summary.json") as tmp:
        tmp.write_text(json.dumps(summary, indent=2))
    _plot_load_curves(curves, geometry, out / "load_test.png")
    console.print(f"point-load radial stiffness over one spoke pitch ({pitch:g} deg): "
                  + ", ".join(f"{a:g} deg: {k / 1e3:.2f} kN/m" for a, k in zip(angles, point))
                  + f"; mean {np.mean(point) / 1e3:.2f} kN/m")
    for key, k in nominal.items():
        console.print(f"plate secant stiffness at the nominal {geometry.nominal_load:g} N, wheel at {key} deg: {k / 1e3:.2f} kN/m")
    console.print(f"wrote {out / 'load_test.csv'}, {out / 'load_test.png'}, {out / 'summary.json'}")
    return EXIT_OK


def _progress(console):
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total}"),
                    TimeRemainingColumn(), console=console, transient=True)


def _plot_load_curves(curves, geometry, path):
    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wheelsoil.provenance import atomic_output

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
    from wheelsoil.granular import load_bed

    from .render import CAMERA_PRESETS, render_bed

    if args.camera not in CAMERA_PRESETS:
        raise _InputError(f"--camera {args.camera!r} is not a preset; choose one of {sorted(CAMERA_PRESETS)}")
    bed = load_bed(args.bed)
    out = args.out or args.bed.with_suffix(".png")
    console = _console()
    console.print(f"wrote {render_bed(bed, out, camera=args.camera, size=tuple(args.size))}")
    return EXIT_OK


def cmd_bench(args) -> int:
    if args.smoke:
        from wheelsoil.benchmarks import smoke

        argv = ["--tolerance", str(args.tolerance)]
        if args.out:
            argv += ["--out", str(args.out)]
        if args.baseline:
            argv += ["--baseline", str(args.baseline)]
        if args.record:
            argv.append("--record")
        return smoke.main(argv)
    from wheelsoil.benchmarks import dem_throughput

    argv = (["--out", str(args.out)] if args.out else []) + (["--no-liggghts"] if args.no_liggghts else [])
    argv += ["--memory-check"] if args.memory_check else []
    return dem_throughput.main(argv)


class _InputError(ValueError):
    pass


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    args.argv = list(sys.argv[1:] if argv is None else argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_INPUT
    from wheelsoil.granular import SimulationUnstableError, WheelsoilInputError

    try:
        return args.func(args)
    except (WheelsoilInputError, _InputError) as exc:
        print(f"wheelsoil {args.command}: error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except SimulationUnstableError as exc:
        print(f"wheelsoil {args.command}: simulation stopped: {exc}", file=sys.stderr)
        return EXIT_UNSTABLE
    except KeyboardInterrupt:
        print(f"wheelsoil {args.command}: interrupted; nothing partial was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
