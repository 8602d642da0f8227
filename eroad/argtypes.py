"""argparse value types shared by the command modules (one clear line on bad values)."""
from __future__ import annotations

import argparse
import math

__all__ = ["positive_float", "nonnegative_int"]


def positive_float(text: str) -> float:
    """A finite number > 0, else argparse's one-line error."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"{text!r} must be positive")
    return v


def nonnegative_int(text: str) -> int:
    """A whole number >= 0, else argparse's one-line error."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be >= 0")
    return v
