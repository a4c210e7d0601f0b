"""The Campbell diagram of any model: natural frequencies against the spin, by the default
method over the sweep (in chunks, with a progress bar), the modes tracked across it by their
eigenvectors (MAC), each point with its growth rate, damping ratio, logarithmic decrement and
whirl direction; harmonic lines k x spin rate with their crossings found by root finding
(the critical speeds); the formulas overlaid with their errors where a model has them.

The spin is a parameter. A model may declare it (Model.spin: its parameter, and its spin rate
as an expression, the torsion gyrocompass's omega_c = H/C of (2.4), emitted as `spin_rate`);
without a declaration, a parameter in rad/s named by the caller is the spin rate itself."""
from __future__ import annotations

import numpy as np

from gyro import ladder, qep
from gyro.equilibrium import equilibria, operators
from gyro.analyses.spin import spin_parameter, spin_rates  # noqa: F401  (spin_parameter: the CLI's)
from gyro.models import Model, ParameterError
from gyro.results import CampbellDiagram, Spectrum
from gyro.results.campbell import Crossing

CHUNK = 256  # parameter sets per call of the default method (the progress bar's step)
MAX_CROSSING_STEPS = 60  # root finding of one crossing (bisection would need 52 for all digits)


BUDGET = 120.0  # s: a sweep whose projected time exceeds max(BUDGET, 20 x its nominal cost) stops
WATCH = 3.0  # s: the projection is trusted after this much time


class SweepBudget(RuntimeError):
    """A sweep stopped early: at the rate seen so far it would take longer than its budget
    (sets that escalate to 40 digits cost about 1 s each)."""


