"""One name per parameter across every command (issue 37, item 5): every command prints the
name the model declares (its metadata's parameters: `lam`, `Mmotor`) and takes the other
name the model records for it (its aliases: `lambda`, `M_motor`, documented before) as the
same parameter; a parameter given by both names is refused in one line. The JSON documents
that keyed the other name (`gyro stability`, `gyro simulate gimbal_precession`) keep that
key beside the declared one. A name's answer is the same bit for bit by either name."""
from __future__ import annotations

import json

import pytest

from tests.conftest import run_cli, error_lines

ALIASED = {"gyrohorizoncompass": ("lam", "lambda", 1.05), "gimbal_precession": ("Mmotor", "M_motor", 1e-4)}


def ok(*args) -> str:
    rc, out, err = run_cli(*args)
    assert rc == 0, (args, err)
    return out


def refused(*args, word: str) -> None:
    rc, out, err = run_cli(*args)
    assert rc == 2 and out == "" and len(error_lines(err)) == 1 and word in err, (args, rc, err)


@pytest.mark.parametrize("model", sorted(ALIASED))
def test_params_prints_the_declared_name_and_the_other_taken(model):
    name, alias, _ = ALIASED[model]
    rows = ok("params", model).splitlines()
    assert any(r.split()[0] == name for r in rows[1:]) and not any(r.split()[0] == alias for r in rows[1:])
    assert f"also taken: {alias} for {name}" in rows


def test_lam_and_lambda_are_one_parameter_at_every_command(tmp_path):
    """frequencies, sweep (--set and --x), stability, tolerance (--spread), stability-map
    (--x): the same
    output by either name, the declared name printed."""
    by = {}
    for n in ("lam", "lambda"):
        by[n] = [ok("frequencies", "gyrohorizoncompass", "--set", f"{n}=1.04", "--set", "eta=0", "--json"),
                 ok("sweep", "gyrohorizoncompass", "--x", n, "--x-range", "1.0", "1.1", "--points", "2",
                    "--set", "eta=0"),
                 ok("stability", "gyrohorizoncompass", "--set", f"{n}=1.04", "--set", "eta=0"),
                 ok("stability", "gyrohorizoncompass", "--set", f"{n}=1.04", "--set", "eta=0", "--json"),
                 ok("tolerance", "gyrohorizoncompass", "--spread", f"{n}=normal:0.01", "--samples", "16",
                    "--set", "eta=0", "--json")]
    assert by["lam"] == by["lambda"]
    freq, sweep, table, stab, tol = by["lambda"]
    assert json.loads(freq)["params"]["lam"] == 1.04
    assert sweep.splitlines()[0].split()[0] == "lam"
    assert ", lam = 1.04" in table.splitlines()[1] and "lambda" not in table.splitlines()[1]
    params = json.loads(stab)["params"]
    assert params["lam"] == params["lambda"] == 1.04  # the key before, kept beside the declared one
    assert [s["name"] for s in json.loads(tol)["spreads"]] == ["lam"]
    maps = [ok("stability-map", "gyrohorizoncompass", "--x", n, "--x-range", "1", "1.1", "--y", "L", "--y-range",
               "2", "3", "--points", "2", "--json", "--out", str(tmp_path / f"{n}.png")) for n in ("lam", "lambda")]
    assert maps[0] == maps[1] and json.loads(maps[0])["x"]["name"] == "lam"
    for cmd in (["frequencies", "gyrohorizoncompass"], ["stability", "gyrohorizoncompass"]):
        refused(*cmd, "--set", "lam=1.04", "--set", "lambda=1.04", word="lam: given twice")


def test_map_takes_lam_as_an_axis_and_as_a_set(tmp_path):
    """`gyro map` over lam (by either name), printed as lam; lam is an axis by either name, so
    --set refuses it by either name."""
    out = {}
    for n in ("lam", "lambda"):
        out[n] = ok("map", "gyrohorizoncompass", "--x", f"{n}=1.0:1.1:2", "--y", "L=2:3:2", "--set", "eta=0",
                    "--json", "--out", str(tmp_path / f"{n}.png"))
    assert out["lam"] == out["lambda"] and json.loads(out["lam"])["x"]["name"] == "lam"
    for axis, given in (("lam", "lambda"), ("lambda", "lam")):
        refused("map", "gyrohorizoncompass", "--x", f"{axis}=1.0:1.1:2", "--y", "L=2:3:2", "--set", "eta=0",
                "--set", f"{given}=1.04", "--out", str(tmp_path / "m.png"), word="is an axis")


def test_mmotor_and_m_motor_are_one_parameter(tmp_path):
    """gimbal_precession: simulate took only M_motor, the other commands only Mmotor."""
    run = ["simulate", "gimbal_precession", "--level", "elementary", "--t-end", "1", "--points", "3", "--json"]
    docs = {n: json.loads(ok(*run, "--set", f"{n}=1e-4")) for n in ("Mmotor", "M_motor")}
    for d in docs.values():
        d.pop("seconds")  # the CPU time of the integration
    assert docs["Mmotor"] == docs["M_motor"]
    assert docs["Mmotor"]["params"]["Mmotor"] == docs["Mmotor"]["params"]["M_motor"] == 1e-4
    refused(*run, "--set", "Mmotor=1e-4", "--set", "M_motor=1e-4", word="Mmotor: given twice")
    refused(*run, "--set", "Mmotr=1e-4", word="M_motor for Mmotor")  # the known names, both
    # the sweep has no equilibrium to answer about (the model turns steadily with no rest
    # point in the motor's range): one line, the same under either name, naming Mmotor
    rc, a, ea = run_cli("sweep", "gimbal_precession", "--x", "M_motor", "--x-range", "0", "1e-3", "--points", "2",
                        "--json")
    rc2, b, eb = run_cli("sweep", "gimbal_precession", "--x", "Mmotor", "--x-range", "0", "1e-3", "--points", "2",
                         "--json")
    assert rc == rc2 == 1 and a == b == "" and ea == eb and "at any Mmotor of the sweep" in ea
