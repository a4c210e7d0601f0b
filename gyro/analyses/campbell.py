"""The Campbell diagram: natural frequencies against spin, by the default method over the
sweep (in chunks, with a progress bar), the formulas overlaid with their errors."""
from __future__ import annotations

import numpy as np

from gyro import ladder
from gyro.kernels import chunks
from gyro.models import Model, ParameterError
from gyro.results import CampbellDiagram, Spectrum

CHUNK = 256  # parameter sets per call of the default method (the progress bar's step)


def batch_default(model: Model, P: np.ndarray, progress=False, desc="default") -> Spectrum:
    """The default method over a large batch, in chunks, with a progress bar."""
    return Spectrum.concat([ladder.spectrum(model, P[s], "default")
                            for s in chunks(len(P), CHUNK, progress, desc)])


def sweep(model: Model, values: dict, lo: float, hi: float, points: int, progress=False) -> CampbellDiagram:
    """Frequencies against spin: H from lo to hi times the set's H (log-spaced)."""
    scale = np.geomspace(lo, hi, points)
    P = np.tile(model.vector(values), (points, 1))
    iH = model.param_names.index("H")
    if values["H"] <= 0:
        raise ParameterError("H: the Campbell diagram scales the spin; give H > 0")
    P[:, iH] = values["H"] * scale
    exact = batch_default(model, P, progress, desc="Campbell")
    approx = ladder.spectrum(model, P, "formulas") if "mode_formulas" in model.meta["functions"] else None
    has_A = "A" in model.param_names
    Omega = P[:, iH] / P[:, model.param_names.index("A")] if has_A else P[:, iH]
    example = model.defaults["H"] / model.defaults["A"] if has_A else model.defaults["H"]
    changed = {k: v for k, v in values.items() if v != model.defaults[k]}
    return CampbellDiagram(model.name, model.meta["title"], Omega, exact, approx, values, example, changed)
