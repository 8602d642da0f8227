"""Does the segmentation's resolution (summary.json 'unresolved', inverse.segmentation.
unresolved_level) bound what the segmentation merged? On saved blind inversions (bench_inverse.py
roots with their run-N/summary.json):

    python results/inverse_blind/20261128-beta-diagnosed-pooled/resolution_check.py NAME=ROOT ...

For every true segment >= 3 s that shares its fitted segment with another true segment (the
segmentation merged them), the true level's offset from the fitted one (-lnGq_err) against the range
unresolved_level gives for a piece of the true segment's length inside the fitted segment (computed
here from the run's segmentation criterion, n_eff; recorded runs predate the summary field). Also
how many of the true pieces >= 3 s were merged, and the alone pieces' offsets for comparison
(|offset| beyond the range: the fit's own error, no merge)."""
import json
import math
import sys
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import load  # noqa: E402

from inverse.segmentation import unresolved_level  # noqa: E402


def fitted_segments(run):
    out = []
    for p in (run / 'summary.json', run / 'nominal' / 'summary.json'):
        if p.is_file():
            s = json.loads(p.read_text())
            crit = s['segmentation']['criterion']
            res = {'n_eff': crit['n_eff'], 'duration_s': s['segments'][-1]['t_end'] - s['segments'][0]['t_start'],
                   'penalty': 1.0, 'n_par': 2, 'series': 1 if 'axle_acc' not in s['segmentation'].get('boundaries_from', '') else 0}
            out += [(g, res) for g in s['segments']]
    return out


def check(root):
    root = Path(root)
    rows = load(root, min_s=0.0)
    n = Counter((r['seed'], r['Gq_fit']) for r in rows)
    merged, alone = [], []
    for r in rows:
        if r['duration_s'] < 3.0:
            continue
        segs = [(g, res) for g, res in fitted_segments(root / f"run-{r['seed']}") if g['Gq_n0'] == r['Gq_fit']]
        if not segs:
            continue
        g, res = segs[0]
        lo_hi = unresolved_level(r['duration_s'], g['t_end'] - g['t_start'], res)
        off = -r['lnGq_err']
        (merged if n[(r['seed'], r['Gq_fit'])] > 1 else alone).append((off, lo_hi))
    return merged, alone


def main(sets):
    print('| set | pieces >= 3 s | merged | merged pieces inside the unresolved range | median |offset| merged / alone |')
    print('|---|---|---|---|---|')
    tot = [0, 0, 0]
    for name, root in sets.items():
        merged, alone = check(root)
        inside = sum(lo <= off <= hi for off, (lo, hi) in ((o, lh) for o, lh in merged if lh))
        med = lambda v: sorted(abs(o) for o, _ in v)[len(v) // 2] if v else float('nan')
        print(f'| {name} | {len(merged) + len(alone)} | {len(merged)} | {inside} / {len(merged)} | '
              f'{med(merged):.2f} / {med(alone):.2f} |')
        tot = [tot[0] + len(merged) + len(alone), tot[1] + len(merged), tot[2] + inside]
    print(f'| all | {tot[0]} | {tot[1]} | {tot[2]} / {tot[1]} ({100 * tot[2] / max(tot[1], 1):.0f} %) | |')


if __name__ == '__main__':
    main(dict(a.split('=', 1) for a in sys.argv[1:]))
