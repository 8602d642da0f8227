"""The damper asymmetry's own signature: the stroke-velocity L-skewness (the moment skewness
before 2026-11-27), and how the verdict uses it.

References that do not come from eroad's truck:
* the L-skewness against its closed form for three distributions (uniform 0, Gumbel
  0.1699, exponential 1/3; Hosking 1990, Table 1) and against its definition as a
  U-statistic over all triples of a small sample, written out here;
* a linear oscillator on a Gaussian base motion answers with Gaussian velocities (skewness
  and L-skewness 0 whatever its stiffness and damping);
* a one-mass oscillator whose damper is stiffer in rebound (extension) than in compression
  moves slowly while extending and fast while compressing: with extension positive, the
  stroke velocity is negatively skewed, and the sign turns with the asymmetry (simulated
  here with its own few lines of semi-implicit Euler, not with eroad's models);
* both statistics are standardised: a sensor gain and offset drop out, a sign flip of the
  channel flips them.
The verdict rules are checked on summaries built by hand (numbers chosen, not simulated).
"""
import itertools
import math

import numpy as np
import pytest

from diagnosis.compare import l_skewness, stroke_velocity_l_skewness, stroke_velocity_skewness
from diagnosis.pipeline import own_signature_record
from diagnosis.signals import Signals
from diagnosis.verdict import (OWN_SD_FLOOR, OWN_SIGNATURE, OWN_Z_MODEL, OWN_Z_NOMINAL, decide,
                               own_signature, own_signature_agrees)

FS = 200.0


def _band_gauss(n, lo, hi, fs, rng):
    """Gaussian noise with a flat spectrum between lo and hi Hz (unit variance)."""
    X = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, 1.0 / fs)
    X[(f < lo) | (f > hi)] = 0.0
    x = np.fft.irfft(X, n)
    return x / x.std()


def _oscillator_stroke(ratio, T=240.0, fs_int=1000.0, seed=3):
    """Stroke (extension positive) of a body on a spring and a damper over a Gaussian base.

    Body 1.5 Hz, damping ratio 0.3 at the mean of the two coefficients; the damper
    coefficient is ``c_reb`` while extending and ``c_reb / ratio`` while compressing."""
    rng = np.random.default_rng(seed)
    n = int(T * fs_int)
    u = 0.01 * _band_gauss(n, 0.3, 20.0, fs_int, rng)
    du = np.gradient(u, 1.0 / fs_int)
    wn = 2 * np.pi * 1.5
    k, m = wn ** 2, 1.0
    c_mean = 2 * 0.3 * wn
    c_reb = 2 * c_mean * ratio / (1 + ratio)
    c_com = c_reb / ratio
    x = v = 0.0
    dt = 1.0 / fs_int
    s = np.empty(n)
    for i in range(n):
        sv = v - du[i]
        c = c_reb if sv > 0 else c_com
        a = (-k * (x - u[i]) - c * sv) / m
        v += a * dt
        x += v * dt
        s[i] = x - u[i]
    step = int(fs_int / FS)
    return s[::step][int(5 * FS):]          # 5 s of start-up dropped


def _signals(channels):
    n = len(next(iter(channels.values())))
    t = np.arange(n) / FS
    return Signals(t, channels, {c: "m" for c in channels}, np.full(n, 15.0), {})


def test_l_skewness_closed_forms():
    # 200 000 samples: the sampling sd of t3 is about 0.002 (uniform) to 0.003
    # (exponential); 0.01 is 3 sd or more
    rng = np.random.default_rng(7)
    n = 200_000
    assert l_skewness(rng.uniform(size=n)) == pytest.approx(0.0, abs=0.01)
    assert l_skewness(rng.gumbel(size=n)) == pytest.approx(0.1699, abs=0.01)
    assert l_skewness(rng.exponential(size=n)) == pytest.approx(1.0 / 3.0, abs=0.01)
    assert l_skewness(-rng.exponential(size=n)) == pytest.approx(-1.0 / 3.0, abs=0.01)
    with pytest.raises(Exception):
        l_skewness([1.0, 1.0, 1.0])


