"""BETA_DIAGNOSED (the model-form term of drives the diagnosis checked and the loop corrected with a
singled-out name, or found none) re-chosen on every saved closed loop pooled, and each set scored out
of sample (python results/inverse_blind/20261128-beta-diagnosed-pooled/pool.py [NAME=ROOT ...], from
the repository root; extra NAME=ROOT closed-loop sets are scored with the chosen values, not used to
choose them).

Sets: the friction drives (our truck with leaf friction and a flexible frame) seeds 1-20, 21-40,
41-60, and the independent truck seeds 1-20, 41-52, 53-72, each in the loop of its stop (records of
../20261128-correct-on-ambiguous and ../20261128-closest-vehicle-effect). 'Diagnosed' rows as
diagnosis.closed_loop.model_form decides; for the two oldest friction sets, whose records predate the
'ambiguous -> open' rule, a correction whose name was neither clear nor identified keeps the open term
(as ../20261128-correct-on-ambiguous/product.py). Segments >= 3 s; the rule of
benchmarks/calibrate_uncertainty.py choose_beta_diagnosed: per quantity the smallest grid value at
which 90 % of the pooled diagnosed intervals hold."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import choose_beta_diagnosed, coverage, load  # noqa: E402
from merges import KEY, sharing  # noqa: E402

from inverse import uncertainty as U  # noqa: E402

AMB = HERE.parent / '20261128-correct-on-ambiguous'
CVE = HERE.parent / '20261128-closest-vehicle-effect'
SETS = {'friction 1-20': AMB / 'seeds1-20', 'friction 21-40': AMB / 'seeds21-40',
        'friction 41-60': CVE / 'fresh-friction-41-60',
        'independent 1-20': AMB / 'independent-cl', 'independent 41-52': AMB / 'independent-41-52',
        'independent 53-72': CVE / 'fresh-independent-53-72'}


def diagnosed_rows(root):
    root = Path(root)
    rec = {json.loads(li)['seed']: json.loads(li) for li in (root / 'results.jsonl').read_text().splitlines()}
    ident = json.loads((root / 'identified.json').read_text()) if (root / 'identified.json').is_file() else None
    out = {'linear': [], 'linear/axles': []}
    shared = sharing(load(root, min_s=0.0))
    for r in load(root):
        r['merged'] = shared[(r['seed'], r['Gq_fit'])] > 1
        loop = rec[r['seed']].get('closed_loop') or {}
        v = loop.get('verdict')
        if r['model_form'] != 'diagnosed':
            continue
        if ident is not None and v != 'none' and not (loop.get('confidence') == 'clear' or ident[str(r['seed'])]):
            continue          # an 'ambiguous' correction: the open term (product.py)
        out[KEY.get(v, 'linear')].append(r)     # diagnosed: 'none' on axles, a name on axle 3
    return out


def fmt(c):
    return ' / '.join(f"{100 * c[q][0]:.0f}" for q in ('ln_Gq_n0', 'w', 'ln_G_n_best')) + f" ({c['ln_Gq_n0'][2]})"


def main(extra):
    sets = {n: diagnosed_rows(r) for n, r in SETS.items()}
    fresh = {n: diagnosed_rows(r) for n, r in extra.items()}
    for key in ('linear', 'linear/axles'):
        const = U.calibration(key)
        pooled = [r for d in sets.values() for r in d[key]]
        chosen = choose_beta_diagnosed(pooled, const)
        print(f"\n## {key}: shipped BETA_DIAGNOSED {const['BETA_DIAGNOSED']}; chosen on all {len(sets)} sets pooled "
              f"({len(pooled)} diagnosed segments): {chosen}")
        print("| set | shipped | pooled choice | choice without this set (its value) |")
        print("|---|---|---|---|")
        for n, d in list(sets.items()) + list(fresh.items()):
            if not d[key]:
                print(f"| {n} | no diagnosed segment | | |")
                continue
            loo = choose_beta_diagnosed([r for m, e in sets.items() if m != n for r in e[key]], const)
            cs = coverage(d[key], const)
            cp = coverage(d[key], {**const, 'BETA_DIAGNOSED': chosen})
            cl = coverage(d[key], {**const, 'BETA_DIAGNOSED': loo})
            tag = ' (fresh: not in the pool)' if n in fresh else ''
            print(f"| {n}{tag} | {fmt(cs)} | {fmt(cp)} | {fmt(cl)} ({', '.join(f'{v:g}' for v in loo.values())}) |")
        allr = pooled + [r for d in fresh.values() for r in d[key]]
        print(f"| all | {fmt(coverage(allr, const))} | {fmt(coverage(allr, {**const, 'BETA_DIAGNOSED': chosen}))} | |")
        print("\nshipped constants, true segments alone in their fitted segment / merged with a neighbour "
              "(merges.py's definition):")
        for n, d in list(sets.items()) + list(fresh.items()):
            a, m = [r for r in d[key] if not r['merged']], [r for r in d[key] if r['merged']]
            if d[key]:
                print(f"  {n}: alone {fmt(coverage(a, const)) if a else '-'}, merged {fmt(coverage(m, const)) if m else '-'}")


if __name__ == '__main__':
    main(dict(a.split('=', 1) for a in sys.argv[1:]))
