"""What Figures 6, 8 and 9 of an inversion say: segments numbered as in Table 1, Figure 8
saying it overlays a random-phase simulation (not a phase-true comparison), Figure 9
defining W1/sd.  The figures are kept (Figure.savefig captured) and their texts read."""
import numpy as np
import pytest
from matplotlib.figure import Figure

from inverse.report import write_figures
from inverse.segmentation import segment
from inverse.synthetic import quarter_predict_rms

from test_inverse_segmentation import DISP, _three_segment_drive


@pytest.fixture()
def figures(tmp_path, monkeypatch):
    saved = {}
    real = Figure.savefig

    def keep(self, path, *a, **k):
        saved[str(path).rsplit("/", 1)[-1]] = self
        return real(self, path, *a, **k)

    monkeypatch.setattr(Figure, "savefig", keep)
    d = _three_segment_drive()
    seg = segment(d.time, {c: d.channels[c] for c in DISP}, d.speed,
                  predict_rms=quarter_predict_rms())
    rng = np.random.default_rng(0)
    meas = {c: np.asarray(d.channels[c], float) for c in DISP}
    sim = {c: v + 1e-3 * rng.standard_normal(v.size) for c, v in meas.items()}
    write_figures(tmp_path, time=d.time, measured=meas, simulated=sim, segmentation=seg,
                  seg_signal=meas[DISP[0]], title="(test)")
    return saved, seg


def _texts(fig):
    out = [t.get_text() for t in fig.texts]
    if fig._suptitle is not None:
        out.append(fig._suptitle.get_text())
    for ax in fig.axes:
        out += [t.get_text() for t in ax.texts] + [ax.get_title()]
    return out


def test_figure6_numbers_segments_as_table1(figures):
    saved, seg = figures
    texts = _texts(saved["figure6_segmentation.png"])
    above = [t for t in texts if t.isdigit()]
    assert above == [str(k) for k in range(1, seg.n_segments + 1)]
    assert not any(t.startswith("S1") for t in texts)
    assert any("Table 1" in t for t in texts)


def test_figure8_says_random_phase_not_phase_true(figures):
    saved, _ = figures
    fig = saved["figure8_time_compare.png"]
    title = fig._suptitle.get_text()
    assert "random-phase" in title and "not a phase-true" in title


def test_figure9_defines_w1_over_sd(figures):
    saved, _ = figures
    texts = " ".join(_texts(saved["figure9_amplitude_distributions.png"]))
    assert "W1/sd" in texts and "Wasserstein-1" in texts and "standard deviation" in texts


def test_table2_says_its_units_and_what_its_means_are():
    """Table 2 carries a unit column, names its means rectified (rect_mean), and its note
    says which columns the unit belongs to."""
    from inverse.report import TABLE2_NOTE, table2

    row = {"channel": "susp_disp_3L", "rms_meas": 0.008, "mean_abs_meas": 0.0045, "rms_sim": 0.0077,
           "rms_err": -0.04, "mean_abs_err": -0.03, "rmse_eq6_norm": 1.4, "wasserstein": 0.04,
           "ks": 0.03}
    df = table2([row])
    assert df["unit"].tolist() == ["m"]
    assert "rect_mean_meas" in df.columns and not any(c.startswith("mean") for c in df.columns)
    assert "'unit' is that of the rms_meas" in TABLE2_NOTE and "rectified mean" in TABLE2_NOTE