def test_l_skewness_is_its_u_statistic_definition():
    # Hosking (1990) eq. 2.3 as sample statistics: l2 = C(n,2)^-1 sum_{i<j} (x_j - x_i) / 2,
    # l3 = C(n,3)^-1 sum_{i<j<k} (x_k - 2 x_j + x_i) / 3 over the ordered sample; the
    # probability-weighted-moment formula must give the same number (rounding only)
    x = np.sort(np.random.default_rng(3).lognormal(size=14))
    l2 = np.mean([(b - a) / 2 for a, b in itertools.combinations(x, 2)])
    l3 = np.mean([(c - 2 * b + a) / 3 for a, b, c in itertools.combinations(x, 3)])
    assert l_skewness(x) == pytest.approx(l3 / l2, rel=1e-12)
    assert l_skewness(x[::-1]) == pytest.approx(l3 / l2, rel=1e-12)      # order does not matter


# per statistic: the bound on a Gaussian record's value, and on the oscillator's values
# (one station of 235 s; measured over base-motion seeds 3-7: skewness ratio 1 -0.02..+0.00,
# ratio 3 -0.15..-0.11, ratio 1/3 +0.11..+0.13, sd about 0.02; L-skewness ratio 1
# -0.0034..+0.0022, ratio 3 -0.026..-0.016, ratio 1/3 +0.018..+0.022, sd about 0.0025):
# bounds 3 sd or more from the values
STATS = {
    # 8 stations x 600 s of a band-limited Gaussian displacement: the skewness of a velocity
    # correlated over about 0.1 s has sd about sqrt(6 / 6000) = 0.03 per station, 0.011 for
    # the mean of 8, so 0.05 is 4.5 sd; the L-skewness's mean of 8 scattered by 0.0007 over
    # 10 such records, so 0.003 is 4.4 sd
    "skewness": (stroke_velocity_skewness, 0.05, 0.06, 0.08),
    "l_skewness": (stroke_velocity_l_skewness, 0.003, 0.009, 0.01),
}


@pytest.mark.parametrize("name", sorted(STATS))
def test_gaussian_strokes_have_no_skewness(name):
    fn, gauss_bound, _, _ = STATS[name]
    rng = np.random.default_rng(11)
    n = int(600 * FS)
    ch = {f"susp_disp_{a}{s}": 0.01 * _band_gauss(n, 0.5, 12.0, FS, rng)
          for a in range(1, 5) for s in "LR"}
    assert abs(fn(_signals(ch))) < gauss_bound


@pytest.mark.parametrize("name", sorted(STATS))
def test_linear_oscillator_symmetric_asymmetric_damper_skewed_by_its_sign(name):
    fn, _, sym_bound, asym_bound = STATS[name]
    s1 = fn(_signals({"susp_disp_1L": _oscillator_stroke(1.0)}))
    s_reb = fn(_signals({"susp_disp_1L": _oscillator_stroke(3.0)}))
    s_com = fn(_signals({"susp_disp_1L": _oscillator_stroke(1 / 3.0)}))
    assert abs(s1) < sym_bound
    assert s_reb < -asym_bound and s_com > asym_bound
    # mirror image: the same asymmetry the other way round, about the same size
    assert abs(s_reb + s_com) < 0.5 * abs(s_reb)


@pytest.mark.parametrize("name", sorted(STATS))
def test_gain_and_offset_drop_out_and_sign_flips(name):
    fn = STATS[name][0]
    s = _oscillator_stroke(3.0)
    a = fn(_signals({"susp_disp_1L": s}))
    b = fn(_signals({"susp_disp_1L": 1000.0 * s + 12.0}))
    c = fn(_signals({"susp_disp_1L": -s}))
    assert b == pytest.approx(a, rel=1e-9, abs=1e-12)
    assert c == pytest.approx(-a, rel=1e-9, abs=1e-12)
    assert fn(_signals({"body_acc_1L": s})) is None


