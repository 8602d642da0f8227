"""The command-line entry point: help lists every command, and bad input exits cleanly."""
import subprocess
import sys

import pytest

from eroad.cli import main

#: the commands the documentation promises (README and docs/*.md), in help order
#: (written out here rather than read from eroad.cli: build_parser skips a command
#: module that fails to import with ModuleNotFoundError, so a lost package would
#: silently drop its commands from the list)
DOCUMENTED_COMMANDS = ("road", "simulate", "effects", "vehicle", "modes", "data", "synth", "invert", "replica", "runs",
                       "study", "pantograph-contact", "reproduce", "diagnose")


def _listed_commands(help_text: str) -> list[str]:
    """Command names in the COMMAND block of argparse's help, in order."""
    lines = help_text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.strip() == "COMMAND") + 1
    names = []
    for ln in lines[start:]:
        if not ln.strip():
            break
        if ln.startswith("    ") and not ln.startswith("      "):   # name column, not a wrapped help
            names.append(ln.split()[0])
    return names


def test_help_lists_commands(capsys):
    """``eroad`` without a command prints the help (exit 0) listing every documented
    command, in order, each with a one-line description, and nothing else."""
    assert main([]) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: eroad")
    assert _listed_commands(out) == list(DOCUMENTED_COMMANDS)


@pytest.mark.parametrize("command", DOCUMENTED_COMMANDS)
def test_each_listed_command_has_working_help(command, capsys):
    """``eroad COMMAND --help`` works for every listed command: argparse exits 0 after
    printing a usage line that names the command."""
    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: eroad {command}")


def test_unknown_command_exits_nonzero():
    """An unknown command: argparse's exit code 2 and its one-line reason, no traceback."""
    proc = subprocess.run([sys.executable, "-m", "eroad.cli", "no-such-command"],
                          capture_output=True, text=True)
    assert proc.returncode == 2
    assert "invalid choice: 'no-such-command'" in proc.stderr
    assert "Traceback" not in proc.stderr
