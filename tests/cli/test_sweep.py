"""`gyro sweep`: a trial analysis on the runtime's shape (docs/architecture.md)."""
from __future__ import annotations

import json

import numpy as np

from gyro import ladder, load
from gyro.analyses.sweep import sweep
from gyro.cli import main


def test_sweep_equals_the_ladder_at_each_value():
    m = load("torsion_gyrocompass")
    r = sweep(m, m.defaults, "Kp", 1e5, 4e5, 4, log=True)
    for i, x in enumerate(r.x):
        ref = ladder.spectrum(m, m.vector(m.parameters({"Kp": x})))
        np.testing.assert_array_equal(r.spectrum.frequencies[i], ref.frequencies[0])
    # omega5 = omega_p = sqrt(Kp/m) (3.7) follows the swept stiffness
    assert np.allclose(np.min(np.abs(r.spectrum.frequencies - np.sqrt(r.x / 0.4)[:, None]), axis=1), 0, atol=1e-6)


def test_sweep_cli_json_and_errors(capsys, tmp_path):
    assert main(["sweep", "torsion_gyrocompass", "--x", "H", "--x-range", "0.2", "0.5", "--points", "3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["x"]["name"] == "H" and len(doc["frequencies"]) == 3 and doc["stability"] == ["stable"] * 3
    assert main(["sweep", "torsion_gyrocompass", "--x", "nope", "--x-range", "0", "1"]) == 2
    assert "--x 'nope': unknown parameter" in capsys.readouterr().err
    assert main(["sweep", "torsion_gyrocompass", "--x", "m", "--x-range", "-1", "1"]) == 2
    assert main(["sweep", "torsion_gyrocompass", "--x", "m", "--x-range", "0.3", "0.5", "--points", "2",
                 "--out", str(tmp_path / "s.png")]) == 0
    assert "wrote" in capsys.readouterr().out and (tmp_path / "s.png").exists()


def test_one_axis_grammar_for_sweeps_and_maps(tmp_path):
    """sweep and stability-map take an axis as gyro map and level-map do, --x NAME=LO:HI[:N],
    with the same output as --x NAME --x-range LO HI --points N (kept); both forms at once,
    a range missing, and counts that disagree are refused in one line, exit 2."""
    from tests.conftest import error_lines, run_cli

    a = run_cli("sweep", "torsion_gyrocompass", "--x", "u=0:7.29e-5:3", "--json")
    b = run_cli("sweep", "torsion_gyrocompass", "--x", "u", "--x-range", "0", "7.29e-5", "--points", "3", "--json")
    assert a[0] == b[0] == 0 and a[1] == b[1]
    a = run_cli("stability-map", "torsion_gyrocompass", "--x", "l2=-0.5:0.3:4", "--y", "H=0.01:10:4", "--y-log",
                "--out", str(tmp_path / "a.png"), "--json")
    b = run_cli("stability-map", "torsion_gyrocompass", "--x", "l2", "--x-range", "-0.5", "0.3", "--y", "H",
                "--y-range", "0.01", "10", "--y-log", "--points", "4", "--out", str(tmp_path / "b.png"), "--json")
    assert a[0] == b[0] == 0 and a[1] == b[1]
    for args, word in ((["--x", "u=0:1e-4", "--x-range", "0", "1e-4"], "--x-range: the axis is given twice"),
                       (["--x", "u"], "--x-range: required with --x NAME"),
                       (["--x", "u=0:1e-4:3", "--points", "4"], "--points: the axes and --points give different"),
                       (["--x", "u=0:x"], "--x u"), (["--x", "u=0:1e-4:2.5"], "N is not an integer")):
        rc, out, err = run_cli("sweep", "torsion_gyrocompass", *args)
        assert rc == 2 and out == "" and len(error_lines(err)) == 1 and word in err, (args, err)
