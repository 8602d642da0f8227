"""argparse value types shared by the command modules (one clear line on bad values)."""
from __future__ import annotations

import argparse
import math

__all__ = ["finite_float", "positive_float", "nonnegative_float", "nonnegative_int"]


def finite_float(text: str) -> float:
    """A finite number, else argparse's one-line error."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return v


def positive_float(text: str) -> float:
    """A finite number > 0, else argparse's one-line error."""
    v = finite_float(text)
    if not v > 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be positive")
    return v


def nonnegative_float(text: str) -> float:
    """A finite number >= 0, else argparse's one-line error."""
    v = finite_float(text)
    if v < 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be >= 0")
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
