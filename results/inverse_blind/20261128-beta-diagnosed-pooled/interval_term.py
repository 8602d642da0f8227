"""Would the segmentation's resolution make a better interval term? (python results/inverse_blind/
20261128-beta-diagnosed-pooled/interval_term.py, from the repository root; needs the bench roots
named in resolution_check.txt.)

For every true piece >= 3 s: its fitted segment's reported 90 % half-width z (today's constants)
and the segment's reported range (lo, hi) for a 3 s piece. Variants of an interval for the piece:
'add' [-z + c lo, z + c hi], 'quad' [-hypot(z, c lo), hypot(z, c hi)], against a common factor k on
z of the same mean width. If the range carried information on which segments hide a piece, 'quad'
would cover more than the common factor at equal width. Pieces of our truck (null and friction
drives) and of the independent truck apart; ln Gq(n0) / ln G(n_best)."""
import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from resolution_check import scored_pieces, unresolved_level  # noqa: E402

SETS = {'null 1-20': '/tmp/s45/base-null', 'null 21-60': '/tmp/s45/base-null2', 'null 61-100': '/tmp/s45/base-null3',
        'null 1-20 axles': '/tmp/s46/axles-data-null', 'friction 1-20': '/tmp/s46/cl-axle3',
        'friction 21-40': '/tmp/s47/fresh-random', 'friction 41-60': '/tmp/s48/fresh-random',
        'independent 1-20': '/tmp/s47/cl-second', 'independent 41-52': '/tmp/s47/fresh-second',
        'independent 53-72': '/tmp/s48/fresh-second'}


def pieces(spec):
    root, _, key = spec.partition('@')
    out = []
    for r, g, res, z in scored_pieces(root, key or None)[0]:
        lh = unresolved_level(3.0, g['t_end'] - g['t_start'], res) or (0.0, 0.0)
        if all(map(math.isfinite, lh)):
            out.append(((-r['lnGq_err'], -r['lnG_n_best_err']), z, lh))
    return out


def bounds(z, lh, mode, c, k=1.0):
    lo, hi = c * lh[0], c * lh[1]
    if mode == 'add':
        return -k * z + lo, k * z + hi
    return -math.hypot(k * z, lo), math.hypot(k * z, hi)


def cover(rows, q, mode, c, k=1.0):
    return sum(a <= x[q] <= b for x, z, lh in rows for a, b in [bounds(z[q], lh, mode, c, k)]) / len(rows)


def width(rows, q, mode, c, k=1.0):
    return sum(b - a for _, z, lh in rows for a, b in [bounds(z[q], lh, mode, c, k)]) / len(rows)


def main():
    data = {n: pieces(s) for n, s in SETS.items()}
    ours = [p for n, d in data.items() if not n.startswith('independent') for p in d]
    ind = [p for n, d in data.items() if n.startswith('independent') for p in d]
    allp = ours + ind
    pc = lambda v: f'{100 * v:.0f}'
    print(f'{len(ours)} pieces of our truck, {len(ind)} of the independent truck (>= 3 s, finite range)\n')
    print('| variant | c | cover ours ln Gq(n0) / ln G(n_best) | independent | common factor k of the same mean width (ln Gq(n0)) | its cover ours / independent |')
    print('|---|---|---|---|---|---|')
    for mode in ('add', 'quad'):
        for c in (0.0, 0.25, 0.5, 1.0):
            w = width(allp, 0, mode, c)
            k = min((1 + i / 100 for i in range(300)), key=lambda k: abs(width(allp, 0, 'add', 0.0, k) - w))
            print(f'| {mode} | {c:g} | {pc(cover(ours, 0, mode, c))} / {pc(cover(ours, 1, mode, c))} | '
                  f'{pc(cover(ind, 0, mode, c))} / {pc(cover(ind, 1, mode, c))} | x{k:.2f} | '
                  f'{pc(cover(ours, 0, "add", 0.0, k))} / {pc(cover(ind, 0, "add", 0.0, k))} |')


if __name__ == '__main__':
    main()
