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
