"""Result objects: each gives the command line's JSON and text, saves and loads itself,
concatenates over batches, pickles, and plots itself."""
from __future__ import annotations

import json
import pickle

import numpy as np
import pytest

from gyro import ladder, load
from gyro.analyses import campbell
from gyro.systems.gimbal_gyroscope import Motion, trajectory
from gyro.analyses.stability_map import stability_grid
from gyro.results import CampbellDiagram, Map, ModalResult, Spectrum
from gyro.results import Motion as MotionResult

MODEL = load("torsion_gyrocompass")


def _batch(n=5):
    P = np.tile(MODEL.vector(MODEL.defaults), (n, 1))
    P[:, MODEL.param_names.index("H")] *= np.linspace(0.5, 2.0, n)
    return P


def test_spectrum_concatenates_saves_loads_and_pickles(tmp_path):
    P = _batch(6)
    whole = ladder.spectrum(MODEL, P)
    parts = Spectrum.concat([ladder.spectrum(MODEL, P[:2]), ladder.spectrum(MODEL, P[2:])])
    for f in ("frequencies", "growth", "error_estimate", "equilibrium"):
        np.testing.assert_array_equal(getattr(parts, f), getattr(whole, f))
    assert list(parts.route) == list(whole.route) and len(parts) == 6
    whole.save(tmp_path / "s.npz")
    back = Spectrum.load(tmp_path / "s.npz")
    np.testing.assert_array_equal(back.frequencies, whole.frequencies)
    assert list(back.route) == list(whole.route) and back.method == "default"
    again = pickle.loads(pickle.dumps(whole))
    np.testing.assert_array_equal(again.error_estimate, whole.error_estimate)


def test_spectrum_gives_the_cli_json_and_text():
    values = MODEL.parameters({"phi": 30})
    spec = ladder.spectrum(MODEL, MODEL.vector(values))
    doc = spec.to_dict(0, MODEL, values)
    assert list(doc) == ["model", "params", "frequencies", "equilibrium", "eigenvalues_re", "method",
                         "error_estimate", "stability"]
    assert json.loads(json.dumps(doc, allow_nan=False)) == doc
    assert spec.table(0, MODEL).splitlines()[-1] == "equilibrium: stable"


def test_spectrum_plots_itself(tmp_path):
    import matplotlib.pyplot as plt

    ax = ladder.spectrum(MODEL, _batch()).plot()
    assert len(ax.lines) == 10
    plt.close("all")


def test_modal_result_round_trip(tmp_path):
    r = ladder.natural_frequencies(MODEL, MODEL.defaults)
    r.save(tmp_path / "m.json")
    assert ModalResult.load(tmp_path / "m.json") == r


def test_campbell_diagram_plots_saves_and_pickles(tmp_path):
    d = campbell.sweep(MODEL, MODEL.defaults, 0.5, 2.0, 6)
    assert isinstance(d, CampbellDiagram) and d.formula_error.shape == (6, 10)
    d.plot(tmp_path / "c.png")
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "6 spins" in d.summary("c.png")
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(d)).Omega, d.Omega)
    d.save(tmp_path / "c.npz")


def test_stability_map_plots_saves_and_loads(tmp_path):
    m = stability_grid(MODEL, MODEL.defaults, "l2", (-0.3, 0.3), "H", (0.1, 1.0), 4)
    assert isinstance(m, Map) and m.kind == "verdict" and m.label.shape == (4, 4)
    assert sum(m.counts().values()) == 16
    m.plot(tmp_path / "m.png")
    m.save(tmp_path / "m.npz")
    back = Map.load(tmp_path / "m.npz")
    assert back.label.tolist() == m.label.tolist() and back.xname == "l2"
    np.testing.assert_array_equal(back.growth, m.growth)


@pytest.mark.parametrize("method", ["closed_form", "DOP853"])
def test_trajectory_gives_the_cli_json_saves_and_plots(method, tmp_path):
    gg = load("gimbal_gyroscope")
    tr = trajectory(Motion(gg.defaults, 1.2, 0.0, 1.0, 200.0), np.linspace(0, 0.2, 5), method)
    assert isinstance(tr, MotionResult)
    assert list(tr.to_dict()) == ["t", "theta", "psi", "phi", "method", "integrals"]
    tr.save(tmp_path / "t.npz")
    back = MotionResult.load(tmp_path / "t.npz")
    np.testing.assert_array_equal(back.theta, tr.theta)
    assert back.integrals == tr.integrals and back.method == method
    assert back.to_dict() == tr.to_dict() and back.table() == tr.table()
    tr.plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").exists()


def test_found_in_review_api(tmp_path):
    """An empty batch gives an empty spectrum; vector validates every value it is given."""
    from gyro.models import ParameterError

    empty = ladder.spectrum(MODEL, np.empty((0, len(MODEL.param_names))))
    assert empty.frequencies.shape == (0, 10) and len(empty) == 0
    for bad in ({"m": -1.0}, {"phi": 500.0}, {"g": float("nan")}, {"mass": 1.0}):
        with pytest.raises(ParameterError):
            MODEL.vector(bad)
    assert MODEL.vector({"H": 0.9})[MODEL.param_names.index("H")] == 0.9


def test_every_saving_result_loads_what_it_saved(tmp_path):
    """One base (gyro.results._io.Result) saves and loads every result kind that saves;
    kinds that could save but not load (CampbellDiagram, Sensitivities, FrequencySweep) load
    through it too: the simple ones field for field."""
    from gyro.results import FrequencySweep
    from gyro.results._io import Result

    import gyro.results as R

    kinds = [getattr(R, n) for n in R.__all__ if isinstance(getattr(R, n), type)]
    saving = [k for k in kinds if hasattr(k, "save")]
    assert all(issubclass(k, Result) for k in saving if k.__name__ != "ModalResult"), \
        [k.__name__ for k in saving if not issubclass(k, Result)]
    spec = ladder.spectrum(MODEL, _batch(3))
    sweep = FrequencySweep(model=MODEL.name, title="t", xname="H", xunit="kg m^2/s", x=np.arange(3.0), spectrum=spec)
    sweep.save(tmp_path / "s.npz")
    back = FrequencySweep.load(tmp_path / "s.npz")
    np.testing.assert_array_equal(back.spectrum.frequencies, spec.frequencies)
    assert back.to_dict() == sweep.to_dict() and back.table() == sweep.table()


def test_a_campbell_diagram_loads_its_crossings_as_crossings(tmp_path):
    """The critical speeds come back as Crossing objects (list[Crossing] rebuilt entry by
    entry), not as dicts, and the loaded diagram prints the same table."""
    from gyro.analyses.campbell import campbell
    from gyro.results.campbell import Crossing

    H = MODEL.defaults["H"]
    d = campbell(MODEL, MODEL.defaults, None, np.linspace(0.2 * H, 2.0 * H, 12), harmonics=(1,))
    assert d.crossings, "the sweep should cross a mode"
    d.save(tmp_path / "c.npz")
    back = CampbellDiagram.load(tmp_path / "c.npz")
    assert all(isinstance(c, Crossing) for c in back.crossings) and back.crossings == d.crossings
    assert back.crossings_table() == d.crossings_table()
