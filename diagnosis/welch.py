"""Welch spectra of the diagnosis: one vectorised implementation.

What it is for: the diagnosis estimates thousands of short spectra per run (band powers,
noise floors, axle-to-body transmissibilities of every candidate and window).
``scipy.signal.welch`` / ``csd`` detrend segment by segment in Python and transform each
signal once per call, so an auto- and cross-spectrum of two signals costs four passes; the
profile of a whole-library diagnosis put 10 % of its time there.  Here the segments of
all signals are cut, detrended and transformed in one array operation, and the cross
spectrum reuses the auto spectra's transforms.

Convention (the one every caller used): periodic Hann window, hop ``L // 2``, the mean
removed per segment ("constant" detrend), one-sided density in unit^2/Hz, averaged by
the mean over segments.  A segment longer than the record is shortened to it, as scipy
does.  ``tests/test_diagnosis_welch.py`` holds the results equal to scipy's to 1e-12.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy import signal

__all__ = ["segment_ffts", "welch", "cross_spectra"]


@lru_cache(maxsize=64)
def _hann(L: int) -> np.ndarray:
    """Periodic Hann window of ``L`` samples (cached, read-only: thousands of calls per
    diagnosis ask for a handful of lengths)."""
    w = signal.get_window("hann", int(L))
    w.setflags(write=False)
    return w


def segment_ffts(x, fs: float, L: int, hop: int | None = None):
    """FFTs of the Welch segments of ``x`` (..., n): ``f`` (nf,) Hz and ``X`` (..., K, nf)
    (periodic Hann, hop ``L // 2`` unless given, mean removed per segment; no scaling)."""
    x = np.asarray(x, float)
    n = x.shape[-1]
    L = int(min(L, n))
    hop = max(1, L // 2) if hop is None else int(hop)
    K = 1 + (n - L) // hop
    seg = np.lib.stride_tricks.sliding_window_view(x, L, axis=-1)[..., :(K - 1) * hop + 1:hop, :]
    seg = seg - seg.mean(axis=-1, keepdims=True)
    return np.fft.rfftfreq(L, 1.0 / fs), np.fft.rfft(seg * _hann(L), axis=-1)


def _density(S: np.ndarray, fs: float, L: int) -> np.ndarray:
    """Mean over segments (axis -2) of a segment product, scaled to a one-sided density."""
    P = S.mean(axis=-2) / (fs * float(np.sum(_hann(L) ** 2)))
    if L % 2:
        P[..., 1:] *= 2.0
    else:
        P[..., 1:-1] *= 2.0
    return P


def welch(x, fs: float, L: int, hop: int | None = None):
    """One-sided Welch PSD of ``x`` (..., n) along the last axis: ``f``, ``P`` (..., nf)."""
    f, X = segment_ffts(x, fs, L, hop)
    return f, _density(np.abs(X) ** 2, fs, min(int(L), np.asarray(x).shape[-1]))


def cross_spectra(x, y, fs: float, L: int, hop: int | None = None):
    """``f``, ``Pxx``, ``Pyy`` and ``Pxy`` (``conj(X) Y``, as ``scipy.signal.csd``) of two
    equally long signals, from one transform of each."""
    f, X = segment_ffts(x, fs, L, hop)
    _, Y = segment_ffts(y, fs, L, hop)
    L = min(int(L), np.asarray(x).shape[-1])
    return (f, _density(np.abs(X) ** 2, fs, L), _density(np.abs(Y) ** 2, fs, L),
            _density(np.conj(X) * Y, fs, L))
