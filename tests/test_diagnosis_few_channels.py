"""A drive logged on one axle only (the README's worked example: axle 3's six channels)
goes through the diagnosis and the closed loop: the front-to-rear comparison, which needs
axles 1 and 3, is reported as not made instead of stopping the run
("front_rear: no axle_acc pair of axles 1 and 3 in both records" before 2026-11-26)."""
from __future__ import annotations

import json
from pathlib import Path

from eroad.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_axle3_only_drive_is_diagnosed_and_says_what_it_could_not_compare(tmp_path, capsys):
    ds = tmp_path / "my-drive"
    assert main(["data", "import", str(ROOT / "examples" / "logger_drive.csv"), "--map",
                 str(ROOT / "examples" / "logger_map.toml"), "--out", str(ds)]) == 0
    out = tmp_path / "diag"
    assert main(["diagnose", str(ds), "--out", str(out), "--quick", "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["front_rear"] is None and s["verdict"]
    report = (out / "report.md").read_text()
    assert "**Front-to-rear delay**: not computed" in report
    capsys.readouterr()
