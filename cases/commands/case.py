"""``wheelsoil case``: list the presets, show a case with every key, check a case file."""

from __future__ import annotations

from . import common


def add_parser(sub) -> None:
    """The ``case`` command on ``sub``."""
    p = sub.add_parser("case", help="list the preset cases, show a case with every key, or check a case file",
                       description="'wheelsoil case list' lists the presets; 'wheelsoil case show CASE' prints the "
                                   "resolved case with every key, its unit, range and default (a template to copy); "
                                   "'wheelsoil case check CASE' validates a case file and prints its hash.")
    p.add_argument("action", choices=["list", "show", "check"])
    p.add_argument("case", nargs="?", default=None, help="case file (.toml) or preset name")
    common.add_set_option(p)
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
    if args.action == "show":
        print(case_to_toml(case, template=True), end="")
    else:  # check
        print(f"{args.case}: valid; case {case.name}, hash {case.case_hash()}")
    return common.EXIT_OK
