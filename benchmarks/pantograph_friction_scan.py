"""Contact-force quality against the pantograph's frame friction (issue 18, item 1).

The built-in truck pantograph has no sourced friction value, so it ships with none
(``frame_friction = 0``).  This scan drives the e-tractor over each given road once per
friction value (``studies.pantograph_contact.contact_drive``: the same drive, the base
moved by the DCDC top, and the base at rest) and reports the contact-force statistics,
how much of the drive the frame spends stuck to the base, and how much the base motion
adds to the force's sd.  It measures; it does not choose a shipped value.

Run:  nice python benchmarks/pantograph_friction_scan.py --road FILE [--road FILE ...]
          --out DIR [--friction-n 0 5 10 20 40] [--speed-kmh 80]
Writes DIR/scan.json, DIR/table.md, DIR/friction_scan.png and DIR/run.json.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def one(road, friction: float, speed_kmh: float) -> dict:
    """One drive at one friction value: statistics with the base moved and at rest, and
    the share of the drive's samples in which the frame sticks to the base."""
    import numpy as np

    from studies.pantograph_contact import contact_drive

    w0 = time.perf_counter()
    out = contact_drive(road, speed_kmh=speed_kmh, frame_friction=friction)
    res, rest = out["result"], out["static"]
    def stuck(r) -> float:
        """Share of the samples after the first second with the frame below its slip force."""
        if friction <= 0:
            return float("nan")
        return float(np.mean(np.abs(r["friction"][r.time >= 1.0]) < friction * (1 - 1e-9)))

    return {"friction_N": friction, "drive": out["stats"], "base_at_rest": out["stats_static"],
            "stuck_share": stuck(res), "stuck_share_at_rest": stuck(rest),
            "duration_s": out["config"]["duration_s"], "base_z_rms_mm": 1e3 * out["config"]["base_z_rms_m"],
            "wall_s": time.perf_counter() - w0}


def table(rows: dict) -> str:
    head = ("| road | friction [N] | sd drive [N] | sd base at rest [N] | sd added by the base "
            "[N] | min / max drive, 20 Hz low-pass [N] | loss drive [%] | frame stuck, drive / at rest [%] |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for name, rs in rows.items():
        for r in rs:
            d, s = r["drive"], r["base_at_rest"]
            added = max(d["sd"] ** 2 - s["sd"] ** 2, 0.0) ** 0.5
            st = ("-" if r["friction_N"] == 0 else
                  f"{100 * r['stuck_share']:.0f} / {100 * r['stuck_share_at_rest']:.0f}")
            lines.append(f"| {name} | {r['friction_N']:g} | {d['sd']:.2f} | {s['sd']:.2f} | "
                         f"{added:.2f} | {d['actual_min']:.1f} / {d['actual_max']:.1f} | "
                         f"{d['loss_percent']:.2f} | {st} |")
    return "\n".join(lines) + "\n"


def plot(rows: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(1, 3, figsize=(14, 4.4), constrained_layout=True)
    for (name, rs), col in zip(rows.items(), ("tab:blue", "tab:red", "tab:green", "tab:purple")):
        f = [r["friction_N"] for r in rs]
        axs[0].plot(f, [r["drive"]["sd"] for r in rs], "o-", color=col, label=f"{name}: base moved")
        axs[0].plot(f, [r["base_at_rest"]["sd"] for r in rs], "s--", color=col, alpha=0.7,
                    label=f"{name}: base at rest")
        axs[1].plot(f, [r["drive"]["loss_percent"] for r in rs], "o-", color=col, label=name)
        axs[2].plot(f[1:], [100 * r["stuck_share"] for r in rs[1:]], "o-", color=col, label=name)
    axs[0].set_ylabel("contact force sd [N] (20 Hz low-pass)")
    axs[1].set_ylabel("contact loss in the drive, base moved [%]")
    axs[2].set_ylabel("samples with the frame stuck to the base [%]")
    axs[2].set_ylim(0, 100)
    for ax in axs:
        ax.set_xlabel("frame friction [N]")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    axs[1].legend(fontsize=8)
    axs[2].legend(fontsize=8)
    fig.suptitle("Truck pantograph (assumed values) on the e-tractor, contact line truck_ohl: "
                 "what frame friction changes")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--road", action="append", required=True, metavar="FILE",
                    help="road file (.npz or .crg); NAME=FILE names it in the table")
    ap.add_argument("--out", required=True, help="folder to write (new or empty)")
    ap.add_argument("--friction-n", type=float, nargs="+", default=[0, 5, 10, 20, 40])
    ap.add_argument("--speed-kmh", type=float, default=80.0)
    a = ap.parse_args(argv)
    out = Path(a.out)
    if out.exists() and any(out.iterdir()):
        print(f"pantograph_friction_scan: {out} is not empty; give a new folder", file=sys.stderr)
        return 2
    from eroad.archive import finish_run_info, run_info, write_run_json
    from roadlib.surface import RoadSurface

    out.mkdir(parents=True, exist_ok=True)
    info = run_info("pantograph_contact", run_id=out.name, command=sys.argv)
    w0 = time.perf_counter()
    rows: dict = {}
    for spec in a.road:
        name, _, file = spec.rpartition("=")
        name = name or Path(file).stem
        road = RoadSurface.load(file)
        rows[name] = []
        for fr in a.friction_n:
            r = one(road, fr, a.speed_kmh)
            rows[name].append(r)
            print(f"{name} friction {fr:g} N: sd {r['drive']['sd']:.2f} N (base at rest "
                  f"{r['base_at_rest']['sd']:.2f}), min {r['drive']['actual_min']:.1f} N, loss "
                  f"{r['drive']['loss_percent']:.2f} %, stuck {100 * r['stuck_share']:.0f} %, "
                  f"{r['wall_s']:.0f} s", flush=True)
    (out / "scan.json").write_text(json.dumps({"speed_kmh": a.speed_kmh, "roads": a.road,
                                               "rows": rows}, indent=1))
    (out / "table.md").write_text(table(rows))
    plot(rows, out / "friction_scan.png")
    write_run_json(out, finish_run_info(info, wall_s=time.perf_counter() - w0))
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
