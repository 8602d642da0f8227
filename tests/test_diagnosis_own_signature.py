"""The damper asymmetry's own signature: the stroke-velocity skewness, and how the verdict uses it.

References that do not come from eroad's truck:
* a linear oscillator on a Gaussian base motion answers with Gaussian velocities (skewness
  0 whatever its stiffness and damping);
* a one-mass oscillator whose damper is stiffer in rebound (extension) than in compression
  moves slowly while extending and fast while compressing: with extension positive, the
  stroke velocity is negatively skewed, and the sign turns with the asymmetry (simulated
  here with its own few lines of semi-implicit Euler, not with eroad's models);
* skewness is a standardised moment: a sensor gain and offset drop out, a sign flip of the
  channel flips it.
The verdict rules are checked on summaries built by hand (numbers chosen, not simulated).
"""
import math

import numpy as np
import pytest

from diagnosis.compare import stroke_velocity_skewness
from diagnosis.pipeline import own_signature_record
from diagnosis.signals import Signals
from diagnosis.verdict import (OWN_SD_FLOOR, OWN_Z_MODEL, OWN_Z_NOMINAL, decide, own_signature,
                               own_signature_agrees)

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


def test_gaussian_strokes_have_no_skewness():
    # 8 stations x 600 s of a band-limited Gaussian displacement: the skewness of a
    # velocity correlated over about 0.1 s has sd about sqrt(6 / 6000) = 0.03 per station,
    # 0.011 for the mean of 8; 0.05 is 4.5 sd
    rng = np.random.default_rng(11)
    n = int(600 * FS)
    ch = {f"susp_disp_{a}{s}": 0.01 * _band_gauss(n, 0.5, 12.0, FS, rng)
          for a in range(1, 5) for s in "LR"}
    assert abs(stroke_velocity_skewness(_signals(ch))) < 0.05


def test_linear_oscillator_symmetric_asymmetric_damper_skewed_by_its_sign():
    s1 = stroke_velocity_skewness(_signals({"susp_disp_1L": _oscillator_stroke(1.0)}))
    s_reb = stroke_velocity_skewness(_signals({"susp_disp_1L": _oscillator_stroke(3.0)}))
    s_com = stroke_velocity_skewness(_signals({"susp_disp_1L": _oscillator_stroke(1 / 3.0)}))
    # one station of 235 s; measured over base-motion seeds 3, 4, 5: ratio 1 -0.02..+0.00,
    # ratio 3 -0.15..-0.11, ratio 1/3 +0.11..+0.13 (sd about 0.02): bounds 3 sd or more away
    assert abs(s1) < 0.06
    assert s_reb < -0.08 and s_com > 0.08
    # mirror image: the same asymmetry the other way round, about the same size
    assert abs(s_reb + s_com) < 0.5 * abs(s_reb)


def test_gain_and_offset_drop_out_and_sign_flips():
    s = _oscillator_stroke(3.0)
    a = stroke_velocity_skewness(_signals({"susp_disp_1L": s}))
    b = stroke_velocity_skewness(_signals({"susp_disp_1L": 1000.0 * s + 12.0}))
    c = stroke_velocity_skewness(_signals({"susp_disp_1L": -s}))
    assert b == pytest.approx(a, rel=1e-9, abs=1e-12)
    assert c == pytest.approx(-a, rel=1e-9, abs=1e-12)
    assert stroke_velocity_skewness(_signals({"body_acc_1L": s})) is None


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


def test_own_signature_names_a_damper_the_transmissibility_cannot_test():
    # transmissibility off for nominal and candidate alike (5.0 -> 5.0): without the own
    # signature the drive is unexplained; with it the damper is named
    own = own_signature("damper_asymmetry", 0.35, NOM, DAMP)
    assert decide(_summary(own=None))["verdict"] == "unexplained"
    d = decide(_summary(own=own))
    assert d["verdict"] == "damper_asymmetry" and d["signature_agrees"] is True
    assert "skewness" in d["reason"] and d["signature_own"]["agrees"] is True
    assert decide(_summary(own=own), own=False)["verdict"] == "unexplained"


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
        s = _oscillator_stroke(ratio, T=120.0, seed=seed)
        return {"susp_disp_1L": s}

    def add_noise(self, rec, seed):
        rng = np.random.default_rng(seed)
        return {k: v + 1e-5 * rng.standard_normal(v.size) for k, v in rec.items()}


def test_pipeline_records_nominal_and_candidate_on_the_same_road_phases():
    # 115 s records: ratio 3 gave -0.16..-0.06 over base-motion seeds 1-15 (sd 0.03); the
    # measurement is seed 99's, the records those of seeds 1-5 (the signature's phases)
    meas = _signals({"susp_disp_1L": _oscillator_stroke(3.0, T=120.0, seed=99)})
    model = _StandInModel()
    rec, dt = own_signature_record(model, meas,
                                   _Entry("damper_asymmetry", {"damper_asymmetry": {"ratio": 3.0}}),
                                   seed=0)
    assert rec["effect"] == "damper_asymmetry" and dt >= 0
    assert len(rec["nominal"]) == len(rec["model"]) == 5
    assert abs(np.mean(rec["nominal"])) < 0.06 and np.mean(rec["model"]) < -0.08
    # paired: both models on the signature's road phases seed + 1 .. seed + 5
    assert sorted(sd for eff, sd in model.calls if not eff) == [1, 2, 3, 4, 5]
    assert sorted(sd for eff, sd in model.calls if eff) == [1, 2, 3, 4, 5]
    r = own_signature_agrees(rec)
    assert r["agrees"] is True and r["z_nominal"] < -OWN_Z_NOMINAL
    # effects without an own signature get none
    assert own_signature_record(_StandInModel(), meas, _Entry("payload", {"payload": {"mass": 1.0}}),
                                seed=0) == (None, None)
