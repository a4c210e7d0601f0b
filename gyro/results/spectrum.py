"""Spectra: a frequency method over a batch, the stability verdict read from it, one set's
modal result, and the distance of approximate frequencies to exact ones."""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field

import numpy as np

from gyro.results import verdict
from gyro.results._io import Result, _axes, _finite_or_none, _pyplot, _write_text, cell


@dataclass
class Spectrum(Result):
    """The result of one frequency method over a batch: arrays of shape (sets, modes)."""

    method: str
    frequencies: np.ndarray  # rad/s, ascending per set
    growth: np.ndarray  # real parts of the eigenvalues (> 0: growing), same order
    error_estimate: np.ndarray  # relative error bound per frequency
    equilibrium: np.ndarray | None = None  # (sets, equilibrium coordinates)
    route: np.ndarray = field(default=None)  # per set: which rung answered (default only)
    growth_known: bool = True  # False for a method that computes no growth rates (formulas)
    modes: np.ndarray | None = None  # (sets, modes, coordinates) complex right eigenvectors, on request
    # (sets, modes) bool: the zero root of a steadily turning coordinate (its phase is free by
    # construction: no force depends on it), which says nothing of the motion's stability
    steady: np.ndarray | None = None

    def damping_ratio(self) -> np.ndarray:
        """zeta = -Re(lambda)/|lambda| per root (0 for an undamped one, NaN at lambda = 0)."""
        with np.errstate(all="ignore"):
            return -self.growth / np.abs(self.growth + 1j * self.frequencies)

    def log_dec(self) -> np.ndarray:
        """Logarithmic decrement delta = -2 pi Re(lambda)/Im(lambda) per root (the decay of
        the amplitude over one damped period); NaN for a root that does not oscillate."""
        with np.errstate(all="ignore"):
            return np.where(self.frequencies > 0, -2 * np.pi * self.growth / self.frequencies, np.nan)

    @property
    def damped(self) -> bool:
        """Any root that decays, resolved from zero (beyond its error bound times |lambda|, and
        1e-9 |lambda|), other than the mirror of a growing one: the text table then shows the
        damping."""
        if not self.growth_known:
            return False
        f, g = self.frequencies, self.growth
        lam = np.abs(g + 1j * f)
        est = np.where(np.isfinite(self.error_estimate), self.error_estimate, np.inf)
        with np.errstate(all="ignore"):
            allow = np.maximum(est, 1e-9) * lam
            decays, grows = g < -allow, g > allow
            # a decaying root mirroring a growing one (sigma -> -sigma at the same frequency: a
            # conservative flutter quadruple) is no damping
            mirror = np.any(grows[:, None, :] & (np.abs(f[:, :, None] - f[:, None, :]) <= 1e-6 * lam[:, :, None])
                            & (np.abs(g[:, :, None] + g[:, None, :]) <= 1e-6 * lam[:, :, None]), axis=2)
            return bool(np.any(decays & ~mirror))

    def __len__(self) -> int:
        return self.frequencies.shape[0]

    @classmethod
    def concat(cls, parts: list["Spectrum"]) -> "Spectrum":
        """One spectrum of the sets of several, in order."""
        cat = {f: (None if getattr(parts[0], f) is None else np.concatenate([getattr(x, f) for x in parts]))
               for f in ("frequencies", "growth", "error_estimate", "equilibrium", "route", "modes", "steady")}
        return cls(parts[0].method, **cat, growth_known=all(p.growth_known for p in parts))

    def to_dict(self, k: int | None = None, model=None, params: dict | None = None) -> dict:
        """The `gyro frequencies --json` document of set k (default 0; its keys are the
        contract) where the model is given; without it, the whole batch: method, and per set
        frequencies, eigenvalues_re, error_estimate, equilibrium, route, stability (the
        verdict's label), null where a value is not finite."""
        if model is None:
            return self._batch_dict() if k is None else {key: v[k] if isinstance(v, list) else v
                                                         for key, v in self._batch_dict().items()}
        k = 0 if k is None else k
        stab = classify(self)
        eq = (None if self.equilibrium is None else
              dict(zip(model.meta["equilibrium_coordinates"], map(float, self.equilibrium[k]))))
        return {
            "model": model.name,
            "params": params,
            "frequencies": [float(w) for w in self.frequencies[k]],
            "equilibrium": eq,
            "eigenvalues_re": [float(g) for g in self.growth[k]],
            "method": self.method,
            "error_estimate": [float(e) if np.isfinite(e) else None for e in self.error_estimate[k]],
            **({"steady_roots": [int(j) for j in np.flatnonzero(self.steady[k])]} if self.steady is not None else {}),
            "stability": {"class": str(stab.label[k]), "growth_rate": float(stab.growth_rate[k]),
                          "unstable_roots": int(stab.unstable_roots[k]),
                          "reason": None if stab.reason is None else stab.reason[k]},
        } | (self.modes_dict(k, model) if self.modes is not None else {})

    def _batch_dict(self) -> dict:
        return {"method": self.method, "frequencies": _finite_or_none(self.frequencies),
                "eigenvalues_re": _finite_or_none(self.growth), "error_estimate": _finite_or_none(self.error_estimate),
                "equilibrium": None if self.equilibrium is None else _finite_or_none(self.equilibrium),
                "route": None if self.route is None else [str(r) for r in self.route],
                "stability": [str(c) for c in classify(self).label]}

    def modes_dict(self, k: int, model) -> dict:
        """`gyro frequencies --modes`: damping ratio, logarithmic decrement and one right
        eigenvector per frequency (coordinates in the `reduced` order, {re, im} lists)."""
        num = lambda a: [float(x) if np.isfinite(x) else None for x in a]  # noqa: E731
        return {"damping_ratio": num(self.damping_ratio()[k]), "log_dec": num(self.log_dec()[k]),
                "coordinates": list(model.meta["reduced"]),
                "modes": [{"re": num(v.real), "im": num(v.imag)} for v in self.modes[k]]}

    def table(self, k: int = 0, model=None) -> str:
        """The `gyro frequencies` text of set k (the model's title and name first where it
        is given)."""
        freqs, est = self.frequencies[k], self.error_estimate[k]
        stab = classify(self)
        damped = self.damped  # a decaying root: the damping ratio and log. decrement shown
        lines = [f"{model.meta['title']} ({model.name})"] if model is not None else []
        lines += [f"natural frequencies by the method '{self.method}'"
                 + (f" (answered by its {self.route[k]} rung)" if self.route is not None else "") + ":",
                 f"{'':>4} {'omega [rad/s]':>16} {'f [Hz]':>14} {'period [s]':>14} {'rel. error <=':>14}"
                 + (f" {'damping ratio':>14} {'log. decr.':>11}" if damped else "")]
        zeta, delta = self.damping_ratio()[k], self.log_dec()[k]
        lam = np.abs(self.growth[k] + 1j * freqs)
        grows = (self.growth[k] > np.maximum(np.where(np.isfinite(est), est, np.inf), 1e-9) * lam) & np.isfinite(est)
        words = set()  # what a word in a number's place means, said below the table
        for i, (w, e) in enumerate(zip(freqs, est), 1):
            with np.errstate(divide="ignore", over="ignore"):
                period = 2 * np.pi / w if w > 0 else np.nan
            if not np.isfinite(w):
                words.add("none")
            elif not np.isfinite(period):
                words.add("-" if w == 0 else "-slow")
            if not np.isfinite(e):
                words.add("unbounded")
            row = (f"{i:>4} {cell(w, '>16.9g')} {cell(w / (2 * np.pi), '>14.6g')} {cell(period, '>14.6g', '-')} "
                   f"{cell(e, '>14.2g', 'unbounded')}")
            if damped:
                row += f" {cell(zeta[i - 1], '>14.6g')} {cell(delta[i - 1], '>11.5g')}"
                words |= {"none"} if not (np.isfinite(zeta[i - 1]) and np.isfinite(delta[i - 1])) else set()
            if grows[i - 1]:
                row += f"   grows at {self.growth[k][i - 1]:.6g} 1/s"
            if self.steady is not None and self.steady[k, i - 1]:
                steady = ", ".join(model.meta.get("steady", {})) if model is not None else "coordinate"
                row += f"   the steady {steady}: its own zero root (a free phase)"
            lines.append(row)
        label = stab.label[k]
        note = {"unstable": f", {stab.unstable_roots[k]} growing root(s), the fastest at {stab.growth_rate[k]:.6g} 1/s",
                "unknown": (f" (the method '{self.method}' computes no growth rates: no verdict; try --method "
                            "default)" if not self.growth_known else
                            " (a root's error is unbounded: this method cannot tell; try --method default)"
                            if self.method != "default" else
                            " (a root's error is unbounded at these parameters: no rung of the default method, "
                            "up to 40 digits, bounds it; no verdict)"),
                "failed": " (these parameters could not be computed)",
                "boundary": f" (rounding could change the verdict: {stab.reason[k]})"}.get(label, "")
        lines += [text for word, text in (
            ("-", "period -: a zero root (omega = 0) has no period"),
            ("-slow", "period -: omega so small that its period 2 pi/omega exceeds a double"),
            ("unbounded", "unbounded: no bound on that root's relative error at these parameters"),
            ("none", "none: no finite value at these parameters")) if word in words]
        lines.append(f"equilibrium: {label}{note}")
        return "\n".join(lines)


    @classmethod
    def _loaded(cls, s) -> "Spectrum":
        if isinstance(s.route, list):
            s.route = np.array(s.route, dtype=object)
        return s

    def plot(self, out=None, x=None, label=None, ax=None):
        """Frequencies of every set against x (the set index by default), one curve a mode,
        into `out` (a file, written whole or not at all, or matplotlib axes; `ax` the same);
        with neither, into a new figure's axes, returned."""
        if out is None and ax is None:
            _, ax = _pyplot().subplots(layout="constrained")
        with _axes(ax if ax is not None else out) as ax:
            x = np.arange(len(self)) if x is None else x
            for j in range(self.frequencies.shape[1]):
                ax.plot(x, self.frequencies[:, j], lw=1, color="k", label=(label or self.method) if j == 0 else None)
            ax.set_yscale("log")
            ax.set_ylabel("natural frequency omega [rad/s]")
        return ax


