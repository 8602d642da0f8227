"""The closed loop's fit on `null` drives against the open-loop default, on the same 140 drives
(run from the repository root: python results/inverse_blind/20261128-axles-on-null-140/score.py).

`axles`: `eroad invert --effects auto` fits the channel set 'axles' where the diagnosis answers
'none' (diagnosis.closed_loop.loop_channels) and then reports the 'diagnosed' model-form term;
these records are that fit run directly (bench_inverse.py --channels axles), so their rows are
scored as 'diagnosed' with the 'linear/axles' constants. `axle3`: the default open-loop fit
(records of ../20261128-boundary-bands/displacement/), scored as its records say (open).
A second column set scores the 'axles' rows with a KAPPA re-set on seeds 1-100 (R_REF 0.521,
KAPPA 3.01 / 3.57 / 5.58, computed before the seeds 101-140 scores were printed), not adopted."""
import sys
from pathlib import Path
sys.path.insert(0, '.'); sys.path.insert(0, 'benchmarks')
import calibrate_uncertainty as CU                      # noqa: E402
from inverse import uncertainty as U                    # noqa: E402

HERE = Path(__file__).resolve().parent
BASE = HERE.parent / '20261128-boundary-bands' / 'displacement'
SETS = [('null 1-20', 'null'), ('null 21-60', 'null2'), ('null 61-100', 'null3'), ('null 101-140 (fresh)', 'null4')]
K100 = dict(U.CALIBRATIONS['linear/axles'], R_REF=0.521, KAPPA={'ln_Gq_n0': 3.01, 'w': 3.57, 'ln_G_n_best': 5.58})


def cov(c) -> str:
    return ' / '.join(f'{100 * c[q][0]:.0f}' for q in CU.QUANTITIES)


def line(name, rows, const, extra=None) -> str:
    c, a = CU.coverage(rows, const), CU.accuracy(rows)
    s = f"| {name} | {c['n']} | {100 * a['g1'][0]:.1f} % | {100 * a['class'][0]:.1f} % | {cov(c)} % |"
    return s + (f" {cov(CU.coverage(rows, extra))} % |" if extra else '')


def main() -> None:
    pool3, poolx = [], []
    print('| set | segments >= 3 s | G(1 cycle/m) within 20 % | class right | 90 % cover ln Gq(n0) / w / ln G(n_best) | same, KAPPA re-set on seeds 1-100 |')
    print('|---|---|---|---|---|---|')
    for name, d in SETS:
        r3 = CU.load(BASE / d)
        rx = CU.load(HERE / 'axles' / d)
        for r in rx:
            r['model_form'] = 'diagnosed'
        pool3 += r3; poolx += rx
        print(line(f'{name}, axle 3 (open loop, default)', r3, U.CALIBRATIONS['linear']) + ' - |')
        print(line(f'{name}, axles (loop closed, verdict none)', rx, U.CALIBRATIONS['linear/axles'], K100))
    print(line('pooled, axle 3', pool3, U.CALIBRATIONS['linear']) + ' - |')
    print(line('pooled, axles', poolx, U.CALIBRATIONS['linear/axles'], K100))


if __name__ == '__main__':
    main()