def test_the_own_signature_is_the_l_skewness():
    # the statistic the records carry, and the one the pipeline computes, are one
    from diagnosis.compare import OWN_STATISTICS

    assert OWN_SIGNATURE["damper_asymmetry"] == "stroke_velocity_l_skewness"
    assert OWN_STATISTICS[OWN_SIGNATURE["damper_asymmetry"]] is stroke_velocity_l_skewness
    assert own_signature("damper_asymmetry", 0.0, [0.0], [0.0])["statistic"] == \
        "stroke_velocity_l_skewness"


# --- the verdict -------------------------------------------------------------------------

def _summary(own=None, chi2=(5.0, 5.0), effect="damper_asymmetry"):
    # share (1 - 0.55) / (1 - 0.4) = 0.75: enough to name, not the whole gap (which would
    # name it on the gap alone)
    entry = {"effect": effect, "accepted": True, "heldout_gap_before": 1.0,
             "heldout_gap_after": 0.55, "improvement": 0.55, "null_improvement_sd": 0.05,
             "parameters": {effect: {"ratio": 3.0}}, "per_band_after": [0.5, 0.9, 0.3]}
    s = {"ranking": [entry],
         "ranking_decision": {"verdict": effect, "confidence": "clear", "reason": "r"},
         "nominal": {"heldout_gap": 1.0, "null_gap_mean": 0.4, "null_gap_std": 0.05,
                     "gap_present": True, "noise_floor": 0.2, "per_band": [1.0, 1.5, 0.4],
                     "per_band_noise_floor": [0.2, 0.3, 0.25], "band_centres_hz": [1.0, 4.0, 16.0]},
         "meta": {"search_ranges": {effect: {"ratio": [0.2, 8.0, True]}}},
         "signature": {"model": effect, "chi2_nominal": chi2[0], "chi2_model": chi2[1],
                       "n_cells": 40, "flagged_nominal": 6, "flagged_model": 6, "pairs_off": []}}
    if own is not None:
        s["signature_own"] = own
    return s


NOM = [0.02, -0.03, 0.05, 0.0, -0.04]          # mean 0, sd 0.0367
DAMP = [0.30, 0.36, 0.27, 0.33, 0.34]          # mean 0.32, sd 0.0356


def test_own_signature_numbers():
    r = own_signature_agrees(own_signature("damper_asymmetry", 0.35, NOM, DAMP))
    pooled = math.sqrt((np.var(NOM, ddof=1) * 4 + np.var(DAMP, ddof=1) * 4) / 8)
    sd = max(pooled, OWN_SD_FLOOR) * math.sqrt(1 + 2 / 10)
    assert r["sd"] == pytest.approx(sd, rel=1e-12)
    assert r["z_nominal"] == pytest.approx(0.35 / sd, rel=1e-12)
    assert r["z_model"] == pytest.approx(0.03 / sd, rel=1e-9)
    assert r["agrees"] is True
    # the floor: identical records do not make an infinitely sharp statistic
    r = own_signature_agrees(own_signature("damper_asymmetry", 0.1, [0.0] * 5, [0.1] * 5))
    assert r["sd"] == pytest.approx(OWN_SD_FLOOR * math.sqrt(1.2), rel=1e-12)
    assert own_signature_agrees({"measured": None, "nominal": NOM, "model": DAMP})["agrees"] is None


