"""Old (no two-input rule for low-passes) against new verdicts on the same drives:
python compare.py DIR [DIR ...]

Every saved summary is re-decided twice with the code's verdict rules: "old" with
diagnosis.verdict.LOWPASS_TWO_INPUT False, "new" with it True (stop 68)."""
import sys

from diagnosis import verdict
from diagnosis.blind import paired


def with_rule(on):
    def run(s):
        keep, verdict.LOWPASS_TWO_INPUT = verdict.LOWPASS_TWO_INPUT, on
        try:
            return verdict.decide(s)
        finally:
            verdict.LOWPASS_TWO_INPUT = keep
    return run


if __name__ == "__main__":
    paired(sys.argv[1:], with_rule(False), with_rule(True), "sensor")
