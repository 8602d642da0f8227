"""Old (no two-input rule for low-passes) against new verdicts on the same drives:
python compare.py DIR [DIR ...]

Every saved summary is re-decided twice with the code's verdict rules: "old" with
diagnosis.verdict.LOWPASS_TWO_INPUT False, "new" with it True (stop 68)."""
import sys

from diagnosis.blind import decide_with, paired

if __name__ == "__main__":
    paired(sys.argv[1:], decide_with(LOWPASS_TWO_INPUT=False), decide_with(LOWPASS_TWO_INPUT=True), "sensor")
