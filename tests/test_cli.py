"""The command-line entry point: help works and bad input exits cleanly."""
import subprocess
import sys

from eroad.cli import main


def test_help_lists_commands(capsys):
    assert main([]) == 0
    out = capsys.readouterr().out
    assert "usage: eroad" in out


def test_unknown_command_exits_nonzero():
    proc = subprocess.run([sys.executable, "-m", "eroad.cli", "no-such-command"],
                          capture_output=True, text=True)
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr
