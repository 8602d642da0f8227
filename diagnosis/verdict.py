"""The verdict of a diagnosis: ``none``, an effect, or ``unexplained`` -- what the data say.

What it is for: the last step of ``eroad diagnose``.  The ranking
(:mod:`diagnosis.which`) says which library effect shrinks the held-out gap beyond
road-phase noise; that is not yet an explanation.  A real truck differs from its model
in ways no library lists, and the library effect nearest to such a difference also
shrinks the gap (on drives of the independent truth family, right and wrong effects
reached similar shrink fractions).  This module decides from the ranking AND two
further checks, using only what ``summary.json`` holds, so a saved summary can be
re-decided (:func:`decide` with its keyword thresholds) with other thresholds -- how the thresholds were set on
one truth family and checked on the other (``benchmarks/bench_diagnosis.py``).

Vocabulary
----------
``none``
    No gap beyond noise (the nominal held-out gap is within ``z`` sd of the
    nominal-vs-nominal gap) and no candidate explains part of it.
``<effect>`` (or ``a+b``)
    Named only when all hold:

    1. the ranking accepted it (held-out improvement beyond its paired null, lower BIC);
    2. it explains at least ``SHARE_MIN`` of the held-out gap ABOVE the gap of a correct
       model (:func:`explained_share`: ``(before - after) / (before - g0)``, ``g0`` the
       nominal-vs-nominal gap);
    3. its road-independent signature agrees: driven over the same road as the nominal
       model, the calibrated model's axle-to-body transmissibility (a ratio of channels
       of one record: the road cancels) matches the measurement to within
       ``SIGNATURE_CHI2_MAX`` (mean z^2 over the tested pair x band cells; about 1 for a
       correct model; with ``signature_null``, not the default, or within what the candidate
       model reaches against its own records on other road phases of the same drive,
       :func:`signature_threshold`) -- or, where the nominal model's is off, removes at least
       ``SIGNATURE_SHARE_MIN`` of its excess (:func:`signature_agrees`).  Which
       transmissibility: ``SIGNATURE_METHOD`` (default ``single_input``; ``two_input``: a
       station's body acceleration on both of its axle accelerations, which the cross-track
       coherence of the road does not enter, with the single-input ratio where a summary has
       no two-input record, :func:`chosen_signature`; not the default yet, docs/diagnosis.md).
       Exception, named on the gap alone: a winner that fails only 3. is still named
       (``ambiguous``, never ``identified``) when it takes the whole gap -- at least
       ``FULL_SHARE_MIN`` of it, leaving a held-out gap within ``FULL_GAP_Z`` sd of a correct
       model's -- with the ranking's own verdict clear; an effect acting on axle and body
       alike cannot move an off transmissibility.  And named on the signature: a winner that
       fails only 2. is still named (``ambiguous``, never ``identified``) when it removes at
       least ``SIGNATURE_STRONG`` of the nominal model's transmissibility excess.  And
       corroborated (``SIGNATURE_CORROBORATE``): a single-input signature off by the fixed
       threshold passes 3. when it lies within the candidate's own scatter and the two-input
       one gives positive evidence (``ambiguous``, never ``identified``).  A near tie of the
       gap with a rival is broken by the transmissibility (:func:`decide`,
       ``SIGNATURE_TIE_BREAK``).  An effect listed in ``OWN_SIGNATURE`` (damper asymmetry) is
       tested on its own road-independent signature instead of the transmissibility it barely
       moves (:func:`own_signature_agrees`: the stroke-velocity L-skewness), both ways; a
       speed_scale winner on the front-to-rear delay, which a speed error scales
       (:func:`delay_test`, ``DELAY_RULE``), both ways, where its intervals are narrow.  ``identified``
    (in the result) is True when the named effect's identity and value are not in doubt
    (no close rival, no range edge) even if a remainder keeps it from "clear"; the closed
    loop (``diagnosis.closed_loop``) corrects with every named effect whose value is not at a
    range edge, whatever its confidence, and says which of these it was.  The front-to-rear delay and the amplitude distribution
       (skewness) are terms of every gap the ranking scores, so 1. already asks them.
       Named on the two-input transmissibility (``LOWPASS_TWO_INPUT``, ``VEHICLE_TWO_INPUT``):
       a winner failing only the single-input ratio, which moves with the road on a four-axle
       truck, when the two-input record shows no difference a correct model would not
       (``ambiguous``, never ``identified``).

    ``confidence`` is ``clear`` when no rival sharing no effect comes within the
    nominal-vs-nominal gap's sd, the calibrated parameter is not at an edge of its
    search range and the effect improves on the nominal model by at least ``CLEAR_Z_MIN``
    sd of its paired noise; else ``ambiguous``.  A calibration at a range edge is never
    named: the verdict is ``unexplained`` with that effect as the closest (its value is a
    bound, and the data ask for more than the searched range holds).
``unexplained``
    A gap is there (nominal gap beyond noise, or an accepted candidate) and no library
    effect passes 1-3 (or the one that does is calibrated at a range edge).  The closest candidate, the share it explains, the bands where
    the gap stays above a correct model's and the transmissibility pairs still off are
    reported.

What it is not: the statistics (``diagnosis.which``, ``diagnosis.compare``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

# a calibrated parameter within EDGE_TOL of its search range's ends (unit coordinates) is "at the
# edge": defined beside the ranking's fold choice, which must agree with the verdict on it
from diagnosis.which import EDGE_TOL

#: the default of a keyword that stands for a module setting: the setting of that name is read
#: when the function is CALLED, not when the module loads, so a setting changed at run time
#: (``diagnosis.blind.decide_with``, a test's monkeypatch) is the one in force everywhere
_SETTING = object()


def _or_setting(value, setting):
    """``value``, or the module ``setting`` where the keyword was left at :data:`_SETTING`."""
    return setting if value is _SETTING else value

#: least share of the held-out gap above a correct model's that a named effect explains.
#: Set on the 18-drive blind set of the independent truth family (the rule of
#: ``diagnosis.blind.sweep``: no confident wrong answer, then the mean of the right-effect
#: and the right-no-effect rates, then nearness to the previous values), checked on the
#: 22 drives of the nominal family; docs/diagnosis.md "Blind set of the verdict".
SHARE_MIN = 0.3
#: largest mean z^2 of the calibrated model's axle-to-body transmissibility against the
#: measurement for its signature to agree (a correct model gives about 1; the standard
#: errors carry a 1 % leakage floor, see diagnosis.compare.transmissibility)
SIGNATURE_CHI2_MAX = 2.0
#: or, where the nominal model's transmissibility is off, the least share of its excess
#: (``chi2_nominal - 1``) the candidate must remove
#: (first set on three drives: effects that do not act on the transmissibility removed
#: -0.05 and 0.08 of it on independent-truck drives -- the scatter between simulations --
#: leaf friction on the embedded drive, whose truth also has a flexible frame, 0.28;
#: kept by the 40-drive blind set's sweep, docs/diagnosis.md)
SIGNATURE_SHARE_MIN = 0.15
#: least improvement of a named effect over the nominal model, in sd of its paired noise
#: (``improvement / null_improvement_sd`` of its ranking entry), for confidence "clear" and for
#: ``identified``.  The ranking accepts against the paired
#: null's mean, which is negative where calibrations fit noise, so an effect can be accepted
#: while improving on the nominal model by less than 2 sd.  Set after a blind failure: on 20
#: independent-truck drives without a library effect, leaf friction 337 N was named "clear" at
#: 1.7 sd; on the saved blind sets the rule downgrades one right "clear" (nominal case 2, leaf
#: friction 593 N at 1.7 sd) and no other (docs/diagnosis.md)
CLEAR_Z_MIN = 3.0
#: A winner whose signature disagrees is still NAMED (confidence "ambiguous", never
#: ``identified``) when it takes the whole gap:
#: it explains at least FULL_SHARE_MIN of the held-out gap above a correct model's AND its
#: held-out gap is within FULL_GAP_Z sd of a correct model's (``residual``), with the ranking's
#: own verdict clear (no close rival) and a gap beyond noise. Without it, an effect that acts
#: on axle and body alike (sensor low-pass, tyre enveloping, speed scale) on a drive whose
#: transmissibility is off for the nominal model too can never be named: on the 22-drive
#: nominal blind set 4 right effects (damper asymmetry, tyre enveloping, speed scale, sensor;
#: shares 0.89-1.08, gap within -0.2..+1.1 sd of a correct model's) were `unexplained`.
#: Set on that set; checked on the independent truck's 38 blind drives (18 with and without
#: library effects, 20 without), where no drive meets it (the nearest: shares 0.79-0.80 with
#: gaps 20-33 sd above a correct model's): docs/diagnosis.md "Named on the gap alone".
FULL_SHARE_MIN = 0.8
FULL_GAP_Z = 2.0
#: NAMED AS A VEHICLE DIFFERENCE: a winner that fails only the transmissibility test (3.) is
#: still named (confidence "ambiguous", never ``identified``) when it changes the vehicle itself
#: (``Effect.acts_on_vehicle``: suspension terms or masses; a single effect), explains at
#: least VEHICLE_SHARE_MIN of the held-out gap above a correct model's, with the ranking's own
#: verdict clear (no close rival), no range edge and a gap beyond noise.  Why: on a four-axle
#: truck the single-input transmissibility moves with the road (docs/diagnosis.md, "Signature:
#: two-input transmissibility") and fails right models of nonlinear effects (leaf friction
#: 2487 N calibrated 2643 N, 92 % of the gap: nominal 2.86, model 3.74, the model against its
#: own records on other road phases 1.1-2.2); the wrong names the test exists to stop were, on
#: every saved blind set, effects that act on the road input or the recorded channels (sensor,
#: tyre enveloping: a road-band misfit looks like a low-pass) or vehicle effects explaining
#: less than half the gap.  The same rule and share the closed loop has corrected with since
#: 2026-11-28 (``diagnosis.closed_loop.CLOSEST_SHARE_MIN``), now said by the verdict itself.
#: Re-decided on the 931 saved blind diagnoses: 13 right names gained, 0 wrong (the nearest
#: wrong: a damper asymmetry at 0.49 and a frame flexibility at 0.46 of the gap); on 56 fresh
#: drives afterwards it changed no verdict; tested fresh at stop 62 on 60 drives of the
#: independent truck with leaf friction (stated first): it fired on 2, both right names gained,
#: 0 lost, 0 wrong (results/diagnosis_blind/20261130-vehicle-difference-powered/;
#: docs/diagnosis.md, "A vehicle effect taking most of the gap, named as a vehicle
#: difference").  None: off.
VEHICLE_SHARE_MIN = 0.6
#: A LOW-PASS NAMED ON THE TWO-INPUT TRANSMISSIBILITY (stop 68): a sensor or tyre-enveloping
#: winner (``LOWPASS_EFFECTS``) that fails only the single-input transmissibility is named
#: (confidence "ambiguous", never ``identified``) when it takes the whole gap -- at least
#: FULL_SHARE_MIN of the held-out gap above a correct model's, its held-out gap within
#: FULL_GAP_Z sd of a correct model's -- AND the nominal model's two-input transmissibility lies
#: within what a correct model reaches against itself on other road phases
#: (``signature_two_input.chi2_correct_model``, its largest value): no vehicle-side difference
#: shows, so what keeps the single-input ratio off is the road (it moves with the road on a
#: four-axle truck), which a low-pass leaves where it was.  Unlike "named on the gap alone" the
#: ranking may be ambiguous (the other low-pass close: their shapes differ only in detail).
#: Why: on every saved blind drive of our truck with a true low-pass answered `unexplained` on
#: the single-input ratio the nominal two-input mean z^2 was 0.5-1.0 (a correct model's own
#: 0.6-1.0), while the independent truck's no-effect drives named a low-pass by the gap showed
#: 1.0-6.2 (its structure differs) and left gaps 3-33 sd above a correct model's.  Re-decided on
#: 1589 saved blind drives: 4 right names gained, 1 wrong (`ambiguous`: a sensor named tyre
#: enveloping); stated, then tested on 36 fresh drives (seed 641): it fired once, right, and gave
#: no name on a no-effect drive (results/diagnosis_blind/20261130-lowpass-two-input-stop68/).
#: False: off.
LOWPASS_TWO_INPUT = True
#: A VEHICLE EFFECT NAMED ON ITS TWO-INPUT TRANSMISSIBILITY (stop 69, stated and tested on fresh
#: drives before it is switched on): a winner that changes the vehicle itself
#: (:func:`acts_on_vehicle`) and fails only the single-input transmissibility -- its share of the
#: gap above a correct model's at least ``share_min``, no range edge, a nominal gap beyond noise --
#: is named (confidence "ambiguous", never ``identified``) when the CALIBRATED model's two-input
#: transmissibility (``signature_two_input.chi2_model``, that record's model the winner) lies within
#: what a correct model reaches against itself on other road phases (its largest
#: ``chi2_correct_model``).  The single-input ratio moves with the road on a four-axle truck (a
#: body station's acceleration follows both axles of its bogie and the other end's); the two-input
#: one does not, and a vehicle the model describes well there has nothing left for the test to
#: find.  Not the 2.0 floor of :func:`signature_threshold`: the independent truck's no-effect drives
#: that a leaf friction shrinks reach 1.4-2.1 against a correct model's 0.7-0.9.  Found on the
#: 1681 saved blind summaries (+3 right, nothing else changed); stated, then 88 fresh drives (seeds 647
#: and 653, 16 of them frame flexibilities and bump stops aimed at it): it fired on none, so the bar
#: (at least one right name) was not met and it stays off
#: (results/diagnosis_blind/20261130-vehicle-two-input-stop69/).  False: off.
VEHICLE_TWO_INPUT = False
#: low-pass effects: a causal low-pass of the recorded channels (``sensor``) or a spatial
#: low-pass of the road input (``tyre_enveloping``).  Their filter acts on the axle and the body
#: acceleration alike, so every channel ratio -- the axle-to-body transmissibility included --
#: cancels it: the transmissibility "agrees" with such a candidate because the effect leaves it
#: where the nominal model had it, which confirms nothing; and their roll-off has the shape of
#: a road's own high-band roll-off.  Measured (stop 64,
#: results/diagnosis_blind/20261130-measured-road-nominal/): our own truck, no effect, on the
#: measured road profile -- a sensor named on 5 of 8 drives, 2 of them `clear`, and tyre
#: enveloping `clear` on a drive without it.  So a low-pass name is never `clear` (nor
#: "identified"): a caveat says why and what to check.  The name itself stays (on synthetic
#: roads it is right in most cases).  Since stop 66 the speed dependence that separates a sensor
#: from the road (its cutoff fixed in Hz, a road's in cycles/m) tests a sensor where it has power
#: and chooses between a tyre and a sensor that tie (``HZ_RULE``); neither name becomes `clear`.
LOWPASS_EFFECTS = ("sensor", "tyre_enveloping")
#: the smallest deviation from "no effect" the verdict names, per effect: effect ->
#: (parameter, neutral value, smallest relative deviation).  A winner calibrated closer to
#: neutral than this is not named: it is no cause a user could act on, only a knob that took up
#: a small remainder.  speed_scale: a vehicle's speed signal is not known better than about 1 %
#: (a wheel-speed signal follows the rolling radius, which tread wear, load and pressure move by
#: that much and more), so a 0.2 % speed error "explaining" a gap is a fit, not a finding.  Set
#: (2026-11-28, stop 43) from the saved blind sets: the only two wrong speed_scale names ever
#: made were at factors 0.9965 and 0.9977 on drives without a library effect (20261124 set;
#: independent truck of 20261128-pool-fresh-40), every right one at 2.05 % or more (the
#: blind benchmark draws 2-10 %); checked blind only by the next set.
NEGLIGIBLE = {"speed_scale": ("factor", 1.0, 0.01)}
#: The other way round, NAMED ON THE SIGNATURE: a winner that explains less than ``share_min``
#: of the gap (but some of it: the ranking accepted it) is still named (confidence
#: "ambiguous", never ``identified``) when it removes at least SIGNATURE_STRONG of the nominal
#: model's transmissibility excess (``(chi2_nominal - chi2_model) / (chi2_nominal - 1)``, the
#: nominal off): the road-independent evidence points at it, and the small share says a
#: larger difference no library lists is there beside it. On the independent truck's 18-drive
#: blind set 2 right effects were `unexplained` for their share alone (payload case 14: share
#: 0.16, transmissibility excess removed 0.53; leaf friction case 16: 0.26 and 0.73); every
#: other `unexplained` drive of the saved blind sets (nominal family and the 20 no-effect
#: drives of the independent truck included) removes at most 0.09 of it. Set on the
#: independent truck, checked on the nominal family (no drive meets it):
#: docs/diagnosis.md "Named on the signature".
SIGNATURE_STRONG = 0.5
#: which axle-to-body transmissibility the signature test (3.) uses: ``"two_input"``
#: (:func:`diagnosis.compare.transmissibility_two_input`: body acceleration of a station on
#: BOTH axle accelerations of that station, which does not depend on the road's cross-track
#: coherence) where the summary holds it (``signature_two_input``), else -- and with
#: ``"single_input"`` -- the single-input ratio (:func:`diagnosis.compare.transmissibility`,
#: ``signature``), which on a four-axle truck still depends on the road
#: (docs/diagnosis.md, "Signature: two-input transmissibility")
SIGNATURE_METHOD = "single_input"
SIGNATURE_METHODS = ("two_input", "single_input")


_MEASURE = {
    "single_input": "mean of ((ln|H_meas| - ln|H_sim|) / se)^2 over tested pair x band cells, "
                    "axle to body acceleration per wheel position",
    "two_input": "mean of ((ln|H_meas| - ln|H_sim|) / se)^2 over tested cells (input, output) x "
                 "band, body acceleration of a station on both axle accelerations of that station "
                 "(H = S_xx^-1 S_xy per bin); bands whose two inputs are nearly fully coherent "
                 "are not resolved and not tested"}


@dataclass(frozen=True)
class Signature:
    """Axle-to-body transmissibility of the nominal and of the candidate model against the
    measurement: mean z^2 over the tested cells and the number flagged (BH).  ``method``:
    ``single_input`` (:func:`diagnosis.compare.transmissibility`) or ``two_input``
    (:func:`diagnosis.compare.transmissibility_two_input`; ``n_unresolved`` cells of the
    candidate's comparison not resolved)."""

    model: str
    chi2_nominal: float
    chi2_model: float
    n_cells: int
    flagged_nominal: int
    flagged_model: int
    pairs_off: tuple = ()
    method: str = "single_input"
    n_unresolved: int | None = None
    #: mean z^2 of the candidate model's record against surrogate measurements the same
    #: model made on other road phases of the same drive: what it would reach if it were right
    chi2_null: tuple = ()

    def record(self) -> dict:
        out = {"model": self.model, "chi2_nominal": _f(self.chi2_nominal),
               "chi2_model": _f(self.chi2_model), "n_cells": int(self.n_cells),
               "flagged_nominal": int(self.flagged_nominal),
               "flagged_model": int(self.flagged_model), "pairs_off": list(self.pairs_off),
               "measure": _MEASURE[self.method], "method": self.method}
        if self.n_unresolved is not None:
            out["n_unresolved"] = int(self.n_unresolved)
        if self.chi2_null:
            out["chi2_correct_model"] = [_f(v) for v in self.chi2_null]
        return out


def _f(v):
    v = float(v)
    return v if math.isfinite(v) else None


def transmissibility_chi2(tr) -> tuple[float, int, int, tuple]:
    """(mean z^2, tested cells, flagged cells, pairs with a flagged cell) of a
    :class:`diagnosis.compare.Transmissibility`."""
    z = np.asarray(tr.log_ratio, float) / np.asarray(tr.se, float)
    ok = np.isfinite(z)
    sig = np.asarray(tr.significant, bool) & ok
    pairs = tuple(f"{a}->{b}" for (a, b), row in zip(tr.pairs, sig) if row.any())
    n = int(ok.sum())
    return (float(np.mean(z[ok] ** 2)) if n else float("nan")), n, int(sig.sum()), pairs


def signature(model_name: str, tr_nominal, tr_model, method: str = "single_input",
              null=()) -> Signature:
    """:class:`Signature` of a candidate from the nominal model's and the candidate's
    transmissibility against the measurement (``Transmissibility`` for ``single_input``,
    ``TwoInputTransmissibility`` for ``two_input``); ``null``: the mean z^2 a correct model
    reaches on this drive (:func:`diagnosis.pipeline.signature_null`)."""
    if method not in SIGNATURE_METHODS:
        raise ValueError(f"method must be one of {', '.join(SIGNATURE_METHODS)}, got {method!r}")
    c0, n0, f0, _ = transmissibility_chi2(tr_nominal)
    c1, n1, f1, p1 = transmissibility_chi2(tr_model)
    nu = getattr(tr_model, "n_unresolved", None) if method == "two_input" else None
    return Signature(model_name, c0, c1, min(n0, n1), f0, f1, p1, method, nu,
                     tuple(float(v) for v in null))


#: one-sided level of the prediction bound on a correct model's signature (:func:`signature_threshold`)
SIGNATURE_NULL_LEVEL = 0.95
#: does the verdict hold a candidate's signature to its own scatter (:func:`signature_threshold`)
#: instead of the fixed ``SIGNATURE_CHI2_MAX``?  Built and measured, NOT the default: on the saved
#: blind sets it named 2 more library effects right on our truck (8/16 -> 10/16) and changed
#: nothing on the independent truck, but on 20 further drives of the independent truck without a
#: library effect (the inversion benchmark's `second` set, diagnosed by the closed loop) it named
#: an effect with confidence "clear" on 3 (damper asymmetry, a sensor low-pass on the measured
#: road: their own scatter over 4 road phases spans 0.6-5.4, so the bound reaches 8-9) where the
#: fixed threshold names 1 (docs/diagnosis.md, "Signature held to what a correct model reaches")
SIGNATURE_USE_NULL = False
#: the sd of ln(mean z^2) of a correct model's signature about its drive's mean, pooled over
#: drives, for :func:`signature_threshold` where ``signature_null`` is on (None, the default:
#: each drive's own sd of its 4 road phases, with Student's t).  Measured over the saved blind
#: summaries holding ``chi2_correct_model``: 0.329 on our truck (166 drives) and 0.327 on the
#: independent truck (137) -- the road's share of the statistic's scatter is the estimator's,
#: not the truck's -- so ``POOLED_NULL_SD`` = 0.33 is what a pooled bound would use; with it a
#: right model exceeds the 0.95 bound on 7 % of our truck's drives.  NOT the default
#: (docs/diagnosis.md, "A pooled bound for the signature"): re-decided on 440 saved drives it
#: names 8 more right effects on our truck and 1 fewer on the independent truck, but adds 3
#: wrong "clear" names, sensor low-passes taken for tyre enveloping, which the fixed threshold
#: refuses only because those drives' transmissibility is off for the nominal model too.
POOLED_NULL_SD = 0.33
SIGNATURE_NULL_SD = None
#: corroborated signature: where the chosen (single-input) signature disagrees at the fixed
#: threshold, does it still agree when BOTH (a) its mean z^2 lies within what the candidate
#: model reaches against its own records on other road phases (:func:`signature_threshold`)
#: and (b) the two-input signature, which the road's cross-track coherence does not enter,
#: gives positive evidence: the nominal model's is off (above ``SIGNATURE_CHI2_MAX``) and the
#: candidate removes at least ``CORROBORATE_SHARE`` of its excess?  Such a name is never
#: "clear" and never ``identified`` (see :func:`decide_one`).
#: Why (2026-11-25): blind nominal case 2 of seed 19 (leaf friction 4009 N, calibrated 4394 N,
#: 89 % of the gap explained) fails the single-input test at 3.99 while the calibrated model
#: scores 2.5-3.7 against itself (threshold 2: a right model fails it there), and its two-input
#: transmissibility goes 19.8 -> 3.04.  Re-decided on the 45 saved blind summaries that hold
#: both records: 2 drives gain the right name (leaf friction, one per family), none changes
#: otherwise; with mere two-input agreement instead of positive evidence 3 wrong names were
#: added (sensor -> tyre enveloping, speed scale and a sensor on no-effect drives of the
#: independent truck: effects that leave the transmissibility where it was).
SIGNATURE_CORROBORATE = True
#: share of the nominal model's two-input excess (mean z^2 - 1) the candidate must remove to
#: corroborate (positive evidence, not mere agreement; as SIGNATURE_STRONG)
CORROBORATE_SHARE = 0.5
#: a near tie of the gap between the ranking's winner and a rival is broken by the
#: transmissibility (:func:`decide`): set a priori (2026-11-25, no saved summary holds a
#: rival's signature), a rival 30 % nearer the measurement in mean z^2; checked blind after
SIGNATURE_TIE_BREAK = True
TIE_RATIO = 0.7

#: effects whose road-independent signature is a statistic of their own rather than the
#: axle-to-body transmissibility (which they barely move): effect -> summary record
#: ``signature_own`` made by :func:`own_signature` from
#: :func:`diagnosis.compare.stroke_velocity_skewness`.  A damper asymmetry makes the stroke
#: velocity lopsided; a linear truck on a Gaussian road leaves it symmetric.  For these
#: effects test 3. is the own signature, both ways: it can name an effect whose
#: transmissibility stays off for reasons of the road (blind nominal case 5 of
#: 20261127-relevel-fresh-40: ratio 2.94, 74 % of the gap explained, transmissibility 4.94
#: -> 4.97 -- `unexplained`), and it withholds a name the measurement's velocity
#: distribution does not support (damper asymmetry was named on drives without it, e.g.
#: case 13 of 20261127-fresh-40).  Added 2026-11-27 after reading those sets; checked blind
#: afterwards (docs/diagnosis.md, "Own signature").
#: The statistic was the moment skewness until 2026-11-27 and is the L-skewness since
#: (:func:`diagnosis.compare.stroke_velocity_l_skewness`; docs/diagnosis.md, "The own
#: signature's statistic"): the third moment's road-phase scatter is heavy-tailed (one
#: rough patch or a tyre lifting off carries it), which refused both damper drives of the
#: seed-73 blind check with the right model (z 3.1 and 4.8).  Saved summaries keep the
#: statistic they were made with (``signature_own["statistic"]``) and are re-decided with it.
OWN_SIGNATURE = {"damper_asymmetry": "stroke_velocity_l_skewness"}
#: is the own signature used (else every effect takes the transmissibility test)
SIGNATURE_OWN = True
#: positive evidence asked of an own signature: the nominal model's value lies at least
#: OWN_Z_NOMINAL prediction sd from the measurement (two-sided 1.2 % for a Gaussian
#: statistic), the candidate's within OWN_Z_MODEL, and the candidate removes at least
#: OWN_SHARE of the nominal's difference.  OWN_Z_MODEL is the two-sided 98 % point of a t
#: with the 8 degrees of freedom of the pooled sd (2.90, rounded): a right model must not
#: be rejected for a skewness estimate's heavy tail.  It was 2.0 in the first version and
#: raised after the development run of blind case 5 (20261127-relevel-fresh-40; ratio 2.94,
#: measured +0.35, the calibrated model +0.24 at z 2.35, the TRUE model's own records
#: +0.17..+0.27): a seen case, so the blind set after it is the check.
#: OWN_SHARE is one-sided since 2026-11-27 (night): the candidate must MOVE the statistic from
#: the nominal's value towards the measurement by at least OWN_SHARE of the nominal's
#: difference; beyond the measurement (overshoot) only OWN_Z_MODEL bounds it.  It was
#: ``|m - mean b| <= (1 - OWN_SHARE) |m - mean a|``, which also capped the overshoot at half
#: the difference, a second bound on the same side as OWN_Z_MODEL and one without a noise
#: scale: blind case 5 of 20261127-frame-grid-fresh-40 (ratio 2.99, calibrated 3.33) was
#: refused by that cap alone, its model having moved the statistic 1.52 of the way at z -1.35.
#: Re-deciding every saved summary with truth changes that drive only.
#: 2.0 since stop 59 (2026-11-29; 2.5 before, two-sided 1.2 %): two-sided 4.6 %, a conventional
#: level for a test that confirms a candidate which has already taken its share of the gap.  Two
#: fresh damper asymmetries of our truck (3.66 and 3.33, stops 58 and 59) stopped at z +2.4 and
#: +2.0 with their gap explained and their value right; re-deciding every saved blind summary
#: (about 450 drives, both trucks) at 2.0 names exactly those two and changes nothing else (no
#: new name on a drive without a damper asymmetry).  In sample: tested, as stated before it ran,
#: on the next fresh set (results/diagnosis_blind/20261129-own-z-2/decision.txt).  The search
#: side of a damper asymmetry keeps 2.5 (OWN_Z_SIDE): calibrations are unchanged
#: Stop 67: 1.645, the one-sided 5 % point (the test IS one-sided: the candidate must move the
#: statistic towards the measurement, ``moved >= OWN_SHARE``, so only a departure on the side the
#: candidate makes counts; 2.0 was one-sided 2.3 %).  Four right damper asymmetries of our trucks
#: (ratios 2.15-2.89, z 1.71-1.81, each ranked first with its share of the gap) were
#: `unexplained` at 2.0; re-deciding all 1477 saved blind summaries at 1.645 names exactly those
#: four and changes nothing else.  A name between 1.645 and OWN_Z_CLEAR is never "clear" (the
#: evidence is at a conventional level, not beyond it).  Tested fresh as stated in
#: results/diagnosis_blind/20261130-own-z-one-sided-stop67/decision.txt.
OWN_Z_NOMINAL = 1.645
OWN_Z_CLEAR = 2.0
#: where the measured own signature departs this far from the nominal model, a damper asymmetry
#: is searched on that side of 1 only (diagnosis.pipeline.OWN_SIDE); the verdict's threshold
#: until stop 59, kept here so that the search ranges stay those of the sets before
OWN_Z_SIDE = 2.5
OWN_Z_MODEL = 3.0
OWN_SHARE = 0.5
@dataclass(frozen=True)
class OwnStatistic:
    """What the verdict and the report need of an own-signature statistic (the function that
    computes it: :data:`diagnosis.compare.OWN_STATISTICS`, same keys)."""

    name: str        # how reasons and reports name it
    measure: str     # what it is, for summary.json
    sd_floor: float  # smallest prediction sd over road phases [-]


#: every own-signature statistic a summary may carry (``signature_own["statistic"]``,
#: ``meta.own_side.statistic``).  ``sd_floor``: with 2 x 5 records the pooled sd can come out
#: small by chance.  Skewness: 0.03, below every value measured on the development drives
#: (0.011-0.23 for the station mean over 3 road phases, mostly 0.05).  L-skewness: 0.003,
#: chosen on our truck's 100 saved blind drives without a damper asymmetry (nominal model's
#: sd over 5 phases 0.0023-0.0085, 5-95 %; 0.003 takes a side on 2 of them, 0.002 on 3, no
#: damper drive's departure falls below 4.4 sd with either); checked on the independent
#: truck's 72 (7 sides at 0.003).
OWN_STATISTICS_USED = {
    "stroke_velocity_skewness": OwnStatistic(
        "stroke-velocity skewness",
        "mean over the wheel stations of the skewness of the suspension stroke velocity "
        "(suspension displacement band-passed 0.5-15 Hz, differentiated)", 0.03),
    "stroke_velocity_l_skewness": OwnStatistic(
        "stroke-velocity L-skewness",
        "mean over the wheel stations of the L-skewness (Hosking 1990) of the suspension stroke "
        "velocity (suspension displacement band-passed 0.5-15 Hz, differentiated)", 0.003),
    # stop 66: the speed test of the two low-passes (diagnosis.hz_fixed); floor 0.1, below the
    # nominal model's sd over 5 road phases on the development drives (0.08-0.45 on ISO roads)
    "hz_fixed_slope": OwnStatistic(
        "speed test (high-band slope against speed at fixed spatial frequency)",
        "pooled within-segment slope, against ln speed, of the record-minus-nominal log power "
        "of the axle accelerations at fixed spatial frequency (0: a roll-off fixed in cycles/m, "
        "as a road or a tyre; negative: fixed in Hz, as a sensor low-pass)", 0.1),
}
#: the floors by statistic, and the floor of the statistic in use
OWN_SD_FLOORS = {k: v.sd_floor for k, v in OWN_STATISTICS_USED.items()}
OWN_SD_FLOOR = OWN_SD_FLOORS[OWN_SIGNATURE["damper_asymmetry"]]


def own_statistic(key: str | None) -> OwnStatistic:
    """The :class:`OwnStatistic` of ``key``; a missing or unknown key means the statistic in
    use (``OWN_SIGNATURE``)."""
    return OWN_STATISTICS_USED.get(key) or OWN_STATISTICS_USED[OWN_SIGNATURE["damper_asymmetry"]]


#: a winner calibrated at an edge of its search range is still named (``ambiguous``, never
#: ``clear`` nor ``identified``, the value a bound) when its own road-independent signature
#: agrees: the edge rule withholds a name because a value pinned at the range's end may
#: stand for another difference the range cannot hold, and the own signature is the
#: independent test of identity the transmissibility is not.  Decided 2026-11-27 from the
#: saved blind sets (docs/diagnosis.md, "Edge and own signature"): an edge-free re-decision
#: of every saved summary names 7 right and 10 wrong (some drives decided in several sets);
#: every wrong one is on the independent truck (payload at -14 t on friction drives 6, a
#: damper ratio at 6 before the own signature existed 3, frame 1), and the one edge winner
#: with an own signature record was right (our truck, ratio 3.71 at 2.34 / 8.0)
OWN_EDGE_NAMES = True


def own_signature(effect: str, measured: float, nominal, model) -> dict:
    """The ``signature_own`` record: the measured value of ``OWN_SIGNATURE[effect]``'s
    statistic and the nominal and candidate models' values on the same road phases (lists,
    one per phase).  The verdict (:func:`own_signature_agrees`) derives everything else, so
    a saved summary can be re-decided with other thresholds."""
    stat = OWN_SIGNATURE[effect]
    return {"effect": effect, "statistic": stat, "measure": own_statistic(stat).measure,
            "measured": _f(measured), "nominal": [_f(v) for v in nominal],
            "model": [_f(v) for v in model]}


def own_signature_agrees(record: Mapping, z_nominal: float = _SETTING,
                         z_model: float = _SETTING, share: float = _SETTING) -> dict:
    """Does the own signature give positive evidence for the candidate?

    With ``m`` the measured value, ``a`` and ``b`` the nominal and candidate models' values
    over the same road phases (n each) and ``s`` their pooled sd (at least the record's
    statistic's ``sd_floor``, :func:`own_statistic`),
    the prediction sd of one measurement against a model's mean is ``s sqrt(1 + 1/n)``:
    ``z0 = (m - mean a) / sd``, ``z1 = (m - mean b) / sd``.  Agrees when ``|z0| >= z_nominal``
    (the nominal model does not make what was measured), ``|z1| <= z_model`` (the candidate
    does) and the candidate moves the statistic towards the measurement by at least ``share``
    of the nominal's difference, ``(mean b - mean a) / (m - mean a) >= share`` (an overshoot is
    bounded by ``z_model`` alone).  Returns the numbers, ``moved`` (that fraction) and
    ``agrees`` (None where the record lacks values)."""
    z_nominal = _or_setting(z_nominal, OWN_Z_NOMINAL)
    z_model = _or_setting(z_model, OWN_Z_MODEL)
    share = _or_setting(share, OWN_SHARE)
    m = record.get("measured")
    a = np.asarray([v for v in record.get("nominal") or [] if v is not None], float)
    b = np.asarray([v for v in record.get("model") or [] if v is not None], float)
    if m is None or a.size < 2 or b.size < 2:
        return {"agrees": None}
    n = _own_numbers(m, a, b, own_statistic(record.get("statistic")).sd_floor)
    ok = bool(abs(n["z_nominal"]) >= z_nominal and abs(n["z_model"]) <= z_model
              and n["moved"] >= share)
    return {"agrees": ok, **n, "statistic": record.get("statistic")}


def _own_numbers(m: float, a: np.ndarray, b: np.ndarray, floor: float) -> dict:
    """The measured value ``m`` against the nominal (``a``) and candidate (``b``) models' values
    over the same road phases: their pooled sd (at least ``floor``) as the prediction sd of one
    measurement against a model's mean, ``s sqrt(1 + 2/(na + nb))``; ``z_nominal``, ``z_model``
    and ``moved`` (the fraction of the way from the nominal's mean to ``m`` the candidate's
    mean lies).  What :func:`own_signature_agrees` and :func:`hz_test` both judge."""
    pooled = math.sqrt((((a - a.mean()) ** 2).sum() + ((b - b.mean()) ** 2).sum())
                       / (a.size + b.size - 2))
    sd = max(pooled, floor) * math.sqrt(1.0 + 2.0 / (a.size + b.size))
    d0, d1 = float(m) - float(a.mean()), float(m) - float(b.mean())
    moved = (float(b.mean()) - float(a.mean())) / d0 if d0 != 0.0 else 0.0
    return {"z_nominal": d0 / sd, "z_model": d1 / sd, "sd": sd, "moved": moved,
            "nominal_mean": float(a.mean()), "model_mean": float(b.mean()), "measured": float(m)}


#: THE SPEED TEST OF THE LOW-PASSES (stop 66; :mod:`diagnosis.hz_fixed`, summary record
#: ``signature_hz``).  A sensor low-pass and a spatial low-pass (tyre enveloping, or a road
#: whose short waves fall off faster than the fitted road's) fit the held-out gap about
#: equally and no channel ratio tells them apart; speed does: a sensor's roll-off stays at its
#: cutoff in Hz, a road's or a tyre's moves with speed.  The measurement shows a roll-off fixed
#: in Hz (a "deficit") when its statistic lies at least HZ_Z prediction sd BELOW the nominal
#: model's (one-sided); a calibrated sensor "moves" the statistic the fraction HZ_MOVED of the
#: way (between half and twice the measured departure: the statistic is steep in the cutoff,
#: a few % of calibration error move it by more than its road-phase scatter).  Two rules:
#:
#: ``"replace"`` (the first, stated and tested fresh at stop 66: FAILED its test, see
#: results/diagnosis_blind/20261130-speed-test-stop66/): a sensor is confirmed only by the speed
#: test (deficit, moved, and its two-input transmissibility agreeing: a vehicle difference is
#: fixed in Hz too), never by the transmissibility; a tyre enveloping is refuted where the
#: deficit is measured and the tyre model makes less than half of it; a tyre winner refuted so,
#: with a close sensor rival that passes, gives the sensor.  It lost a right tyre enveloping (the
#: truth's tyre showed a deficit the tyre model does not make) and a right sensor on the measured
#: road (where the nominal model's own scatter is too large for any deficit to show, and "not
#: confirmed" became "refuted").
#:
#: ``"powered"`` (the second, from that failure): the test decides only where it has power --
#: the calibrated sensor's own value lies at least HZ_POWER_Z sd from the nominal model's.  There
#: a sensor is confirmed (deficit, moved, two-input transmissibility agreeing) or refuted (any of
#: them failing); where it has no power the transmissibility rules stand as before.  A tyre
#: enveloping is never refuted by it; only where the ranking's winner is a tyre enveloping with
#: a sensor as its close rival does it choose: the sensor, when its test confirms it and the tyre
#: model's own value lies at least HZ_Z sd from the measurement (``ambiguous``).
#: ``"off"``: no speed test.
HZ_RULES = ("off", "replace", "powered")
#: "off" until the second rule passes its stated fresh test (the first failed its own):
#: results/diagnosis_blind/20261130-speed-test-powered-stop66/decision.txt
HZ_RULE = "off"
HZ_Z = 2.0
HZ_MOVED = (0.5, 2.0)
HZ_POWER_Z = 2.0


#: THE FRONT-TO-REAR DELAY OF A SPEED ERROR (stop 67).  A speed signal off by a factor shifts
#: every response band and no channel ratio -- the transmissibility cannot confirm it -- but one
#: thing measures it directly: a bump reaches the rear axle wheelbase/(true speed) after the
#: front one, so the measured front-to-rear delay over the nominal model's (``front_rear``,
#: diagnosis.compare.front_rear; GCC of the lag in recorded distance, 95 % intervals over time
#: blocks, one per side) IS the factor recorded/true speed.  A speed_scale winner is tested on it
#: in place of the transmissibility, both ways, where it has power:
#:   confirmed when every pair's interval excludes 1, their mean ratio lies at least DELAY_MIN
#:   from 1 (in ln), and the calibrated factor lies within DELAY_AGREE of the pairs' interval
#:   envelope;
#:   refuted when every pair's interval lies within DELAY_MIN of 1 (the delay shows no speed
#:   error a user could act on), or when the intervals are narrower than DELAY_MIN and the
#:   calibrated factor lies outside their envelope widened by DELAY_AGREE;
#:   otherwise (wide intervals, as on the measured road profile: 0.47 and 2.3) not decided
#:   here -- the transmissibility rules stand.
#: DELAY_MIN 0.015: on the saved blind drives without a speed error the delay ratio of the
#: independently written truck reads up to 1.0 % off (0.990-1.000: its geometry is not ours;
#: our truck 0.997-1.004), the speed errors drawn are 2-10 %; NEGLIGIBLE's 1 % stays the floor of
#: any name.  DELAY_AGREE 0.01: the calibrated factor lay within 0.4 % of the mean delay ratio on
#: every saved drive with a narrow interval (the ranking's gap has the delay as a term), so 1 %
#: refuses only a calibration the delay contradicts.  Set on development data (docs/diagnosis.md,
#: "The front-to-rear delay of a speed error"); tested fresh as stated in
#: results/diagnosis_blind/20261130-delay-stop67/decision.txt.
DELAY_RULE = True
DELAY_MIN = 0.015
DELAY_AGREE = 0.01


def delay_test(summary: Mapping, factor: float | None) -> dict:
    """The front-to-rear delay test of a speed_scale winner calibrated at ``factor`` (recorded /
    true speed): ``ratio`` (geometric mean over the front/rear pairs of measured/simulated
    delay), ``ci`` (envelope of their 95 % intervals), ``powered`` (the test decides),
    ``agrees`` (True/False where powered, else None) and ``why``."""
    rows = [r for r in ((summary.get("front_rear") or {}).get("delay") or [])
            if r.get("delay_ratio_meas_over_sim") and all(
                v is not None and v > 0 for v in (r.get("delay_ratio_ci95") or [None, None]))]
    out = {"statistic": "front_rear_delay", "agrees": None, "powered": False, "factor": factor}
    if not rows or factor is None or not factor > 0:
        return out
    lr = np.log([r["delay_ratio_meas_over_sim"] for r in rows])
    lo = float(np.log(min(r["delay_ratio_ci95"][0] for r in rows)))
    hi = float(np.log(max(r["delay_ratio_ci95"][1] for r in rows)))
    lf = math.log(factor)
    excl = all(r["delay_ratio_ci95"][0] > 1.0 or r["delay_ratio_ci95"][1] < 1.0 for r in rows)
    mean = float(lr.mean())
    inside = lo - DELAY_AGREE <= lf <= hi + DELAY_AGREE
    out.update(ratio=math.exp(mean), ci=[math.exp(lo), math.exp(hi)], n_pairs=len(rows),
               pairs_exclude_1=excl, factor_inside=inside)
    if excl and abs(mean) >= DELAY_MIN and inside:
        return dict(out, powered=True, agrees=True, why="confirms")
    if -DELAY_MIN < lo and hi < DELAY_MIN:
        return dict(out, powered=True, agrees=False, why="no_speed_error")
    if hi - lo < DELAY_MIN and not inside:
        return dict(out, powered=True, agrees=False, why="contradicts")
    return out


def delay_text(res: Mapping) -> str:
    """One clause on the delay test's numbers, for a reason."""
    r, (lo, hi), f = res["ratio"], res["ci"], res["factor"]
    head = (f"the front-to-rear delay measured over the nominal model's (what a speed error "
            f"scales; {res['n_pairs']} front/rear pair(s)) is {r:.4f} [{lo:.4f}, {hi:.4f}]")
    if res["why"] == "confirms":
        return (f"{head}: the recorded speed reads {r - 1:+.1%} off the true one, and the "
                f"calibrated factor {f:.4f} matches it (check the speed signal: a wheel-speed "
                f"signal follows the rolling radius, which load, pressure and wear move)")
    if res["why"] == "no_speed_error":
        return (f"{head}, within {DELAY_MIN:.1%} of 1: the delay shows no speed error a cause "
                f"could be made of, whatever the calibrated factor ({f:.4f}) takes up")
    return (f"{head}, which the calibrated factor {f:.4f} contradicts (more than "
            f"{DELAY_AGREE:.0%} outside)")


def hz_test(record: Mapping, effect: str, z: float = _SETTING, moved_range=_SETTING,
            rule: str | None = None) -> dict:
    """The speed test of low-pass ``effect`` on a ``signature_hz`` record: the numbers as
    :func:`own_signature_agrees` gives them (``z_nominal``, ``z_model``, ``sd``, ``moved``, the
    means) plus ``deficit`` (the measurement's roll-off is fixed in Hz), ``powered`` (the
    candidate's value lies ``HZ_POWER_Z`` sd or more from the nominal model's), ``agrees``
    (sensor: deficit and moved within ``moved_range``; under ``rule`` "powered" None where the
    test has no power; tyre enveloping: None, the test does not confirm it) and ``refutes``
    (tyre enveloping: deficit and moved below ``moved_range[0]``; what rule "replace" reads).
    ``agrees`` None and ``refutes`` False where the record lacks the values."""
    z = _or_setting(z, HZ_Z)
    moved_range = _or_setting(moved_range, HZ_MOVED)
    rule = HZ_RULE if rule is None else rule
    m = record.get("measured")
    a = np.asarray([v for v in record.get("nominal") or [] if v is not None and math.isfinite(v)], float)
    b = np.asarray([v for v in ((record.get("models") or {}).get(effect) or [])
                    if v is not None and math.isfinite(v)], float)
    if m is None or not math.isfinite(m) or a.size < 2 or b.size < 2:
        return {"agrees": None, "refutes": False, "powered": False, "statistic": record.get("statistic")}
    n = _own_numbers(m, a, b, own_statistic("hz_fixed_slope").sd_floor)
    deficit = bool(n["z_nominal"] <= -z)
    powered = bool(abs(n["model_mean"] - n["nominal_mean"]) / n["sd"] >= HZ_POWER_Z)
    moved, lo, hi = n["moved"], *moved_range
    out = {**n, "statistic": "hz_fixed_slope", "deficit": deficit, "powered": powered,
           "effect": effect, "rule": rule}
    if effect == "sensor":
        ok = None if (rule == "powered" and not powered) else bool(deficit and lo <= moved <= hi)
        return dict(out, agrees=ok, refutes=False)
    return dict(out, agrees=None, refutes=bool(deficit and moved < lo))


def hz_text(res: Mapping, effect: str) -> str:
    """The speed test's numbers in words (reasons and the report)."""
    if not math.isfinite(res.get("measured", float("nan"))):
        return "the speed test could not be made"
    where = ("a roll-off fixed in Hz" if res["deficit"] else "no roll-off fixed in Hz beyond the "
             "road-phase scatter")
    return (f"the speed test (high-band slope against speed at fixed spatial frequency; 0 for a "
            f"road or a tyre, negative for a roll-off fixed in Hz) reads {where}: measured "
            f"{res['measured']:+.2f}, nominal model {res['nominal_mean']:+.2f} (z "
            f"{res['z_nominal']:+.1f}, at most {-HZ_Z:g} asked), {effect} {res['model_mean']:+.2f} "
            f"(it moves the statistic {res['moved']:.0%} of the way, {HZ_MOVED[0]:.0%}-"
            f"{HZ_MOVED[1]:.0%} asked)")


def own_side(measured, nominal, z_nominal: float = _SETTING, statistic: str | None = None) -> int:
    """Which way the measurement's own-signature statistic departs from the nominal model's:
    +1 (-1) where it lies at least ``z_nominal`` prediction sd above (below) the mean of the
    nominal model's values on the signature's road phases, else 0.  The prediction sd is
    ``max(sd, floor) sqrt(1 + 1/n)`` with the nominal values' own sd (n - 1 degrees of
    freedom) and the floor of ``statistic`` (:func:`own_statistic`; default the one in use) --
    the candidate's values do not exist yet when the search range is set
    (``diagnosis.pipeline.OWN_SIDE``)."""
    z_nominal = _or_setting(z_nominal, OWN_Z_SIDE)
    a = np.asarray([v for v in (nominal or []) if v is not None], float)
    if measured is None or a.size < 2 or not math.isfinite(float(measured)):
        return 0
    floor = own_statistic(statistic).sd_floor
    sd = max(float(a.std(ddof=1)), floor) * math.sqrt(1.0 + 1.0 / a.size)
    z = (float(measured) - float(a.mean())) / sd
    return 1 if z >= z_nominal else (-1 if z <= -z_nominal else 0)


def signature_threshold(record: Mapping, signature_max: float = _SETTING,
                        level: float = _SETTING, pooled_sd: float | None = None) -> float:
    """The largest mean z^2 at which a signature agrees on this drive.

    ``signature_max``, or -- where it is higher -- the one-sided ``level`` prediction bound
    of what the candidate model reaches against its own records on other road phases
    (``chi2_correct_model``, n values): ln values taken as normal, ``exp(m + t_{n-1}(level)
    s sqrt(1 + 1/n))`` with their mean ``m`` and sd ``s`` (one value: that value).  With
    ``pooled_sd`` the sd is that value instead, known (:data:`POOLED_NULL_SD`, pooled over
    many drives; used where :data:`SIGNATURE_NULL_SD` is set), and the quantile the normal one: ``exp(m + z(level) pooled_sd sqrt(1 +
    1/n))``.  A model is not held to a standard it would miss if it were right: on a
    four-axle truck the single-input ratio moves with the road's cross-track coherence (4-13
    for the nominal model against itself on one blind drive, docs/diagnosis.md); at 0.95 a
    correct model is rejected about once in 20.
    """
    signature_max = _or_setting(signature_max, SIGNATURE_CHI2_MAX)
    level = _or_setting(level, SIGNATURE_NULL_LEVEL)
    null = [float(v) for v in (record.get("chi2_correct_model") or [])
            if v is not None and math.isfinite(v) and v > 0]
    if not null:
        return float(signature_max)
    ln = np.log(null)
    n = ln.size
    if pooled_sd is not None:
        from scipy.stats import norm

        q, sd = float(norm.ppf(level)), float(pooled_sd)
    elif n == 1:
        return max(float(signature_max), null[0])
    else:
        from scipy.stats import t as student_t

        q, sd = float(student_t.ppf(level, n - 1)), float(ln.std(ddof=1))
    bound = math.exp(float(ln.mean()) + q * sd * math.sqrt(1.0 + 1.0 / n))
    return max(float(signature_max), bound)


def chosen_signature(summary: Mapping, method: str = _SETTING) -> tuple[dict, str]:
    """The signature record the verdict uses and its method: ``summary["signature_two_input"]``
    for ``two_input`` when it holds both numbers and at least one tested cell, else
    ``summary["signature"]`` (single input; what summaries before the two-input estimate
    hold, and the fallback where no station has both axle accelerations or no band is
    resolved)."""
    method = _or_setting(method, SIGNATURE_METHOD)
    if method not in SIGNATURE_METHODS:
        raise ValueError(f"signature_method must be one of {', '.join(SIGNATURE_METHODS)}, "
                         f"got {method!r}")
    if method == "two_input":
        s2 = summary.get("signature_two_input") or {}
        if (s2.get("chi2_nominal") is not None and s2.get("chi2_model") is not None
                and (s2.get("n_cells") or 0) > 0):
            return s2, "two_input"
    return summary.get("signature") or {}, "single_input"


def edge_parameters(params: Mapping, ranges: Mapping, tol: float = EDGE_TOL) -> list[str]:
    """Names ``effect.param`` of calibrated values within ``tol`` (unit coordinates) of an
    end of their search range ``ranges[effect][param] = [lo, hi, log]``."""
    out = []
    for eff, pv in (params or {}).items():
        for p, (lo, hi, log) in (ranges.get(eff) or {}).items():
            if p not in pv or pv[p] is None:
                continue
            x = float(pv[p])
            if log and lo > 0 and x > 0:
                u = (math.log(x) - math.log(lo)) / (math.log(hi) - math.log(lo))
            else:
                u = (x - lo) / (hi - lo)
            if u <= tol or u >= 1.0 - tol:
                out.append(f"{eff}.{p}")
    return out


def _entry_edges(entry: Mapping, ranges: Mapping) -> list[str]:
    """The range edges of a winner's calibration: of every fold, except a fold at an edge whose
    value the whole record fitted worse than the other fold's (``fold_choice``,
    :func:`diagnosis.which.fold_edge_choice`: the value is then the other fold's)."""
    folds = list(entry.get("parameters_per_fold") or [entry.get("parameters") or {}])
    dropped = discarded_fold(entry)
    if dropped is not None and len(folds) > dropped:
        folds.pop(dropped)
    return sorted({e for p in folds for e in edge_parameters(p, ranges)})


def discarded_fold(entry: Mapping) -> int | None:
    """Index of the fold whose edge calibration the whole record set aside, else None."""
    ch = entry.get("fold_choice") or {}
    return int(ch["edge_fold"]) if ch.get("edge_discarded") else None


def negligible(entry: Mapping, table: Mapping = None):
    """``(parameter, value, relative deviation, limit)`` when ``entry`` (a ranking record) is
    calibrated closer to no effect than :data:`NEGLIGIBLE` allows, else None."""
    table = NEGLIGIBLE if table is None else table
    spec = table.get(entry.get("effect"))
    if spec is None:
        return None
    pname, neutral, lim = spec
    value = ((entry.get("parameters") or {}).get(entry["effect"]) or {}).get(pname)
    if value is None or not math.isfinite(float(value)):
        return None
    dev = abs(float(value) - neutral) / abs(neutral)
    return (pname, float(value), dev, lim) if dev < lim else None


def explained_share(entry: Mapping, nominal: Mapping) -> float:
    """Share of the held-out gap above a correct model's that ``entry`` removes:
    ``(before - after) / (before - g0)``, ``g0`` the nominal-vs-nominal gap (the nominal
    model scored against surrogate measurements the nominal model made: what a correct
    model reaches against one measurement).  NaN where the nominal gap is not above g0."""
    g0 = nominal.get("null_gap_mean")
    b, a = entry.get("heldout_gap_before"), entry.get("heldout_gap_after")
    if g0 is None or b is None or a is None or not b > g0:
        return float("nan")
    return float((b - a) / (b - g0))


def residual(summary: Mapping, entry: Mapping | None, top: int = 3) -> dict:
    """What is left: the held-out gap after ``entry`` (or the nominal model) against the gap
    of a correct model, and the bands where it stays furthest above."""
    nom = summary.get("nominal") or {}
    fc = nom.get("band_centres_hz") or []
    floor_b = np.asarray([np.nan if v is None else v for v in nom.get("per_band_noise_floor") or []],
                         float)
    after_b = (entry or {}).get("per_band_after") or nom.get("per_band") or []
    after_b = np.asarray([np.nan if v is None else v for v in after_b], float)
    bands = []
    if after_b.size and after_b.size == floor_b.size == len(fc):
        ex = after_b - floor_b
        for i in np.argsort(-np.nan_to_num(ex, nan=-np.inf))[:top]:
            if np.isfinite(ex[i]) and ex[i] > 0:
                bands.append({"band_centre_hz": float(fc[i]), "gap": float(after_b[i]),
                              "sampling_floor": float(floor_b[i])})
    gap = float(entry["heldout_gap_after"]) if entry else float(nom.get("heldout_gap", float("nan")))
    return {"model": entry["effect"] if entry else "nominal", "heldout_gap": gap,
            "correct_model_gap": _f(nom.get("null_gap_mean", float("nan"))),
            "correct_model_sd": _f(nom.get("null_gap_std", float("nan"))),
            "sampling_floor": _f(nom.get("noise_floor", float("nan"))),
            "nominal_gap": _f(nom.get("heldout_gap", float("nan"))),
            "bands_left": bands}


def signature_agrees(c0, c1, signature_max: float = _SETTING,
                     signature_share: float = _SETTING):
    """Does the candidate's transmissibility agree with the measurement?  ``c0``, ``c1``:
    mean z^2 of the nominal and of the candidate model (None: not computed -> None).
    Yes when ``c1 <= signature_max`` (within what a correct model gives), or when the
    nominal model is off and the candidate removes at least ``signature_share`` of the
    excess ``c0 - 1`` (the effect is there, beside differences no library lists: the
    remainder is reported).  An effect that leaves an off transmissibility as it was (a
    sensor low-pass, tyre enveloping: both act on axle and body alike) does not agree."""
    signature_max = _or_setting(signature_max, SIGNATURE_CHI2_MAX)
    signature_share = _or_setting(signature_share, SIGNATURE_SHARE_MIN)
    if c1 is None:
        return None
    if c1 <= signature_max:
        return True
    return bool(c0 is not None and c0 > signature_max
                and (c0 - c1) / (c0 - 1.0) >= signature_share)


def _signature_distance(single: Mapping | None, two: Mapping | None, method: str):
    """(method, mean z^2 of the model) a tie between two candidates is judged on: the
    two-input record where ``method`` is ``"two_input"`` and it has cells, else the single
    input; None where the record lacks the number."""
    if method == "two_input" and two and (two.get("n_cells") or 0) > 0 \
            and two.get("chi2_model") is not None:
        return float(two["chi2_model"])
    if single and single.get("chi2_model") is not None:
        return float(single["chi2_model"])
    return None


#: name a leaf friction that the body's force balance measures (:mod:`diagnosis.force_balance`,
#: read before the verdict into ``meta.force_balance``): a direct measurement of the effect's own
#: force, with no road in it, so a stronger road-independent signature than any band ratio.  It
#: names what the gap-based rules left as ``none``, ``unexplained`` or another effect -- the
#: independent truck's frictions whose calibrated model closed only a quarter of a gap its other
#: differences make (docs/diagnosis.md).  Never "clear": the gap's share is not asked.  Stated and
#: tested at stop 74 (results/diagnosis_blind/20261201-force-balance/).
FORCE_BALANCE_NAMES = True
#: least force [N] the balance must read to name a friction: the blind strengths' weak end is
#: 500 N (diagnosis.blind.STRENGTHS); on drives without friction the balance read -552..+157 N on
#: both trucks (development drives and test 2 of stop 74, 36 drives), 157 N the only one detected
FORCE_BALANCE_F_MIN = 300.0


def decide(summary: Mapping, *, tie_break: bool = _SETTING, **kw) -> dict:
    """:func:`decide_gap`, then :func:`force_balance_view`."""
    return force_balance_view(decide_gap(summary, tie_break=tie_break, **kw), summary)


def force_balance_view(d: dict, summary: Mapping, names: bool = _SETTING, f_min: float = _SETTING) -> dict:
    """The decision ``d`` with a leaf friction the force balance measures named (see
    :data:`FORCE_BALANCE_NAMES`); unchanged where the summary has no available balance."""
    names, f_min = _or_setting(names, FORCE_BALANCE_NAMES), _or_setting(f_min, FORCE_BALANCE_F_MIN)
    fb = (summary.get("meta") or {}).get("force_balance") or {}
    if not (names and fb.get("available") and fb.get("detected")) or d.get("verdict") == "leaf_friction":
        return d
    if float(fb.get("force_N", 0.0)) < f_min:
        return d
    lo, hi = fb["interval_90_N"]
    before = {k: d.get(k) for k in ("verdict", "confidence", "reason")}
    was = (f"the gap-based rules answered {before['verdict']} ({before['confidence']}): {before['reason']}"
           if before["verdict"] else "")
    return dict(d, verdict="leaf_friction", confidence="ambiguous", identified=False, edge=[],
                named_on="force_balance", before_force_balance=before,
                reason=(f"the body's own force balance measures a leaf friction of {fb['force_N']:.0f} N per "
                        f"spring (90 % {max(lo, 0.0):.0f}-{hi:.0f} N) without any road; {was}"))


def decide_gap(summary: Mapping, *, tie_break: bool = _SETTING, **kw) -> dict:
    """Verdict, confidence, reason and what is left, from a diagnosis summary: see
    :func:`decide_one` for the rules and the keywords.

    With ``tie_break`` (``SIGNATURE_TIE_BREAK``): where the ranking's winner is named but a
    rival came within noise of its held-out gap (the ranking's confidence "ambiguous") and
    the summary holds that rival's signature (``signature_rival``), the rival is named
    instead when it passes every test too and its transmissibility is nearer the
    measurement: mean z^2 at most ``TIE_RATIO`` times the winner's, two-input where both
    have it.  The gap cannot tell the two apart, the road-independent statistic can.  Only
    ever one name for another: a drive answered ``none`` or ``unexplained`` stays so.
    """
    tie_break = _or_setting(tie_break, SIGNATURE_TIE_BREAK)
    d = decide_one(summary, **kw)
    swapped = _lowpass_swap(summary, d, **kw)
    if swapped is not None:
        return swapped
    if d["verdict"] == "unexplained":
        d = with_gap_side(d, summary)
    R = summary.get("signature_rival") or {}
    rd = summary.get("ranking_decision") or {}
    if not (tie_break and R.get("effect") and d["verdict"] not in ("none", "unexplained")
            and d["verdict"] == rd.get("verdict") and rd.get("confidence") == "ambiguous"):
        return d
    both = bool((summary.get("signature_two_input") or {}).get("n_cells")
                and (R.get("two_input") or {}).get("n_cells"))
    method = "two_input" if both else "single_input"
    dw = _signature_distance(summary.get("signature"), summary.get("signature_two_input"), method)
    dr = _signature_distance(R.get("single_input"), R.get("two_input"), method)
    if dw is None or dr is None or not dr <= TIE_RATIO * dw:
        return dict(d, tie_break={"rival": R["effect"], "method": method, "winner_chi2": dw,
                                  "rival_chi2": dr, "swapped": False})
    d2 = decide_one(_rival_view(summary, R, verdict=R["effect"]), **kw)
    info = {"rival": R["effect"], "method": method, "winner_chi2": dw, "rival_chi2": dr,
            "swapped": d2["verdict"] == R["effect"]}
    if not info["swapped"]:
        return dict(d, tie_break=info)
    what = "two-input" if method == "two_input" else "single-input"
    return dict(d2, tie_break=info, identified=False, confidence="ambiguous",
                reason=(f"{d2['reason']}; {rd['verdict']} fits the held-out gap as well (within "
                        f"noise), but {R['effect']}'s {what} axle-to-body transmissibility is "
                        f"nearer the measurement (mean z^2 {dr:.2g} against {dw:.2g}), so "
                        f"{R['effect']} is named -- not 'clear'"))


def _rival_view(summary: Mapping, rival: Mapping, **decision) -> dict:
    """The summary as :func:`decide_one` would read it had the ranking chosen the close rival
    (``signature_rival``): its signatures in the winner's place, the ranking's decision updated
    with ``decision`` (``verdict``, and ``reason`` where given)."""
    return dict(summary, signature=rival.get("single_input") or {},
                signature_two_input=rival.get("two_input") or {},
                ranking_decision=dict(summary.get("ranking_decision") or {}, **decision))


def _lowpass_swap(summary: Mapping, d: Mapping, **kw) -> dict | None:
    """Where the ranking's winner is tyre enveloping and its close rival a sensor (the two
    low-passes, within noise of each other on the gap), and the speed test refutes the tyre
    (a roll-off fixed in Hz it does not make) while confirming the sensor: the sensor is named
    instead when it passes every test itself (:func:`decide_one` on it), ``ambiguous``.  The
    other way round (a sensor winner whose roll-off moves with speed) names nothing: a roll-off
    fixed in cycles/m is the road's as much as a tyre's.  None: no swap."""
    R = summary.get("signature_rival") or {}
    rd = summary.get("ranking_decision") or {}
    rec = summary.get("signature_hz") or {}
    if not (HZ_RULE != "off" and rd.get("verdict") == "tyre_enveloping"
            and R.get("effect") == "sensor" and (rec.get("models") or {}).get("sensor")):
        return None
    w, r = hz_test(rec, "tyre_enveloping"), hz_test(rec, "sensor")
    if HZ_RULE == "replace":
        if d["verdict"] == "tyre_enveloping" or not (w.get("refutes") and r.get("agrees")):
            return None
    elif not (r.get("agrees") and w.get("z_model") is not None and abs(w["z_model"]) >= HZ_Z):
        return None
    e = next((x for x in summary.get("ranking") or [] if x.get("effect") == "sensor"), None)
    if e is None:
        return None
    d2 = decide_one(_rival_view(summary, R, verdict="sensor", reason=(
        f"sensor shrinks the held-out gap from {e['heldout_gap_before']:.3g} to "
        f"{e['heldout_gap_after']:.3g}; tyre_enveloping, ranked first, comes within noise of it")),
        **kw)
    if d2["verdict"] != "sensor":
        return None
    return dict(d2, identified=False, confidence="ambiguous", lowpass_swap=True,
                reason=(f"{d2['reason']}; tyre enveloping does not make the roll-off fixed in Hz "
                        f"the speed test finds (its own value {w['model_mean']:+.2f}, z "
                        f"{w['z_model']:+.1f} from the measurement), so the sensor is named -- not "
                        f"'clear'"))


@dataclass
class _SignatureTest:
    """Outcome of test 3. for one winner (:func:`_signature_test`)."""

    agrees: bool | None            # None: no signature record
    c0: float | None               # nominal / candidate mean z^2 of the transmissibility
    c1: float | None
    sig_max: float                 # the mean z^2 the transmissibility was held to
    corroborated: bool = False     # passed on the two-input corroboration
    own: dict | None = None        # own-signature numbers, where that test replaced it


#: how the reason names the two signatures
def _what_own(own_res: Mapping) -> str:
    return (f"{own_statistic(own_res.get('statistic')).name} (its own signature; the "
            "transmissibility, which it barely moves, is not used)")


def _own_clause(own_res: Mapping, effect: str, agrees: bool, signature_max: float) -> str:
    """The clause a reason gives for a road-independent test other than the transmissibility
    (``_SignatureTest.own``): the front-to-rear delay of a speed error, the speed test of a
    low-pass, or an own-signature statistic; ``agrees`` is the test's outcome (for the speed test
    it includes the two-input transmissibility, which ``own_res['agrees']`` does not)."""
    stat = own_res.get("statistic")
    if stat == "front_rear_delay":
        return delay_text(own_res) + ("" if not agrees else
                                      " (the verdict tests a speed error on this instead of the "
                                      "transmissibility, which a speed error leaves where it was)")
    if stat == "hz_fixed_slope":
        return hz_text(own_res, effect) + (
            "" if agrees or own_res.get("two_input_ok", True) else
            f"; its two-input transmissibility disagrees with the measurement (mean z^2 "
            f"{own_res['two_input_chi2']:.2g}, at most {signature_max:.2g} asked): a roll-off fixed "
            f"in Hz with a vehicle difference beside it")
    if agrees:
        return (f"its {_what_own(own_res)} agrees: measured {own_res['measured']:+.3f}, nominal "
                f"model {own_res['nominal_mean']:+.3f} (z {own_res['z_nominal']:+.1f}), {effect} "
                f"{own_res['model_mean']:+.3f} (z {own_res['z_model']:+.1f})")
    return (f"its {_what_own(own_res)} does not single it out: measured {own_res['measured']:+.3f}, "
            f"nominal model {own_res['nominal_mean']:+.3f} (z {own_res['z_nominal']:+.1f}, at least "
            f"{OWN_Z_NOMINAL:g} asked), {effect} {own_res['model_mean']:+.3f} (z "
            f"{own_res['z_model']:+.1f}, at most {OWN_Z_MODEL:g} asked; it moves the statistic "
            f"{own_res.get('moved', float('nan')):.0%} of the way from the nominal model's value to "
            f"the measurement, at least {OWN_SHARE:.0%} asked)")


def _two_input_numbers(summary: Mapping, effect: str) -> tuple[float | None, float | None, float | None]:
    """From ``signature_two_input``: the nominal model's mean z^2 against the measurement, the
    calibrated model's (where the record is of ``effect``) and the largest a correct model reaches
    against itself on other road phases; None for what the record does not hold."""
    two = summary.get("signature_two_input") or {}
    own = [float(v) for v in (two.get("chi2_correct_model") or []) if v is not None]
    nom, mod = two.get("chi2_nominal"), two.get("chi2_model")
    return ((None if nom is None else float(nom)),
            (None if mod is None or two.get("model") != effect else float(mod)),
            (max(own) if own else None))


def _what(sig_method: str) -> str:
    return ("two-input axle-to-body transmissibility" if sig_method == "two_input"
            else "axle-to-body transmissibility")


def _signature_test(summary: Mapping, win: Mapping, sig: Mapping, sig_method: str, *,
                    signature_max: float, signature_share: float, signature_null: bool,
                    corroborate: bool, own: bool, null_sd: float | None = None) -> _SignatureTest:
    """Test 3.: the chosen transmissibility record against its threshold, the two-input
    corroboration of an off single-input one, and -- for an effect with an own signature
    (``OWN_SIGNATURE``) -- the own signature instead, both ways."""
    c0, c1 = sig.get("chi2_nominal"), sig.get("chi2_model")
    sig_max = (signature_threshold(sig, signature_max, pooled_sd=null_sd) if signature_null
               else float(signature_max))
    agrees = signature_agrees(c0, c1, sig_max, signature_share)
    corroborated = False
    if agrees is False and corroborate and sig_method == "single_input":
        s2 = summary.get("signature_two_input") or {}
        own_max = signature_threshold(sig, signature_max)
        d0, d1 = s2.get("chi2_nominal"), s2.get("chi2_model")
        # positive evidence: the nominal model's two-input transmissibility is off and the
        # candidate removes at least CORROBORATE_SHARE of its excess (an effect that acts
        # on axle and body alike leaves it where it was and corroborates nothing)
        a2 = bool((s2.get("n_cells") or 0) > 0 and d0 is not None and d1 is not None
                  and d0 > signature_max and (d0 - d1) / (d0 - 1.0) >= CORROBORATE_SHARE)
        if sig.get("chi2_correct_model") and c1 is not None and c1 <= own_max and a2:
            agrees, corroborated = True, True
            sig_max = own_max
    # an effect with a signature of its own (OWN_SIGNATURE) is tested on it, both ways:
    # the transmissibility it barely moves neither confirms nor refutes it
    rec_own = summary.get("signature_own") or {}
    if own and win["effect"] in OWN_SIGNATURE and rec_own.get("effect") == win["effect"]:
        own_res = own_signature_agrees(rec_own)
        if own_res["agrees"] is not None:
            return _SignatureTest(own_res["agrees"], c0, c1, sig_max, False, own_res)
    # a speed error: the front-to-rear delay measures it directly (DELAY_RULE), where it has power
    if DELAY_RULE and win["effect"] == "speed_scale":
        fac = ((win.get("parameters") or {}).get("speed_scale") or {}).get("factor")
        dres = delay_test(summary, fac)
        if dres["powered"]:
            return _SignatureTest(dres["agrees"], c0, c1, sig_max, False, dres)
    # a low-pass: where the speed test (HZ_RULE) has power it confirms or refutes a sensor in
    # place of the transmissibility, which cancels it; rule "replace" also refutes a tyre
    rec_hz = summary.get("signature_hz") or {}
    if HZ_RULE != "off" and ((rec_hz.get("models") or {}).get(win["effect"])):
        hz = hz_test(rec_hz, win["effect"])
        if win["effect"] == "sensor" and hz["agrees"] is not None:
            s2 = summary.get("signature_two_input") or {}
            c2 = s2.get("chi2_model") if (s2.get("n_cells") or 0) > 0 else None
            two_ok = c2 is None or c2 <= signature_max
            return _SignatureTest(bool(hz["agrees"] and two_ok), c0, c1, sig_max, False,
                                  dict(hz, two_input_chi2=c2, two_input_ok=two_ok))
        if HZ_RULE == "replace" and hz.get("refutes"):
            return _SignatureTest(False, c0, c1, sig_max, False, hz)
    return _SignatureTest(agrees, c0, c1, sig_max, corroborated, None)


#: stop 65: an ``unexplained`` gap is placed on the road's side or the vehicle's by the nominal
#: model's two-input axle-to-body transmissibility (the body of a station on both of its axle
#: accelerations; what the road under the wheels does not enter): no flagged cell (Benjamini-
#: Hochberg, q = 0.05, as reported) -> the road-independent comparison sees no vehicle difference.
#: Measured on every saved blind drive answered ``unexplained`` (one count per drive, 2026-11-23
#: to stop 65; development data, not a fresh test): our own truck with no effect (the road model is
#: all that can be wrong) 23 of 24 "road" (14 of 14 on the measured profile); the independently
#: written truck with no library effect 173 of 186 "vehicle", with a library effect the ranking
#: missed 48 of 48; our truck with a missed library effect 26 of 82 "vehicle" (the misses are mostly
#: effects the data barely show: "road" there means no vehicle difference the comparison can see)
GAP_SIDE_MIN_FLAGS = 1
#: what the rule read on those drives: (drives read right, drives) for a correct vehicle model
#: ("road") and for a truck that differs from ours ("vehicle"); the report quotes them
GAP_SIDE_MEASURED = {"road": (23, 24), "vehicle": (221, 234)}


def gap_side(summary: Mapping) -> dict | None:
    """Which side an unexplained gap most likely lies on, from the nominal model's two-input
    transmissibility against the measurement (:data:`GAP_SIDE_MIN_FLAGS`).

    Returns
    -------
    None where the record has no two-input transmissibility (no station with an axle and a body
    acceleration on both sides), else ``{"side": "road" | "vehicle", "flagged": n, "tested": m,
    "pairs": [pairs with a flagged cell], "bands_hz": [flagged band centres]}``
    """
    tr = summary.get("transmissibility_two_input") or {}
    cells = tr.get("cells") or []
    top = road_input_top_hz(summary)
    tested = [c for c in cells if c.get("p_value") is not None
              and (top is None or float((c.get("band_hz") or [0.0, 0.0])[1]) <= top)]
    if not tested:
        return None
    flagged = [c for c in tested if c.get("significant")]
    pairs = sorted({f"{c.get('input')}->{c.get('output')}" for c in flagged})
    bands = sorted({round(float(c["band_centre_hz"]), 3) for c in flagged if c.get("band_centre_hz")})
    return {"side": "vehicle" if len(flagged) >= GAP_SIDE_MIN_FLAGS else "road",
            "flagged": len(flagged), "tested": len(tested), "pairs": pairs, "bands_hz": bands,
            "road_input_top_hz": top}


def road_input_top_hz(summary: Mapping) -> float | None:
    """Up to which frequency [Hz] the road excites the vehicle all along the record: the lowest
    nmax of the diagnosis's road segments times the recorded speed's 5th percentile
    (``meta.speed_mps``, written since stop 65; None for older summaries).  Above it a band of a
    stretch holds no road input, and its transmissibility is not the vehicle's: on our nominal
    truck over a measured profile ending at 2 cycles/m, driven at 9 m/s with noise-free channels,
    the 17.8-22.4 Hz band flagged 14 two-input cells (coherence 0.41-0.54) and read "vehicle"."""
    meta = summary.get("meta") or {}
    v = (meta.get("speed_mps") or {}).get("p05")
    nmax = [r.get("nmax") for r in meta.get("road_segments") or [] if r.get("nmax") is not None]
    if v is None or not nmax:
        return None
    return float(min(nmax)) * float(v)


def with_gap_side(decision: dict, summary: Mapping) -> dict:
    """An ``unexplained`` decision with :func:`gap_side` added (``gap_side``) and said at the end
    of its reason."""
    side = gap_side(summary)
    if side is None:
        txt = ""
    elif side["side"] == "road":
        txt = ("; the nominal model's two-input transmissibility agrees with the measurement, so "
               "the gap most likely lies in the road model")
    else:
        txt = (f"; the nominal model's two-input transmissibility differs from the measurement "
               f"({side['flagged']} cells), so the vehicle differs in a way no library effect "
               "represents")
    return dict(decision, gap_side=side, reason=decision["reason"] + txt)


def _no_winner(summary: Mapping, base: dict, gap_present: bool) -> dict:
    """``none`` (no gap beyond noise) or ``unexplained`` (a gap no candidate reduces)."""
    nom = summary.get("nominal") or {}
    rd = summary.get("ranking_decision") or {}
    ranking = list(summary.get("ranking") or [])
    if not gap_present:
        return dict(base, verdict="none", confidence="none",
                    reason=rd.get("reason") or "no gap beyond noise",
                    residual=residual(summary, None))
    best = ranking[0] if ranking else None
    return dict(base, verdict="unexplained", confidence="none",
                closest=best["effect"] if best else None,
                explained_share=_f(explained_share(best, nom)) if best else None,
                reason=("the nominal model leaves a held-out gap beyond noise (gap "
                        f"{nom.get('heldout_gap', float('nan')):.3g} against "
                        f"{nom.get('null_gap_mean', float('nan')):.3g} +- "
                        f"{nom.get('null_gap_std', float('nan')):.2g} for a correct model) and "
                        "no library effect reduces it beyond noise"),
                residual=residual(summary, None))


def decide_one(summary: Mapping, *, share_min: float = _SETTING,
               signature_max: float = _SETTING,
               signature_share: float = _SETTING,
               signature_method: str = _SETTING,
               signature_null: bool = _SETTING,
               signature_null_sd: float | None = _SETTING,
               corroborate: bool = _SETTING,
               own: bool = _SETTING,
               vehicle_share: float | None = _SETTING) -> dict:
    """Verdict, confidence, reason and what is left, from a diagnosis summary.

    Reads ``summary["ranking"]`` (entries, accepted first), ``summary["ranking_decision"]``
    (the ranking's own verdict and confidence), ``summary["nominal"]``, the signature
    record :func:`chosen_signature` picks for ``signature_method`` (``signature_two_input``
    or ``signature``) and ``summary["meta"]["search_ranges"]``.  ``signature_null``: hold the
    signature to the candidate's own scatter (:func:`signature_threshold`, where the record
    has ``chi2_correct_model``) rather than to ``signature_max`` alone.  ``vehicle_share``: the
    share of the gap a vehicle effect failing only the transmissibility must explain to be named
    (:data:`VEHICLE_SHARE_MIN`; None: never).  A winner calibrated at an edge of its search range is
    ``unexplained`` (closest: that effect): the data ask for more than the range holds.

    Returns
    -------
    dict with ``verdict``, ``confidence``, ``reason``, ``explained_share``,
    ``closest`` (effect or None), ``edge`` (list), ``signature_agrees`` (bool or None),
    ``signature_method`` (the transmissibility used), ``residual`` (see :func:`residual`),
    ``thresholds``.
    """
    share_min = _or_setting(share_min, SHARE_MIN)
    signature_max = _or_setting(signature_max, SIGNATURE_CHI2_MAX)
    signature_share = _or_setting(signature_share, SIGNATURE_SHARE_MIN)
    signature_method = _or_setting(signature_method, SIGNATURE_METHOD)
    signature_null = _or_setting(signature_null, SIGNATURE_USE_NULL)
    signature_null_sd = _or_setting(signature_null_sd, SIGNATURE_NULL_SD)
    corroborate = _or_setting(corroborate, SIGNATURE_CORROBORATE)
    own = _or_setting(own, SIGNATURE_OWN)
    vehicle_share = _or_setting(vehicle_share, VEHICLE_SHARE_MIN)
    nom = summary.get("nominal") or {}
    rd = summary.get("ranking_decision") or {}
    ranking = list(summary.get("ranking") or [])
    ranges = (summary.get("meta") or {}).get("search_ranges") or {}
    gap_present = bool(nom.get("gap_present", False))
    rv = rd.get("verdict", "none")
    win = next((e for e in ranking if e.get("effect") == rv and e.get("accepted")), None)
    thresholds = {"share_min": share_min, "signature_chi2_max": signature_max,
                  "signature_share_min": signature_share, "edge_tol": EDGE_TOL,
                  "signature_method": signature_method, "signature_null": bool(signature_null),
                  "signature_null_sd": signature_null_sd,
                  "corroborate": bool(corroborate), "own_signature": bool(own),
                  "vehicle_share": vehicle_share}
    sig, sig_method = chosen_signature(summary, signature_method)
    base = {"explained_share": None, "closest": None, "edge": [], "signature_agrees": None,
            "signature_method": sig_method if sig else None, "identified": False,
            "thresholds": thresholds, "ranking_verdict": rv,
            "ranking_confidence": rd.get("confidence", "none"), "named_on": None}
    if win is None:
        return _no_winner(summary, base, gap_present)

    # --- the tests: 2. share, 3. signature, and the range edge
    share = explained_share(win, nom)
    edges = _entry_edges(win, ranges)
    st = _signature_test(summary, win, sig, sig_method, signature_max=signature_max,
                         signature_share=signature_share, signature_null=signature_null,
                         corroborate=corroborate, own=own, null_sd=signature_null_sd)
    agrees, c0, c1, sig_max, own_res = st.agrees, st.c0, st.c1, st.sig_max, st.own
    # no transmissibility at all (no wheel station logs both an axle and a body
    # acceleration): test 3. cannot be made, which counts as not confirmed -- never as agreed
    unchecked = bool(agrees is None and own_res is None and not summary.get("transmissibility"))
    what = _what(sig_method)
    out = dict(base, explained_share=_f(share), closest=win["effect"], edge=edges,
               signature_agrees=agrees, signature_max=_f(sig_max), residual=residual(summary, win),
               signature_corroborated=st.corroborated)
    if own_res is not None:
        out["signature_own"] = {k: (_f(v) if isinstance(v, float) else v)
                                for k, v in own_res.items()}
    remainder = ""
    if own_res is None and agrees and c1 is not None and c1 > sig_max:
        remainder = (f"; its {what} moves towards the measurement (mean z^2 {c0:.2g} "
                     f"-> {c1:.2g}) but stays off: a difference beyond it remains")
    sig_frac = ((c0 - c1) / (c0 - 1.0) if c0 is not None and c1 is not None and c0 > sig_max
                else float("nan"))
    on_signature = bool(own_res is None and not (share >= share_min) and share > 0
                        and sig_frac >= SIGNATURE_STRONG and gap_present)
    edge_named = bool(edges and OWN_EDGE_NAMES and own_res is not None and agrees)

    # --- what fails: any failure leaves the drive unexplained (but see on_gap_alone)
    short = []
    if not (share >= share_min) and not on_signature:
        short.append(f"it explains {share:.0%} of the held-out gap above a correct model's "
                     f"(at least {share_min:.0%} asked)" if math.isfinite(share) else
                     "its share of the gap above a correct model's is undefined")
    if agrees is False and own_res is not None:
        short.append(_own_clause(own_res, win["effect"], False, signature_max))
    elif unchecked:
        short.append(f"its road-independent signature cannot be checked: {NO_PAIR_TEXT}")
    elif agrees is False:
        short.append(f"its {what} still disagrees with the measurement "
                     f"(mean z^2 {c1:.2g}, nominal {c0:.2g}, at most {sig_max:.2g} asked"
                     + (" -- what the model reaches against itself here" if sig_max > signature_max
                        else "")
                     + (f"; off: {', '.join(sig.get('pairs_off', [])[:4])}" if sig.get("pairs_off")
                        else "") + ")")
    small = negligible(win)
    if small:
        name, value, dev, lim = small
        short.append(f"it calibrates at {name} = {value:.4g}, {dev:.2%} from no effect: below the "
                     f"{lim:.0%} that makes it a cause rather than a fit of a small remainder")
    if edges and not edge_named:
        # a winner pinned at its search range's end is not an estimate: the data ask for
        # more than the range holds; on the saved blind sets every such name was wrong (3 of
        # 3, independent truck: payload -> damper ratio at 6, leaf friction -> payload at
        # +14 t), none right (docs/diagnosis.md, "Verdict")
        short.append(f"it calibrates at the edge of its search range ({', '.join(edges)}): "
                     "the data ask for more than the range holds")
    res = out["residual"]
    gap_z = ((res["heldout_gap"] - res["correct_model_gap"]) / res["correct_model_sd"]
             if res.get("correct_model_sd") else float("nan"))
    unconfirmed = agrees is False or unchecked
    # the three ways a winner is named although test 3. did not confirm it share these: the
    # transmissibility (or its absence) is the one failure, there is a gap beyond noise, and
    # (gap alone, low-pass) the winner takes the whole gap
    only_ratio_fails = own_res is None and unconfirmed and len(short) == 1 and gap_present
    whole_gap = share >= FULL_SHARE_MIN and gap_z <= FULL_GAP_Z
    ranking_clear = rd.get("confidence") == "clear"
    on_gap_alone = only_ratio_fails and ranking_clear and whole_gap
    as_vehicle = (not on_gap_alone and only_ratio_fails and ranking_clear and vehicle_share is not None
                  and share >= vehicle_share and acts_on_vehicle(win["effect"]))
    # named on the two-input record: the single-input ratio is what failed, the two-input one
    # holds a correct model's own scatter to compare with
    two_nominal, two_model, two_own_max = _two_input_numbers(summary, win["effect"])
    on_two = (not (on_gap_alone or as_vehicle) and only_ratio_fails and agrees is False
              and sig_method != "two_input" and two_own_max is not None)
    lowpass_two = bool(LOWPASS_TWO_INPUT and on_two and whole_gap and win["effect"] in LOWPASS_EFFECTS
                       and two_nominal is not None and two_nominal <= two_own_max)
    vehicle_two = bool(VEHICLE_TWO_INPUT and on_two and not lowpass_two and acts_on_vehicle(win["effect"])
                       and two_model is not None and two_model <= two_own_max)
    if short and not (on_gap_alone or as_vehicle or lowpass_two or vehicle_two):
        return dict(out, verdict="unexplained", confidence="none",
                    reason=(f"a gap is there and no library effect explains it: the closest, "
                            f"{win['effect']}, shrinks the held-out gap from "
                            f"{win['heldout_gap_before']:.3g} to {win['heldout_gap_after']:.3g}, but "
                            + "; and ".join(short)))

    # --- named: the reason, and each caveat that keeps it from "clear"
    conf = rd.get("confidence", "clear")
    lowpass = win["effect"] in LOWPASS_EFFECTS
    reason = rd.get("reason") or ""
    reason += (f"; it explains {share:.0%} of the gap above a correct model's"
               + ("" if agrees is not True or remainder or own_res is not None or lowpass else
                  f"; its {what} agrees with the measurement")
               + remainder)
    if own_res is not None:
        reason += "; " + _own_clause(own_res, win["effect"], True, signature_max)
    caveats = []
    if (own_res is not None and own_res.get("agrees") and "z_nominal" in own_res
            and own_res.get("statistic") != "hz_fixed_slope"
            and abs(own_res["z_nominal"]) < OWN_Z_CLEAR):
        caveats.append(f"; its own signature departs from the nominal model's by "
                       f"{abs(own_res['z_nominal']):.1f} sd only (the one-sided 5 % level "
                       f"{OWN_Z_NOMINAL:g} is met, {OWN_Z_CLEAR:g} asked for 'clear')")
    if remainder and conf == "clear":
        caveats.append(" (so not 'clear')")
    if edge_named:
        caveats.append(f"; it calibrates at the edge of its search range ({', '.join(edges)}) in "
                       f"{'a fold' if len(win.get('parameters_per_fold') or []) > 1 else 'the fit'}: "
                       f"named on its own signature, the value is a bound -- not 'clear', no correction (a bound is not an estimate)")
    if on_signature:
        caveats.append(
            f"; named on its {what}: it removes {sig_frac:.0%} of the nominal model's excess "
            f"there (mean z^2 {c0:.2g} -> {c1:.2g}) though it explains only {share:.0%} of the "
            f"held-out gap above a correct model's ({share_min:.0%} asked otherwise): a larger "
            f"difference no library effect lists remains beside it -- not 'clear'")
    if on_gap_alone:
        why = (f"its road-independent signature cannot be checked ({NO_PAIR_TEXT})" if unchecked else
               f"its {what} stays off (mean z^2 {c1:.2g}, nominal {c0:.2g}, at most "
               f"{sig_max:.2g} asked): the effect does not bring it nearer, so the "
               f"signature cannot confirm it, and what keeps the transmissibility off (a difference "
               f"beyond it, or this drive's noise) is not known")
        caveats.append(
            f"; named on the gap alone: with it the held-out gap ({res['heldout_gap']:.3g}) is "
            f"a correct model's ({res['correct_model_gap']:.3g} +- {res['correct_model_sd']:.2g}), "
            f"but {why} -- not 'clear'")
    if as_vehicle:
        why = (f"road-independent signature cannot be checked ({NO_PAIR_TEXT}): the nearest "
               f"description of the vehicle the library has" if unchecked else
               f"{what} does not confirm it (mean z^2 {c1:.2g}, nominal {c0:.2g}, at most "
               f"{sig_max:.2g} asked): the nearest description of the vehicle the library has, and "
               f"something beyond it may remain")
        caveats.append(
            f"; named as a vehicle difference: it changes the vehicle itself, explains most of the "
            f"gap (at least {vehicle_share:.0%} asked) and no rival comes close, but its {why} "
            f"-- not 'clear'")
    if lowpass_two:
        caveats.append(
            f"; named on the gap and the two-input transmissibility: with it the held-out gap "
            f"({res['heldout_gap']:.3g}) is a correct model's ({res['correct_model_gap']:.3g} +- "
            f"{res['correct_model_sd']:.2g}); its single-input {what} stays off (mean z^2 {c1:.2g}, "
            f"nominal {c0:.2g}, at most {sig_max:.2g} asked), but the nominal model's two-input "
            f"transmissibility is within what a correct model reaches against itself (mean z^2 "
            f"{two_nominal:.2g}, a correct model up to {two_own_max:.2g}): no "
            f"vehicle-side difference shows -- not 'clear'")
    if vehicle_two:
        caveats.append(
            f"; named on its two-input transmissibility: its single-input {what} stays off (mean "
            f"z^2 {c1:.2g}, nominal {c0:.2g}, at most {sig_max:.2g} asked; that ratio moves with the "
            f"road on a four-axle truck), but its two-input transmissibility (a station's body on "
            f"both of its axles) is within what a correct model reaches against itself (mean z^2 "
            f"{two_model:.2g}, nominal {two_nominal:.2g}, a correct model up to {two_own_max:.2g}) "
            f"-- not 'clear'")
    if st.corroborated:
        s2 = summary["signature_two_input"]
        caveats.append(
            f"; its single-input transmissibility (mean z^2 {c1:.2g}) is off by the fixed "
            f"threshold ({signature_max:.2g}) but within what the model reaches against "
            f"itself on other road phases (up to {sig_max:.2g}), and its two-input "
            f"transmissibility agrees (mean z^2 {s2['chi2_nominal']:.2g} -> "
            f"{s2['chi2_model']:.2g}): corroborated, not 'clear'")
    dropped = discarded_fold(win)
    if dropped is not None:
        wr = win["fold_choice"]["whole_record_gap"]
        caveats.append(
            f"; one fold's calibration lay at an edge of the search range, the other's inside, and "
            f"the whole record fits the inside value better (gap summed over both window sets "
            f"{wr[1 - dropped]:.3g} against {wr[dropped]:.3g}): the value is that fold's -- not 'clear'")
    if lowpass and own_res is not None and own_res.get("statistic") == "hz_fixed_slope":
        caveats.append(
            f"; {win['effect']} is a low-pass of the recorded channels: no channel ratio can confirm "
            "it, the speed test does (its roll-off stays in Hz as the speed changes, where a road's "
            "or a tyre's moves with it); check the logger's filter settings before acting on it -- "
            "not 'clear'")
    elif lowpass:
        caveats.append(
            f"; {win['effect']} is a low-pass ({'of the recorded channels' if win['effect'] == 'sensor' else 'of the road under the tyres'}): "
            "it acts on the axle and the body alike, so no channel ratio can confirm it"
            + (" (the transmissibility agrees because the effect leaves it where it was)" if agrees else "")
            + ", and its roll-off "
            "looks like the road's own (a road whose short waves fall off faster than the fitted "
            "road's reads the same): check the logger's filter settings and the tyres before "
            "acting on it -- not 'clear'")
    z_abs = improvement_z(win)
    weak = z_abs is not None and z_abs < CLEAR_Z_MIN
    if weak:
        caveats.append(f"; it improves on the nominal model by only {z_abs:.1f} sd of its paired "
                       f"noise ({CLEAR_Z_MIN:g} asked for 'clear')")
    if not gap_present:
        # the paired comparison can see an effect the whole gap's road-phase scatter hides,
        # but then the share above is a ratio over a difference within noise (it can read
        # far over 100 %): a name that rests on the paired test alone is never 'clear'
        caveats.append(
            f"; the nominal model's own held-out gap ({nom.get('heldout_gap', float('nan')):.3g}) "
            f"is within a correct model's scatter ({nom.get('null_gap_mean', float('nan')):.3g} +- "
            f"{nom.get('null_gap_std', float('nan')):.2g}): the name rests on the paired "
            f"comparison alone, and the share is not a measure here")
    if caveats:
        conf = "ambiguous"
        reason += "".join(caveats)
    # identified: the effect is named and neither a rival nor a range edge puts its identity
    # or value in doubt (a remainder beyond it does not), and there is a gap beyond noise to
    # correct: what a correction may use
    return dict(out, verdict=rv, confidence=conf, reason=reason,
                identified=bool(rd.get("confidence") == "clear" and not edges and gap_present
                                and not weak and not lowpass and not on_gap_alone and not on_signature
                                and not as_vehicle and not vehicle_two and not st.corroborated
                                and dropped is None),
                named_on=("gap_alone" if on_gap_alone else "vehicle_share" if as_vehicle
                          else "two_input" if (lowpass_two or vehicle_two)
                          else "signature" if on_signature else None))


#: why test 3. cannot be made on a drive without an axle and a body acceleration at one station
NO_PAIR_TEXT = ("the dataset has no wheel station with both an axle and a body acceleration, "
                "so the axle-to-body transmissibility is not measured")


def acts_on_vehicle(effect: str) -> bool:
    """Whether a ranked effect changes the vehicle itself (``vehicles.effects``
    ``Effect.acts_on_vehicle``: suspension terms or masses), not the road the tyres see or the
    recorded channels; a pair ``a+b``, None or an effect the library does not hold: False. The one
    test of it for the verdict and the closed loop (``closest_vehicle_effect``)."""
    from vehicles.effects import EFFECTS

    return effect in EFFECTS and bool(EFFECTS[effect].acts_on_vehicle)


def improvement_z(entry: Mapping) -> float | None:
    """A ranking entry's held-out improvement over the nominal model in sd of its paired
    noise (``improvement / null_improvement_sd``); None where the entry lacks them."""
    imp, sd = entry.get("improvement"), entry.get("null_improvement_sd")
    if imp is None or sd is None or not sd > 0:
        return None
    return float(imp) / float(sd)


def search_ranges(candidates: Sequence) -> dict:
    """``{effect: {param: [lo, hi, log]}}`` of :class:`diagnosis.which.Candidate` objects."""
    return {c.name: {p.name: [float(p.lo), float(p.hi), bool(p.log)] for p in c.params}
            for c in candidates}