def test_the_floor_follows_the_records_statistic():
    # a summary saved with the moment skewness is re-decided with that statistic's floor
    # (0.03), a new one with the L-skewness's (0.003): identical records, different sd
    from diagnosis.verdict import OWN_SD_FLOORS

    new = own_signature("damper_asymmetry", 0.01, [0.0] * 5, [0.01] * 5)
    old = dict(new, statistic="stroke_velocity_skewness")
    assert own_signature_agrees(new)["sd"] == pytest.approx(
        OWN_SD_FLOORS["stroke_velocity_l_skewness"] * math.sqrt(1.2), rel=1e-12)
    assert own_signature_agrees(old)["sd"] == pytest.approx(
        OWN_SD_FLOORS["stroke_velocity_skewness"] * math.sqrt(1.2), rel=1e-12)
    assert own_signature_agrees(new)["agrees"] is True          # 0.01 is 3 floors from 0
    assert own_signature_agrees(old)["agrees"] is False         # and a third of one


def test_own_signature_names_a_damper_the_transmissibility_cannot_test():
    # transmissibility off for nominal and candidate alike (5.0 -> 5.0): without the own
    # signature the drive is unexplained; with it the damper is named (the rule that names a
    # vehicle effect taking most of the gap on the share alone is off where this is tested)
    own = own_signature("damper_asymmetry", 0.35, NOM, DAMP)
    assert decide(_summary(own=None), vehicle_share=None)["verdict"] == "unexplained"
    d = decide(_summary(own=own))
    assert d["verdict"] == "damper_asymmetry" and d["signature_agrees"] is True
    assert "skewness" in d["reason"] and d["signature_own"]["agrees"] is True
    assert decide(_summary(own=own), own=False, vehicle_share=None)["verdict"] == "unexplained"


WEAK = [0.05, 0.02, 0.06, 0.01, 0.01]          # a nearly symmetric damper: mean 0.03


@pytest.mark.parametrize("measured, model, why", [
    (0.01, DAMP, "the measurement shows no asymmetry"),          # nominal within noise
    (0.80, DAMP, "the candidate falls short of it"),             # |z_model| > 3
    (0.03, WEAK, "a candidate matching a measurement the nominal model makes too"),
])
def test_own_signature_withholds_a_name_the_transmissibility_would_give(measured, model, why):
    own = own_signature("damper_asymmetry", measured, NOM, model)
    r = own_signature_agrees(own)
    assert not r["agrees"], why
    assert abs(r["z_nominal"]) < OWN_Z_NOMINAL or abs(r["z_model"]) > OWN_Z_MODEL
    # the transmissibility agrees (3.0 -> 1.1): named without the own signature
    assert decide(_summary(own=None, chi2=(3.0, 1.1)))["verdict"] == "damper_asymmetry"
    d = decide(_summary(own=own, chi2=(3.0, 1.1)))
    assert d["verdict"] == "unexplained" and "skewness" in d["reason"]


def test_own_signature_of_another_effect_is_not_used():
    own = own_signature("damper_asymmetry", 0.01, NOM, DAMP)        # would veto a damper
    s = _summary(own=own, chi2=(3.0, 1.1), effect="leaf_friction")
    s["meta"]["search_ranges"] = {"leaf_friction": {"ratio": [0.2, 8.0, True]}}
    d = decide(s)
    assert d["verdict"] == "leaf_friction" and "signature_own" not in d


# --- the wiring ---------------------------------------------------------------------------

class _Entry:
    def __init__(self, effect, effects):
        self.effect, self.effects = effect, effects


class _StandInModel:
    """Runs the one-mass oscillator: symmetric without effects, rebound-heavy with them;
    a different base motion per road seed.  Logs what it was asked to run."""

    def __init__(self):
        self.calls = []

    def run(self, effects, t0, t1, seed):
        self.calls.append((bool(effects), seed))
        ratio = effects["damper_asymmetry"]["ratio"] if effects else 1.0
        s = _oscillator_stroke(ratio, T=240.0, seed=seed)
        return {"susp_disp_1L": s}

    def add_noise(self, rec, seed):
        rng = np.random.default_rng(seed)
        return {k: v + 1e-5 * rng.standard_normal(v.size) for k, v in rec.items()}


