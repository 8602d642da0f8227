"""Scoring of the blind check (diagnosis.blind.score) on hand-made results."""
import pytest

from diagnosis.blind import Z_PAIRED, format_confusion, score


def _r(case, effect, verdict, conf, true_shrink=None, z=None):
    return dict(case=case, effect=effect, verdict=verdict, confidence=conf,
                correct=(verdict == effect),
                confident_wrong=(verdict not in (effect, "none") and conf == "clear"),
                localisation_hit=True, n_flagged=3, predicted_shrink=0.3 if verdict == effect else 0.0,
                true_shrink=true_shrink, true_paired_z=z, heldout_gap_before=0.5, null_sd=0.05)


def test_score_counts_detectable_cases_by_the_paired_gate():
    """A case is detectable when the truth effect at its true strength has a positive
    held-out shrink and a paired z above Z_PAIRED (the ranking's own gate); a strong z with
    a negative shrink (the truth does not close the gap in the diagnosis model) is not."""
    res = [_r(0, "none", "none", "none"),
           _r(1, "payload", "payload", "clear", 0.3, Z_PAIRED + 2),
           _r(2, "bump_stop", "payload", "ambiguous", -0.05, Z_PAIRED + 2),      # not detectable
           _r(3, "sensor", "none", "none", 0.08, Z_PAIRED - 1),                  # not detectable
           _r(4, "frame_flex", "tyre_enveloping", "clear", 0.2, Z_PAIRED + 5)]   # confident wrong
    sc = score(res)
    assert sc["n_detectable"] == 2
    assert sc["detectable_top1_accuracy"] == pytest.approx(0.5)
    assert sc["top1_accuracy"] == pytest.approx(2 / 5)
    assert sc["confident_wrong"] == 1
    assert sc["null_none_rate"] == 1.0
    assert sc["undetectable_none_rate"] == pytest.approx(0.5)
    assert "payload" in format_confusion(sc)
