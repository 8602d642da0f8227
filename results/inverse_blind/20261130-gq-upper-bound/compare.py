"""Old bound (4.096e-3) against the new (32.768e-3) on the same null drives, segments >= 3 s:
python results/inverse_blind/20261130-gq-upper-bound/compare.py ROOT_OLD ROOT_NEW (repository root;
each ROOT holds bench_inverse.py's results.jsonl)."""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, '.'); sys.path.insert(0, 'benchmarks')
import calibrate_uncertainty as CU                      # noqa: E402
from inverse import uncertainty as U                    # noqa: E402

OLD_TOP = 4.096e-3


def summary(rows) -> str:
    c, a = CU.coverage(rows, U.CALIBRATIONS['linear']), CU.accuracy(rows)
    med = float(np.median([abs(r['lnGq_err']) for r in rows])) if rows else float('nan')
    cov = ' / '.join(f"{100 * c[q][0]:.0f}" for q in CU.QUANTITIES)
    return (f"{len(rows)} | {100 * a['g1'][0]:.1f} % | {100 * a['class'][0]:.1f} % | {med:.3f} | {cov} %")


def main() -> None:
    old, new = (CU.load(Path(p)) for p in sys.argv[1:3])
    key = lambda r: (r['seed'], round(r['t_start'], 3) if 't_start' in r else round(r['duration_s'], 3))  # noqa: E731
    ko, kn = {key(r): r for r in old}, {key(r): r for r in new}
    common = sorted(set(ko) & set(kn))
    print(f"segments >= 3 s: old {len(old)}, new {len(new)}, paired {len(common)}")
    print("| set | bound | segments | G(1) within 20 % | class right | median abs ln Gq(n0) err | 90 % cover ln Gq(n0) / w / ln G(n_best) |")
    print("|---|---|---|---|---|---|---|")
    for name, sel in (("all", lambda r: True), ("truth above 4.096e-3", lambda r: r['Gq_true'] > OLD_TOP),
                      ("truth at or below 4.096e-3", lambda r: r['Gq_true'] <= OLD_TOP)):
        ro = [ko[k] for k in common if sel(ko[k])]
        rn = [kn[k] for k in common if sel(kn[k])]
        print(f"| {name} | old | {summary(ro)} |")
        print(f"| {name} | new | {summary(rn)} |")
    pinned_old = sum(ko[k]['Gq_fit'] >= OLD_TOP * 0.999 for k in common)
    above_new = sum(kn[k]['Gq_fit'] > OLD_TOP * 1.001 for k in common)
    print(f"\nfits on the old bound (old): {pinned_old}; fits above it (new): {above_new}")
    g1 = lambda r: abs(r['lnG_1cpm_err']) <= math.log(1.2)  # noqa: E731
    gained = sum(g1(kn[k]) and not g1(ko[k]) for k in common)
    lost = sum(g1(ko[k]) and not g1(kn[k]) for k in common)
    changed = sum(abs(kn[k]['lnGq_err'] - ko[k]['lnGq_err']) > 1e-6 for k in common)
    print(f"G(1) within 20 %: gained {gained}, lost {lost}; segments whose ln Gq(n0) changed at all: {changed}")


if __name__ == '__main__':
    main()
