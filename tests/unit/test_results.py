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


def _every_result():
    """One result of every type in gyro.results (and the nested Crossing and Trial), each
    from its producer, small: {name: result}."""
    from gyro.analyses import harmonic
    from gyro.analyses.forced import forced_response
    from gyro.analyses.level_map import level_map
    from gyro.analyses.scene import select
    from gyro.analyses.sensitivity import sensitivities
    from gyro.analyses.sweep import sweep
    from gyro.analyses.tolerance import parse_spread, tolerance
    from gyro.results import classify, verdict
    from gyro.results.campbell import Crossing
    from gyro.systems import gimbal_precession as pr
    from gyro.systems import gyrohorizoncompass as ghc

    P = _batch(3)
    spec = ladder.spectrum(MODEL, P)
    scene = select(MODEL, "frequencies", P[:2], 1e-6, {"modes": None})
    ghc_values = ghc.parameters({"A": 1.0, "B": 1.05, "C": 1.1, "J": 1.0, "L": 0.5, "I": 1.0, "nu": 1.0, "zeta": 0.5,
                                 "eta": 0.2})
    gg = load("gimbal_gyroscope")
    out = {
        "Spectrum": spec, "Stability": classify(spec),
        "Verdict": verdict.make(["stable", "boundary"], [None, "roots merge"]),
        "ModalResult": ladder.natural_frequencies(MODEL, MODEL.defaults),
        "CampbellDiagram": campbell.campbell(MODEL, MODEL.defaults, None,
                                             np.linspace(0.2, 2.0, 5) * MODEL.defaults["H"], harmonics=(1,)),
        "Crossing": Crossing(1, 2, 0.5, 120.0, 119.5, 3),
        "FrequencySweep": sweep(MODEL, MODEL.defaults, "H", 0.2, 0.9, 3),
        "Sensitivities": sensitivities(MODEL, P[:1]),
        "ToleranceStudy": tolerance(MODEL, MODEL.defaults, [parse_spread("Kp=normal:0.01")], 16, seed=3),
        "Scene": scene, "Trial": scene.trials[0],
        "HarmonicResponse": harmonic.unbalance_response(MODEL, MODEL.defaults, *harmonic.input_names(MODEL)[:2],
                                                        1e-6, 0.0, "H", 0.2, 0.9, 4),
        "ForcedResponse": forced_response(MODEL, P[:1], [(1, 1, 1e-3, 0.0)]),
        "EquilibriumStability": ghc.stability(ghc_values),
        "Map verdict": stability_grid(MODEL, MODEL.defaults, "l2", (-0.3, 0.3), "H", (0.1, 1.0), 3),
        "Map condition": ghc.condition_map(dict(ghc_values), ("zeta", 0.1, 0.8, 3), ("eta", 0.0, 0.9, 2)),
        "Map error": level_map(MODEL, "formulas", "linear_exact:default", ("H", 0.2, 0.9, 2), ("Kgamma", 10, 60, 2),
                               {}, 1e-2),
        "Motion closed form": trajectory(Motion(gg.defaults, 1.2, 0.0, 1.0, 200.0), np.linspace(0, 0.2, 5)),
        "Motion image point": pr.simulate(pr.parameters({}), np.linspace(0, 1, 3), "elementary"),
    }
    return out


@pytest.fixture(scope="module")
def every_result():
    return _every_result()


def test_every_result_type_is_in_the_contract(every_result):
    """Every type that gyro.results exports (Crossing and Trial among them) is a Result:
    save, load, to_dict, table, plot; a type without a plot says why."""
    import gyro.results as R
    from gyro.results._io import Result

    kinds = {getattr(R, n) for n in R.__all__ if isinstance(getattr(R, n), type)} - {Result}
    built = {type(r) for r in every_result.values()}
    assert kinds <= built, sorted(k.__name__ for k in kinds - built)
    for k in built:
        assert issubclass(k, Result), k.__name__
        assert all(callable(getattr(k, m, None)) for m in ("save", "load", "to_dict", "table", "plot")), k.__name__
        if k.plot is Result.plot:
            assert k.NO_PLOT, f"{k.__name__}: no plot and no reason"


@pytest.mark.parametrize("name", ["Spectrum", "Stability", "Verdict", "ModalResult", "CampbellDiagram", "Crossing",
                                  "FrequencySweep", "Sensitivities", "ToleranceStudy", "Scene", "Trial",
                                  "HarmonicResponse", "ForcedResponse", "EquilibriumStability", "Map verdict",
                                  "Map condition", "Map error", "Motion closed form", "Motion image point"])
def test_every_result_round_trips(name, every_result, tmp_path):
    """save then load gives a result of the same type whose document and text are the
    same (nested results rebuilt in their types); the document is strict JSON; the plot
    is drawn, or refused with its reason."""
    from gyro.results._io import Result

    r = every_result[name]
    path = tmp_path / ("r.json" if name == "ModalResult" else "r.npz")
    r.save(path)
    back = type(r).load(path)
    assert type(back) is type(r)
    doc = r.to_dict()
    assert json.loads(json.dumps(doc, allow_nan=False)) == json.loads(json.dumps(back.to_dict(), allow_nan=False))
    assert back.table() == r.table() and r.table()
    for f in ("spectrum", "sensitivities", "exact", "trials", "crossings"):
        if isinstance(getattr(r, f, None), (Result, list)):
            nested = getattr(back, f)
            assert [type(x) for x in np.atleast_1d(nested)] == [type(x) for x in np.atleast_1d(getattr(r, f))], f
    import matplotlib.pyplot as plt

    fig = plt.figure()  # drawn, not rendered: a file is written in the test below
    if type(r).plot is Result.plot:
        with pytest.raises(NotImplementedError, match="no plot"):
            r.plot(fig)
        assert not fig.axes
    else:
        r.plot(fig)
        assert fig.axes
    plt.close(fig)


def test_a_plot_draws_into_given_axes_or_figure(every_result, tmp_path):
    """plot(out): out a file, or matplotlib axes (a one-panel plot) or a figure (panels)."""
    import matplotlib.pyplot as plt

    for name in ("Map condition", "Motion image point"):
        every_result[name].plot(tmp_path / "r.png")
        assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    for name in ("Map verdict", "Map condition", "Map error", "FrequencySweep"):
        fig, ax = plt.subplots()
        every_result[name].plot(ax)
        assert ax.collections or ax.lines, name
        plt.close(fig)
    for name in ("Motion closed form", "Motion image point", "CampbellDiagram", "Sensitivities"):
        fig = plt.figure()
        every_result[name].plot(fig)
        assert fig.axes, name
        plt.close(fig)


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
    assert back.table() == d.table()


def test_an_error_map_never_prints_nan():
    """A point where a level could not answer is NaN in the map: its table says 'none' and
    the summary line states no largest error where no point could be computed (it printed
    'nan' before)."""
    m = Map("error", "m", "t", "a", "b", np.arange(2.0), np.arange(2.0), np.array([[np.nan, 1e-3], [2e-3, np.nan]]),
            info={"level": "x", "against": "y", "tol": 1e-2, "measure": "error", "changed": {}, "failed": {},
                  "seconds": 0.0})
    assert "nan" not in m.table() and "none" in m.table() and "largest error 0.002" in m.summary("f.png")
    m.values[:] = np.nan
    with np.errstate(all="raise"):
        line = m.summary("f.png")
    assert "nan" not in line and line.endswith("x against y; no point could be computed)")
