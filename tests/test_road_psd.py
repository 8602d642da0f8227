"""ISO 8608 class table, PSD formula and the anisotropic surface PSD (roadlib.psd).

Reference: ISO 8608:2016, Table (classes A-H): Gd(n0) geometric means 16e-6 m^3 for A,
each following class a factor 4 higher, class bounds a factor 2 either side of the mean,
n0 = 0.1 cycles/m, w = 2.
"""
import math

import numpy as np
import pytest
from scipy import integrate

from eroad.errors import EroadInputError
from roadlib.psd import ISO_CLASSES, N0, class_gd0, class_of, iso_psd, lateral_density, surface_psd

TABLE = {"A": 16e-6, "B": 64e-6, "C": 256e-6, "D": 1024e-6, "E": 4096e-6, "F": 16384e-6,
         "G": 65536e-6, "H": 262144e-6}


def test_class_table_matches_iso_8608():
    """Exact table values (tolerance: float round-off, 1e-12 relative)."""
    assert N0 == 0.1
    assert list(ISO_CLASSES) == list("ABCDEFGH")
    for name, gd0 in TABLE.items():
        c = ISO_CLASSES[name]
        assert c.gd0 == pytest.approx(gd0, rel=1e-12)
        assert class_gd0(name.lower()) == pytest.approx(gd0, rel=1e-12)
        assert c.nominal_bounds == pytest.approx((gd0 / 2, gd0 * 2), rel=1e-12)
    assert ISO_CLASSES["A"].lower == 0.0 and math.isinf(ISO_CLASSES["H"].upper)


def test_class_of_means_bounds_and_extremes():
    """The mean of each class is in it; a bound belongs to the upper class; open ends."""
    for name, gd0 in TABLE.items():
        assert class_of(gd0) == name
        assert class_of(gd0 * 1.99) == name
    assert class_of(32e-6) == "B" and class_of(31.9e-6) == "A"
    assert class_of(1e-9) == "A" and class_of(1.0) == "H"
    with pytest.raises(EroadInputError, match="positive"):
        class_of(-1.0)
    with pytest.raises(EroadInputError, match="unknown ISO 8608 road class 'Z'"):
        class_gd0("Z")


def test_iso_psd_formula_and_refusals():
    """Gd(n) = Gd(n0) (n/n0)^-w exactly (round-off)."""
    n = np.array([0.05, 0.1, 1.0])
    assert iso_psd(n, 256e-6, 2.0) == pytest.approx(256e-6 * (n / 0.1) ** -2, rel=1e-14)
    assert iso_psd(0.1, 1e-4, 2.7) == pytest.approx(1e-4, rel=1e-14)
    with pytest.raises(EroadInputError, match="n must be > 0"):
        iso_psd([0.0, 1.0], 1e-4)
    with pytest.raises(EroadInputError, match="waviness"):
        iso_psd(1.0, 1e-4, w=-1)
    with pytest.raises(EroadInputError, match="Gd\\(n0\\)"):
        iso_psd(1.0, 0.0)


@pytest.mark.parametrize("w", [1.5, 2.0, 2.6])
@pytest.mark.parametrize("lam", [0.5, 1.0, 3.0])
def test_surface_psd_marginal_is_the_1d_iso_psd(w, lam):
    """eq (5): integral over n_y of Gq(n_x, n_y) = Gd(n_x) for every lam (quadrature, 1e-7)."""
    for nx in (0.02, 0.3, 2.0):
        val, _ = integrate.quad(lambda ny: surface_psd(nx, ny, 256e-6, w, lam), -np.inf, np.inf,
                                epsabs=0, epsrel=1e-10, limit=200)
        assert val == pytest.approx(iso_psd(nx, 256e-6, w), rel=1e-7)


def test_surface_psd_lateral_line_spectrum():
    """A lateral line of the eq (5) surface has the one-sided PSD Gd(n) lam^(1-w)
    (closed form in docs/roadlib.md; quadrature tolerance 1e-6)."""
    w, lam, gd0 = 2.0, 2.5, 256e-6
    for n in (0.2, 1.0):
        two_sided, _ = integrate.quad(lambda nx: surface_psd(nx, n, gd0, w, lam), 0, np.inf,
                                      epsabs=0, epsrel=1e-10, limit=200)
        assert 2 * two_sided == pytest.approx(iso_psd(n, gd0, w) * lam ** (1 - w), rel=1e-6)


def test_lateral_density_refuses_bad_lambda():
    with pytest.raises(EroadInputError, match="lambda"):
        lateral_density(0.1, 0.1, 2.0, lam=0.0)
