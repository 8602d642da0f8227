"""Paired re-decision of saved blind drives: each summary decided by two verdict rules.

A verdict rule that needs no new record (a threshold, a test on statistics every summary already
carries) is judged on the SAME drives with and without it: no simulation noise between the two
columns, only the rule.  Used by the stated tests under results/diagnosis_blind/ (their
``compare.py``): set on the saved sets (development), then on fresh drives.

What it is not: the verdict (:mod:`diagnosis.verdict`), the blind benchmark (:mod:`diagnosis.blind`).
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Iterable, Mapping


def summary_of(folder: Path, case: int) -> dict | None:
    """A blind case's summary: ``caseNNN-summary.json`` (a committed set) or
    ``caseNNN-run/summary.json`` (a bench work folder); None when neither exists."""
    for p in (folder / f"case{case:03d}-summary.json", folder / f"case{case:03d}-run" / "summary.json"):
        if p.is_file():
            return json.loads(p.read_text())
    return None


def right(decision: Mapping, truth: str) -> bool:
    """A library effect named as itself; no library effect answered ``none`` or ``unexplained``."""
    v = decision["verdict"]
    return v == truth if truth != "none" else v in ("none", "unexplained")


def wrong_name(decision: Mapping, truth: str) -> bool:
    v = decision["verdict"]
    return v not in ("none", "unexplained") and v != truth


def _blank() -> dict:
    return {"focus": [0, 0, 0], "effect": [0, 0, 0], "null": [0, 0, 0], "wrong": [0, 0],
            "clear_wrong": [0, 0], "right_to_wrong": 0, "changed": 0, "drives": 0}


def _line(name: str, c: Mapping, focus: str) -> str:
    return (f"{name}: drives {c['drives']}; library effects right {c['effect'][0]} -> {c['effect'][1]} "
            f"of {c['effect'][2]} ({focus} {c['focus'][0]} -> {c['focus'][1]} of {c['focus'][2]}); "
            f"no effect none/unexplained {c['null'][0]} -> {c['null'][1]} of {c['null'][2]}; wrong "
            f"names {c['wrong'][0]} -> {c['wrong'][1]} (clear {c['clear_wrong'][0]} -> "
            f"{c['clear_wrong'][1]}); right -> wrong {c['right_to_wrong']}; changed {c['changed']}")


def paired(folders: Iterable, old: Callable[[dict], dict], new: Callable[[dict], dict],
           focus: str, out=print) -> dict:
    """Decide every saved case of ``folders`` (each with ``blind.json``) with ``old`` and ``new``
    (summary -> decision); print each drive whose verdict or confidence changed, a line per folder
    and one for all (``focus``: the effect whose count is shown apart).  Returns the totals:
    ``[old, new, cases]`` for ``effect``, ``null`` and ``focus``, ``[old, new]`` for ``wrong`` and
    ``clear_wrong``, and the counts ``right_to_wrong``, ``changed``, ``drives``."""
    total = _blank()
    for d in map(Path, folders):
        c = _blank()
        for r in json.loads((d / "blind.json").read_text())["results"]:
            s = summary_of(d, r["case"])
            if s is None:
                continue
            truth = r["effect"]
            a, b = old(s), new(s)
            c["drives"] += 1
            key = "null" if truth == "none" else "effect"
            for i, dd in enumerate((a, b)):
                c[key][i] += right(dd, truth)
                c["focus"][i] += truth == focus and right(dd, truth)
                c["wrong"][i] += wrong_name(dd, truth)
                c["clear_wrong"][i] += wrong_name(dd, truth) and dd["confidence"] == "clear"
            c[key][2] += 1
            c["focus"][2] += truth == focus
            c["right_to_wrong"] += right(a, truth) and not right(b, truth)
            if (a["verdict"], a["confidence"]) != (b["verdict"], b["confidence"]):
                c["changed"] += 1
                out(f"  {d} case {r['case']} truth {truth} {r.get('value')}: {a['verdict']} "
                    f"({a['confidence']}) -> {b['verdict']} ({b['confidence']})")
        out(_line(str(d), c, focus))
        for k, v in c.items():
            total[k] = [x + y for x, y in zip(total[k], v)] if isinstance(v, list) else total[k] + v
    out(_line("ALL", total, focus))
    return total
