"""Read a parameter TOML named by a built-in id or given as a file (one clear line on failure)."""
from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Callable, Iterable

from eroad.errors import EroadInputError

__all__ = ["read_builtin_or_file"]


def read_builtin_or_file(name_or_path, data_dir: Path, prefix: str, kind: str,
                         builtin_ids: Callable[[], Iterable[str]]) -> tuple[Path, dict]:
    """``name_or_path`` without a suffix is the built-in ``data_dir/<prefix><name>.toml``;
    with one, a file.  Returns the path and the parsed TOML; unknown ids, missing files
    and invalid TOML raise :class:`EroadInputError` naming ``kind``."""
    p = Path(name_or_path)
    if not p.suffix:
        p = Path(data_dir) / f"{prefix}{name_or_path}.toml"
        if not p.is_file():
            raise EroadInputError(f"unknown {kind} '{name_or_path}' (built-in: "
                                  f"{', '.join(builtin_ids())})")
    if not p.is_file():
        raise EroadInputError(f"{kind} file not found: {p}")
    try:
        return p, tomllib.loads(p.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise EroadInputError(f"{p}: not valid TOML ({exc})") from None
