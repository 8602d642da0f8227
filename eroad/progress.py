"""Progress bars for long commands (``eroad invert``, ``eroad diagnose``).

What this module is for: one place that decides whether a bar is shown (stderr
is a terminal, no ``--json``, no ``--quiet``) and makes it (tqdm, on stderr).
A hidden bar is still a working object, so the code that advances it needs no
``if``.  What it is not: a log; results and messages a user must see are printed
by the commands.
"""
from __future__ import annotations

import contextlib
import re
import sys
from typing import Iterator

__all__ = ["wants_progress", "progress_bar", "MessageCounter"]


def wants_progress(args=None, stream=None) -> bool:
    """Whether to show a bar: ``stream`` (default stderr) is a terminal and the
    command line has neither ``--json`` nor ``--quiet``."""
    stream = sys.stderr if stream is None else stream
    if args is not None and (getattr(args, "json", False) or getattr(args, "quiet", False)):
        return False
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


@contextlib.contextmanager
def progress_bar(show: bool, desc: str = "", total: int | None = None) -> Iterator:
    """A tqdm bar on stderr, hidden (``disable=True``) unless ``show``.

    Parameters
    ----------
    show : bool
        Draw the bar (see :func:`wants_progress`).
    desc : str
        Text before the bar.
    total : int, optional
        Units of work (may be changed later with ``bar.reset(total=...)``).

    Yields
    ------
    tqdm.tqdm
        The bar: ``update(n)``, ``reset(total=...)``, ``set_description(text)``,
        ``write(line)`` (a line above the bar).
    """
    from tqdm.auto import tqdm

    bar = tqdm(total=total, desc=desc, file=sys.stderr, disable=not show, leave=False,
               dynamic_ncols=True, unit="step")
    try:
        yield bar
    finally:
        bar.close()


class MessageCounter:
    """Turn a command's one-line progress messages into bar steps.

    Parameters
    ----------
    bar : tqdm.tqdm
        The bar to advance.
    total_pattern : str
        Regular expression whose first group is a number of steps announced by a
        message (added to the bar's total).
    step_pattern : str
        Regular expression of a message that finishes one step.
    echo : bool
        Also print every message above the bar.
    """

    def __init__(self, bar, total_pattern: str, step_pattern: str, echo: bool = False) -> None:
        self.bar = bar
        self._total = re.compile(total_pattern)
        self._step = re.compile(step_pattern)
        self.echo = echo

    def __call__(self, message: str) -> None:
        m = self._total.search(message)
        if m:
            self.bar.total = (self.bar.total or 0) + int(m.group(1))
            self.bar.refresh()
        if self._step.search(message):
            self.bar.update(1)
        else:
            self.bar.set_description(message.strip()[:40])
        if self.echo:
            self.bar.write(message)
