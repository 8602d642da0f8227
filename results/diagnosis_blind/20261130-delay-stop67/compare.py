"""Old (no delay test) against new verdicts on the same drives:
python compare.py DIR [DIR ...]

Each DIR holds blind.json and caseNNN-summary.json (a committed set) or caseNNN-run/summary.json
(a bench work folder).  Every summary is re-decided twice with the code's verdict rules:
"old" with diagnosis.verdict.DELAY_RULE False, "new" with it True (the front-to-rear delay test
of a speed_scale winner, stop 67).  The delay test needs no record beyond `front_rear`, which
every summary since 2026-11-21 carries."""
import sys

from diagnosis import verdict
from diagnosis.blind import paired


def with_rule(on):
    def run(s):
        keep, verdict.DELAY_RULE = verdict.DELAY_RULE, on
        try:
            return verdict.decide(s)
        finally:
            verdict.DELAY_RULE = keep
    return run


if __name__ == "__main__":
    paired(sys.argv[1:], with_rule(False), with_rule(True), "speed_scale")
