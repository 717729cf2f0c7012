"""``wheelsoil prepare-bed``: a soil bin filled, settled and levelled (a case's, or from options)."""

from __future__ import annotations

import argparse
from pathlib import Path

from wheelsoil.gravity import GRAVITY_PRESETS
from wheelsoil.parameters import smoke

from ..units import gravity_argument
from . import common

#: prepare-bed's defaults without a CASE: the smoke run's bed (the parameter set every layer takes its defaults
#: from), so that ``wheelsoil prepare-bed`` makes the bed ``wheelsoil run`` uses.
BED_DEFAULTS = {"length": smoke.SOIL["length"], "width": smoke.SOIL["width"], "depth": smoke.SOIL["depth"],
                "dmin": smoke.SOIL["diameter_min"], "dmax": smoke.SOIL["diameter_max"],
                "gravity": GRAVITY_PRESETS[smoke.GRAVITY], "seed": smoke.SEED}


def add_parser(sub) -> None:
    """The ``prepare-bed`` command on ``sub``."""
    p = sub.add_parser("prepare-bed", help="fill, settle and level a soil bin (a case's, or from options); write it",
                       description="Fill a bin with polydisperse spheres, settle under gravity until the kinetic "
                                   "energy per particle is below the threshold, level at the target depth, and "
                                   "write the bed to HDF5. With a CASE (file or preset, plus --set overrides) the "
                                   "bed is the case's soil, the one 'wheelsoil run CASE' uses; without, the "
                                   "options below describe it. Identical beds are reused from the cache "
                                   "(WHEELSOIL_CACHE, default ~/.cache/wheelsoil).")
    p.add_argument("case", nargs="?", default=None, help="case file (.toml) or preset whose bed to prepare")
    common.add_set_option(p)
    add_bed_options(p)
    p.add_argument("--out", type=Path, default=Path("bed.h5"), help="bed file to write (default bed.h5)")
    p.set_defaults(func=cmd)


def add_bed_options(p: argparse.ArgumentParser) -> None:
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
    common.add_arch_option(p)


def spec_from_args(args):
    from wheelsoil.granular import BedSpec

    given = [k for k in BED_DEFAULTS if getattr(args, k) is not None] + (["walled"] if args.walled else [])
    if getattr(args, "case", None):
        if given:
            raise common.InputError(f"--{given[0]} does not go with a CASE: set the case's soil instead, e.g. "
                              f"--set soil.length=1.0 ('wheelsoil case show {args.case}' lists the keys)")
        from .. import build
        from ..schema import load_case

        return build.bed_spec(load_case(args.case, args.set or []))
    if args.set:
        raise common.InputError("--set needs a CASE (e.g. wheelsoil prepare-bed smoke-1g-steer --set soil.gravity=moon)")
    v = {k: (getattr(args, k) if getattr(args, k) is not None else BED_DEFAULTS[k]) for k in BED_DEFAULTS}
    return BedSpec(length=v["length"], width=v["width"], depth=v["depth"], diameter_min=v["dmin"],
                   diameter_max=v["dmax"], gravity=(0.0, 0.0, -v["gravity"]), seed=v["seed"],
                   periodic=not args.walled)


def prepare(args, console):
    from wheelsoil.granular import prepare_bed

    spec = spec_from_args(args)
    bed = prepare_bed(spec, use_cache=not args.no_cache, progress=console.is_terminal, arch=args.arch)
    origin = "reused from cache" if bed.meta.get("from_cache") else f"prepared in {bed.meta['prepare_seconds']:.1f} s"
    console.print(f"[bold]{bed.summary()}[/bold] ({origin})")
    return bed


def cmd(args) -> int:
    console = common.console()
    bed = prepare(args, console)
    console.print(f"wrote {bed.save(args.out)}")
    return common.EXIT_OK
