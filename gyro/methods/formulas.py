"""``formulas``: the paper's approximate formulas (3.2)-(3.28), corrected where the
derivation shows them wrong, emitted by `make derive` and run as compiled C over the
batch. The estimate is the size of what each formula neglects (its small parameter to its
order)."""
from __future__ import annotations

import numpy as np

from gyro import cbackend
from gyro.kernels import chunks, compiled
from gyro.models import Model
from gyro.results import Spectrum

NAME = "formulas"
RUNG = 1
COST = 1.8e-7  # s per set on one core, compiled (bench/results/ladder.json)
CHUNK = 8192


def available(model: Model) -> bool:
    return "mode_formulas" in model.meta["functions"]


def solve(model: Model, P: np.ndarray, tol: float | None = None) -> Spectrum:
    """The model's mode formulas (metadata 'mode_formulas') over the batch: for each mode,
    among its candidate formulas the one whose own error estimate is smallest, sorted by
    frequency. Compiled: one pass of the generated C (templates/mode_select.c.j2); without a
    compiler, NumPy. A model without formulas is refused in one line (ParameterError)."""
    if not available(model):
        from gyro.errors import ParameterError

        raise ParameterError(f"method formulas: {model.name} has no approximate formulas; try --method default")
    kernel = compiled(cbackend.mode_formulas_selected, model)
    if kernel is not None:
        with np.errstate(all="ignore"):
            f, e = kernel(P)
        return Spectrum("formulas", f, np.zeros(f.shape), e, growth_known=False)
    if P.shape[0] > CHUNK:  # cache-sized pieces: the selection is memory-bound
        return Spectrum.concat([solve(model, P[s]) for s in chunks(P.shape[0], CHUNK)])
    f, e = per_mode(model, P, model.numpy.mode_formulas)
    order = np.argsort(f, axis=1, kind="stable")  # as the C's insertion sort: ties keep their order
    f, e = np.take_along_axis(f, order, 1), np.take_along_axis(e, order, 1)
    return Spectrum("formulas", f, np.zeros(f.shape), e, growth_known=False)


def per_mode(model: Model, P: np.ndarray, evaluate=None) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies, estimates), (sets, modes) in the rows of metadata 'mode_formulas' (not
    sorted): per mode the candidate whose own estimate is smallest; the estimate infinite
    where that formula is outside its domain (0/0, a negative square). `evaluate` is the
    generated mode_formulas (default: compiled where there is a compiler)."""
    from gyro.kernels import function

    with np.errstate(all="ignore"):
        omega, estimate = (evaluate or function(model, "mode_formulas"))(P)
    N = P.shape[0]
    n = len(model.meta["mode_formulas"])
    omega, estimate = np.reshape(omega, (N, n, -1)), np.reshape(estimate, (N, n, -1))
    f, e = omega[..., 0], estimate[..., 0]
    for j in range(1, omega.shape[2]):
        better = estimate[..., j] < e
        f = np.where(better, omega[..., j], f)
        e = np.where(better, estimate[..., j], e)
    with np.errstate(invalid="ignore"):
        e = np.where(np.isfinite(f) & (f > 0), e, np.inf)
    return f, e
