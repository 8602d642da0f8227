"""Shared error type for bad user input.

Every package raises :class:`EroadInputError` (or a subclass) for input a user
can fix: a bad parameter, a malformed file, a missing channel.  The command line
catches it and prints one line, ``eroad: error: <message>``, exits with code 2
and never shows a traceback.  Messages name what is wrong and where (file,
column, row, parameter).
"""


class EroadInputError(Exception):
    """A problem with user input; the message is a single line for the user."""


class SimulationError(RuntimeError):
    """A simulation failed (diverged, solver did not converge); the message names
    the simulated time and the likely cause."""
