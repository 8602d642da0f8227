"""Score the e-tractor's null inversions (bench_inverse.py --vehicle e_tractor records) as the
dump truck's null sets are scored: G(1 cycle/m) within 20 %, class right, and the 90 % intervals
(the shipped 'linear' constants, those the runs reported with: the open-loop axle-3 fit) --
run from the repository root: python results/inverse_blind/20261130-e-tractor/score.py ROOT"""
import sys
from pathlib import Path
sys.path.insert(0, '.'); sys.path.insert(0, 'benchmarks')
import calibrate_uncertainty as CU                      # noqa: E402
from inverse import uncertainty as U                    # noqa: E402


def main() -> None:
    rows = CU.load(Path(sys.argv[1]))
    c, a = CU.coverage(rows, U.CALIBRATIONS['linear']), CU.accuracy(rows)
    print('| set | segments >= 3 s | G(1 cycle/m) within 20 % | class right | 90 % cover ln Gq(n0) / w / ln G(n_best) |')
    print('|---|---|---|---|---|')
    cov = ' / '.join(f'{100 * c[q][0]:.0f}' for q in CU.QUANTITIES)
    print(f"| e-tractor null 201-220, axle 3 (open loop, default) | {c['n']} | {100 * a['g1'][0]:.1f} % "
          f"| {100 * a['class'][0]:.1f} % | {cov} % |")


if __name__ == '__main__':
    main()
