"""Sufficient stability conditions against the spectrum, for any model that declares them
(Model.conditions, derive/outputs/conditions.py): `gyro stability` and `gyro map`.

For a batch of parameter sets: the equilibrium (gyro.equilibrium), the margins of every
declared set with their rounding bounds (the emitted `conditions` and `conditions_rounding`,
the latter times the unit roundoff), and the spectrum of the linearisation: the eigenvalues
of the companion matrix of the emitted operator M, D, K at the equilibrium
(gyro.qep.companion_matrix), each with its error radius (gyro.qep.eigen_radii). The verdicts
are read through gyro.results.verdict:

- a declared set is a sufficient condition: it holds where every margin exceeds its bound,
  fails where some margin lies below minus its bound, and is undecided otherwise
  (verdict.condition); the condition of the model holds where some applicable set holds;
- the spectrum's verdict (verdict.spectrum): conservative (a Hamiltonian spectrum) where M,
  K are symmetric and D skew to rounding, else every disk must lie in Re z < 0; a coordinate
  the stiffness and damping leave free (a zero row and column of K and D, or of K on a
  conservative operator) has an exact double zero root, set aside (marginal), unless the
  coordinate turns steadily (a `steady` coordinate: its own zero roots say nothing) or a
  margin is zero merely within rounding; a defective root (kappa = inf: a Jordan block) is
  a boundary, rounding's choice;
- the set's verdict: the condition decided and holding is `stable` whatever the spectrum
  (a Lyapunov function keeps the roots on the axis); otherwise the spectrum's, except that
  a condition undecided (a margin within its bound of zero) where the spectrum is not
  certainly unstable (nor marginal) is a `boundary`, with the margin named.

What only one system has is reached through its model's declaration `system` (metadata: a
dotted module name, imported here by name): each of these hooks is optional, and without
it the generic behaviour above holds.

- OPTIONS: the command-line options the system takes beyond the generic ones ("orbit");
- condition_parameters(model, sets, options, need_equilibrium) -> the values of a set;
- condition_equilibrium(model, P) -> (qe, ok): a closed-form equilibrium;
- conditions_in_force(model, P, margins, bounds, options) -> which margins make up the
  condition at each set: [(rows, margins, bounds, labels)], alternatives, each sufficient;
- condition_conservative(model, M, D, K), condition_free(model, M, D, K): per set, whether
  the spectrum is Hamiltonian and how many coordinates are free;
- condition_report(model, values, a, options) -> what `gyro stability` shows: a dict with
  `equilibrium`, `lines`, `extra` (keys of its JSON), `shown` (labels), `condition`;
- condition_options(model, values, options) -> the options of one set's analysis;
- condition_name(model, options): the condition's name in a map;
- condition_axes(model): map axes beside the parameters; condition_check_axes(model, names,
  options); condition_point(model, base, axes, options, sets) -> the values at one grid
  point, checked; condition_moved(model, names, options, sets) -> the declared parameters a
  map moves.
"""
from __future__ import annotations

import numpy as np

from gyro import qep
from gyro.equilibrium import equilibria, operators
from gyro.errors import ParameterError, grid_axis
from gyro.kernels import function
from gyro.models import Model
from gyro.qep import companion_matrix
from gyro.results import verdict

U = qep.UNIT_ROUNDOFF
BOUNDARY, MARGINAL = -1, -2  # a map's values besides 2 (the condition holds), 1 (spectrally stable), 0
NEEDS = ("conditions: `Model(conditions={NAME: Conditions([(LABEL, MARGIN), ...], DOC)})`, "
         "sufficient conditions as margins in the parameters, each > 0 where it holds (docs/models.md)")


# ------------------------------------------------------------------ the declaration


def declared(model: Model) -> list[dict]:
    """The declared sets ({name, labels, doc}, in order); a model without any is refused in one
    line."""
    sets = model.meta.get("conditions") or []
    if not sets or "conditions" not in model.meta["functions"]:
        raise ParameterError(f"{model.name} declares no conditions (Model.conditions: named sets of "
                             "sufficient conditions, margins > 0 where each holds; docs/models.md)")
    return sets


