"""The ``eroad`` command line: one entry point, subcommands contributed by packages.

Each package that offers commands has a module ``<package>/cli.py`` with a
function ``register(subparsers)`` that adds its subcommands with
``subparsers.add_parser(...)`` and sets ``func=`` on each (a callable taking the
parsed ``argparse.Namespace`` and returning an exit code).  Adding a command is
adding it in its own package; this file only lists the packages.

Errors: :class:`eroad.errors.EroadInputError` becomes one line on stderr and exit
code 2; :class:`eroad.errors.SimulationError` one line and exit code 3.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from eroad import __version__
from eroad.errors import EroadInputError, SimulationError

#: packages whose ``cli`` module contributes subcommands, in help order
COMMAND_MODULES = (
    "roadlib.cli",
    "vehicles.cli",
    "vehicles.cli_modes",
    "drives.cli",
    "inverse.cli",
    "studies.cli",
    "studies.cli_pantograph",
    "studies.reproduce",
    "diagnosis.cli",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="eroad",
        description="Heavy vehicles on electrified roads: ISO 8608 roads, Exudyn truck "
        "models, inverse road modelling, pantograph-base excitation, gap diagnosis.",
    )
    parser.add_argument("--version", action="version", version=f"eroad {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a package without commands yet
            if exc.name == name:
                continue
            raise
        module.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0 if args.command is None else 2
    try:
        code = args.func(args)
    except EroadInputError as exc:
        print(f"eroad: error: {exc}", file=sys.stderr)
        return 2
    except SimulationError as exc:
        print(f"eroad: simulation failed: {exc}", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print("eroad: interrupted", file=sys.stderr)
        return 130
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
