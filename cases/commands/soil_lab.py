"""``wheelsoil soil-lab TEST``: the virtual soil lab's tests from the command line (:mod:`wheelsoil.soillab`).

TEST is ``poured`` (bulk density), ``repose`` (angle of repose, draw-down), ``shear`` (direct shear box), ``plate``
(plate sinkage at the CMU plate sizes, with the measured curves beside) or ``wheel`` (static sinkage of a CMU wheel).
Every option defaults to :mod:`wheelsoil.parameters.soil_lab`; each test writes ``TEST.csv``, ``TEST.json`` and
``TEST.png`` into ``--out``. Bad input (an unknown test, a plate wider than the box, particles too coarse for it, a
stress the contact cannot carry, a measured file without its columns) is refused before any work.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from wheelsoil.errors import WheelsoilInputError
from wheelsoil.gravity import GRAVITY_PRESETS
from wheelsoil.material import PairProperties
from wheelsoil.parameters import soil_lab

from ..units import gravity_argument
from . import common

TESTS = ("poured", "repose", "shear", "plate", "wheel")


def add_parser(sub) -> None:
    m, p = soil_lab.PARTICLE_MATERIAL, soil_lab.PARTICLE_PAIR
    parser = sub.add_parser(
        "soil-lab", help="the virtual soil lab: poured bed, angle of repose, direct shear, plate and wheel sinkage",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("test", metavar="TEST", help=f"one of {', '.join(TESTS)}")
    g = parser.add_argument_group("particles")
    g.add_argument("--dmin", type=float, default=soil_lab.DIAMETER_MIN, help="smallest particle diameter [m]")
    g.add_argument("--dmax", type=float, default=soil_lab.DIAMETER_MAX, help="largest particle diameter [m]")
    g.add_argument("--density", type=float, default=m.density, help="particle density [kg/m^3]")
    g.add_argument("--youngs-modulus", type=float, default=m.youngs_modulus, help="Young's modulus [Pa]")
    g.add_argument("--poisson-ratio", type=float, default=m.poisson_ratio, help="Poisson's ratio [-]")
    g.add_argument("--friction", type=float, default=p.static_friction, help="particle sliding friction [-]")
    g.add_argument("--rolling-friction", type=float, default=p.rolling_friction, help="rolling friction [-]")
    g.add_argument("--restitution", type=float, default=p.restitution, help="restitution [-]")
    g.add_argument("--rolling-model", choices=PairProperties.ROLLING_MODELS, default=p.rolling_model,
                   help="rolling-resistance law of every soil contact (particles, box, plates): cdt (constant "
                        "directional torque) or epsd (elastic-plastic spring-dashpot, holds a torque at rest)")
    g.add_argument("--pour-friction-factor", type=float, default=1.0,
                   help="sliding and rolling friction times this while the bed is poured: 1 a loose pour, 0 the "
                        "densest, above 1 looser (at most 3) [-]")
    g.add_argument("--gravity", type=gravity_argument, default=GRAVITY_PRESETS["earth"],
                   help="'earth', 'moon' or m/s^2 (the sand's tests: earth)")
    g.add_argument("--seeds", type=int, nargs="+", default=None,
                   help="random packings (poured, repose: the spread; plate, wheel: replicas; shear: the first)")
    t = parser.add_argument_group("the tests")
    t.add_argument("--plate", type=float, nargs="+", default=list(soil_lab.PLATE_DIAMETERS),
                   help="plate diameters [m] (plate)")
    t.add_argument("--box", type=float, nargs=3, default=None, metavar=("LENGTH", "WIDTH", "DEPTH"),
                   help="the bed's box [m] (poured, plate, wheel; default the parameter set's: the plate's for "
                        "the poured bed)")
    t.add_argument("--speed", type=float, default=None,
                   help=f"pressing speed (plate, wheel; default {soil_lab.PRESS['speed']:g}) or the shear box's shear "
                        f"speed (shear; default {soil_lab.SHEAR['speed']:g}) [m/s]")
    t.add_argument("--max-sinkage", type=float, default=soil_lab.PRESS["max_sinkage"], help="pressing depth [m]")
    t.add_argument("--wheel", choices=("smooth", "grouser"), default="smooth", help="the CMU wheel (wheel)")
    t.add_argument("--stresses", type=float, nargs="+", default=list(soil_lab.SHEAR["normal_stresses"]),
                   help="normal stresses of the shear box [Pa]")
    t.add_argument("--measured-box", choices=("large", "small", "both"), default="both",
                   help="which CMU sandbox's measured curves to compare with (plate, wheel)")
    t.add_argument("--measured", type=Path, default=None,
                   help="the measured plate_sinkage.csv or wheel_sinkage.csv (default ../shared/...)")
    t.add_argument("--shear-json", type=Path, default=None,
                   help="a shear.json of this lab: its peak friction angle and cohesion give the plates' bearing "
                        "capacity (plate)")
    parser.add_argument("--out", type=Path, default=Path("wheelsoil-output/soil-lab"), help="output folder")
    parser.add_argument("--cache", type=Path, default=None, help="bed cache folder (default the user cache)")
    parser.add_argument("--progress", action="store_true", help="progress bars on the terminal")
    parser.add_argument("--checkpoint-every", type=int, default=None, metavar="SAMPLES",
                        help="plate, wheel: keep the state every SAMPLES samples in OUT/.TEST-...checkpoint.h5, so "
                             "that the same command run again after an interruption continues the test from there "
                             "(a test already finished in that command is run again); the same SAMPLES gives the "
                             "same curve, interrupted or not, and another than a run without checkpoints "
                             "(default: none)")
    common.add_arch_option(parser)
    parser.set_defaults(func=run)


def _bed_spec(args, box: dict, seed: int):
    from wheelsoil.granular.bed_spec import BedSpec
    from wheelsoil.material import Material

    material = Material("soil-lab particles", youngs_modulus=args.youngs_modulus, poisson_ratio=args.poisson_ratio,
                        density=args.density)
    pair = PairProperties(restitution=args.restitution, static_friction=args.friction,
                          rolling_friction=args.rolling_friction, rolling_model=args.rolling_model)
    return BedSpec(length=box["length"], width=box["width"], depth=box["depth"], diameter_min=args.dmin,
                   diameter_max=args.dmax, gravity=(0.0, 0.0, -args.gravity), material=material, pair=pair,
                   wall_material=soil_lab.TOOL_MATERIAL,
                   wall_pair=dataclasses.replace(soil_lab.TOOL_PAIR, rolling_model=args.rolling_model), seed=seed,
                   periodic=False,
                   pour_friction_factor=args.pour_friction_factor)


def _shear_envelope(path: Path | None) -> tuple[float | None, float]:
    if path is None:
        return None, 0.0
    if not path.is_file():
        raise WheelsoilInputError(f"--shear-json {str(path)!r} does not exist")
    data = json.loads(path.read_text())
    if data.get("test") != "shear" or "peak" not in data:
        raise WheelsoilInputError(f"--shear-json {str(path)!r} is not a shear.json of 'wheelsoil soil-lab shear'")
    return float(data["peak"]["friction_angle_deg"]), max(float(data["peak"]["cohesion_Pa"]), 0.0)


def _specs(args):
    """Every spec of the chosen test, built (and so checked) before any work."""
    from wheelsoil import soillab

    seeds = args.seeds or ([0] if args.test in ("plate", "wheel", "shear") else list(soil_lab.POURED_SEEDS))
    press_speed = soil_lab.PRESS["speed"] if args.speed is None else args.speed
    if args.box and args.test in ("repose", "shear"):
        raise WheelsoilInputError(f"--box {' '.join(f'{v:g}' for v in args.box)}: the {args.test} test has its own "
                                  "apparatus; --box sets the bed of the poured, plate and wheel tests")
    if args.speed is not None and args.test in ("poured", "repose"):
        raise WheelsoilInputError(f"--speed {args.speed:g}: the {args.test} test has no speed to set; --speed sets the "
                                  "plate's and wheel's pressing speed and the shear box's shear speed")
    if args.test == "poured":
        box = dict(zip(("length", "width", "depth"), args.box)) if args.box else soil_lab.PLATE_BOX
        return seeds, _bed_spec(args, box, seeds[0]), None
    if args.test == "repose":
        spec = soillab.ReposeSpec(seeds=tuple(seeds))
        return seeds, _bed_spec(args, soil_lab.PLATE_BOX, seeds[0]), spec
    if args.test == "shear":
        speed = {} if args.speed is None else {"speed": args.speed}
        spec = soillab.ShearSpec(normal_stresses=tuple(args.stresses), **speed)
        return seeds, _bed_spec(args, soil_lab.PLATE_BOX, seeds[0]), spec
    if args.test == "plate":
        box = dict(zip(("length", "width", "depth"), args.box)) if args.box else soil_lab.PLATE_BOX
        specs = [soillab.PlateSpec(diameter=d, speed=press_speed, max_sinkage=args.max_sinkage) for d in args.plate]
        bed = _bed_spec(args, box, seeds[0])
        for s in specs:
            soillab.specs.check_plate_fits("plate diameter", s.diameter, bed.length, bed.width)
            soillab.specs.check_resolution("plate diameter", s.diameter, bed.diameter_max)
        return seeds, bed, specs
    box = dict(zip(("length", "width", "depth"), args.box)) if args.box else soil_lab.WHEEL_BOX
    spec = soillab.WheelPressSpec(wheel=args.wheel, speed=press_speed, max_sinkage=args.max_sinkage)
    return seeds, _bed_spec(args, box, seeds[0]), spec


def _measured(args):
    from wheelsoil import soillab

    box = None if args.measured_box == "both" else args.measured_box
    if args.test == "plate":
        return soillab.load_plate_curves(args.measured, box=box)
    return [c for c in soillab.load_wheel_curves(args.measured, box=box) if c.wheel == args.wheel]


def run(args) -> int:
    import dataclasses

    from rich.console import Console

    from wheelsoil import soillab
    from wheelsoil.provenance import writable_folder
    from wheelsoil.soillab import report

    if args.test not in TESTS:
        raise WheelsoilInputError(f"soil-lab TEST = {args.test!r} is unknown; choose one of {list(TESTS)}")
    if args.checkpoint_every is not None and (args.test not in ("plate", "wheel") or args.checkpoint_every < 1):
        raise WheelsoilInputError(f"--checkpoint-every = {args.checkpoint_every}: give a whole number of samples >= 1, "
                                  "for the plate and wheel tests only")
    seeds, bed_spec, spec = _specs(args)
    friction_angle, cohesion = _shear_envelope(args.shear_json) if args.test == "plate" else (None, 0.0)
    measured = _measured(args) if args.test in ("plate", "wheel") and (args.measured or _shared_present()) else []
    out = writable_folder(args.out)
    console = Console(stderr=True)
    common = dict(cache_dir=args.cache, arch=args.arch, progress=args.progress)
    if args.test == "poured":
        figures, paths = report.write_poured(soillab.poured_bed_test(bed_spec, seeds, **common), out)
    elif args.test == "repose":
        figures, paths = report.write_repose(soillab.repose_test(bed_spec, spec, **common), out)
    elif args.test == "shear":
        figures, paths = report.write_shear(soillab.shear_test(bed_spec, spec, **common), out)
    else:
        results = []
        for seed in seeds:
            bed = dataclasses.replace(bed_spec, seed=seed)
            if args.test == "plate":
                results += [soillab.plate_test(bed, s, **common,
                                               **_checkpoint(args, out, f"plate-{1e3 * s.diameter:g}mm-seed{seed}"))
                            for s in spec]
            else:
                results.append(soillab.wheel_press_test(bed, spec, **common,
                                                        **_checkpoint(args, out, f"wheel-{spec.wheel}-seed{seed}")))
        figures, paths = report.write_penetration(results, measured, out, args.test, friction_angle=friction_angle,
                                                  cohesion=cohesion)
    console.print(f"soil-lab {args.test}: " + report.headline(args.test, figures))
    for p in paths.values():
        console.print(f"  wrote {p}")
    return 0


def _checkpoint(args, out: Path, name: str) -> dict:
    """The pressing test's checkpoint options (none without --checkpoint-every)."""
    if args.checkpoint_every is None:
        return {}
    return {"checkpoint": out / f".{name}.checkpoint.h5", "checkpoint_every": args.checkpoint_every}


def _shared_present() -> bool:
    from wheelsoil.soillab.measured import default_data_dir

    return default_data_dir().is_dir()