def test_pipeline_records_nominal_and_candidate_on_the_same_road_phases():
    # 235 s records, L-skewness: ratio 3 gave -0.026..-0.016 over base-motion seeds 1-10 (sd
    # 0.0036), ratio 1 -0.0034..+0.0029 (sd 0.0022, so 0.001 for a mean of 5: 0.004 is 4 of
    # those); the measurement is seed 99's (-0.021), the records those of seeds 1-5 (the
    # signature's phases).  At 115 s the L-skewness of one station was too noisy for the
    # nominal test (z -2.4)
    meas = _signals({"susp_disp_1L": _oscillator_stroke(3.0, T=240.0, seed=99)})
    model = _StandInModel()
    rec, dt = own_signature_record(model, meas,
                                   _Entry("damper_asymmetry", {"damper_asymmetry": {"ratio": 3.0}}),
                                   seed=0)
    assert rec["effect"] == "damper_asymmetry" and dt >= 0
    assert len(rec["nominal"]) == len(rec["model"]) == 5
    assert abs(np.mean(rec["nominal"])) < 0.004 and np.mean(rec["model"]) < -0.012
    # paired: both models on the signature's road phases seed + 1 .. seed + 5
    assert sorted(sd for eff, sd in model.calls if not eff) == [1, 2, 3, 4, 5]
    assert sorted(sd for eff, sd in model.calls if eff) == [1, 2, 3, 4, 5]
    r = own_signature_agrees(rec)
    assert r["agrees"] is True and r["z_nominal"] < -OWN_Z_NOMINAL
    # effects without an own signature get none
    assert own_signature_record(_StandInModel(), meas, _Entry("payload", {"payload": {"mass": 1.0}}),
                                seed=0) == (None, None)


# ------------------------------------------------------------- the stroke-velocity term of the gap
def _windows(ratio, seed, n_windows=4, T=160.0):
    """``n_windows`` windows (8 stations: the same stroke with station-wise sensor noise) of
    one oscillator record with damper ratio ``ratio``."""
    s = _oscillator_stroke(ratio, T=T, seed=seed)
    rng = np.random.default_rng(seed + 1000)
    n = len(s) // n_windows
    return [_signals({f"susp_disp_{a}{side}": s[j * n:(j + 1) * n] + 1e-5 * rng.standard_normal(n)
                      for a in range(1, 5) for side in "LR"})
            for j in range(n_windows)]


def test_stroke_velocity_term_per_channel_agrees_with_the_station_mean():
    from diagnosis.compare import stroke_velocity_skewness_per_channel

    w = _windows(3.0, seed=5, n_windows=1)[0]
    per = stroke_velocity_skewness_per_channel(w)
    assert sorted(per) == sorted(w.channels)
    assert np.mean(list(per.values())) == pytest.approx(stroke_velocity_skewness(w), abs=1e-12)


