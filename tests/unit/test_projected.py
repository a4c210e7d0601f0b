"""gyro.ode.projected, the projected integration of a motion that keeps a manifold (a
model's constraints, gyro.analyses.motion.Constraints): on the unit circle y0^2 + y1^2 = 1
of y' = (y1, -y0), projected by scaling onto it. Its samples lie on the circle to rounding
and follow (cos t, -sin t) as the unprojected run does (DOP853 at rtol 1e-10 over 20 s
errs by some 1e-10; held to 1e-8); a projection that never comes within the tolerance, or
finds no point, ends the run in one line rather than as an answer."""
from __future__ import annotations

import numpy as np
import pytest

from gyro import ode


def _fun(t, y):
    return np.array([y[1], -y[0]])


def _onto_circle(rtol, atol):
    seen = []

    def project(y, before):
        out = y / np.hypot(y[0], y[1])
        ratio = float(np.max(np.abs(out - y) / (atol + rtol * np.maximum(np.abs(y), np.abs(before)))))
        seen.append(ratio)
        return out, ratio

    return project, seen


def test_the_samples_lie_on_the_manifold_and_follow_the_motion():
    t = np.linspace(0.0, 20.0, 5)  # 5 s between samples: pieces shorter than that where the drift asks
    project, seen = _onto_circle(1e-10, 1e-12)
    Y = ode.projected(_fun, t, np.array([1.0, 0.0]), "DOP853", 1e-10, 1e-12, {}, project)
    assert np.max(np.abs(np.hypot(Y[:, 0], Y[:, 1]) - 1.0)) <= 4 * np.finfo(float).eps
    assert np.max(np.abs(Y - np.column_stack([np.cos(t), -np.sin(t)]))) < 1e-8
    assert len(seen) >= len(t) - 1 and max(r for r in seen if r <= 1) <= 1.0


@pytest.mark.parametrize("ratio, match", [
    (2.0, "the motion leaves its constraints faster than the tolerance allows"),
    (np.inf, "cannot be put back on its constraints"),
])
def test_a_projection_out_of_tolerance_is_no_answer(ratio, match):
    with pytest.raises(FloatingPointError, match=match):
        ode.projected(_fun, np.linspace(0.0, 1.0, 3), np.array([1.0, 0.0]), "DOP853", 1e-10, 1e-12, {},
                      lambda y, before: (y, ratio))


def test_a_multistep_run_is_held_to_the_manifold_at_its_samples():
    """BDF and LSODA are not restarted (a restart costs them their history): their samples are
    projected where each correction is within the tolerance, else the run is no answer."""
    t = np.linspace(0.0, 1.0, 3)
    Y = np.column_stack([np.cos(t), -np.sin(t)]) * (1 + np.array([0.0, 1e-12, 1e-8]))[:, None]
    project, _ = _onto_circle(1e-10, 1e-12)
    with pytest.raises(FloatingPointError, match="leaves the constraints by .* at t = 1 s"):
        ode.checked(Y, t, "BDF", 1e-10, project)
    out = ode.checked(Y[:2], t[:2], "BDF", 1e-10, project)
    assert np.max(np.abs(np.hypot(out[:, 0], out[:, 1]) - 1.0)) <= 2 * np.finfo(float).eps
