"""Does the segmentation's resolution (summary.json 'unresolved', inverse.segmentation.
unresolved_level) bound what the segmentation merged? On saved blind inversions (bench_inverse.py
roots with their run-N/summary.json):

    python results/inverse_blind/20261128-beta-diagnosed-pooled/resolution_check.py NAME=ROOT[@KEY] ...

(Each row's interval constants: the calibration its run's summary.json names; runs that predate
that field take KEY, inverse.uncertainty.CALIBRATIONS, default 'linear', or in a closed loop the
key its verdict chooses, as merges.py does.)

For every true segment >= 3 s that shares its fitted segment with another true segment (the
segmentation merged them), two offsets against the range unresolved_level gives for a piece of
the true segment's length inside the fitted segment (computed here from the run's segmentation
criterion, n_eff; recorded runs predate the summary field):
* segmentation alone: the piece's true level at N_SEG (0.3 cycles/m, where the 3-20 Hz
  displacement power the segmentation partitions lies at about 10 m/s) against the
  duration-weighted mean of the true levels of all pieces sharing the fitted segment;
* as the user sees it: the true ln Gq(n0) against the fitted one (-lnGq_err), which adds the
  fit's own error (no part of the range; the alone pieces' median |offset| shows its size);
* the two combined, for every piece >= 3 s: the true Gq(n0) and G(n_best) inside an envelope, the
  segment's reported 90 % interval (today's constants) widened by the segment's reported range
  (summary.json 'unresolved', a 3 s piece). Built as a Table 1 column and dropped: it held for
  99 %, a bound rather than an interval, and as an interval term the range does no better than a
  common factor of the same width (interval_term.py)."""
import json
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / 'benchmarks'))
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[2]))
from calibrate_uncertainty import load, reported_sd  # noqa: E402

from inverse import uncertainty as U  # noqa: E402
from inverse.pipeline import unresolved_row  # noqa: E402
from inverse.segmentation import unresolved_level  # noqa: E402
from merges import KEY as LOOP_KEY, sharing  # noqa: E402



def calibration_key(case, res, key=None):
    """The uncertainty calibration the run used (its summary's), else the closed loop's choice by
    verdict (LOOP_KEY), else ``key`` or 'linear'."""
    if res.get('key'):
        return res['key']
    loop = case.get('closed_loop')
    return LOOP_KEY.get(loop.get('verdict'), 'linear') if loop else (key or 'linear')


def fitted_segments(run):
    out = []
    for p in (run / 'summary.json', run / 'nominal' / 'summary.json'):
        if p.is_file():
            s = json.loads(p.read_text())
            crit = s['segmentation']['criterion']
            res = {'n_eff': crit['n_eff'], 'duration_s': s['segments'][-1]['t_end'] - s['segments'][0]['t_start'],
                   'penalty': 1.0, 'n_par': 2, 'series': 1 if 'axle_acc' not in s['segmentation'].get('boundaries_from', '') else 0,
                   'key': s['fit'].get('uncertainty_calibration')}
            out += [(g, res) for g in s['segments']]
    return out


def scored_pieces(root, key=None):
    """(row, fitted segment, its resolution inputs, z90 half-widths of ln Gq(n0) and ln G(n_best)
    with the constants the run used) for every true piece >= 3 s whose fitted segment is found,
    and the rows of every length (to tell which pieces share a fitted segment)."""
    root = Path(root)
    rec = {json.loads(li)['seed']: json.loads(li) for li in (root / 'results.jsonl').read_text().splitlines()}
    rows = load(root, min_s=0.0)
    out = []
    for r in rows:
        if r['duration_s'] < 3.0:
            continue
        segs = [(g, res) for g, res in fitted_segments(root / f"run-{r['seed']}") if g['Gq_n0'] == r['Gq_fit']]
        if not segs:
            continue
        g, res = segs[0]
        const = U.calibration(calibration_key(rec[r['seed']], res, key))
        z = (U.Z90 * reported_sd(r, 'ln_Gq_n0', r['sd_laplace']['ln_Gq_n0'], const),
             U.Z90 * reported_sd(r, 'ln_G_n_best', r['sd_ln_G_n_best_laplace'], const))
        out.append((r, g, res, z))
    return out, rows