def batch_default(model: Model, P: np.ndarray, progress=False, desc="default", budget: float | None = BUDGET,
                  watch: float = WATCH, scheduler=None) -> Spectrum:
    """The default method over a large batch, in chunks (1 set first, growing to CHUNK; one
    at a time once sets cost over 0.25 s, as escalating ones do), with a progress bar. Once
    `watch` seconds have passed, a sweep whose projected time (the rate so far times the
    sets) exceeds max(budget, 20 x the batch's cost at the default method's measured rate)
    stops with SweepBudget, one line saying how far it got: a range over 300 decades stops
    in seconds, not after 15 minutes. With a `scheduler` (gyro.executor: 'local', an address
    or a Client) the batch runs on Dask in the sweep executor's chunks instead, without the
    budget: the user has chosen the scale."""
    import time

    from gyro.methods import get

    if scheduler is not None:  # on Dask, in the sweep executor's chunks (the bits of this process's run)
        from gyro.analyses.sweep import spectra

        return spectra(model, P, "default", scheduler, progress, desc)
    limit = None if budget is None else max(budget, 20 * len(P) * get("default").COST)
    t0, first, warm, parts, start, size = time.perf_counter(), 0, 0.0, [], 0, 1
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(P), desc=desc, unit="set", leave=False)
    try:
        while start < len(P):
            stop = min(start + size, len(P))
            parts.append(ladder.spectrum(model, P[start:stop], "default"))
            if bar is not None:
                bar.update(stop - start)
            if not parts[:-1]:  # the first chunk carries one-off costs (compiling the C): the clock starts after it
                warm = time.perf_counter() - t0
                t0, first = time.perf_counter(), stop
            spent = time.perf_counter() - t0
            per_set = spent / (stop - first) if stop > first else warm / stop
            if limit is not None and stop < len(P) and stop > first and spent > watch and per_set * len(P) > limit:
                raise SweepBudget(f"the sweep would take about {per_set * len(P):.0f} s ({per_set:.2g} s a set "
                                  f"after {stop} of {len(P)}): sets at extreme values escalate to 40-digit "
                                  "arithmetic; narrow the range or use fewer points")
            slow = per_set > 0.25  # sets escalating to 40 digits (~1 s each, and uneven): one at a time
            start, size = stop, 1 if slow else min(2 * size, CHUNK)
    finally:
        if bar is not None:
            bar.close()
    return Spectrum.concat(parts) if parts else ladder.spectrum(model, P, "default")


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion |a* b|^2 / (|a|^2 |b|^2) of every pair: a (r, n), b (s, n)
    -> (r, s)."""
    num = np.abs(a.conj() @ b.T) ** 2
    den = np.sum(np.abs(a) ** 2, axis=1)[:, None] * np.sum(np.abs(b) ** 2, axis=1)[None, :]
    with np.errstate(all="ignore"):
        return np.where(den > 0, num / den, 0.0)


def track(lam: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """Per point, the permutation that puts each root in its mode's column: from the first
    point's ascending order, each next point's roots assigned to the modes by the largest
    total MAC with the previous point's eigenvectors (scipy's linear_sum_assignment), the
    closeness of the roots breaking ties. Returns order (N, n): lam[i, order[i]] is tracked."""
    from scipy.optimize import linear_sum_assignment

    N, n = lam.shape
    order = np.empty((N, n), int)
    order[0] = np.arange(n)
    for i in range(1, N):
        prev_l, prev_v = lam[i - 1, order[i - 1]], vec[i - 1, order[i - 1]]
        if not (np.all(np.isfinite(prev_v)) and np.all(np.isfinite(vec[i]))):
            order[i] = np.arange(n)  # a point that could not be computed: sorted order
            continue
        with np.errstate(all="ignore"):
            near = np.abs(prev_l[:, None] - lam[i][None, :]) / np.maximum(np.abs(prev_l[:, None]), 1e-300)
        cost = -mac(prev_v, vec[i]) + 1e-3 * np.nan_to_num(np.minimum(near, 1.0), nan=1.0)
        rows, cols = linear_sum_assignment(cost)
        order[i, rows] = cols
    return order


def whirl(vec: np.ndarray, freq: np.ndarray, reduced: list, pairs: list) -> np.ndarray:
    """'forward', 'backward' or 'mixed' per root (None without declared pairs, or for a root
    that does not oscillate). A pair (a, b) of coordinates whirls forward when its orbit runs
    from a to b, as x to y for a spin about z: with x(t) = Re(X e^{i w t}), the sign of
    -Im(conj(X_a) X_b). A root whose pairs (those with an amplitude above 1e-3 of the largest
    pair's) disagree, or whose orbit is flat (|2 Im(conj(X_a) X_b)| below 1e-6 of
    |X_a|^2 + |X_b|^2), is mixed."""
    shape = freq.shape
    out = np.full(shape, None, dtype=object)
    if not pairs:
        return out
    ia = [reduced.index(a) for a, _ in pairs]
    ib = [reduced.index(b) for _, b in pairs]
    Xa, Xb = vec[..., ia], vec[..., ib]
    amp = np.abs(Xa) ** 2 + np.abs(Xb) ** 2
    with np.errstate(all="ignore"):
        s = -2 * np.imag(np.conj(Xa) * Xb) / amp
        strong = amp >= 1e-3 * np.max(amp, axis=-1, keepdims=True)
    fwd = np.all(~strong | (s > 1e-6), axis=-1)
    bwd = np.all(~strong | (s < -1e-6), axis=-1)
    label = np.where(fwd, "forward", np.where(bwd, "backward", "mixed")).astype(object)
    ok = (freq > 0) & np.all(np.isfinite(vec), axis=-1)
    out[ok] = label[ok]
    return out


def _tracked_root(model, base, iv, spin, x, target):
    """The root at spin value x nearest to `target` (a tracked root interpolated between two
    grid points): one set by the default method. Returns (root, spin rate, its index in that
    set's ascending order: the number `gyro frequencies` gives it there, less one)."""
    P = base.copy()
    P[iv] = x
    s = ladder.spectrum(model, P, "default")
    lam = s.growth[0] + 1j * s.frequencies[0]
    j = int(np.nanargmin(np.abs(lam - target)))
    return lam[j], float(spin_rates(model, spin, P[None])[0]), j


def crossings(model: Model, base: np.ndarray, spin: str, values, rate, lam, harmonics) -> list[Crossing]:
    """Where a line k x spin rate meets a tracked mode's damped frequency: each sign change
    of Im(lambda_j) - k rate between grid points, refined by Brent's method on the spin
    value with the spectrum solved there (not read off the grid). The crossing's mode is
    numbered as `gyro frequencies` numbers it at the crossing's spin (ascending |lambda| of
    that set), its branch by the tracked column (1-based)."""
    from scipy.optimize import brentq

    iv = model.param_names.index(spin)
    out = []
    for k in harmonics:
        g = lam.imag - k * rate[:, None]
        for j in range(lam.shape[1]):
            for i in np.flatnonzero(np.sign(g[:-1, j]) * np.sign(g[1:, j]) < 0):
                x0, x1 = values[i], values[i + 1]
                l0, l1 = lam[i, j], lam[i + 1, j]

                def h(x):
                    t = (x - x0) / (x1 - x0)
                    root, r, _ = _tracked_root(model, base, iv, spin, x, (1 - t) * l0 + t * l1)
                    return root.imag - k * r

                try:
                    x = brentq(h, x0, x1, xtol=4 * qep.EPS * max(abs(x0), abs(x1)), rtol=4 * qep.EPS,
                               maxiter=MAX_CROSSING_STEPS)
                except ValueError:  # the sign change does not survive the exact roots: none
                    continue
                t = (x - x0) / (x1 - x0)
                root, r, at = _tracked_root(model, base, iv, spin, x, (1 - t) * l0 + t * l1)
                out.append(Crossing(int(k), at + 1, float(x), float(r), float(root.imag), j + 1))
    return sorted(out, key=lambda c: (c.value, c.k, c.mode))


def campbell(model: Model, values: dict, spin: str | None, sweep_values, harmonics=(), progress=False,
             log=False, scheduler=None) -> CampbellDiagram:
    """The Campbell diagram over the spin parameter's `sweep_values` (absolute, in its unit),
    the other parameters at `values`."""
    spin = spin_parameter(model, spin)
    x = np.asarray(sweep_values, float)
    P = np.tile(model.vector(values), (len(x), 1))
    P[:, model.param_names.index(spin)] = x
    for v in (x[0], x[-1]):
        model.parameters({spin: v})  # the ends of the range are valid values
    exact = batch_default(model, P, progress, desc="Campbell", scheduler=scheduler)
    qe = exact.equilibrium if exact.equilibrium is not None else equilibria(model, P)[0]
    M, D, K = operators(model, P, qe)
    lam = exact.growth + 1j * exact.frequencies
    vec = qep.eigenvectors(M, D, K, lam)
    order = track(lam, vec)
    lam_t = np.take_along_axis(lam, order, 1)
    vec_t = np.take_along_axis(vec, order[..., None], 1)
    rate = spin_rates(model, spin, P)
    approx = ladder.spectrum(model, P, "formulas") if "mode_formulas" in model.meta["functions"] else None
    pairs = [tuple(p) for p in model.meta.get("spin", {}).get("whirl", [])] if model.meta.get(
        "spin", {}).get("parameter") == spin else []
    tracked = Spectrum("default", lam_t.imag, lam_t.real, np.take_along_axis(exact.error_estimate, order, 1),
                       modes=vec_t)
    example = float(spin_rates(model, spin, model.vector(model.defaults)[None])[0])
    changed = {k: v for k, v in values.items() if v != model.defaults[k] and k != spin}
    return CampbellDiagram(
        model.name, model.meta["title"], rate, exact, approx, values, example, changed,
        spin=spin, values_swept=x, tracked=tracked,
        whirl=whirl(vec_t, lam_t.imag, model.meta["reduced"], pairs),
        harmonics=[int(k) for k in harmonics],
        crossings=crossings(model, P[0], spin, x, rate, lam_t, harmonics),
        rate_label=_rate_label(model, spin), log=log, order=order)


def _rate_label(model: Model, spin: str) -> str:
    decl = model.meta.get("spin", {})
    if decl.get("parameter") == spin and decl.get("rate") != spin:
        return f"spin rate {decl['rate']} [rad/s]"
    return f"spin rate {spin} [rad/s]"


def sweep(model: Model, values: dict, lo: float, hi: float, points: int, progress=False, spin=None,
          harmonics=(), scheduler=None) -> CampbellDiagram:
    """Frequencies against spin: the spin parameter from lo to hi times the set's value
    (log-spaced)."""
    spin = spin_parameter(model, spin)
    if values[spin] <= 0:
        raise ParameterError(f"{spin}: --range scales the set's {spin}, which is {values[spin]:g}; give "
                             f"{spin} > 0 or an absolute --spin-range")
    return campbell(model, values, spin, values[spin] * np.geomspace(lo, hi, points), harmonics, progress, log=True,
                    scheduler=scheduler)
