"""Every saved blind diagnosis re-decided with today's rules (diagnosis.verdict.decide) and with one
relaxed rule: a winner that fails ONLY the transmissibility test is named when it explains at least
SHARE of the held-out gap and its transmissibility is no further off than the nominal model's (mean
z^2 at most (1 + TOL) times the nominal's).  Prints, per setting, what would change: library-effect
drives gained, no-effect drives lost (a name where none is true), wrong names; then the misses of
the independent truck under today's rules with the ranking's winner and the reason.
Run from the repository root: python results/diagnosis_blind/20261128-signature-relaxed-redecided/redecide.py"""
import collections
import glob
import json
import sys

sys.path.insert(0, '.')
import diagnosis.verdict as V  # noqa: E402


def load():
    out = []
    for f in sorted(glob.glob('results/diagnosis_blind/2026112*/*/blind.json')):
        base = f.rsplit('/', 1)[0]
        for c in json.load(open(f))['results']:
            try:
                s = json.load(open(f"{base}/case{c['case']:03d}-summary.json"))
            except OSError:
                continue
            out.append((base.split('diagnosis_blind/')[1], c, s))
    return out


def relaxed(s, v, share_min, tol):
    if v['verdict'] != 'unexplained' or v.get('closest') is None:
        return v['verdict']
    if v.get('signature_agrees') is not False or v.get('edge'):
        return v['verdict']
    share = v.get('explained_share')
    if share is None or not share >= share_min:
        return v['verdict']
    if (s.get('ranking_decision') or {}).get('confidence') != 'clear':
        return v['verdict']
    win = next((e for e in s.get('ranking') or [] if e.get('effect') == v['closest'] and e.get('accepted')), None)
    if win is None or V.negligible(win):
        return v['verdict']
    sig, m = V.chosen_signature(s, V.SIGNATURE_METHOD)
    st = V._signature_test(s, win, sig, m, signature_max=V.SIGNATURE_CHI2_MAX,
                           signature_share=V.SIGNATURE_SHARE_MIN, signature_null=V.SIGNATURE_USE_NULL,
                           corroborate=V.SIGNATURE_CORROBORATE, own=V.SIGNATURE_OWN, null_sd=V.SIGNATURE_NULL_SD)
    if st.own is not None or st.c0 is None or st.c1 is None:
        return v['verdict']
    return v['closest'] if st.c1 <= st.c0 * (1 + tol) else v['verdict']


def main():
    rows = [(b, c, s, V.decide(s)) for b, c, s in load()]
    T = collections.Counter()
    for b, c, s, v in rows:
        lib = c['effect'] != 'none'
        right = v['verdict'] == c['effect'] if lib else v['verdict'] in ('none', 'unexplained')
        T[(c['family'], 'library effect' if lib else 'no effect')] += 1
        T[(c['family'], 'library effect right' if lib else 'no effect right')] += right
    print(f'{len(rows)} saved diagnoses, today\'s rules:', dict(sorted(T.items())))
    for share_min in (0.4, 0.5, 0.6, 0.7):
        for tol in (0.0, 0.1):
            D = collections.Counter()
            for b, c, s, v in rows:
                nv = relaxed(s, v, share_min, tol)
                if nv == v['verdict']:
                    continue
                if c['effect'] == 'none':
                    D[(c['family'], 'no-effect drive named')] += 1
                elif nv == c['effect']:
                    D[(c['family'], 'library effect gained')] += 1
                else:
                    D[(c['family'], f'wrong name ({nv} for {c["effect"]})')] += 1
            print(f'share >= {share_min}, tolerance {tol}: {dict(sorted(D.items()))}')
    print('\nindependent truck, library effect missed under today\'s rules:')
    for b, c, s, v in rows:
        if c['family'] != 'second' or c['effect'] == 'none' or v['verdict'] == c['effect']:
            continue
        rv = (s.get('ranking_decision') or {}).get('verdict')
        print(f"{b[:34]:34s} {c['effect']:14s} {c['scenario']:16s} {c['value']:9.0f} ranking {rv:17s} -> "
              f"{v['verdict']}: {(v.get('reason') or '')[:200]}")


if __name__ == '__main__':
    main()
