"""G(1) with the loop inverting at the refined value against the shipped loop, same saved diagnoses (stop 51):
python results/inverse_blind/20261128-refined-value/g1_paired.py  (from the repository root).

refined-81-100.jsonl: bench_inverse.py --effects-auto --no-profile --diagnoses R (R: refined_diagnoses.py's
copies) from a worktree at 4f67d65 (--no-profile = the shipped loop); the shipped loop's records:
../20261128-effect-profile/fresh-friction-81-100/. Segments >= 3 s."""
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / '20261128-effect-profile'))
from score_profile import paired  # noqa: E402
from score_third import corrected_pairs, load, whole_set  # noqa: E402


def main():
    base = load(HERE.parent / '20261128-effect-profile' / 'fresh-friction-81-100')
    ref = load(HERE / 'refined-81-100.jsonl')
    seeds, a, b = corrected_pairs(ref, base, flag='corrected')
    print(f"corrected drives ({len(seeds)}): " + paired(a, b))
    print(f"whole set ({len(set(ref) & set(base))} drives): " + paired(*whole_set(ref, base)))


if __name__ == '__main__':
    main()