@dataclass
class Stability(Result):
    """Per set: 'stable', 'unstable' (with its growth rate, 1/s), 'marginal' (an exact zero
    root: a neutral direction), 'boundary' (rounding could change the verdict: two roots
    merged within their error bounds, or a root not resolved from zero), 'unknown' (a
    root's error is unbounded) or 'failed' (the set could not be computed): the labels of
    gyro.results.verdict."""

    label: np.ndarray  # (sets,) str
    growth_rate: np.ndarray  # (sets,) largest real part, 1/s (0 when stable)
    unstable_roots: np.ndarray  # (sets,) int: growing modes (eigenvalue pairs, or quadruples, with a growing member)
    slowest_growth: np.ndarray  # (sets,) smallest growing real part, 1/s (0 when stable)
    reason: np.ndarray | None = None  # (sets,) why a set is 'boundary' (gyro.results.verdict); None elsewhere

    NO_PLOT = "a label per set: the figure of what holds it draws it (a map, a Campbell diagram, a sweep)"

    def __len__(self) -> int:
        return len(self.label)

    def to_dict(self) -> dict:
        """Per set: `stability` (the label), `growth_rate` and `slowest_growth` (1/s),
        `unstable_roots`, `reason` (null, or why there is no plain verdict)."""
        reason = self.reason if self.reason is not None else [None] * len(self)
        num = lambda a: [float(g) if np.isfinite(g) else None for g in a]  # noqa: E731
        return {"stability": [str(c) for c in self.label], "growth_rate": num(self.growth_rate),
                "slowest_growth": num(self.slowest_growth),
                "unstable_roots": [int(n) for n in self.unstable_roots], "reason": [r for r in reason]}

    def table(self) -> str:
        """A line per set: its label, the growing modes and the fastest rate, or the reason."""
        d = self.to_dict()
        lines = []
        for k, label in enumerate(d["stability"]):
            if label == "unstable":
                n = d["unstable_roots"][k]
                label += f" ({n} growing mode{'s' if n != 1 else ''}, the fastest at {self.growth_rate[k]:.4g} 1/s)"
            elif d["reason"][k]:
                label += f" ({d['reason'][k]})"
            lines.append(f"{k + 1:>4}  {label}")
        return "\n".join(lines)

    @classmethod
    def _loaded(cls, s) -> "Stability":
        s.label = np.array(s.label, dtype=object)
        s.reason = None if s.reason is None else np.array(s.reason, dtype=object)
        return s


