"""``eroad runs list|show``: the run archive (:mod:`eroad.archive`) on the command line.

``eroad runs list [ROOT | --root results] [--study NAME] [--json]`` prints a table of
every run folder under the root (study, run-id, status, start, wall time);
``eroad runs show RUN [--root results] [--json]`` prints the essentials of one
run's ``run.json`` and ``summary.json``.  RUN is a run folder, a run-id or a
unique run-id prefix.  See ``docs/studies.md``.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from eroad.archive import NOT_RECORDED, RunRecord, find_run, list_runs
from eroad.errors import EroadInputError

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``eroad runs`` with its actions ``list`` and ``show``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The top-level ``eroad`` subparsers.
    """
    runs = subparsers.add_parser(
        "runs", help="list and inspect archived study runs",
        description="List and inspect archived runs under <root>/<study>/<run-id>/.")
    runs.set_defaults(func=lambda args: _usage(runs))
    actions = runs.add_subparsers(dest="runs_action", metavar="ACTION")

    p_list = actions.add_parser("list", help="table of archived runs",
                                description="Table of archived runs, oldest first.")
    p_list.add_argument("root_pos", nargs="?", metavar="ROOT", default=None,
                        help="results root folder (same as --root)")
    p_list.add_argument("--root", default=None,
                        help="results root folder (default: results)")
    p_list.add_argument("--study", default=None, help="only runs of this study")
    p_list.add_argument("--json", action="store_true",
                        help="print the list as JSON instead of a table")
    p_list.set_defaults(func=_cmd_list)

    p_show = actions.add_parser("show", help="details of one run",
                                description="Essentials of run.json and summary.json of one "
                                "run.")
    p_show.add_argument("run", metavar="RUN",
                        help="run folder, run-id or unique run-id prefix")
    p_show.add_argument("--root", default="results",
                        help="results root searched for run-ids (default: results)")
    p_show.add_argument("--json", action="store_true",
                        help="print {path, run, summary} as JSON")
    p_show.set_defaults(func=_cmd_show)


def _usage(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


def _fmt_wall(wall: float | None) -> str:
    if wall is None:
        return "-"
    if wall < 10:
        return f"{wall:.2f} s"
    if wall < 600:
        return f"{wall:.1f} s"
    return f"{wall / 60:.1f} min"


def _row(rec: RunRecord) -> dict[str, Any]:
    return {"study": rec.study, "run_id": rec.run_id, "status": rec.status,
            "start_utc": rec.start or None, "wall_s": rec.wall_s, "path": str(rec.path)}


def _cmd_list(args: argparse.Namespace) -> int:
    if args.root_pos is not None and args.root is not None and args.root_pos != args.root:
        raise EroadInputError(f"two results roots given: {args.root_pos} and --root {args.root}")
    args.root = args.root_pos or args.root or "results"
    records = list_runs(args.root, study=args.study)
    if args.json:
        print(json.dumps([_row(r) for r in records], indent=2))
        return 0
    if not records:
        missing = "" if Path(args.root).is_dir() else " (no such folder)"
        print(f"no runs under {args.root}{missing}")
        return 0
    header = ("STUDY", "RUN-ID", "STATUS", "START (UTC)", "WALL")
    rows = [(r.study, r.run_id, r.status, r.start[:19].replace("T", " ") or "-",
             _fmt_wall(r.wall_s)) for r in records]
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(header)]
    for row in (header, *rows):
        print("  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip())
    return 0


def _scalar_items(d: dict, prefix: str = "") -> list[tuple[str, str]]:
    """Flatten scalars of a (nested) dict into ``(dotted.key, text)``; long
    lists and deeper structures are summarised by their size."""
    items: list[tuple[str, str]] = []
    for key, val in d.items():
        name = f"{prefix}{key}"
        if isinstance(val, dict):
            if prefix.count(".") >= 1:
                items.append((name, f"{{{len(val)} entries}}"))
            else:
                items.extend(_scalar_items(val, name + "."))
        elif isinstance(val, list):
            if len(val) <= 6 and all(not isinstance(v, (dict, list)) for v in val):
                items.append((name, json.dumps(val)))
            else:
                items.append((name, f"[{len(val)} items]"))
        else:
            items.append((name, "null" if val is None else str(val)))
    return items


def _text(value: Any, none: str = NOT_RECORDED) -> str:
    return none if value is None or value == "" else str(value)


def _cmd_show(args: argparse.Namespace) -> int:
    rec = find_run(args.run, root=args.root)
    if args.json:
        print(json.dumps({"path": str(rec.path), "run": rec.info, "summary": rec.summary},
                         indent=2))
        return 0
    info = rec.info
    git = info.get("git") or {}
    commit = _text(git.get("commit"))
    dirty = git.get("dirty")
    if dirty is True:
        commit += " (dirty)"
    elif dirty is None or isinstance(dirty, str):
        commit += f" (dirty: {_text(dirty)})"
    versions = info.get("versions") or {}
    host = info.get("host") or {}
    seed = info.get("seed")
    lines = [
        ("run", f"{rec.study}/{rec.run_id}"),
        ("path", str(rec.path)),
        ("status", rec.status),
        ("command", _text(info.get("command"))),
        ("overrides", _text(info.get("overrides") and json.dumps(info["overrides"]), "none")),
        ("seed", _text(seed, "none (the run draws nothing random)")),
        ("git", commit),
        ("host", _text(host.get("hostname"))),
        ("versions", ", ".join(f"{k} {v}" for k, v in versions.items() if v) or NOT_RECORDED),
        ("start", _text(info.get("start_utc"))),
        ("end", _text(info.get("end_utc"), "-" if rec.status == "running" else NOT_RECORDED)),
        ("wall", _fmt_wall(rec.wall_s) if rec.wall_s is not None else NOT_RECORDED),
    ]
    err = info.get("error")
    if err:
        lines.append(("error", f"{err.get('type', '')}: {err.get('message', '')}".strip(": ")))
    for key, val in (info.get("extra") or {}).items():
        if not isinstance(val, (dict, list)) and val is not None:
            lines.append((key, str(val)))
    width = max(len(k) for k, _ in lines)
    for key, val in lines:
        print(f"{key.ljust(width)}  {val}")
    print()
    if rec.summary is None:
        print("summary: (no summary.json)")
    else:
        print("summary:")
        items = _scalar_items(rec.summary)
        width = max((len(k) for k, _ in items), default=0)
        for key, val in items:
            print(f"  {key.ljust(width)}  {val}")
    return 0
