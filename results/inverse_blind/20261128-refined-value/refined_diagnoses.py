"""Copies of saved diagnoses with the named leaf friction's value replaced by the refined one (stop 51).

    python results/inverse_blind/20261128-refined-value/refined_diagnoses.py DIAG_ROOT VALUES OUT_ROOT

DIAG_ROOT: a bench_inverse.py --effects-auto root (run-SEED/diagnose); VALUES: refine_values.py's
values.jsonl; OUT_ROOT gets run-SEED/diagnose for every seed of DIAG_ROOT, the verdict's ranking entry
carrying the refined force where the verdict is leaf_friction (everything else as diagnosed). The loop
then inverts at that value: bench_inverse.py --effects-auto --diagnoses OUT_ROOT."""
import json
import shutil
import sys
from pathlib import Path


def main(diag_root, values, out_root):
    refined = {r['seed']: r['force'] for r in map(json.loads, Path(values).read_text().splitlines())}
    for run in sorted(Path(diag_root).glob('run-*')):
        seed = int(run.name.split('-')[1])
        dst = Path(out_root) / run.name / 'diagnose'
        shutil.rmtree(dst, ignore_errors=True)
        shutil.copytree(run / 'diagnose', dst)
        summ = json.loads((dst / 'summary.json').read_text())
        if summ.get('verdict') == 'leaf_friction' and seed in refined:
            entry = next(e for e in summ['ranking'] if e['effect'] == 'leaf_friction')
            was = entry['parameters']['leaf_friction']['force']
            entry['parameters']['leaf_friction']['force'] = refined[seed]
            (dst / 'summary.json').write_text(json.dumps(summ, indent=2))
            print(f"seed {seed}: leaf friction {was:.0f} -> {refined[seed]:.0f} N")


if __name__ == '__main__':
    main(*sys.argv[1:4])
