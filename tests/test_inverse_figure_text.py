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
