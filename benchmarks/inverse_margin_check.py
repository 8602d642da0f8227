"""Does a wider transient margin lower the inversion's G(1 cycle/m) scatter on `null` drives?

Development check (2026-11-27; docs/inverse.md, "Left"): the drives of
``bench_inverse.py --scenario null --cases 20 --data-root DATA`` inverted in-process with the
features' transient margin (``inverse.features.FeatureSpec.margin_s`` / ``margin_frac``) set
from the command line, scored as ``bench_inverse.score_run`` does, with the G(1) error against
the truth and against the true road under the fit's own window.  Run it at the defaults
(0.75 0.2) as the reference in the same session.

    python benchmarks/inverse_margin_check.py 0.75 0.2 --data-root /tmp/bench/data-null
    python benchmarks/inverse_margin_check.py 1.5 0.3 --data-root /tmp/bench/data-null
"""
from __future__ import annotations

import argparse
import functools
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("margin_s", type=float)
    ap.add_argument("margin_frac", type=float)
    ap.add_argument("--data-root", required=True, help="bench_inverse's null datasets (null-S and blind-null-S)")
    ap.add_argument("--cases", type=int, default=20)
    ap.add_argument("--out", default="/tmp/eroad-margin-check")
    a = ap.parse_args(argv)

    import inverse.pipeline as P
    from inverse.features import FeatureSpec

    # the pipeline builds its FeatureSpec with the defaults; give it the margins asked for
    P.FeatureSpec = functools.partial(FeatureSpec, margin_s=a.margin_s, margin_frac=a.margin_frac)
    import bench_inverse as B
    from inverse.cli import run_inversion

    root = Path(a.data_root)
    rows = []
    for s in range(1, a.cases + 1):
        out = Path(a.out) / f"{a.margin_s:g}-{a.margin_frac:g}" / f"run-{s}"
        summ = run_inversion(root / f"blind-null-{s}", out, workers=1, seed=0, force=True)
        case = B.score_run(root / f"null-{s}", "null", summ)
        for r in case["segments"]:
            ow = r.get("oracle_fit_window")
            if r["duration_s"] < 3 or not ow:
                continue
            lo = math.log(ow["Gq"] * 10 ** -ow["w"] / (r["Gq_true"] * 10 ** -r["w_true"]))
            rows.append((r["lnG_1cpm_err"], r["lnG_1cpm_err"] - lo))
    e = np.array([x[0] for x in rows])
    d = np.array([x[1] for x in rows])
    print(f"margin {a.margin_s:g} s / {a.margin_frac:g}: {e.size} segments >= 3 s, G(1) within 20 % "
          f"{np.mean(np.abs(e) < math.log(1.2)):.3f}, signed sd {e.std(ddof=1):.3f}, "
          f"fit about the road under its window sd {d.std():.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
