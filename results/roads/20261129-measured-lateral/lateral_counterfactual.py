"""bench_inverse.py with the inversion's linear model told another lateral road structure (a counterfactual).

Not an option of the inversion.  Default: every pair of tyre inputs less than
inverse.lateral.DUAL_DY_MAX (0.5 m) apart gets coherence 1 instead of the isotropic surface's (the
dual tyres of a side; on the simulator's grid also the neighbouring grid lines a tyre's input mixes),
as on the measured-profile road (its tracks are linear mixes across the width: coherence 0.99 between a
side's twin tyres).  --measured-structure: every tyre pair as on that road (_measured_lines).  Same arguments as benchmarks/bench_inverse.py; --workers 1 keeps
the patch in this process.  --linear-only: no simulation corrections (the hybrid fit's offsets come
from the time simulator, whose road is the isotropic grid, and would take the patch back out);
--isotropic: the patch off (the reference for --linear-only).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))

from inverse import lateral, linear_features  # noqa: E402

_orig = linear_features.LinearFeatures._coherence


def _duals_one_rut(self, k, w):
    g = _orig(self, k, w).copy()
    near = (self._dy > 0) & (self._dy < lateral.DUAL_DY_MAX)
    g[:, near, :] = 1.0
    return g


_orig_fit = linear_features.fit_hybrid


def _no_corrections(*args, **kw):
    kw["corrections"] = 0
    return _orig_fit(*args, **kw)


if "--linear-only" in sys.argv:     # no simulation offsets: the linear model's lateral structure stands
    sys.argv.remove("--linear-only")
    linear_features.fit_hybrid = _no_corrections


def _measured_lines(y, grid_y):
    """The measured-profile road's own structure: a tyre at y reads a(y) p(x) + (1 - a(y)) p(x + 40 m)
    (drives.synth.profile_mix_weight, width 3 m), written as two 'lines' far apart (p and the shifted p:
    unrelated, coherence 0 at 1000 m), scaled so that the fitted level is the PSD of the tracks at
    benchmarks.bench_inverse.REF_TRACK_Y (the benchmark's truth, a^2 + (1 - a)^2 = 0.692 of p's)."""
    from benchmarks.bench_inverse import REF_TRACK_Y
    from drives.synth import profile_mix_weight

    a, at = float(profile_mix_weight(y, 3.0)), float(profile_mix_weight(REF_TRACK_Y[1], 3.0))
    s = (at ** 2 + (1 - at) ** 2) ** 0.5
    return [(0.0, a / s), (1000.0, (1 - a) / s)]


if "--measured-structure" in sys.argv:   # every pair of tyres as on the measured road (not only the duals)
    sys.argv.remove("--measured-structure")
    linear_features._tyre_lines = _measured_lines
elif "--isotropic" in sys.argv:       # the reference: the patch off
    sys.argv.remove("--isotropic")
else:
    linear_features.LinearFeatures._coherence = _duals_one_rut

if __name__ == "__main__":
    from benchmarks.bench_inverse import main
    sys.exit(main(sys.argv[1:]))
