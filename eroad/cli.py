"""The ``eroad`` command line: one entry point, subcommands contributed by packages.

Each package that offers commands has a module ``<package>/cli.py`` with a
function ``register(subparsers)`` that adds its subcommands with
``subparsers.add_parser(...)`` and sets ``func=`` on each (a callable taking the
parsed ``argparse.Namespace`` and returning an exit code).  Adding a command is
adding it in its own package; this file only lists the packages.

Errors: :class:`eroad.errors.EroadInputError` becomes one line on stderr and exit
code 2; :class:`eroad.errors.SimulationError` one line and exit code 3.  With
``--json`` the error is instead one JSON object on stdout,
``{"error": {"kind": "input", "message": "...", "exit_code": 2}}``, so a caller
parsing stdout always gets JSON.  A closed stdout (``eroad ... | head``) ends the
command quietly.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
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
    "inverse.cli_replica",
    "studies.cli",
    "studies.cli_pantograph",
    "studies.cli_pantograph_contact",
    "studies.reproduce",
    "diagnosis.cli",
)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="eroad",
        description="Heavy vehicles on electrified roads: ISO 8608 roads, Exudyn truck "
        "models, inverse road modelling, pantograph-base excitation, gap diagnosis.",
    )
    parser.add_argument("--version", action="version", version=f"eroad {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:  # a package without commands yet
            if exc.name == name:
                continue
            raise
        module.register(sub)
    return parser


class _Parser(argparse.ArgumentParser):
    """An argparse parser whose usage errors are one JSON object on stdout when the
    command line asks for ``--json``."""

    def error(self, message: str):  # noqa: D401 - argparse API
        if "--json" in sys.argv[1:]:
            _json_error("usage", f"{self.prog}: {message}", 2)
            raise SystemExit(2)
        super().error(message)


def _json_error(kind: str, message: str, code: int) -> None:
    print(json.dumps({"error": {"kind": kind, "message": message, "exit_code": code}}),
          flush=True)


def _fail(args, kind: str, prefix: str, message: str, code: int) -> int:
    if getattr(args, "json", False):
        _json_error(kind, message, code)
    else:
        print(f"eroad: {prefix}: {message}", file=sys.stderr)
    return code


def _stdout_closed() -> int:
    """stdout's reader went away (``| head``): silence the rest and exit quietly.

    Python flushes stdout once more at exit; pointing it at /dev/null keeps that
    flush from raising a second BrokenPipeError (the recipe of the Python docs,
    "Note on SIGPIPE")."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # pragma: no cover - stdout without a file descriptor
        pass
    return 141   # 128 + SIGPIPE, what a shell reports for a command ended by a closed pipe


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except BrokenPipeError:
        return _stdout_closed()


def _main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0 if args.command is None else 2
    try:
        code = args.func(args)
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except EroadInputError as exc:
        return _fail(args, "input", "error", str(exc), 2)
    except SimulationError as exc:
        return _fail(args, "simulation", "simulation failed", str(exc), 3)
    except KeyboardInterrupt:
        return _fail(args, "interrupted", "interrupted", "interrupted", 130)
    return int(code or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
