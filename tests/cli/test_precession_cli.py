"""The command-line contract of issue 21: `gyro simulate gimbal_precession --level ...`,
`gyro level-map ...`, `gyro scene gimbal_precession motion ...`: keys, exit codes, one-line
errors naming the parameter or the event, nothing written on failure."""
from __future__ import annotations

import json

import pytest

from gyro.systems.gimbal_precession import LEVELS
from tests.conftest import run_cli

SIM_KEYS = {"model", "level", "params", "t", "x", "y", "alpha", "beta"}


@pytest.mark.parametrize("level", LEVELS)
def test_simulate_every_level_gives_the_contract_keys(level):
    rc, out, err = run_cli("simulate", "gimbal_precession", "--level", level, "--t-end", "2", "--points", "5",
                           "--set", "l_y=5e-4", "--set", "M_motor=0", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert SIM_KEYS <= set(d) and d["model"] == "gimbal_precession" and d["level"] == level
    assert len(d["t"]) == len(d["x"]) == len(d["y"]) == len(d["alpha"]) == len(d["beta"]) == 5
    assert d["params"]["l_y"] == 5e-4 and "M_motor" in d["params"]  # command-line names
    assert d["x"][0] == 0.0 and d["y"][0] == 0.0  # alpha0 = beta0 = 0: the image point at the origin


def test_simulate_table_and_figure(tmp_path):
    out_png = tmp_path / "m.png"
    rc, out, err = run_cli("simulate", "gimbal_precession", "--level", "elementary", "--t-end", "1",
                           "--points", "3", "--out", str(out_png))
    assert rc == 0, err
    assert "level elementary" in out and out_png.stat().st_size > 0


@pytest.mark.parametrize("args,needle", [
    (["--set", "Hx=1"], "unknown parameter 'Hx'"),
    (["--set", "H=abc"], "parameter H: not a number"),
    (["--set", "H=nan"], "parameter H"),
    (["--set", "l_x=inf"], "parameter l_x"),
    (["--set", "H=0"], "parameter H"),
    (["--set", "A1=-1e-3"], "parameter A1"),
    (["--set", "B2=0"], "parameter B2"),
    (["--set", "beta0=1.6"], "parameter beta0"),
    (["--set", "f_alpha=-1"], "parameter f_alpha"),
    (["--set", "l_x=0.1", "--t-end", "30"], "beta reaches +-90 deg"),
    (["--level", "exact"], "--level: unknown level 'exact'"),
    (["--t-end", "-1"], "--t-end"),
    (["--points", "1"], "--points"),
])
def test_simulate_bad_input_exits_2_in_one_line_and_writes_nothing(tmp_path, args, needle):
    out_png = tmp_path / "m.png"
    base = {"--level": "full", "--t-end": "20", "--points": "11"}
    flags = [a for a in args if a.startswith("--")]
    cmd = ["simulate", "gimbal_precession"]
    for k, v in base.items():
        if k not in flags:
            cmd += [k, v]
    rc, out, err = run_cli(*cmd, *args, "--out", str(out_png))
    assert rc == 2, (rc, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in err
    assert not out_png.exists() and out == ""


def test_simulate_level_required_and_only_for_this_model():
    rc, _, err = run_cli("simulate", "gimbal_precession", "--t-end", "1")
    assert rc == 2 and "--level: required" in err
    rc, _, err = run_cli("simulate", "gimbal_gyroscope", "--t-end", "1", "--level", "full")
    assert rc == 2 and "--level: not for gimbal_gyroscope; its motion takes --method" in err


def test_level_map_contract(tmp_path):
    out_png = tmp_path / "map.png"
    rc, out, err = run_cli("level-map", "gimbal_precession", "--level", "elementary", "--against", "rigorous",
                           "--x", "k_xi1=0:1e-4:3", "--y", "l_x=5e-4:1e-3:2", "--t-end", "5", "--tol", "1e-2",
                           "--out", str(out_png), "--json", "--quiet")
    assert rc == 0, err
    d = json.loads(out)
    assert {"x", "y", "values", "level", "against", "tol"} <= set(d)
    assert d["level"] == "elementary" and d["against"] == "rigorous" and d["tol"] == 1e-2
    assert len(d["values"]) == 2 and all(len(r) == 3 for r in d["values"])
    assert d["values"][0][0] < 1e-2 < d["values"][0][2]  # balanced: enough; k_xi1 = 1e-4: not
    assert out_png.stat().st_size > 0


@pytest.mark.parametrize("args,needle", [
    (["--level", "elementary", "--against", "small2"], "--against: unknown level 'small2'"),
    (["--level", "rigorous", "--against", "rigorous"], "the same level"),
    (["--level", "rigorous", "--against", "full", "--question", "frequencies"], "--question frequencies"),
    (["--level", "elementary", "--against", "rigorous", "--x", "k_xi1=1:0:3"], "need LO < HI"),
    (["--level", "elementary", "--against", "rigorous", "--x", "nope=0:1:3"], "unknown parameter"),
    (["--level", "elementary", "--against", "rigorous", "--tol", "2"], "--tol"),
    (["--level", "elementary", "--against", "rigorous", "--set", "H=-1"], "parameter H"),
])
def test_level_map_bad_input_exits_2(tmp_path, args, needle):
    out_png = tmp_path / "map.png"
    cmd = ["level-map", "gimbal_precession", "--x", "k_xi1=0:1e-4:2", "--y", "l_x=5e-4:1e-3:2", "--t-end", "1"]
    if "--x" in args:
        cmd = ["level-map", "gimbal_precession", "--y", "l_x=5e-4:1e-3:2", "--t-end", "1"]
    rc, out, err = run_cli(*cmd, *args, "--out", str(out_png))
    assert rc == 2, (rc, err)
    assert len(err.strip().splitlines()) == 1 and needle in err and not out_png.exists()


def test_level_map_is_generic_over_the_models_levels(tmp_path):
    """The same command on the torsion gyrocompass's frequency levels: the formulas against
    the exact operator."""
    rc, out, err = run_cli("level-map", "torsion_gyrocompass", "--level", "formulas", "--against", "linear_exact",
                           "--x", "u=5e-5:1e-4:2", "--y", "H=1:3:2", "--out", str(tmp_path / "t.png"), "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["against"] == "linear_exact:default" and "frequencies" in d["measure"]
    assert all(0 < v < 1 for row in d["values"] for v in row)


def test_level_map_of_another_models_unknown_level_exits_2(tmp_path):
    rc, _, err = run_cli("level-map", "gimbal_gyroscope", "--level", "a", "--against", "b", "--x", "A0=1:2:2",
                         "--y", "B0=1:2:2", "--out", str(tmp_path / "m.png"))
    assert rc == 2 and "--level: unknown level 'a' of gimbal_gyroscope" in err


def test_scene_picks_the_cheapest_adequate_theory():
    """Balanced, frictionless, the image point near the origin: elementary is enough at
    1e-3; with the outer ring's imbalance it is not, and the small form (28), which keeps it, is."""
    rc, out, err = run_cli("scene", "gimbal_precession", "motion", "--tol", "1e-3", "--t-end", "5", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert {"model", "question", "level", "tried", "error_bound", "seconds", "t", "x", "y"} <= set(d)
    assert d["level"] == "elementary" and max(d["error_bound"]) <= 1e-3
    rc, out, err = run_cli("scene", "gimbal_precession", "motion", "--tol", "1e-3", "--horizon", "5",
                           "--set", "k_xi1=1e-4", "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["level"] == "small" and d["tried"][0]["level"] == "elementary"  # (28) keeps the imbalance


def test_a_parameter_typed_by_its_alias_is_the_same_parameter():
    """M_motor (the symbol Mmotor: names M_* are refused by the emitters) and the paper's
    lambda (the symbol lam) are taken by every command through Model.parameters; an alias
    naming no parameter would be refused at derive time."""
    from gyro.models import load

    for name, alias, symbol, value in (("gimbal_precession", "M_motor", "Mmotor", 0.25),
                                       ("gyrohorizoncompass", "lambda", "lam", 1.5)):
        model = load(name)
        assert model.meta["aliases"][alias] == symbol and symbol in model.param_names
        assert model.canonical(alias) == symbol and model.canonical(symbol) == symbol
        assert model.parameters({alias: value})[symbol] == value
        assert model.vector({alias: value})[model.param_names.index(symbol)] == value


def test_an_unknown_level_lists_each_known_one_once(tmp_path):
    rc, _, err = run_cli("level-map", "gimbal_precession", "--level", "nosuch", "--against", "small",
                         "--x", "k_xi1=0:1e-4:2", "--y", "l_x=5e-4:1e-3:2", "--out", str(tmp_path / "m.png"))
    assert rc == 2 and err.count("\n") == 1, err
    known = err.strip().split("known: ")[1].split(", ")
    assert len(known) == len(set(known)), known
    # its own five in its order, and the exact operator's levels every model with one has
    assert [k for k in known if not k.startswith("linear_exact")] == ["elementary", "small", "rigorous", "image", "full"]
    assert "linear_exact:default" in known
