"""Old (VEHICLE_TWO_INPUT off) against new (on) verdicts on the same drives:
python compare.py DIR [DIR ...]   (no DIR: every saved blind set under results/diagnosis_blind)

Every saved summary is re-decided twice with the code's verdict rules, differing only in
diagnosis.verdict.VEHICLE_TWO_INPUT (stop 69)."""
import glob
import sys
from pathlib import Path

from diagnosis.blind import decide_with, paired

if __name__ == "__main__":
    dirs = sys.argv[1:] or sorted({str(Path(p).parent) for p in
                                   glob.glob("results/diagnosis_blind/*/**/blind.json", recursive=True)})
    paired(dirs, decide_with(VEHICLE_TWO_INPUT=False), decide_with(VEHICLE_TWO_INPUT=True), "frame_flex")
