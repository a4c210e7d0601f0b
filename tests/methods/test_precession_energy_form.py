"""gimbal_precession's energy form Q (the largest growth rate lambda of the nutation's energy
comes from it) enclosed over a tube's box by the centred form too: over boxes 1e-3 wide on a
flat ring and a turning base, every point value inside, and the interval at most a tenth of
the natural extension's (measured: a 70th at the median, a 10.6th at the worst of 40 boxes)."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import intervals
from gyro.systems import gimbal_precession as pr


@pytest.mark.skipif(not intervals.compiled(), reason="no C compiler: the first-order forms only")
def test_the_energy_form_is_enclosed_by_the_centred_form_over_a_tube_box():
    v = pr.parameters({"u_zeta": 1.0, "C1": 1e-3, "C2": 3e-3})
    rng = np.random.default_rng(7)
    c = np.stack([rng.uniform(-1, 1, 40), rng.uniform(-1.2, 1.2, 40), np.full(40, v["H"])], -1)
    w = np.array([1e-3, 1e-3, 1e-3 * v["H"]])
    enc = pr._tube_intervals(v, c - w, c + w)
    for _ in range(10):
        at = pr._at(v, c + w * rng.uniform(-1, 1, c.shape))["Q"]
        assert np.all(enc["Q"][0] <= at) and np.all(at <= enc["Q"][1])
    P = pr.vector(v)
    (lo, hi), = intervals.evaluate(pr._tube_function(), [(P, P), ((c - w).T, (c + w).T)])
    natural = pr._unpack(hi.T)["Q"] - pr._unpack(lo.T)["Q"]
    assert np.all(enc["Q"][1] - enc["Q"][0] <= natural / 10)