def classify(spec: Spectrum, rel: float = 1e-9) -> Stability:
    """Stability of each set's equilibrium from its spectrum.

    A root grows when its real part exceeds what its error allows: max(estimate, rel)
    times |lambda| (the conservative gyroscopic spectrum lies on the imaginary axis, so a
    real part within rounding of it is noise). A root with |lambda| within its own error of
    zero (estimate >= 1: a neutral direction, omega1 at the pole or without Earth rate) is
    marginal, and so is an exact zero root. A method that computes no growth rates (the
    formulas: Spectrum.growth_known) gives no verdict ('unknown'). No verdict without a bound: a set with a frequency or growth rate that is not
    finite is 'failed' (it could not be computed), and one where a root's error is
    unbounded (infinite or NaN: a method that lost a root, as polyroots does) is 'unknown',
    unless a root with a bounded error grows, which makes it 'unstable' all the same."""
    lam = np.abs(spec.growth + 1j * spec.frequencies)
    est = np.asarray(spec.error_estimate, dtype=float)
    bounded = np.isfinite(est)
    allow = np.maximum(np.where(bounded, est, np.inf), rel) * lam
    # a root resolved from zero has a relative error below 1/2; one that is not (a rounded
    # split of a double zero root, 3e-20 with an error of 0.95) shows no growth, and it is
    # neutral, as is an exact zero root (lambda = 0: a free direction)
    resolved = bounded & (est < 0.5)
    growing = (spec.growth > allow) & resolved
    neutral = bounded & ~resolved | (lam == 0)
    if spec.steady is not None:  # a steady coordinate's own zero root is no neutral mode of the motion
        neutral &= ~spec.steady
    failed = ~np.all(np.isfinite(spec.frequencies) & np.isfinite(spec.growth), axis=1)
    # a steady coordinate's own zero root is zero by construction, whatever bound a rung gives it
    unknown = ~np.all(bounded | (spec.steady if spec.steady is not None else False), axis=1)
    if not spec.growth_known:  # the formulas assume a stable gyrocompass: no growth rates
        unknown = np.ones(len(lam), bool)
    # boundaries (gyro.results.verdict): rounding could change the verdict where two resolved
    # roots lie within their error bounds of each other (a possible Krein collision or
    # Jordan block), or where a root is not resolved from zero but is not an exact zero
    # (rounding decides whether it is a zero root, an oscillation or a growth: phi = 90 deg)
    radius = np.where(resolved & (lam > 0), np.where(resolved, est, 0.0) * lam, -np.inf)  # -inf: meets none
    merged = np.any(verdict.overlapping(spec.growth + 1j * spec.frequencies, radius), axis=2) & resolved
    merged &= verdict.cluster_meets_axis(spec.growth + 1j * spec.frequencies, radius, est)
    unresolved = bounded & ~resolved & (lam > 0)
    if spec.steady is not None:  # a steady coordinate's own zero root is zero by construction
        unresolved &= ~spec.steady
    boundary = (merged | unresolved).any(axis=1)
    label = np.where(failed, "failed", np.where(
        growing.any(axis=1), "unstable", np.where(
            unknown, "unknown", np.where(boundary, "boundary", np.where(neutral.any(axis=1), "marginal", "stable")))))
    reason = np.full(len(label), None, dtype=object)
    for k in np.flatnonzero(label == "boundary"):
        if unresolved[k].any():
            j = int(np.argmax(unresolved[k]))
            reason[k] = (f"root {j + 1} ({_root(spec, k, j, 3)}) is not resolved from zero (relative error "
                         f"{est[k, j]:.2g}): rounding decides whether it is a zero root")
        else:
            i, j = np.flatnonzero(merged[k])[:2]
            reason[k] = (f"roots {i + 1} and {j + 1} ({_root(spec, k, i, 9)}, {_root(spec, k, j, 9)}) merge within "
                         "their error bounds near the imaginary axis: a possible collision")
    rate = np.where(growing, spec.growth, 0.0).max(axis=1)
    slowest = np.where(growing, spec.growth, np.inf).min(axis=1)
    return Stability(label.astype(object), rate, growing.sum(axis=1), np.where(np.isfinite(slowest), slowest, 0.0),
                     reason)


