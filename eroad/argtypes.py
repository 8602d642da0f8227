"""argparse value types shared by the command modules (one clear line on bad values)."""
from __future__ import annotations

import argparse
import math

__all__ = ["positive_float"]


def positive_float(text: str) -> float:
    """A finite number > 0, else argparse's one-line error."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    return v