def test_stroke_velocity_term_pins_the_damper_ratio():
    # the measurement: the one-mass oscillator with a damper 3x stiffer in rebound; the
    # "models": the same oscillator on other base motions with ratios 1..8.  The term
    # against the measurement is large for the symmetric damper, and its smallest value
    # over the ratio grid lies within a factor 1.5 of the truth (the band powers alone leave
    # a damper's gap flat towards high ratios: blind case 15 calibrated 3.71 at 2.34 and 8.0)
    from diagnosis.which import StrokeVelocityTerm

    ch = [f"susp_disp_{a}{s}" for a in range(1, 5) for s in "LR"]
    meas = _windows(3.0, seed=21)
    nominal = [_windows(1.0, seed=s) for s in (31, 32, 33, 34)]
    term = StrokeVelocityTerm(ch, weight=1.0)
    term.prepare("held", meas, nominal)
    assert np.all(term._sigma["held"] >= StrokeVelocityTerm.SIGMA_FLOOR)
    # the symmetric damper skews less than measured (measured negative): rho > 0, z large
    z_nominal = term.z(_windows(1.0, seed=41), "held")
    assert z_nominal > 4.0
    ratios = [1.0, 1.5, 2.0, 3.0, 4.5, 6.0, 8.0]
    # two model road phases per ratio, as the calibration averages its seeds; per-window
    # skewness scatters by 0.03 between phases (sigma above), the skewness moves by 0.03
    # between ratios 3 and 4.5: hence the x1.5 tolerance
    terms = [np.mean([term.term(_windows(r, seed=s), "held") for s in (41, 42)]) for r in ratios]
    best = ratios[int(np.argmin(terms))]
    assert 2.0 <= best <= 4.5, dict(zip(ratios, np.round(terms, 2)))
    # the ends are penalised, not flat: 1 and 8 cost more than the truth's neighbourhood
    assert terms[-1] > min(terms) + 1.0 and terms[0] > min(terms) + 10.0
    # and z says which way: the symmetric damper skews less than measured (z > 0), a ratio
    # of 8 more (z < 0)
    assert term.z(_windows(8.0, seed=41), "held") < 0.0 < z_nominal
    # the term is 0 without weight and before it is prepared for a window set
    assert StrokeVelocityTerm(ch).term(meas, "held") == 0.0
    assert term.term(meas, "calib") == 0.0


# ------------------------------------------------- an edge calibration named on its own signature
def _edge_summary(own, effect="damper_asymmetry"):
    s = _summary(own=own, effect=effect)
    # one fold at the top of the range (8.0), the other inside: the edge rule's case
    s["ranking"][0]["parameters_per_fold"] = [{effect: {"ratio": 2.34}}, {effect: {"ratio": 8.0}}]
    return s


def test_edge_calibration_named_on_its_own_signature_is_never_clear():
    from diagnosis import verdict

    own = own_signature("damper_asymmetry", 0.35, NOM, DAMP)         # agrees
    d = decide(_edge_summary(own))
    assert d["edge"] == ["damper_asymmetry.ratio"]
    assert d["verdict"] == "damper_asymmetry"
    assert d["confidence"] == "ambiguous" and d["identified"] is False
    assert "edge of its search range" in d["reason"] and "bound" in d["reason"]
    # without the exception (or without the own signature) the edge withholds the name
    old = verdict.OWN_EDGE_NAMES
    try:
        verdict.OWN_EDGE_NAMES = False
        assert decide(_edge_summary(own))["verdict"] == "unexplained"
    finally:
        verdict.OWN_EDGE_NAMES = old
    assert decide(_edge_summary(own), own=False)["verdict"] == "unexplained"


def test_edge_calibration_whose_own_signature_disagrees_stays_unexplained():
    own = own_signature("damper_asymmetry", 0.80, NOM, DAMP)         # the candidate falls short
    d = decide(_edge_summary(own))
    assert d["verdict"] == "unexplained" and d["edge"] == ["damper_asymmetry.ratio"]
    assert "edge of its search range" in d["reason"]


# ------------------------------------------- the side of 1 a damper asymmetry is searched on
def test_own_side_numbers():
    """The search side of a damper asymmetry: beyond OWN_Z_SIDE (2.5, the verdict's threshold
    until stop 59, kept for the search so that calibrations stay those of the sets before)."""
    from diagnosis.verdict import OWN_Z_SIDE, own_side

    sd = max(float(np.std(NOM, ddof=1)), OWN_SD_FLOOR) * math.sqrt(1 + 1 / 5)
    assert OWN_Z_SIDE == 2.5
    assert own_side(OWN_Z_SIDE * sd * 1.01, NOM) == 1
    assert own_side(-OWN_Z_SIDE * sd * 1.01, NOM) == -1
    assert own_side(OWN_Z_SIDE * sd * 0.99, NOM) == 0          # not beyond the threshold
    assert own_side(None, NOM) == 0 and own_side(0.5, [0.1]) == 0