def _root(spec: Spectrum, k: int, j: int, digits: int) -> str:
    """Root j of set k as the table shows it: omega in rad/s, and its real part (1/s) where
    that lies beyond the root's error bound from zero."""
    w, g, e = spec.frequencies[k, j], spec.growth[k, j], spec.error_estimate[k, j]
    return f"{w:.{digits}g} rad/s" + (f" with Re {g:.3g} 1/s" if abs(g) > e * abs(g + 1j * w) else "")


@dataclass
class ModalResult(Result):
    """Natural frequencies of a model at one parameter set, with the equilibrium used."""

    model: str
    params: dict
    equilibrium: dict
    frequencies: list  # rad/s, ascending
    eigenvalues_re: list = field(default_factory=list)  # real parts, same order (growth if > 0)
    error_estimate: list = field(default_factory=list)  # last Newton step, relative

    NO_PLOT = "one set's frequencies: a list (gyro frequencies prints them)"

    def to_dict(self) -> dict:
        return asdict(self)

    def table(self) -> str:
        lines = [f"{self.model}: natural frequencies at one set",
                 f"{'':>4} {'omega [rad/s]':>16} {'Re lambda [1/s]':>16} {'rel. error <=':>14}"]
        for i, w in enumerate(self.frequencies):
            g = self.eigenvalues_re[i] if i < len(self.eigenvalues_re) else float("nan")
            e = self.error_estimate[i] if i < len(self.error_estimate) else float("nan")
            lines.append(f"{i + 1:>4} {cell(w, '>16.9g')} {cell(g, '>16.6g')} {cell(e, '>14.2g', 'unbounded')}")
        return "\n".join(lines)

    def save(self, path) -> None:
        """Its JSON document (the one format it has had), written whole or not at all."""
        _write_text(path, json.dumps(self.to_dict(), indent=1))

    @classmethod
    def load(cls, path) -> "ModalResult":
        with open(path) as fh:
            return cls(**json.load(fh))


# --------------------------------------------------------------------------- sweeps


def nearest_error(approx: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """Relative distance of each approximate frequency to the nearest exact one."""
    with np.errstate(all="ignore"):
        return np.min(np.abs(approx[:, :, None] / exact[:, None, :] - 1), axis=2)

