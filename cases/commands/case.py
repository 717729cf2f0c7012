"""``wheelsoil case``: list the presets, show a case with every key, check a case file, carry a case to another
gravity by similarity."""

from __future__ import annotations

from . import common


def add_parser(sub) -> None:
    """The ``case`` command on ``sub``."""
    p = sub.add_parser("case", help="list the preset cases, show a case with every key, check a case file, or carry "
                                    "a case to another gravity",
                       description="'wheelsoil case list' lists the presets; 'wheelsoil case show CASE' prints the "
                                   "resolved case with every key, its unit, range and default (a template to copy); "
                                   "'wheelsoil case check CASE' validates a case file and prints its hash; "
                                   "'wheelsoil case similar CASE --gravity moon' prints the case carried to that "
                                   "gravity with every dimensionless group kept (times x tau, speeds / tau, load and "
                                   "moduli / tau^2, tau = sqrt(g / g_new); wheelsoil.cases.similarity), the same run "
                                   "in other units.")
    p.add_argument("action", choices=["list", "show", "check", "similar"])
    p.add_argument("case", nargs="?", default=None, help="case file (.toml) or preset name")
    common.add_set_option(p)
    p.add_argument("--gravity", help="similar: the new gravity ('earth', 'moon', a magnitude in m/s^2)")
    p.add_argument("--keep", nargs="+", default=[], metavar="SECTION.KEY",
                   help="similar: keys left as they are (e.g. soil.youngs_modulus: grains as stiff as in CASE)")
    p.set_defaults(func=cmd)


def cmd(args) -> int:
    import os

    os.environ.setdefault("ENABLE_TAICHI_HEADER_PRINT", "0")  # stdout is the case text: no Taichi banner
    from ..schema import case_to_toml, load_case, preset_names, preset_text

    if args.action == "list":
        for name in preset_names():
            first = next((ln for ln in preset_text(name).splitlines() if ln.startswith("description")), "")
            print(f"{name:22s} {first.split('=', 1)[-1].strip().strip(chr(34))}")
        return common.EXIT_OK
    if not args.case:
        raise common.InputError("give a case file or preset name ('wheelsoil case list' shows the presets)")
    case = load_case(args.case, args.set or [])
    if args.action == "similar":
        import argparse

        from wheelsoil.gravity import GRAVITY_PRESETS

        from ..similarity import similar_case
        from ..units import gravity_argument

        if args.gravity is None:
            raise common.InputError("'wheelsoil case similar' needs --gravity (earth, moon or a magnitude in m/s^2)")
        try:
            gravity = args.gravity if args.gravity in GRAVITY_PRESETS else gravity_argument(args.gravity)
        except argparse.ArgumentTypeError as exc:
            raise common.InputError(f"--gravity: {exc}") from None
        case = similar_case(case, gravity, keep=tuple(args.keep))
        print(case_to_toml(case, template=True), end="")
        return common.EXIT_OK
    if args.action == "show":
        print(case_to_toml(case, template=True), end="")
    else:  # check
        print(f"{args.case}: valid; case {case.name}, hash {case.case_hash()}")
    return common.EXIT_OK