def require(model: Model) -> None:
    """What both commands need, or one line: declared conditions, and an operator about an
    equilibrium (not about a stationary motion of momenta given as inputs)."""
    declared(model)
    if model.meta.get("momenta"):
        raise ParameterError(f"{model.name}: its operator depends on the momenta {', '.join(model.meta['momenta'])} "
                             "of a stationary motion; the conditions are read about an equilibrium")


def finite_margins(model: Model, a: dict, where=lambda k: "") -> None:
    """Every margin and bound finite where there is an equilibrium (a parameter at zero in
    a margin's denominator gives none): otherwise one line naming the margin, never a
    verdict read from NaN."""
    bad = a["ok"][:, None] & ~(np.isfinite(a["margins"]) & np.isfinite(a["bounds"]))
    if bad.any():
        k, j = np.argwhere(bad)[0]
        raise ParameterError(f"the margin {labels(model)[j]} of {model.name} is not finite at these parameters "
                             f"(a parameter at zero in its denominator?){where(k)}")


def labels(model: Model) -> list[str]:
    return [label for s in declared(model) for label in s["labels"]]


def system(model: Model):
    """The model's own runtime module (metadata `system`), or None."""
    from gyro.catalog import declared_module

    name = model.meta.get("system")
    if not name:
        return None
    return declared_module(name, f"{model.name}: its declared system", model)


def _hook(model: Model, name: str, default=None):
    return getattr(system(model), name, default)


def check_options(model: Model, options: dict) -> None:
    """Every option set (true) must be one the model's system takes: one line otherwise."""
    takes = _hook(model, "OPTIONS", ())
    for key, value in options.items():
        if value and key not in takes:
            raise ParameterError(f"--{key}: {model.name} has no {key} option (its system declares none)")


