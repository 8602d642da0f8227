"""The friction drives' closed loop as the code now runs it, against the rule before, on segments >= 3 s
(python results/inverse_blind/20261128-correct-on-ambiguous/product.py, from the repository root).

Old: corrections on 'clear' or identified names only (the smaller 'diagnosed' model-form term on
them), axle 3 on 'unexplained'. New: every name not at a range edge corrects; a correction with a
name not singled out keeps the 'open' term; 'unexplained' drives are fitted on axle 3's
accelerations alone (ACC below). Composed from the
records of this folder; `identified.json` per set holds each diagnosis's verdict_detail.identified."""
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import accuracy, coverage, load  # noqa: E402

sys.path.insert(0, str(HERE))
from compose_unexplained import cov as cover  # noqa: E402

OLD = {'seeds1-20': HERE.parent / '20261128-acceleration-only-fit' / 'closed-loop' / 'axle3'}
#: the axle3_acc fits of each set's 'unexplained' drives (for seeds 1-20 the open-loop fits of stop 46)
ACC = {'seeds1-20': HERE.parent / '20261128-acceleration-only-fit' / 'axle3-acc' / 'random',
       'seeds21-40': HERE / 'seeds21-40-unexplained-axle3acc'}


def records(root):
    return {json.loads(l)['seed']: json.loads(l) for l in (root / 'results.jsonl').read_text().splitlines()}


def main():
    pooled = {'old': {}, 'new': {}}
    for name in ('seeds1-20', 'seeds21-40'):
        root = HERE / name
        ident = json.loads((root / 'identified.json').read_text())
        rec = records(root)
        conf = {s: c['closed_loop']['confidence'] for s, c in rec.items()}
        verdict = {s: c['closed_loop']['verdict'] for s, c in rec.items()}
        singled = {s: conf[s] == 'clear' or ident[str(s)] for s in rec}
        new_rows = load(root)
        for r in new_rows:            # the records were made before the model form depended on it
            if r['model_form'] == 'diagnosed' and verdict[r['seed']] != 'none' and not singled[r['seed']]:
                r['model_form'] = 'open'
        acc_rows = load(ACC[name])
        acc_seeds = {r['seed'] for r in acc_rows}
        new = {'linear': [r for r in new_rows if not (verdict[r['seed']] == 'unexplained' and r['seed'] in acc_seeds)],
               'linear/axle3_acc': [r for r in acc_rows if verdict[r['seed']] == 'unexplained']}
        # the old rule: the nominal rows where only the new rule corrects
        if name in OLD:
            old_rows = load(OLD[name])
        else:
            nominal = load(root, open_loop=True)
            old_rows = [r for r in new_rows if singled[r['seed']] or verdict[r['seed']] in ('none', 'unexplained')]
            old_rows = [dict(r, model_form='diagnosed' if verdict[r['seed']] != 'unexplained' else 'open') for r in old_rows]
            old_rows += [r for r in nominal if not singled[r['seed']] and verdict[r['seed']] not in ('none', 'unexplained')]
        old = {'linear': old_rows}
        for label, d in (('old', old), ('new', new)):
            rows = sum(d.values(), [])
            a = accuracy(rows)
            print(f"{name} {label}: {len(rows)} segments, G(1 cycle/m) within 20 % {100 * a['g1'][0]:.1f} %, class right "
                  f"{100 * a['class'][0]:.1f} %, 90 % intervals cover {cover(d)} % (ln Gq(n0) / w / ln G(n_best))")
            for k, v in d.items():
                pooled[label].setdefault(k, []).extend(v)
    for label, d in pooled.items():
        rows = sum(d.values(), [])
        a = accuracy(rows)
        print(f"pooled {label}: {len(rows)} segments, G(1 cycle/m) within 20 % {100 * a['g1'][0]:.1f} %, class right "
              f"{100 * a['class'][0]:.1f} %, 90 % intervals cover {cover(d)} %")


if __name__ == '__main__':
    main()
