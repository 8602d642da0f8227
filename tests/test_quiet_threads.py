"""vehicles.builder._quiet silences a solver call in its own thread only, and two overlapping
threads leave ``sys.stdout`` as they found it.

The defect this guards: with ``contextlib.redirect_stdout`` two threads whose quiet sections
overlapped (A in, B in, A out, B out) left ``sys.stdout`` as A's StringIO, so every later
line of the command vanished (``eroad invert --effects auto``'s closing lines, intermittently).
The interleaving is forced here with events, so the test does not depend on timing.
"""
from __future__ import annotations

import io
import sys
import threading

from vehicles.builder import _exu, _quiet


def test_overlapping_quiet_sections_restore_stdout_and_pass_other_threads_lines(monkeypatch):
    orig = io.StringIO()
    monkeypatch.setattr(sys, "stdout", orig)
    console = _exu().config.printToConsole
    a_in, b_in, a_out = threading.Event(), threading.Event(), threading.Event()

    def thread_a():
        with _quiet():
            print("from A, quiet")
            a_in.set()
            b_in.wait(5)
        a_out.set()

    t = threading.Thread(target=thread_a)
    t.start()
    a_in.wait(5)
    print("from main, not quiet")           # another thread's quiet section must not eat it
    with _quiet():                           # B in (while A is in)
        b_in.set()
        a_out.wait(5)                        # A out (while B is in)
        print("from B, quiet")
    t.join(5)                                # B out
    assert sys.stdout is orig
    assert orig.getvalue() == "from main, not quiet\n"
    assert _exu().config.printToConsole == console
    print("after")
    assert orig.getvalue().endswith("after\n")
