"""Stability of the equilibrium over a grid of two parameters, by the default method."""
from __future__ import annotations

import numpy as np

from gyro.analyses.campbell import batch_default
from gyro.models import Model
from gyro.results import Map, classify


def stability_grid(model: Model, values: dict, xname, xrange, yname, yrange, points, progress=False,
                   xlog=False, ylog=False, scheduler=None) -> Map:
    """Stability over a grid of two parameters (log-spaced where asked), a verdict Map; on Dask with a
    `scheduler` (gyro.executor), to the bit the in-process map."""
    xs = (np.geomspace if xlog else np.linspace)(*xrange, points)
    ys = (np.geomspace if ylog else np.linspace)(*yrange, points)
    X, Y = np.meshgrid(xs, ys)
    P = np.tile(model.vector(values), (X.size, 1))
    P[:, model.param_names.index(xname)] = X.ravel()
    P[:, model.param_names.index(yname)] = Y.ravel()
    st = classify(batch_default(model, P, progress, desc="stability map", scheduler=scheduler))
    shape = X.shape
    layers = {"growth": st.growth_rate.reshape(shape), "unstable_roots": st.unstable_roots.reshape(shape),
              "slowest": st.slowest_growth.reshape(shape), "reasons": st.reason.reshape(shape)}
    changed = {k: v for k, v in values.items() if v != model.defaults[k] and k not in (xname, yname)}
    return Map("verdict", model.name, model.meta["title"], xname, yname, xs, ys, st.label.reshape(shape), layers,
               xlog, ylog, {p.name: p.unit for p in model.params}, {"changed": changed})
