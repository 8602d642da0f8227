"""Sensitivity of the railway reference case to the contact wire's pre-sag (issue 18).

The EN 50318:2002 reference-model ranges (``studies.pantograph_contact.REFERENCE_RANGES``) are
missed by the reference line as shipped (``catenary/data/line_en50318.toml``, pre-sag 55 mm from
a secondary source that calls it a "standard preview" value).  Whether the standard's
reference catenary has pre-sag at all could not be checked (docs/pantograph_contact.md).  This
scan runs the reference case (both speeds, the shipped pantograph, everything else as shipped)
at a list of pre-sags and counts the statistics inside their published ranges.  It measures;
it does not choose the shipped value.

Run:  nice python benchmarks/catenary_presag_scan.py --out DIR [--presag-mm 0 10 20 ...]
Writes DIR/scan.json (every statistic per pre-sag and speed), DIR/table.md and
DIR/presag_scan.png (each statistic against the pre-sag, the published range shaded).
"""
from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

#: the statistics plotted, their unit scale and label (max_support_uplift is in m)
PANELS = (("mean", 1.0, "mean [N]"), ("sd", 1.0, "sd [N]"),
          ("stat_max", 1.0, "mean + 3 sd [N]"), ("stat_min", 1.0, "mean - 3 sd [N]"),
          ("actual_max", 1.0, "actual max [N]"), ("actual_min", 1.0, "actual min [N]"),
          ("max_support_uplift", 1000.0, "max uplift at support [mm]"))


def scan(presags_m, line: str = "en50318") -> list:
    """One railway-reference run per pre-sag [m]: ``[{presag_m, cases: {speed: {...}}}]``."""
    from catenary.line import load_line
    from studies.pantograph_contact import railway_reference

    base = load_line(line)
    out = []
    for ps in presags_m:
        r = railway_reference(line=replace(base, presag=float(ps)))
        out.append({"presag_m": float(ps), "cases": r["cases"]})
        inside = sum(sum(c["inside"].values()) for c in r["cases"].values())
        total = sum(len(c["inside"]) for c in r["cases"].values())
        print(f"pre-sag {1000 * ps:5.1f} mm: {inside}/{total} statistics inside the published ranges; "
              + "; ".join(f"{k} km/h sd {c['stats']['sd']:.1f} N, uplift {1000 * c['stats']['max_support_uplift']:.1f} mm"
                          for k, c in r["cases"].items()), flush=True)
    return out


def table(rows: list) -> str:
    speeds = list(rows[0]["cases"])
    head = "| pre-sag [mm] | " + " | ".join(f"{q} {s}" for s in speeds for q in ("sd [N]", "act. min [N]", "uplift [mm]")) \
        + " | inside |"
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        cells = []
        n_in = n = 0
        for s in speeds:
            c = r["cases"][s]
            for q, f in (("sd", 1.0), ("actual_min", 1.0), ("max_support_uplift", 1000.0)):
                mark = "" if c["inside"].get(q, True) else " (out)"
                cells.append(f"{f * c['stats'][q]:.1f}{mark}")
            n_in += sum(c["inside"].values())
            n += len(c["inside"])
        lines.append(f"| {1000 * r['presag_m']:.1f} | " + " | ".join(cells) + f" | {n_in}/{n} |")
    return "\n".join(lines) + "\n"


def plot(rows: list, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    x = np.array([1000 * r["presag_m"] for r in rows])
    speeds = list(rows[0]["cases"])
    fig, axs = plt.subplots(2, 4, figsize=(15, 7), constrained_layout=True)
    colours = ("tab:blue", "tab:red")
    for ax, (q, f, label) in zip(axs.flat, PANELS):
        for s, col in zip(speeds, colours):
            y = [f * r["cases"][s]["stats"][q] for r in rows]
            ax.plot(x, y, "o-", color=col, label=f"{s} km/h")
            rng = rows[0]["cases"][s]["ranges"].get(q)
            if rng:
                ax.axhspan(f * rng[0], f * rng[1], color=col, alpha=0.15)
        ax.set_xlabel("contact wire pre-sag [mm]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axs.flat[0].legend(title="line: speed (band: EN 50318 range)")
    ax = axs.flat[-1]
    for s, col in zip(speeds, colours):
        ax.plot(x, [sum(r["cases"][s]["inside"].values()) for r in rows], "o-", color=col, label=f"{s} km/h")
    ax.set_xlabel("contact wire pre-sag [mm]")
    ax.set_ylabel("statistics inside the range (of 8)")
    ax.set_ylim(0, 8.5)
    ax.grid(alpha=0.3)
    ax.legend()
    fig.suptitle("Railway reference case (EN 50318-type line, secondary-source parameters): "
                 "contact-force statistics against the contact wire's pre-sag")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder to write (new or empty)")
    ap.add_argument("--presag-mm", type=float, nargs="+", default=[0, 10, 20, 27.5, 35, 45, 55])
    ap.add_argument("--line", default="en50318")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if out.exists() and any(out.iterdir()):
        print(f"catenary_presag_scan: {out} is not empty; give a new folder", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    rows = scan([p / 1000.0 for p in a.presag_mm], a.line)
    (out / "scan.json").write_text(json.dumps({"line": a.line, "rows": rows}, indent=1))
    (out / "table.md").write_text(table(rows))
    plot(rows, out / "presag_scan.png")
    print(table(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
