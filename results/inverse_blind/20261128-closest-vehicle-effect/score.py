"""The friction drives' closed loop before and after the closest-effect rule, segments >= 3 s
(python results/inverse_blind/20261128-closest-vehicle-effect/score.py [FRESH_ROOT], from the
repository root).

Before: the loop of stop 47 as composed by ../20261128-correct-on-ambiguous/product.py ('new'):
every name corrects, 'unexplained' drives fitted on axle 3's accelerations without a correction.
After: the 'unexplained' drives whose closest effect qualifies (diagnosis.closed_loop.
closest_vehicle_effect; seeds 12, 37 and 38) replaced by their rerun with the same diagnoses
(same-drives/, `bench_inverse.py --effects-auto --diagnoses`), all other drives unchanged; every
'unexplained' drive's intervals with the 'unexplained' model-form term (before: the open one).
With a closed-loop root run with the rule (fresh drives): before / after on it, see :func:`fresh`."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
AMB = HERE.parent / '20261128-correct-on-ambiguous'
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
sys.path.insert(0, str(AMB))
from calibrate_uncertainty import accuracy, load  # noqa: E402
from compose_unexplained import cov  # noqa: E402

ACC = {'seeds1-20': HERE.parent / '20261128-acceleration-only-fit' / 'axle3-acc' / 'random',
       'seeds21-40': AMB / 'seeds21-40-unexplained-axle3acc'}
L = 0.1823215567939546   # ln 1.2


def key(r):
    return (r['seed'], round(r['duration_s'], 3))


def records(root):
    return {json.loads(l)['seed']: json.loads(l) for l in (Path(root) / 'results.jsonl').read_text().splitlines()}


def line(label, d):
    rows = sum(d.values(), [])
    a = accuracy(rows)
    print(f"{label}: {len(rows)} segments, G(1 cycle/m) within 20 % {100 * a['g1'][0]:.1f} %, class right "
          f"{100 * a['class'][0]:.1f} %, 90 % intervals cover {cov(d)} % (ln Gq(n0) / w / ln G(n_best))")
    return rows


def paired(before, after):
    A, B = {key(r): r for r in before}, {key(r): r for r in after}
    ks = sorted(set(A) & set(B))
    g = lambda r: abs(r['lnG_1cpm_err']) <= L
    c = lambda r: r['class_true'] == r['class_fit']
    print(f"  paired over {len(ks)} segments: G(1) {sum(g(B[k]) and not g(A[k]) for k in ks)} gained / "
          f"{sum(g(A[k]) and not g(B[k]) for k in ks)} lost; class {sum(c(B[k]) and not c(A[k]) for k in ks)} / "
          f"{sum(c(A[k]) and not c(B[k]) for k in ks)}")


def saved():
    pooled = {'before': [], 'after': []}
    for name in ('seeds1-20', 'seeds21-40'):
        rec = records(AMB / name)
        verdict = {s: c['closed_loop']['verdict'] for s, c in rec.items()}
        rows = load(AMB / name)
        ident = json.loads((AMB / name / 'identified.json').read_text())
        for r in rows:     # as product.py: a correction with a name not singled out keeps the open term
            s = r['seed']
            if r['model_form'] == 'diagnosed' and verdict[s] != 'none' and not (
                    rec[s]['closed_loop']['confidence'] == 'clear' or ident[str(s)]):
                r['model_form'] = 'open'
        acc = [r for r in load(ACC[name]) if verdict.get(r['seed']) == 'unexplained']
        # before: stop 47's loop, whose 'unexplained' drives carried the open term
        before = {'linear': [r for r in rows if verdict[r['seed']] != 'unexplained'],
                  'linear/axle3_acc': [dict(r, model_form='open') for r in acc]}
        redo = load(HERE / 'same-drives' / name)
        seeds = {r['seed'] for r in redo}
        # after: today's, the 'unexplained' term (BETA_UNEXPLAINED) on every such drive
        after = {'linear': before['linear'],
                 'linear/axle3_acc': [dict(r, model_form='unexplained') for r in acc if r['seed'] not in seeds] + redo}
        b, a = line(f"{name} before", before), line(f"{name} after ", after)
        paired(b, a)
        pooled['before'].append(before)
        pooled['after'].append(after)
    for label, ds in pooled.items():
        line(f"pooled {label}", {k: sum((d[k] for d in ds), []) for k in ds[0]})
    return pooled['after']


def fresh(root):
    """A closed-loop root run with the rule: after = its records as they are; before = stop 47's loop
    on the same drives, i.e. where the rule corrected an 'unexplained' drive its nominal inversion
    (same channels, recorded beside the corrected one), and every 'unexplained' drive with the open
    term."""
    root = Path(root)
    rec = records(root)
    verdict = {s: (c.get('closed_loop') or {}).get('verdict') for s, c in rec.items()}
    fired = sorted(s for s, c in rec.items() if verdict[s] == 'unexplained' and c['closed_loop'].get('corrected'))
    print(f"{root}: verdicts {sorted(set(verdict.values()), key=str)}; 'unexplained' drives corrected by the rule: {fired}")
    after_rows = load(root)
    nominal = {key(r): r for r in load(root, open_loop=True) if r['seed'] in fired}
    before_rows = [dict(r, model_form='open') for r in nominal.values()] + [
        dict(r, model_form='open') if verdict[r['seed']] == 'unexplained' else r
        for r in after_rows if r['seed'] not in fired]

    def grouped_rows(rows):
        return {'linear/axles': [r for r in rows if verdict[r['seed']] == 'none'],
                'linear/axle3_acc': [r for r in rows if verdict[r['seed']] == 'unexplained'],
                'linear': [r for r in rows if verdict[r['seed']] not in ('none', 'unexplained')]}
    b = line('before (stop 47)', grouped_rows(before_rows))
    a = line('after (today)   ', grouped_rows(after_rows))
    paired(b, a)
    for s in fired:
        print(f"  seed {s}: ln G(1) " + ' '.join(f"{r['lnG_1cpm_err']:+.2f}" for r in before_rows if r['seed'] == s)
              + ' -> ' + ' '.join(f"{r['lnG_1cpm_err']:+.2f}" for r in after_rows if r['seed'] == s))
    return grouped_rows(after_rows)


if __name__ == '__main__':
    if len(sys.argv) == 2:
        fresh(sys.argv[1])
    else:
        saved()
