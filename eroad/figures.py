"""Saving a matplotlib figure: one drawing, every file asked for, then closed."""
from __future__ import annotations

from pathlib import Path

__all__ = ["save_figure"]


def save_figure(fig, path, dpi: int = 150) -> list[Path]:
    """Save ``fig`` to ``path`` (a path, or a list of paths: one file per format, e.g. PNG
    and PDF of the same drawing), creating the folder, and close it.

    Returns
    -------
    list of Path
        The files written, in the order given.
    """
    import matplotlib.pyplot as plt

    paths = [Path(p) for p in path] if isinstance(path, (list, tuple)) else [Path(path)]
    for p in paths:
        p.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(p, dpi=dpi)
    plt.close(fig)
    return paths
