"""The ladder of frequency methods: one entry point over the methods of gyro.methods.

Every method returns, for each parameter set of a batch, the natural frequencies in
ascending order with a relative error estimate for each (docs/methods.md). From the
cheapest to the most exact: ``formulas`` (the paper's approximations), ``polyroots`` (the
characteristic polynomial), ``companion`` (the first-order eigenproblem), ``default``
(the structured solver, escalating by itself) and ``reference`` (40 digits). The ladder
is a loop over the methods' modules: a method is one module with a name, a rung and a
measured cost.
"""
from __future__ import annotations

import numpy as np

from gyro.equilibrium import EquilibriumError, equilibrium
from gyro.methods import DEFAULT_TOL, get, names
from gyro.models import Model
from gyro.results import ModalResult, Spectrum, Stability, classify

__all__ = ["METHODS", "DEFAULT_TOL", "spectrum", "classify", "natural_frequencies", "cost",
           "Spectrum", "Stability", "as_batch"]

METHODS = names()  # in the ladder's order


def cost(method: str) -> float:
    """A method's measured time per set (s, one core): what a selector weighs."""
    return get(method).COST


def as_batch(model: Model, params) -> np.ndarray:
    P = np.asarray(params, dtype=float)
    if P.ndim == 1:
        P = P[None, :]
    if P.ndim != 2 or P.shape[1] != len(model.param_names):
        raise ValueError(f"params: expected shape (sets, {len(model.param_names)}), got {P.shape}")
    return P


def spectrum(model: Model, params, method: str = "default", tol: float = DEFAULT_TOL,
             modes: bool = False) -> Spectrum:
    """Natural frequencies of a batch of parameter sets (rows of `params`, in the order of
    model.param_names) by one method of the ladder; with `modes`, the right eigenvectors
    too (Spectrum.modes: with_modes)."""
    if modes:
        return with_modes(model, params, spectrum(model, params, method, tol))
    if method not in METHODS:
        raise ValueError(f"method: unknown {method!r}; known: {', '.join(METHODS)}")
    P = as_batch(model, params)
    if P.shape[0] == 0:  # an empty batch: an empty spectrum
        n = len(model.meta["reduced"])
        empty = np.zeros((0, n))
        return Spectrum(method, empty, empty.copy(), empty.copy(),
                        np.zeros((0, len(model.meta["equilibrium_coordinates"]))), np.zeros(0, object))
    if model.meta.get("nondifferentiable"):
        return _where_linearisable(model, P, method, tol)
    return steady_roots(model, get(method).solve(model, P, tol))


class OperatorUndefined(ArithmeticError):
    """The linear operator does not exist at a set: a non-smooth term (derive/nonsmooth.py)
    sits on its kink at the reference."""


def _where_linearisable(model: Model, P, method: str, tol: float) -> Spectrum:
    """A model with non-smooth terms whose derivative the operator needs (metadata
    'nondifferentiable'): the sets where the operator is not finite at a finite equilibrium
    have no linearisation; one such set alone is refused naming the terms, a batch answers
    its other sets and gives those NaN (no verdict: 'failed')."""
    from gyro.equilibrium import equilibria, operators

    qe, ok = equilibria(model, P)
    undefined = np.zeros(len(P), bool)
    if ok.any():
        k = np.flatnonzero(ok)
        M, D, K = operators(model, P[k], qe[k])
        finite = np.all(np.isfinite(M), axis=(1, 2)) & np.all(np.isfinite(D), axis=(1, 2)) & np.all(
            np.isfinite(K), axis=(1, 2))
        undefined[k[~finite]] = True
    if not undefined.any():
        return steady_roots(model, get(method).solve(model, P, tol))
    if undefined.all() and len(P) == 1:
        terms = "; ".join(f"{t}, its argument there {a}" for t, a in
                          ((d["term"], d["argument_at_reference"]) for d in model.meta["nondifferentiable"]))
        raise OperatorUndefined(f"no linear operator at this set: a non-smooth term of the model sits on its kink "
                                f"at the reference, where it has no derivative (of {terms}); the nonlinear "
                                "equations hold there (gyro simulate)")
    good = np.flatnonzero(~undefined)
    n = len(model.meta["reduced"])
    shape = (len(P), n)
    freq, growth, err = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    eq = np.full((len(P), len(model.meta["equilibrium_coordinates"])), np.nan)
    if good.size:
        sub = steady_roots(model, get(method).solve(model, P[good], tol))
        freq[good], growth[good], err[good] = sub.frequencies, sub.growth, sub.error_estimate
        if sub.equilibrium is not None:
            eq[good] = sub.equilibrium
        return Spectrum(method, freq, growth, err, eq, growth_known=sub.growth_known)
    return Spectrum(method, freq, growth, err, eq)