def test_candidates_searched_on_the_side_the_signature_shows():
    from diagnosis.pipeline import OWN_SIDE_RANGES, SEARCH, candidates

    def rng(sides):
        c = next(c for c in candidates(["damper_asymmetry", "payload"], sides=sides)
                 if c.name == "damper_asymmetry")
        return c.params[0].lo, c.params[0].hi

    assert rng(None) == SEARCH["damper_asymmetry"]["ratio"] == rng({"damper_asymmetry": 0})
    assert rng({"damper_asymmetry": 1}) == OWN_SIDE_RANGES["damper_asymmetry"][1] == (1.0, 8.0)
    assert rng({"damper_asymmetry": -1}) == OWN_SIDE_RANGES["damper_asymmetry"][2] == (0.2, 1.0)
    # a side for another effect changes nothing
    pay = [c for c in candidates(["payload"], sides={"payload": 1})][0].params[0]
    assert (pay.lo, pay.hi) == SEARCH["payload"]["mass"]


class _TruckConventionModel(_StandInModel):
    """The stand-in with eroad's sign of the suspension displacement (compression positive:
    a rebound-heavy damper skews the stroke velocity positive, as on the truck below)."""

    def run(self, effects, t0, t1, seed):
        return {k: -v for k, v in super().run(effects, t0, t1, seed).items()}


def test_pipeline_side_from_the_nominal_models_phases_and_reused_by_the_record():
    from diagnosis.pipeline import own_side_record

    # measured: the oscillator with a rebound-heavy damper (ratio 3) in the truck's sign
    meas = _signals({"susp_disp_1L": -_oscillator_stroke(3.0, T=240.0, seed=99)})
    model = _TruckConventionModel()
    rec, runs, dt = own_side_record(model, meas, seed=0)
    assert dt >= 0 and len(runs) == 5 and len(rec["nominal"]) == 5
    assert sorted(sd for eff, sd in model.calls) == [1, 2, 3, 4, 5]     # the signature's phases
    assert not any(eff for eff, sd in model.calls)                      # the nominal model only
    assert rec["sides"]["damper_asymmetry"] == 1                         # above the nominal's
    assert rec["ranges"]["damper_asymmetry"] == [1.0, 8.0]
    # the record after the ranking reuses the nominal runs: only the candidate is driven
    model.calls.clear()
    rec2, _ = own_signature_record(model, meas,
                                   _Entry("damper_asymmetry", {"damper_asymmetry": {"ratio": 3.0}}),
                                   seed=0, nominal_runs=runs)
    assert rec2["nominal"] == rec["nominal"]
    assert all(eff for eff, sd in model.calls) and len(model.calls) == 5
    # a compression-heavy damper: the other side; a symmetric one: the whole range
    low = _signals({"susp_disp_1L": -_oscillator_stroke(1 / 3.0, T=240.0, seed=99)})
    assert own_side_record(_TruckConventionModel(), low, seed=0)[0]["ranges"]["damper_asymmetry"] \
        == [0.2, 1.0]
    sym = _signals({"susp_disp_1L": -_oscillator_stroke(1.0, T=240.0, seed=99)})
    rec3, _, _ = own_side_record(_TruckConventionModel(), sym, seed=0)
    assert rec3["sides"]["damper_asymmetry"] == 0 and rec3["ranges"]["damper_asymmetry"] is None


