"""Natural frequencies against any one parameter, by any method of the ladder."""
from __future__ import annotations

import numpy as np

from gyro import executor, ladder
from gyro.models import Model, load
from gyro.results import FrequencySweep, Spectrum

CHUNK = 256
ROUTE = "U32"  # the route's text in a fixed-width array (chunks travel as plain arrays)


def warm(model_ref) -> None:
    """Load the model and its compiled kernels in a worker (once per worker)."""
    model = load(model_ref)
    ladder.spectrum(model, model.vector(), "default")


def model_ref(model: Model) -> str:
    """What a worker loads the model by: its name, or its folder for a model from a path."""
    from gyro.models import GENERATED

    return model.name if model.directory == GENERATED / model.name else str(model.directory)


def spectrum_chunk(start, stop, model_ref, P, method):
    """The spectra of the sets start..stop of P: a chunk of the sweep executor."""
    s = ladder.spectrum(load(model_ref), P[start:stop], method)
    out = {"frequencies": s.frequencies, "growth": s.growth, "error_estimate": s.error_estimate}
    if s.equilibrium is not None:
        out["equilibrium"] = s.equilibrium
    if s.route is not None:
        out["route"] = s.route.astype(ROUTE)
    return out


def spectra(model: Model, P: np.ndarray, method: str = "default", scheduler=None, progress: bool = False,
            desc: str = "sweep", chunk: int = CHUNK, folder=None) -> Spectrum:
    """The spectra of a large batch over the sweep executor (gyro.executor): in this process
    by default, or on Dask (scheduler 'local', an address, or a Client), bit for bit alike."""
    ref = model_ref(model)
    out = executor.run(spectrum_chunk, P.shape[0], chunk, (ref, P, method), scheduler, folder, progress, desc,
                       warm=warm, warm_args=(ref,))
    if P.shape[0] == 0:
        return ladder.spectrum(model, P, method)
    route = out.get("route")
    return Spectrum(method, out["frequencies"], out["growth"], out["error_estimate"], out.get("equilibrium"),
                    None if route is None else np.asarray(route).astype(object),
                    growth_known=method != "formulas")


def sweep(model: Model, values: dict, xname: str, lo: float, hi: float, points: int, method: str = "default",
          log: bool = False, progress: bool = False, scheduler=None) -> FrequencySweep:
    x = (np.geomspace if log else np.linspace)(lo, hi, points)
    P = np.tile(model.vector(values), (points, 1))
    P[:, model.param_names.index(xname)] = x
    spec = spectra(model, P, method, scheduler, progress)
    unit = next(p.unit for p in model.params if p.name == xname)
    return FrequencySweep(model.name, model.meta["title"], xname, unit, x, spec, log)
