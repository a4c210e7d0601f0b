"""Natural frequencies against any one parameter, by any method of the ladder."""
from __future__ import annotations

import numpy as np

from gyro import ladder
from gyro.kernels import chunks
from gyro.models import Model
from gyro.results import FrequencySweep, Spectrum

CHUNK = 256


def sweep(model: Model, values: dict, xname: str, lo: float, hi: float, points: int, method: str = "default",
          log: bool = False, progress: bool = False) -> FrequencySweep:
    x = (np.geomspace if log else np.linspace)(lo, hi, points)
    P = np.tile(model.vector(values), (points, 1))
    P[:, model.param_names.index(xname)] = x
    spec = Spectrum.concat([ladder.spectrum(model, P[s], method) for s in chunks(points, CHUNK, progress, "sweep")])
    unit = next(p.unit for p in model.params if p.name == xname)
    return FrequencySweep(model.name, model.meta["title"], xname, unit, x, spec, log)