def margins(model: Model, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(margins, bounds), each (sets, margins in the declared order): the margins of every
    declared set and their rounding bounds (u times the emitted scale)."""
    n = P.shape[0]
    with np.errstate(all="ignore"):
        m = np.asarray(function(model, "conditions")(P)[0]).reshape(n, -1)
        b = U * np.asarray(function(model, "conditions_rounding")(P)[0]).reshape(n, -1)
    return m, b


def every_set(model: Model, P, marg, bnd, options) -> list:
    """The generic alternatives: every declared set at every parameter set."""
    out, start = [], 0
    rows = np.ones(P.shape[0], bool)
    for s in declared(model):
        k = len(s["labels"])
        out.append((rows, marg[:, start:start + k], bnd[:, start:start + k], tuple(s["labels"])))
        start += k
    return out


# ------------------------------------------------------------------ the analysis


def conservative(M, D, K) -> np.ndarray:
    """Per set: M, K symmetric and D skew to rounding (the ladder's test)."""
    from gyro.methods.polyroots import conservative as test

    return test(M, D, K)


def free_coordinates(model: Model, M, D, K) -> tuple[np.ndarray, np.ndarray]:
    """Per set: how many coordinates the operator leaves free (an exactly zero row and column
    of K, and of D unless the operator is conservative: q = e_c and q = t e_c both solve it,
    an exact double zero root), and how many of those turn steadily (declared `steady`)."""
    zk = np.all(K == 0, axis=2) & np.all(K == 0, axis=1)
    zd = np.all(D == 0, axis=2) & np.all(D == 0, axis=1)
    cons = conservative(M, D, K)
    free = zk & (zd | cons[:, None])
    reduced = model.meta["reduced"]
    steady = np.array([c in model.meta.get("steady", {}) for c in reduced], bool)
    if len(steady) != free.shape[1]:  # an operator over other coordinates (multipliers): none steady
        steady = np.zeros(free.shape[1], bool)
    return np.sum(free, axis=1), np.sum(free & steady[None, :], axis=1)


def analyse(model: Model, P: np.ndarray, options: dict | None = None) -> dict:
    """Batch P (sets, parameters): the equilibrium `qe` (`ok` where there is one), the
    margins and their `bounds`, `sufficient` (the condition decided and holding),
    `condition_decided`, `why` (the undecided margin), the eigenvalues (sets, 2n) and their
    `radius`, `spectrum_verdict`, `verdict` (the set's), `boundary`, `spectrally_stable`,
    `growth` (the largest real part) and M, D, K."""
    options = dict(options or {})
    P = np.atleast_2d(np.asarray(P, float))
    n = P.shape[0]
    with np.errstate(all="ignore"):
        found = _hook(model, "condition_equilibrium")
        qe, ok = found(model, P) if found else equilibria(model, P)
        ok = np.asarray(ok, bool) & np.all(np.isfinite(qe), axis=1)
        marg, bnd = margins(model, P)
        M, D, K = operators(model, P, qe)
        Mc = np.where(ok[:, None, None] & np.all(np.isfinite(M), axis=(1, 2))[:, None, None], M, np.eye(M.shape[-1]))
        A = companion_matrix(Mc, D, K)
        ok &= np.all(np.isfinite(A), axis=(1, 2))
        m2 = A.shape[-1]
        eig = np.full((n, m2), np.nan + 0j)
        radius = np.full((n, m2), np.inf)
        if ok.any():
            eig[ok], radius[ok] = qep.eigen_radii(A[ok], Mc[ok])
    alternatives = _hook(model, "conditions_in_force", every_set)(model, P, marg, bnd, options)
    held, decided_all = np.zeros(n, bool), np.ones(n, bool)
    applies, rounded = np.zeros(n, bool), np.zeros(n, bool)
    why = np.full(n, None, dtype=object)
    for rows, mg, bd, names in alternatives:
        rows = np.asarray(rows, bool)
        if not rows.any():
            continue
        h, d, w = verdict.condition(mg[rows], bd[rows], names)
        held[rows] |= h
        decided_all[rows] &= d
        applies[rows] = True
        idx = np.flatnonzero(rows)
        take = (w != None) & (why[idx] == None)  # noqa: E711 (elementwise on object arrays)
        why[idx[take]] = w[take]
        # a margin near zero whose terms do not all vanish: its zero is rounding's
        rounded[rows] |= np.any((np.abs(mg[rows]) <= bd[rows]) & (bd[rows] > 0), axis=1)
    decided = held | (decided_all | ~applies)
    sufficient = held & ok
    cons_hook = _hook(model, "condition_conservative")
    cons = np.asarray(cons_hook(model, Mc, D, K) if cons_hook else conservative(Mc, D, K), bool) & ok | ~ok
    free_hook = _hook(model, "condition_free")
    if free_hook:
        free, steady = free_hook(model, M, D, K), np.zeros(n, int)
    else:
        free, steady = free_coordinates(model, Mc, D, K)
    # a free coordinate is exact only where no margin is zero merely within rounding
    free = np.where(rounded, 0, free)
    steady = np.where(rounded, 0, steady)
    spec = verdict.make(np.full(n, "failed", dtype=object))
    for group in (cons, ~cons):
        if group.any():
            v = verdict.spectrum(eig[group], radius[group], conservative=bool(cons[group][0]), exact_zero=free[group])
            spec.label[group], spec.reason[group] = v.label, v.reason
    # the zero roots of steadily turning coordinates alone: no neutral direction of the motion
    own = (spec.label == "marginal") & (free > 0) & (free == steady)
    spec.label[own], spec.reason[own] = "stable", None
    # an infinite radius of a finite eigenvalue is a computed Jordan block (the eigenvectors
    # exactly parallel: kappa = inf): rounding decides, a boundary, never 'unknown' (which
    # the maps have no class for)
    jordan = ok & (spec.label == "unknown")
    spec.label[jordan] = "boundary"
    spec.reason[jordan] = "a defective root (exactly parallel eigenvectors: a Jordan block): rounding decides"
    growth = np.max(eig.real, axis=1)
    stable = ok & ((spec.label == "stable") | sufficient)  # a Lyapunov function puts the spectrum on the axis
    # the verdict of the set: the condition decided and holding is stable whatever the
    # spectrum; otherwise the spectrum's, unless the condition is undecided and the
    # spectrum not certainly unstable (then whether it holds, or the set is only spectrally
    # stable, is rounding's choice: a boundary); an exact zero root (marginal) explains an
    # undecided margin: it stays marginal
    label, reason = spec.label.copy(), spec.reason.copy()
    label[sufficient] = "stable"
    reason[sufficient] = None
    undecided = ok & ~decided & (spec.label != "unstable") & (spec.label != "marginal")
    label[undecided], reason[undecided] = "boundary", why[undecided]
    label[~ok], reason[~ok] = "failed", "no equilibrium, or an operator that is not finite"
    return {"qe": qe, "ok": ok, "margins": marg, "bounds": bnd, "sufficient": sufficient,
            "condition_decided": decided, "why": why, "eigenvalues": eig, "radius": radius,
            "spectrum_verdict": spec, "verdict": verdict.make(label, reason), "boundary": label == "boundary",
            "spectrally_stable": stable, "growth": growth, "M": M, "D": D, "K": K}


# ------------------------------------------------------------------ one set: `gyro stability`


def parameters(model: Model, sets: dict, options: dict | None = None, need_equilibrium: bool = True) -> dict:
    """The values of a set from NAME=VALUE pairs (the system's own rules where it has them),
    checked; ParameterError naming the parameter."""
    options = dict(options or {})
    check_options(model, options)
    own = _hook(model, "condition_parameters")
    if own:
        return own(model, sets, options, need_equilibrium)
    return model.parameters(sets)


def no_equilibrium(model: Model, P: np.ndarray) -> str:
    from gyro.equilibrium import unbalanced

    return unbalanced(model, P) or "no equilibrium found at these parameters (Newton's method did not converge)"


def _name(model: Model, options: dict) -> str:
    own = _hook(model, "condition_name")
    return own(model, options) if own else " or ".join(s["name"] for s in declared(model))


def _report(model: Model, values: dict, a: dict, options: dict) -> dict:
    own = _hook(model, "condition_report")
    if own:
        return own(model, values, a, options)
    units = model.meta.get("coordinate_units", {})
    qe = {c: float(v) for c, v in zip(model.meta["equilibrium_coordinates"], a["qe"][0])}
    qe.update({c: 0.0 for c in model.meta.get("symmetric_zero", []) if c not in qe})
    parts = [f"{c} = {v:.9g} {units.get(c, '')}".rstrip() for c, v in qe.items()]
    parts += [f"{c}' = {rate} (steady)" for c, rate in model.meta.get("steady", {}).items()]
    return {"equilibrium": qe, "lines": ["equilibrium: " + (", ".join(parts) or "the model's reference state")],
            "extra": {}, "shown": labels(model), "condition": _name(model, options)}


def stability(model: Model, values: dict, options: dict | None = None):
    """One set: its equilibrium, the margins, the spectrum and the verdict, as a
    gyro.results.EquilibriumStability (the `gyro stability --json` document). A set without
    an equilibrium is refused in one line."""
    from gyro.results import EquilibriumStability

    options = dict(options or {})
    declared(model)
    own = _hook(model, "condition_options")
    if own:
        options = own(model, values, options)
    P = model.vector(values)[None]
    a = analyse(model, P, options)
    if not a["ok"][0]:
        raise ParameterError(no_equilibrium(model, P[0]))
    finite_margins(model, a)
    r = _report(model, values, a, options)
    every = labels(model)
    shown = [every.index(k) for k in r["shown"]]
    eig, radii = a["eigenvalues"][0], a["radius"][0]
    order = np.lexsort((eig.real, eig.imag))
    eig, radii = eig[order], radii[order]
    v = a["verdict"]
    return EquilibriumStability(
        verdict=str(v.label[0]), boundary_reason=v.reason[0] if v.label[0] in ("boundary", "marginal") else None,
        margin_bounds={every[j]: float(a["bounds"][0, j]) for j in shown}, radii=radii,
        model=model.name, title=model.meta["title"], params={k: float(x) for k, x in values.items()},
        aliases=model.aliases, equilibrium=r["equilibrium"], extra=r["extra"], lines=list(r["lines"]),
        condition=r["condition"], conditions={every[j]: float(a["margins"][0, j]) for j in shown},
        sufficient=bool(a["sufficient"][0]), orbit=bool(options.get("orbit", False)),
        eigenvalues=np.stack([eig.real, eig.imag], axis=1), spectrally_stable=bool(a["spectrally_stable"][0]))


# ------------------------------------------------------------------ a grid: `gyro map`


def axis_names(model: Model) -> tuple:
    own = _hook(model, "condition_axes")
    return tuple(model.param_names) + tuple(own(model) if own else ()) + tuple(model.aliases)


def parse_axis(model: Model, flag: str, text: str) -> tuple[str, float, float, int]:
    """NAME=LO:HI:N over a parameter (its declared name or another taken for it) or an axis
    the system adds -> (name as typed, lo, hi, n)."""
    return grid_axis(flag, text, axis_names(model), 1000)


def _point(model: Model, base: dict, axes: dict, options: dict, sets: dict) -> dict:
    own = _hook(model, "condition_point")
    if own:
        return own(model, base, axes, options, sets)
    v = dict(base)
    for name, value in axes.items():
        v[model.canonical(name)] = value
    where = "at " + ", ".join(f"{k} = {x:.6g}" for k, x in axes.items())
    try:
        return model.parameters(v)
    except ParameterError as exc:
        raise ParameterError(f"{exc} ({where})") from None


def condition_map(model: Model, sets: dict, xaxis, yaxis, options: dict | None = None):
    """The condition's region, the spectrally stable one and the unstable one over a grid of
    two axes ((name, lo, hi, n) each), a condition Map, the other parameters from `sets` (NAME=VALUE, over
    the defaults). Values: 2 where the sufficient condition holds, 1 spectrally stable
    outside it, 0 unstable, -1 (BOUNDARY) where rounding could change the verdict, -2
    (MARGINAL) an exact zero root. Every grid point is checked first (ParameterError naming
    the point where a parameter is out of range or there is no equilibrium)."""
    from gyro.results import Map

    options = dict(options or {})
    declared(model)
    (xn, xlo, xhi, nx), (yn, ylo, yhi, ny) = xaxis, yaxis
    base = parameters(model, sets, options, need_equilibrium=False)  # each point is checked
    x, y = np.linspace(xlo, xhi, nx), np.linspace(ylo, yhi, ny)
    points = [_point(model, base, {xn: xv, yn: yv}, options, sets) for yv in y for xv in x]
    P = model.vectors(points)
    a = analyse(model, P, options)
    if not a["ok"].all():
        k = int(np.argmin(a["ok"]))
        xv, yv = x[k % nx], y[k // nx]
        raise ParameterError(f"{no_equilibrium(model, P[k])} (at {xn} = {xv:.6g}, {yn} = {yv:.6g})")
    finite_margins(model, a, lambda k: f" (at {xn} = {x[k % nx]:.6g}, {yn} = {y[k // nx]:.6g})")
    label = a["verdict"].label
    values = np.select([label == "boundary", label == "marginal", a["sufficient"], label == "stable"],
                       [BOUNDARY, MARGINAL, 2, 1], 0).reshape(ny, nx)
    # the growth of a certainly unstable set; 0 elsewhere (a boundary's growth is rounding's)
    growth = np.where(label == "unstable", np.maximum(a["growth"], 0.0), 0.0).reshape(ny, nx)
    own = _hook(model, "condition_moved")
    moved = own(model, (xn, yn), options, sets) if own else {model.canonical(xn), model.canonical(yn)}
    shape = (ny, nx)
    layers = {"growth": growth, "boundary": (label == "boundary").reshape(shape),
              "reasons": a["verdict"].reason.reshape(shape)}
    info = {"condition": _name(model, options), "orbit": bool(options.get("orbit", False)),
            "base": {k: float(v) for k, v in base.items() if k not in moved}}
    return Map("condition", model.name, model.meta["title"], model.canonical(xn), model.canonical(yn), x, y,
               values.astype(int), layers, info=info)


def check_axes(model: Model, xaxis, yaxis, options: dict, sets: dict) -> None:
    """The axes are two different names, neither --set nor fixed by an option."""
    if model.canonical(xaxis[0]) == model.canonical(yaxis[0]):
        raise ParameterError(f"--x and --y are both {xaxis[0]!r}")
    own = _hook(model, "condition_check_axes")
    if own:
        own(model, (xaxis[0], yaxis[0]), options)
    given = {model.canonical(k) for k in sets}
    for axis in (xaxis, yaxis):
        if model.canonical(axis[0]) in given:
            raise ParameterError(f"parameter {axis[0]}: is an axis; do not --set it")
