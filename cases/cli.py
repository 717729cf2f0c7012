"""The ``wheelsoil`` command line: the parser built from the commands (one module each, :mod:`.commands`) and the
map from errors to exit codes.

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
import importlib
import sys

from .commands import COMMANDS
from .commands.common import EXIT_BUG, EXIT_INPUT, EXIT_OK, EXIT_SWEEP_FAILED, EXIT_UNSTABLE, InputError

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_BUG", "EXIT_INPUT", "EXIT_UNSTABLE", "EXIT_SWEEP_FAILED"]

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


def build_parser() -> argparse.ArgumentParser:
    """The ``wheelsoil`` parser: every command of :data:`.commands.COMMANDS` adds its own subparser."""
    from wheelsoil import __version__

    parser = argparse.ArgumentParser(prog="wheelsoil", description=MAIN_HELP,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"wheelsoil {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"{__package__}.commands.{name}").add_parser(sub)
    return parser


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
    except (WheelsoilInputError, InputError) as exc:
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
