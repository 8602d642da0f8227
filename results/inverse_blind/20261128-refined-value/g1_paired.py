"""G(1) with the loop inverting at the refined value against the shipped loop, same saved diagnoses (stop 51):
python results/inverse_blind/20261128-refined-value/g1_paired.py  (from the repository root).

refined-81-100.jsonl: bench_inverse.py --effects-auto --no-profile --diagnoses R (R: refined_diagnoses.py's
copies) from a worktree at 4f67d65 (--no-profile = the shipped loop); the shipped loop's records:
../20261128-effect-profile/fresh-friction-81-100/. Segments >= 3 s."""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-effect-profile'))
from score_profile import paired, rows  # noqa: E402
from score_third import load  # noqa: E402


def main():
    base = load(HERE.parent / '20261128-effect-profile' / 'fresh-friction-81-100')
    ref = load(HERE / 'refined-81-100.jsonl')
    seeds = sorted(s for s in ref if (ref[s].get('closed_loop') or {}).get('corrected') and s in base)
    print(f"corrected drives ({len(seeds)}): "
          + paired(sum((rows(base[s]) for s in seeds), []), sum((rows(ref[s]) for s in seeds), [])))
    allc = sorted(set(ref) & set(base))
    print(f"whole set ({len(allc)} drives): "
          + paired(sum((rows(base[s]) for s in allc), []), sum((rows(ref[s]) for s in allc), [])))


if __name__ == '__main__':
    main()
