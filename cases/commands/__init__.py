"""The ``wheelsoil`` commands, one module each: ``add_parser(sub)`` declares a command's options on the argparse
subparsers ``sub`` and sets its ``func``, a function of the parsed arguments returning the exit code
(:mod:`.common` holds the exit codes and the options and checks the commands share). :mod:`wheelsoil.cases.cli`
builds the parser from :data:`COMMANDS` and maps errors to exit codes."""

#: The command modules, in the order ``wheelsoil --help`` lists them.
COMMANDS = ("run", "case", "batch", "replicate", "convergence", "carry", "prepare_bed", "render", "bench", "wheel",
            "validate", "soil_lab")