def steady_roots(model: Model, spec: Spectrum) -> Spectrum:
    """Mark the zero roots that steadily turning coordinates own (Spectrum.steady). Such a
    coordinate is absent from L and the forces (the derivation proves it), so K e_c = 0 and
    lambda = 0 is a root of each, exactly: per set, the len(steady) roots of smallest
    |lambda|, each of which must be zero within its own error (lambda = 0, or an estimate of
    1/2 or more). Any other zero root stays a neutral mode."""
    s = len(model.meta.get("steady", {}))
    if not s or len(spec) == 0:
        return spec
    from dataclasses import replace

    lam = np.abs(spec.growth + 1j * spec.frequencies)
    zero = (lam == 0) | ~(spec.error_estimate < 0.5)
    mark = np.zeros(lam.shape, bool)
    rows = np.arange(len(lam))
    order = np.argsort(np.where(np.isfinite(lam), lam, np.inf), axis=1)[:, :s]
    for j in range(s):
        mark[rows, order[:, j]] = zero[rows, order[:, j]]
    return replace(spec, steady=mark)


def with_modes(model: Model, params, spec: Spectrum) -> Spectrum:
    """The spectrum with its mode shapes: for each root lambda = growth + i omega, the right
    eigenvector of J(lambda) about the set's equilibrium (gyro.qep.eigenvectors), over the
    reduced coordinates in their own units."""
    from dataclasses import replace

    from gyro import qep
    from gyro.equilibrium import equilibria, operators

    P = as_batch(model, params)
    qe = spec.equilibrium if spec.equilibrium is not None else equilibria(model, P)[0]
    M, D, K = operators(model, P, qe)
    return replace(spec, modes=qep.eigenvectors(M, D, K, spec.growth + 1j * spec.frequencies))


def require_finite(model: Model, spec, where: str = "these parameters") -> None:
    """One line (a numerical failure, FloatingPointError), no table, where set 0 of `spec`
    has no finite spectrum, saying why: no equilibrium found (a model such as
    gimbal_precession, whose gyroscope precesses instead of resting), or a root without a
    finite value."""
    if np.all(np.isfinite(spec.frequencies[0])) and np.all(np.isfinite(spec.growth[0])):
        return
    if spec.equilibrium is not None and not np.all(np.isfinite(spec.equilibrium[0])):
        raise FloatingPointError(f"{model.name}: no equilibrium found at {where}, so no natural frequencies "
                                 "about one")
    raise FloatingPointError(f"a frequency is not finite at {where}")


def natural_frequencies(model: Model, values: dict, method: str = "default") -> ModalResult:
    """The natural frequencies of the exact operator about the exact equilibrium, for one
    parameter set, by a method of the ladder (the default one unless told)."""
    spec = spectrum(model, model.vector(values), method)
    if not np.all(np.isfinite(spec.frequencies)):
        raise EquilibriumError(f"{model.name}: no finite spectrum at this set (method {method!r})")
    eq = spec.equilibrium[0] if spec.equilibrium is not None else equilibrium(model, model.vector(values))
    return ModalResult(
        model=model.name, params=values,
        equilibrium=dict(zip(model.meta["equilibrium_coordinates"], map(float, eq))),
        frequencies=[float(f) for f in spec.frequencies[0]],
        eigenvalues_re=[float(r) for r in spec.growth[0]],
        error_estimate=[float(e) for e in spec.error_estimate[0]])