N_SEG = 0.3   # cycles/m


def ln_g(r, n=N_SEG):
    return math.log(r['Gq_true']) - r['w_true'] * math.log(n / 0.1)


def check(root, key=None):
    pieces, rows = scored_pieces(root, key)
    n = sharing(rows)
    groups = {}
    for r in rows:
        groups.setdefault((r['seed'], r['Gq_fit']), []).append(r)
    merged, alone = [], []
    for r, g, res, (z_sd, z_nb) in pieces:
        lo_hi = unresolved_level(r['duration_s'], g['t_end'] - g['t_start'], res)
        off = -r['lnGq_err']
        grp = groups[(r['seed'], r['Gq_fit'])]
        mix = math.log(sum(q['duration_s'] * math.exp(ln_g(q)) for q in grp) / sum(q['duration_s'] for q in grp))
        # the envelope around the fitted values (today's reported sd of the run's channel set and
        # model form) widened by the reported range of a 3 s piece
        u = unresolved_row(g['t_end'] - g['t_start'], res)
        elo, ehi = u['ln_level'] if u else (0.0, 0.0)
        elo, ehi = -math.inf if elo is None else elo, math.inf if ehi is None else ehi
        envelope = (elo - z_sd <= off <= ehi + z_sd, elo - z_nb <= -r['lnG_n_best_err'] <= ehi + z_nb)
        (merged if n[(r['seed'], r['Gq_fit'])] > 1 else alone).append((off, lo_hi, ln_g(r) - mix, envelope))
    return merged, alone


def main(sets):
    print('| set | pieces >= 3 s | merged | inside the range: true level against the true mix | '
          'fitted against true ln Gq(n0) | median |fitted - true| merged / alone | '
          '90 % interval widened by the range, ln Gq(n0): merged / alone | the same, ln G(n_best) |')
    print('|---|---|---|---|---|---|---|---|')
    tot = [0] * 9
    for name, spec in sets.items():
        root, _, key = spec.partition('@')
        merged, alone = check(root, key or None)
        seg = sum(lh is not None and lh[0] <= d <= lh[1] for _, lh, d, _ in merged)
        fit = sum(lh is not None and lh[0] <= o <= lh[1] for o, lh, _, _ in merged)
        em, ea = sum(e[0] for *_, e in merged), sum(e[0] for *_, e in alone)
        bm, ba = sum(e[1] for *_, e in merged), sum(e[1] for *_, e in alone)
        med = lambda v: sorted(abs(o) for o, *_ in v)[len(v) // 2] if v else float('nan')
        print(f'| {name} | {len(merged) + len(alone)} | {len(merged)} | {seg} / {len(merged)} | {fit} / {len(merged)} | '
              f'{med(merged):.2f} / {med(alone):.2f} | {em} / {len(merged)}, {ea} / {len(alone)} | '
              f'{bm} / {len(merged)}, {ba} / {len(alone)} |')
        for i, v in enumerate((len(merged) + len(alone), len(merged), seg, fit, em, ea, len(alone), bm, ba)):
            tot[i] += v
    pc = lambda a, b: f'{a} / {b} ({100 * a / max(b, 1):.0f} %)'
    print(f'| all | {tot[0]} | {tot[1]} | {pc(tot[2], tot[1])} | {pc(tot[3], tot[1])} | | '
          f'{pc(tot[4], tot[1])}, {pc(tot[5], tot[6])} | {pc(tot[7], tot[1])}, {pc(tot[8], tot[6])} |')


if __name__ == '__main__':
    main(dict(a.split('=', 1) for a in sys.argv[1:]))
