"""Old (own signature at z 2.0) against new (one-sided 5 %, z 1.645, diagnosis.verdict.OWN_Z_NOMINAL
since stop 67) verdicts on the same drives:  python compare.py DIR [DIR ...]

Each DIR holds blind.json and caseNNN-summary.json (a committed set) or caseNNN-run/summary.json
(a bench work folder)."""
import sys

from diagnosis import verdict
from diagnosis.blind import paired

OLD_Z = 2.0


def old(s):
    orig = verdict.own_signature_agrees
    verdict.own_signature_agrees = lambda rec, z_nominal=OLD_Z, **k: orig(rec, z_nominal=z_nominal, **k)
    try:
        return verdict.decide(s)
    finally:
        verdict.own_signature_agrees = orig


if __name__ == "__main__":
    paired(sys.argv[1:], old, verdict.decide, "damper_asymmetry")
