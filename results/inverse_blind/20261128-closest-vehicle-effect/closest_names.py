"""How right is an 'unexplained' verdict's closest library effect? (python
results/inverse_blind/20261128-closest-vehicle-effect/closest_names.py, from the repository root)

Every saved blind diagnosis (results/diagnosis_blind/*/<family>/caseNNN-summary.json with the truth
in blind.json) is re-decided with today's rules (diagnosis.verdict.decide). For the 'unexplained'
verdicts, the closest effect (verdict_detail.closest) is compared with the planted one, split by
whether the effect acts on the vehicle itself (vehicles.effects: Effect.acts_on_vehicle), by
ranking confidence and by the share of the held-out gap it explains. Older sets and reruns of the
same drives are included (as saved). Nothing is written."""
import json
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT))
from diagnosis.verdict import decide  # noqa: E402
from vehicles.effects import EFFECTS  # noqa: E402


def rows():
    out = []
    for bj in sorted((ROOT / 'results' / 'diagnosis_blind').glob('*/*/blind.json')):
        for r in json.loads(bj.read_text()).get('results', []):
            p = bj.parent / f"case{r['case']:03d}-summary.json"
            if not p.is_file():
                continue
            d = decide(json.loads(p.read_text()))
            if d['verdict'] != 'unexplained':
                continue
            truth = r.get('truth_effect') or r.get('effect') or r.get('truth')
            cl = d.get('closest')
            out.append(dict(set=bj.parent.parent.name, family=bj.parent.name, truth=truth, closest=cl,
                            share=float(d.get('explained_share') or 0.0), ranking=d.get('ranking_confidence'),
                            edge=bool(d.get('edge')), vehicle=bool(cl in EFFECTS and EFFECTS[cl].acts_on_vehicle)))
    return out


def main():
    rs = rows()
    print(f"{len(rs)} 'unexplained' verdicts in the saved blind diagnoses")
    for thr in (0.5, 0.6, 0.7):
        for vehicle in (True, False):
            sel = [r for r in rs if r['share'] >= thr and r['ranking'] == 'clear' and not r['edge']
                   and r['vehicle'] == vehicle]
            right = sum(r['truth'] == r['closest'] for r in sel)
            kinds = Counter((r['family'], r['closest'], 'right' if r['truth'] == r['closest'] else f"truth {r['truth']}")
                            for r in sel)
            print(f"share >= {thr}, ranking clear, inside range, acts on the "
                  f"{'vehicle' if vehicle else 'road input / channels'}: {len(sel)}, closest right {right}")
            for k, n in sorted(kinds.items()):
                print(f"    {n} x {k[0]} family, closest {k[1]}: {k[2]}")


if __name__ == '__main__':
    main()