def test_truck_sign_of_the_skewness_follows_the_ratio(tmp_path):
    # OWN_SIDE_RANGES maps a statistic above the nominal model's to ratio > 1: that is the
    # truck's sign (eroad's own Exudyn truck, 30 s null-scenario drives, seed 5: L-skewness
    # ratio 3 +0.033, 1/3 -0.025, 1 +0.004; a symmetric damper's road-phase scatter about
    # 0.005 -- the skewness gave +0.24 and -0.13 with a scatter about 0.05)
    from diagnosis.pipeline import load_measured
    from drives.synth import synth_command

    sk = {}
    for r in (1 / 3.0, 3.0):
        out = tmp_path / f"r{r:.2f}"
        synth_command(scenario="null", seed=5, effects=[f"damper_asymmetry.ratio={r!r}"], out=out)
        sk[r] = stroke_velocity_l_skewness(load_measured(out)[1])
    assert sk[3.0] > 0.015 and sk[1 / 3.0] < -0.01


def test_an_overshoot_within_noise_agrees_and_a_short_move_does_not():
    # identical records: the prediction sd is the L-skewness floor, 0.003 sqrt(1.2) = 0.00329.
    # The nominal model makes 0, the measurement is +0.015 (4.6 sd off).  A candidate at
    # +0.0235 moves the statistic 1.57 of the way (overshoot, 2.6 sd beyond the measurement,
    # within OWN_Z_MODEL): it agrees.  The rule before 2026-11-27 (night) capped the
    # overshoot at half the difference and refused it (blind case 5 of the frame-grid set).
    sd = OWN_SD_FLOOR * math.sqrt(1.2)
    over = own_signature_agrees(own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.0235] * 5))
    assert over["moved"] == pytest.approx(0.0235 / 0.015, rel=1e-9)
    assert over["z_model"] == pytest.approx(-0.0085 / sd, rel=1e-9)
    assert abs(over["z_model"]) <= OWN_Z_MODEL and over["agrees"] is True
    d = decide(_summary(own=own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.0235] * 5)))
    assert d["verdict"] == "damper_asymmetry"
    # a candidate at +0.006 moves it 0.4 of the way: within OWN_Z_MODEL of the measurement
    # (2.7 sd) but short of OWN_SHARE: refused, and the drive is unexplained
    short = own_signature_agrees(own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.006] * 5))
    assert abs(short["z_model"]) <= OWN_Z_MODEL and short["moved"] == pytest.approx(0.4)
    assert short["agrees"] is False
    d = decide(_summary(own=own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.006] * 5)))
    assert d["verdict"] == "unexplained"
    # too far beyond the measurement: +0.03 is 4.6 sd past it
    far = own_signature_agrees(own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.03] * 5))
    assert far["agrees"] is False


def test_a_short_move_is_said_in_the_reason():
    d = decide(_summary(own=own_signature("damper_asymmetry", 0.015, [0.0] * 5, [0.006] * 5)))
    assert "moves the statistic 40% of the way" in d["reason"] and "at least 50% asked" in d["reason"]


def test_own_signature_at_the_one_sided_five_percent_level_names_but_never_clearly():
    """Saved blind drive (seed 607 nominal case 15: damper asymmetry 2.31, ranked first with 98 %
    of the gap): its L-skewness departs from the nominal model's by 1.81 sd, which the one-sided
    5 % level (1.645) accepts and the old 2.0 did not; the name is never 'clear' below
    OWN_Z_CLEAR."""
    import json
    from pathlib import Path

    from diagnosis import verdict
    from diagnosis.verdict import OWN_Z_CLEAR

    s = json.loads((Path(__file__).resolve().parents[1] / "results/diagnosis_blind/"
                    "20261130-speed-test-stop66/nominal/case015-summary.json").read_text())
    d = decide(s)
    assert d["verdict"] == "damper_asymmetry" and d["confidence"] == "ambiguous", d["reason"]
    z = d["signature_own"]["z_nominal"]
    assert OWN_Z_NOMINAL <= abs(z) < OWN_Z_CLEAR
    assert "1.8 sd only" in d["reason"] and "asked for 'clear'" in d["reason"]
    assert verdict.own_signature_agrees(s["signature_own"], z_nominal=2.0)["agrees"] is False
