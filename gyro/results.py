"""Result objects: what an analysis returns. Each turns into the command line's JSON (the
keys of the contract), saves and loads itself, concatenates over batches, pickles (plain
dataclasses of arrays) and plots itself. Results are leaves: they import no analysis.

- `Spectrum`: a frequency method over a batch (sets, modes), and `Stability` from it;
- `ModalResult`: one set's frequencies with its equilibrium (a JSON document);
- `CampbellDiagram`: frequencies against spin, formulas overlaid;
- `StabilityMap`: stability of the equilibrium over two parameters;
- `Trajectory`: a motion in time (the gimbal's closed form or an integrator).
"""
from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np

FORMULA_BAD = 0.01  # a formula errs by more than 1 %: shaded in the Campbell diagram


# --------------------------------------------------------------------------- saving


def _save_npz(obj, path) -> None:
    """Every field of a dataclass of arrays and scalars into one .npz (objects as JSON)."""
    data = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray) and v.dtype != object:
            data[f.name] = v
        else:
            data[f.name] = np.array(json.dumps(_jsonable(v)))
    path = Path(path)
    _clean_stale(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}{TMP_TAG}")
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _load_npz(cls, path):
    with np.load(path, allow_pickle=False) as z:
        kw = {}
        for f in fields(cls):
            if f.name not in z:
                continue
            v = z[f.name]
            kw[f.name] = json.loads(v.item()) if v.dtype.kind == "U" else v
    return cls(**kw)


def _jsonable(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, Spectrum):
        return {f.name: _jsonable(getattr(v, f.name)) for f in fields(v)}
    return v


TMP_TAG = ".gyro-tmp"  # temporaries beside an output: .<name>.<pid>.gyro-tmp<suffix>


def _clean_stale(out: Path) -> None:
    """Remove temporaries that a killed run left beside `out` (their process is gone)."""
    for tmp in out.parent.glob(f".{out.name}.*{TMP_TAG}*"):
        try:
            pid = int(tmp.name[len(out.name) + 2:].split(".", 1)[0])
            os.kill(pid, 0)  # alive: a concurrent run's, left alone
        except (ValueError, ProcessLookupError):
            tmp.unlink(missing_ok=True)
        except PermissionError:
            pass


def _shown_rows(n: int):
    """The rows a text table of a motion shows: all up to 21, else 11 spread evenly."""
    return range(n) if n <= 21 else np.unique(np.linspace(0, n - 1, 11).round().astype(int))


def _more_rows(n: int) -> list[str]:
    return [f"({n} points; 11 shown; --json prints all)"] if n > 21 else []


def save_figure(fig, out) -> None:
    """A figure written atomically: a temporary file in the same folder, renamed. A failed
    run leaves nothing half-written; a killed one leaves a temporary named after the output
    and its process, which the next run that writes the same output removes."""
    out = Path(out)
    _clean_stale(out)
    tmp = out.with_name(f".{out.name}.{os.getpid()}{TMP_TAG}{out.suffix or '.png'}")
    try:
        fig.savefig(tmp, dpi=130)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


# --------------------------------------------------------------------------- spectra


@dataclass
class Spectrum:
    """The result of one frequency method over a batch: arrays of shape (sets, modes)."""

    method: str
    frequencies: np.ndarray  # rad/s, ascending per set
    growth: np.ndarray  # real parts of the eigenvalues (> 0: growing), same order
    error_estimate: np.ndarray  # relative error bound per frequency
    equilibrium: np.ndarray | None = None  # (sets, equilibrium coordinates)
    route: np.ndarray = field(default=None)  # per set: which rung answered (default only)
    growth_known: bool = True  # False for a method that computes no growth rates (formulas)

    def __len__(self) -> int:
        return self.frequencies.shape[0]

    @classmethod
    def concat(cls, parts: list["Spectrum"]) -> "Spectrum":
        """One spectrum of the sets of several, in order."""
        cat = {f: (None if getattr(parts[0], f) is None else np.concatenate([getattr(x, f) for x in parts]))
               for f in ("frequencies", "growth", "error_estimate", "equilibrium", "route")}
        return cls(parts[0].method, **cat, growth_known=all(p.growth_known for p in parts))

    def to_dict(self, k: int, model, params: dict) -> dict:
        """The `gyro frequencies --json` document of set k (its keys are the contract)."""
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
            "stability": {"class": str(stab.label[k]), "growth_rate": float(stab.growth_rate[k]),
                          "unstable_roots": int(stab.unstable_roots[k])},
        }

    def table(self, k: int, model) -> str:
        """The `gyro frequencies` text of set k."""
        freqs, est = self.frequencies[k], self.error_estimate[k]
        stab = classify(self)
        lines = [f"{model.meta['title']} ({model.name})",
                 f"natural frequencies by the method '{self.method}'"
                 + (f" (answered by its {self.route[k]} rung)" if self.route is not None else "") + ":",
                 f"{'':>4} {'omega [rad/s]':>16} {'f [Hz]':>14} {'period [s]':>14} {'rel. error <=':>14}"]
        lam = np.abs(self.growth[k] + 1j * freqs)
        grows = (self.growth[k] > np.maximum(np.where(np.isfinite(est), est, np.inf), 1e-9) * lam) & np.isfinite(est)
        for i, (w, e) in enumerate(zip(freqs, est), 1):
            period = 2 * np.pi / w if w > 0 else float("inf")
            row = f"{i:>4} {w:>16.9g} {w / (2 * np.pi):>14.6g} {period:>14.6g} {e:>14.2g}"
            if grows[i - 1]:
                row += f"   grows at {self.growth[k][i - 1]:.6g} 1/s"
            lines.append(row)
        label = stab.label[k]
        note = {"unstable": f", {stab.unstable_roots[k]} growing root(s), the fastest at {stab.growth_rate[k]:.6g} 1/s",
                "unknown": (f" (the method '{self.method}' computes no growth rates: no verdict; try --method "
                            "default)" if not self.growth_known else
                            " (a root's error is unbounded: this method cannot tell; try --method default)"),
                "failed": " (these parameters could not be computed)"}.get(label, "")
        lines.append(f"equilibrium: {label}{note}")
        return "\n".join(lines)

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "Spectrum":
        s = _load_npz(cls, path)
        if isinstance(s.route, list):
            s.route = np.array(s.route, dtype=object)
        return s

    def plot(self, x=None, ax=None, label=None):
        """Frequencies of every set against x (the set index by default), one curve a mode."""
        plt = _pyplot()
        if ax is None:
            _, ax = plt.subplots(layout="constrained")
        x = np.arange(len(self)) if x is None else x
        for j in range(self.frequencies.shape[1]):
            ax.plot(x, self.frequencies[:, j], lw=1, color="k", label=(label or self.method) if j == 0 else None)
        ax.set_yscale("log")
        ax.set_ylabel("natural frequency omega [rad/s]")
        return ax


@dataclass
class Stability:
    """Per set: 'stable', 'unstable' (with its growth rate, 1/s), 'marginal' (a root whose
    real part, or whose frequency, is zero only within its error estimate), 'unknown' (a
    root's error is unbounded) or 'failed' (the set could not be computed)."""

    label: np.ndarray  # (sets,) str
    growth_rate: np.ndarray  # (sets,) largest real part, 1/s (0 when stable)
    unstable_roots: np.ndarray  # (sets,) int: growing modes (eigenvalue pairs, or quadruples, with a growing member)
    slowest_growth: np.ndarray  # (sets,) smallest growing real part, 1/s (0 when stable)


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
    failed = ~np.all(np.isfinite(spec.frequencies) & np.isfinite(spec.growth), axis=1)
    unknown = ~np.all(bounded, axis=1)
    if not spec.growth_known:  # the formulas assume a stable gyrocompass: no growth rates
        unknown = np.ones(len(lam), bool)
    label = np.where(failed, "failed", np.where(
        growing.any(axis=1), "unstable", np.where(
            unknown, "unknown", np.where(neutral.any(axis=1), "marginal", "stable"))))
    rate = np.where(growing, spec.growth, 0.0).max(axis=1)
    slowest = np.where(growing, spec.growth, np.inf).min(axis=1)
    return Stability(label.astype(object), rate, growing.sum(axis=1), np.where(np.isfinite(slowest), slowest, 0.0))


@dataclass
class ModalResult:
    """Natural frequencies of a model at one parameter set, with the equilibrium used."""

    model: str
    params: dict
    equilibrium: dict
    frequencies: list  # rad/s, ascending
    eigenvalues_re: list = field(default_factory=list)  # real parts, same order (growth if > 0)
    error_estimate: list = field(default_factory=list)  # last Newton step, relative

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=1)

    def save(self, path) -> None:
        with open(path, "w") as fh:
            fh.write(self.to_json())

    @classmethod
    def load(cls, path) -> "ModalResult":
        with open(path) as fh:
            return cls(**json.load(fh))


# --------------------------------------------------------------------------- sweeps


def nearest_error(approx: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """Relative distance of each approximate frequency to the nearest exact one."""
    with np.errstate(all="ignore"):
        return np.min(np.abs(approx[:, :, None] / exact[:, None, :] - 1), axis=2)


@dataclass
class CampbellDiagram:
    """Frequencies against spin Omega: the exact operator (default method) and, where the
    model has them, the formulas with each one's relative error."""

    model: str
    title: str
    Omega: np.ndarray  # (points,) rad/s
    exact: Spectrum
    formulas: Spectrum | None
    values: dict  # the set the sweep scales
    Omega_example: float  # the paper example's spin, marked
    changed: dict = field(default_factory=dict)  # the parameters that differ from the defaults

    @property
    def formula_error(self) -> np.ndarray | None:
        return None if self.formulas is None else nearest_error(self.formulas.frequencies, self.exact.frequencies)

    @property
    def bad(self) -> np.ndarray:
        err = self.formula_error
        return np.any(~(err <= FORMULA_BAD), axis=1) if err is not None else np.zeros(len(self.Omega), bool)

    @property
    def shaded_fraction(self) -> float:
        return float(np.mean(self.bad))

    def summary(self, out) -> str:
        failed = int(np.sum(classify(self.exact).label == "failed"))
        return (f"gyro: wrote {out} ({len(self.Omega)} spins, {self.shaded_fraction:.0%} of the sweep "
                "has a formula off by more than 1%" + (f"; {failed} spins could not be computed" if failed else "")
                + ")")

    def plot(self, out) -> None:
        """Frequencies against spin (modes numbered at the right), the formulas dashed; below,
        each formula's relative error against spin on a log scale with the 1 % line."""
        plt = _pyplot()
        W = self.Omega
        panels = 2 if self.formulas is not None else 1
        fig, axes = plt.subplots(panels, 1, figsize=(8, 9 if panels == 2 else 6), sharex=True,
                                 layout="constrained", height_ratios=[3, 2][:panels], squeeze=False)
        ax = axes[0, 0]
        ex = self.exact.frequencies
        for j in range(ex.shape[1]):
            ax.loglog(W, ex[:, j], color="k", lw=1.4, label="exact operator (default method)" if j == 0 else None)
            if np.isfinite(ex[-1, j]):
                ax.annotate(f"{j + 1}", (W[-1], ex[-1, j]), xytext=(3, 0), textcoords="offset points",
                            fontsize=7, va="center")
        if self.formulas is not None:
            fo, err = self.formulas.frequencies, self.formula_error
            with np.errstate(all="ignore"):
                near = np.take_along_axis(ex, np.argmin(np.abs(fo[:, :, None] / ex[:, None, :] - 1), axis=2), 1)
            for j in range(fo.shape[1]):
                ax.loglog(W, fo[:, j], color="tab:blue", lw=1.0, ls="--",
                          label="formulas (3.2)-(3.28)" if j == 0 else None)
                bad = ~(err[:, j] <= FORMULA_BAD)
                ax.fill_between(W, np.where(np.isfinite(fo[:, j]), fo[:, j], near[:, j]), near[:, j],
                                where=bad, color="tab:red", alpha=0.35, lw=0)
            ax.fill_between([], [], color="tab:red", alpha=0.35, label="a formula errs by more than 1%")
            eax = axes[1, 0]
            colors = plt.get_cmap("tab10")
            with np.errstate(all="ignore"):
                shown = np.where(err > 0, err, np.nan)
            for j in range(err.shape[1]):
                eax.loglog(W, shown[:, j], color=colors(j % 10), lw=1.1, label=f"formula for mode {j + 1}")
            eax.axhline(FORMULA_BAD, color="tab:red", lw=0.9, ls="--", label="1 %")
            eax.set_ylabel("relative error of the formula")
            eax.set_xlabel("spin Omega = H/A [rad/s]")
            eax.grid(True, which="both", alpha=0.25)
            eax.legend(fontsize=6.5, ncol=4, loc="best")
            eax.axvline(self.Omega_example, color="0.5", lw=0.8, ls=":")
        else:
            ax.set_xlabel("spin Omega = H/A [rad/s]")
        ax.axvline(self.Omega_example, color="0.5", lw=0.8, ls=":", label="paper example")
        ax.set_ylabel("natural frequency omega [rad/s]")
        changed = "" if not self.changed else "\n(" + ", ".join(f"{k} = {v:g}" for k, v in self.changed.items()) + ")"
        ax.set_title(f"Campbell diagram: {self.title}{changed}", fontsize=10)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=8, loc="upper left")
        save_figure(fig, out)
        plt.close(fig)

    def save(self, path) -> None:
        _save_npz(self, path)


def _edges(v: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid points: midpoints, geometric ones on a log axis."""
    u = np.log(v) if log else v
    mid = (u[1:] + u[:-1]) / 2
    e = np.concatenate([[2 * u[0] - mid[0]], mid, [2 * u[-1] - mid[-1]]])
    return np.exp(e) if log else e


@dataclass
class StabilityMap:
    """Stability of the equilibrium over a grid of two parameters (arrays (y, x))."""

    model: str
    title: str
    units: dict  # parameter -> unit
    x: np.ndarray
    y: np.ndarray
    xname: str
    yname: str
    label: np.ndarray  # 'stable', 'marginal', 'unstable'
    growth: np.ndarray  # fastest growth rate, 1/s
    unstable_roots: np.ndarray
    slowest: np.ndarray  # slowest growing rate, 1/s
    xlog: bool = False
    ylog: bool = False
    changed: dict = field(default_factory=dict)  # parameters that differ from the defaults

    def __getitem__(self, key):  # the grid as a mapping, as sweeps and tests read it
        return getattr(self, key)

    def get(self, key, default=None):
        return getattr(self, key, default)

    def counts(self) -> dict:
        out = {k: int(np.sum(self.label == k)) for k in ("stable", "marginal", "unstable")}
        out.update({k: int(np.sum(self.label == k)) for k in ("unknown", "failed") if np.any(self.label == k)})
        return out

    def summary(self, out) -> str:
        return f"gyro: wrote {out} ({', '.join(f'{v} {k}' for k, v in self.counts().items())})"

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "StabilityMap":
        m = _load_npz(cls, path)
        m.label = np.array(m.label, dtype=object)
        return m

    def plot(self, out, lines=()) -> None:
        """Regions by the number of growing modes (stable, marginal, one, two or more),
        solid contours of the fastest growth rate and dashed ones of the slowest where two or
        more pairs grow (a growth that gyroscopic coupling slows down shows there, not in the
        fastest). `lines`: (xs, ys, label) curves to overlay, such as an analytic boundary."""
        plt = _pyplot()
        from matplotlib.colors import ListedColormap

        degree = np.minimum(self.unstable_roots, 2)
        code = np.where(self.label == "marginal", 1, np.where(degree > 0, degree + 1, 0))
        code = np.where(np.isin(self.label, ["failed", "unknown"]), 4, code)
        colors = ["#cfe8cf", "#f3e3a1", "#f2b8b0", "#d9786c", "#9a9a9a"]
        names = ["stable", "marginal", "unstable: one growing mode", "unstable: two or more",
                 "no verdict (failed, or error unbounded)"]
        fig, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
        ax.pcolormesh(_edges(self.x, self.xlog), _edges(self.y, self.ylog), code,
                      cmap=ListedColormap(colors), vmin=-0.5, vmax=4.5, shading="flat")
        for key, style, where in (("growth", "-", self.unstable_roots > 0),
                                  ("slowest", "--", self.unstable_roots > 1)):
            g = np.where(where & (self[key] > 0), self[key], np.nan)
            if np.sum(np.isfinite(g)) > 3 and np.nanmax(g) > np.nanmin(g):
                lo, hi = np.log10(np.nanmin(g)), np.log10(np.nanmax(g))
                step = 0.5 if hi - lo > 1.5 else 0.1  # half decades, or tenths of one
                levels = np.arange(np.ceil(lo / step) * step, hi, step)
                if levels.size == 0:
                    continue
                cs = ax.contour(self.x, self.y, np.log10(g), levels=levels, colors="k", linewidths=0.6,
                                linestyles=style)
                # every other level labelled, spaced along the lines: labels that do not overlap
                ax.clabel(cs, cs.levels[::2], fmt=lambda v: f"{10**v:.2g}/s", fontsize=6.5,
                          inline_spacing=4, use_clabeltext=True)
        for xs, ys, label in lines:
            ax.plot(xs, ys, color="tab:blue", lw=1.2, ls=":", label=label)
        for code_, (name, color) in enumerate(zip(names, colors)):
            if np.any(code == code_):
                ax.fill_between([], [], color=color, label=name)
        ax.set_xscale("log" if self.xlog else "linear")
        ax.set_yscale("log" if self.ylog else "linear")
        ax.set_xlim(self.x[0], self.x[-1])
        ax.set_ylim(self.y[0], self.y[-1])
        ax.set_xlabel(f"{self.xname} [{self.units[self.xname]}]")
        ax.set_ylabel(f"{self.yname} [{self.units[self.yname]}]")
        changed = "" if not self.changed else "; " + ", ".join(f"{k} = {v:g}" for k, v in self.changed.items())
        ax.set_title(f"Stability of the equilibrium: {self.title}\n(contours: growth rate, "
                     f"solid the fastest, dashed the slowest growing root{changed})", fontsize=9)
        ax.legend(fontsize=8, loc="best")
        save_figure(fig, out)
        plt.close(fig)


# --------------------------------------------------------------------------- motions


@dataclass
class Trajectory:
    """A motion of the gimbal gyroscope: theta, psi, phi at the times t, the method, the
    integrals at t = 0 and, from the closed form, the motion type and the period of theta."""

    model: str
    title: str
    method: str
    t: np.ndarray
    theta: np.ndarray
    psi: np.ndarray
    phi: np.ndarray
    integrals: dict
    motion_type: str | None = None
    period: float | None = None

    def to_dict(self) -> dict:
        """The `gyro simulate --json` document (its keys are the contract)."""
        return {"t": self.t.tolist(), "theta": self.theta.tolist(), "psi": self.psi.tolist(),
                "phi": self.phi.tolist(), "method": self.method, "integrals": self.integrals}

    def table(self) -> str:
        import math

        I, t = self.integrals, self.t
        lines = [f"{self.title} ({self.model}), method {self.method}",
                 f"integrals at t = 0: H = {I['H']:.9g}, L = {I['L']:.9g}, M = {I['M']:.9g}"]
        if self.motion_type is not None:
            period = ("none (stationary or on the separatrix)" if not math.isfinite(self.period)
                      else f"{self.period:.9g} s")
            lines.append(f"motion: {self.motion_type}; period of theta {period}")
        lines.append(f"{'t [s]':>14} {'theta [rad]':>18} {'psi [rad]':>18} {'phi [rad]':>18}")
        for i in _shown_rows(len(t)):
            lines.append(f"{t[i]:>14.6g} {self.theta[i]:>18.12g} {self.psi[i]:>18.12g} {self.phi[i]:>18.12g}")
        return "\n".join(lines + _more_rows(len(t)))

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "Trajectory":
        return _load_npz(cls, path)

    def plot(self, out) -> None:
        """theta, psi, phi against t, written whole or not at all."""
        plt = _pyplot()
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
        for ax, y, name in zip(axes, (self.theta, self.psi, self.phi), ("theta", "psi", "phi")):
            ax.plot(self.t, y, lw=1)
            ax.set_ylabel(f"{name} [rad]")
        axes[0].set_title(f"gimbal gyroscope, {self.method}")
        axes[-1].set_xlabel("t [s]")
        fig.tight_layout()
        save_figure(fig, out)
        plt.close(fig)


def _finite_or_none(a) -> list:
    """Rows of numbers for strict JSON: a value that could not be computed is null."""
    return [[float(v) if np.isfinite(v) else None for v in row] for row in np.asarray(a, float)]


@dataclass
class FrequencySweep:
    """Natural frequencies against one parameter (a Campbell diagram over any parameter)."""

    model: str
    title: str
    xname: str
    xunit: str
    x: np.ndarray
    spectrum: Spectrum
    xlog: bool = False

    def to_dict(self) -> dict:
        """The `gyro sweep --json` document."""
        s = self.spectrum
        return {"model": self.model, "x": {"name": self.xname, "unit": self.xunit, "values": self.x.tolist()},
                "method": s.method, "frequencies": _finite_or_none(s.frequencies),
                "eigenvalues_re": _finite_or_none(s.growth),
                "error_estimate": [[float(e) if np.isfinite(e) else None for e in row] for row in s.error_estimate],
                "stability": [str(c) for c in classify(s).label]}

    def summary(self, out) -> str:
        c = classify(self.spectrum).label
        return (f"gyro: wrote {out} ({len(self.x)} values of {self.xname}: "
                f"{int(np.sum(c == 'stable'))} stable, {int(np.sum(c == 'marginal'))} marginal, "
                f"{int(np.sum(c == 'unstable'))} unstable)")

    def plot(self, out) -> None:
        plt = _pyplot()
        fig, ax = plt.subplots(figsize=(8, 6), layout="constrained")
        self.spectrum.plot(self.x, ax=ax, label=f"method '{self.spectrum.method}'")
        ax.set_xscale("log" if self.xlog else "linear")
        ax.set_xlabel(f"{self.xname} [{self.xunit}]")
        ax.set_title(f"Natural frequencies against {self.xname}: {self.title}", fontsize=10)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=8)
        save_figure(fig, out)
        plt.close(fig)

    def save(self, path) -> None:
        _save_npz(self, path)


# --------------------------------------------------------------------------- gyrohorizoncompass


@dataclass
class EquilibriumStability:
    """The relative equilibrium of one parameter set: its conditions (margins, > 0 when
    satisfied), whether the sufficient one holds, and the spectrum of the linearisation."""

    model: str
    title: str
    params: dict  # command-line names
    equilibrium: dict
    theta: float
    chi: float
    conditions: dict  # name -> margin
    sufficient: bool
    orbit: bool
    eigenvalues: np.ndarray  # (2n, 2): re, im
    spectrally_stable: bool

    def to_dict(self) -> dict:
        """The `gyro stability --json` document (its keys are the contract)."""
        return {"model": self.model, "params": dict(self.params), "equilibrium": dict(self.equilibrium),
                "theta": float(self.theta), "chi": float(self.chi),
                "conditions": {k: float(v) for k, v in self.conditions.items()},
                "sufficient": bool(self.sufficient),
                "eigenvalues": [[float(a), float(b)] for a, b in np.asarray(self.eigenvalues)],
                "spectrally_stable": bool(self.spectrally_stable)}

    @property
    def gyroscopically_stabilised(self) -> bool:
        return self.spectrally_stable and not self.sufficient

    def table(self) -> str:
        which = "(4.3)" if self.orbit else "(3.6)"
        lines = [f"{self.title} ({self.model})",
                 "parameters: " + ", ".join(f"{k} = {v:.6g}" for k, v in self.params.items()),
                 "relative equilibrium (3.1): alpha = beta = gamma = 0, "
                 f"epsilon0 = {self.equilibrium['epsilon0']:.9g} rad",
                 f"theta = (C - A)/I = {self.theta:.6g}, chi = (C - B)/I = {self.chi:.6g}",
                 f"{'condition (margin > 0 when it holds)':<48} {'margin':>14}"]
        for k, v in self.conditions.items():
            lines.append(f"{k:<48} {v:>14.6g}" + ("" if v > 0 else "  fails"))
        lines.append(f"{'eigenvalues':<22} {'re':>16} {'im':>16}")
        for re, im in np.asarray(self.eigenvalues):
            lines.append(f"{'':<22} {re:>16.6g} {im:>16.9g}")
        verdict = ("stable: the sufficient condition holds" if self.sufficient else
                   "spectrally stable outside the sufficient condition (gyroscopic stabilisation)"
                   if self.spectrally_stable else "unstable")
        lines.append(f"sufficient {which}: {'yes' if self.sufficient else 'no'}; "
                     f"spectrally stable: {'yes' if self.spectrally_stable else 'no'}; {verdict}")
        return "\n".join(lines)

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "EquilibriumStability":
        s = _load_npz(cls, path)
        s.eigenvalues = np.asarray(s.eigenvalues, float)
        return s


@dataclass
class ConditionMap:
    """Over a grid of two axes (arrays (y, x)): 2 where the sufficient condition ((3.6), or
    (4.3) on the orbit) holds, 1 where the linearisation is spectrally stable outside it
    (gyroscopic stabilisation), 0 where it is unstable."""

    model: str
    title: str
    xname: str
    yname: str
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray  # (y, x) int
    growth: np.ndarray  # (y, x) largest real part, 1/s (0 when stable)
    orbit: bool = False
    base: dict = field(default_factory=dict)  # the other parameters (command-line names)

    KIND = "2: {c} holds, 1: spectrally stable outside {c}, 0: unstable"

    @property
    def kind(self) -> str:
        return self.KIND.format(c="(4.3)" if self.orbit else "(3.6)")

    def counts(self) -> dict:
        v = np.asarray(self.values)
        return {"sufficient": int(np.sum(v == 2)), "gyroscopic": int(np.sum(v == 1)), "unstable": int(np.sum(v == 0))}

    def to_dict(self) -> dict:
        """The `gyro map --json` document (its keys are the contract)."""
        return {"x": {"name": self.xname, "values": np.asarray(self.x).tolist()},
                "y": {"name": self.yname, "values": np.asarray(self.y).tolist()},
                "values": np.asarray(self.values).astype(int).tolist(), "kind": self.kind}

    def summary(self, out) -> str:
        c = self.counts()
        which = "(4.3)" if self.orbit else "(3.6)"
        return (f"gyro: wrote {out} ({self.values.size} points: {c['sufficient']} where {which} holds, "
                f"{c['gyroscopic']} spectrally stable outside it, {c['unstable']} unstable)")

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "ConditionMap":
        m = _load_npz(cls, path)
        m.values = np.asarray(m.values, int)
        return m

    def plot(self, out) -> None:
        plt = _pyplot()
        from matplotlib.colors import ListedColormap

        which = "(4.3)" if self.orbit else "(3.6)"
        colors = ["#f2b8b0", "#f3e3a1", "#cfe8cf"]
        names = ["unstable", f"spectrally stable outside {which} (gyroscopic stabilisation)", f"{which} holds"]
        fig, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
        ax.pcolormesh(_edges(np.asarray(self.x), False), _edges(np.asarray(self.y), False), self.values,
                      cmap=ListedColormap(colors), vmin=-0.5, vmax=2.5, shading="flat")
        for code in (2, 1, 0):
            if np.any(self.values == code):
                ax.fill_between([], [], color=colors[code], label=f"{names[code]}: {int(np.sum(self.values == code))}")
        ax.set_xlim(_edges(np.asarray(self.x), False)[[0, -1]])
        ax.set_ylim(_edges(np.asarray(self.y), False)[[0, -1]])
        ax.set_xlabel(self.xname)
        ax.set_ylabel(self.yname)
        fixed = ", ".join(f"{k} = {v:.3g}" for k, v in self.base.items() if k not in ("theta", "chi"))
        ax.set_title(f"{self.title}: {which} against the spectrum\n({fixed})", fontsize=8)
        ax.legend(fontsize=8, loc="best")
        save_figure(fig, out)
        plt.close(fig)


@dataclass
class AngleTrajectory:
    """A motion in the model's coordinates (the gyrohorizoncompass's alpha, beta, gamma,
    epsilon) at the times t, with the integral E along it."""

    model: str
    title: str
    method: str
    t: np.ndarray
    coordinates: tuple
    q: np.ndarray  # (len(t), len(coordinates))
    E: np.ndarray  # (len(t),)
    params: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The `gyro simulate --json` document (its keys are the contract)."""
        d = {"t": np.asarray(self.t).tolist()}
        for k, name in enumerate(self.coordinates):
            d[name] = np.asarray(self.q)[:, k].tolist()
        d["E"] = np.asarray(self.E).tolist()
        d["method"] = self.method
        return d

    @property
    def drift(self) -> float:
        """max |E - E(0)| / |E(0)| along the motion."""
        E = np.asarray(self.E)
        return float(np.max(np.abs(E - E[0])) / abs(E[0])) if E[0] != 0 else float(np.max(np.abs(E - E[0])))

    def table(self) -> str:
        t, q = np.asarray(self.t), np.asarray(self.q)
        lines = [f"{self.title} ({self.model}), method {self.method}",
                 f"E(0) = {self.E[0]:.12g}; max |E - E(0)|/|E(0)| = {self.drift:.2g}"]
        lines.append(f"{'t [s]':>12}" + "".join(f"{n + ' [rad]':>18}" for n in self.coordinates))
        for i in _shown_rows(len(t)):
            lines.append(f"{t[i]:>12.6g}" + "".join(f"{v:>18.11g}" for v in q[i]))
        return "\n".join(lines + _more_rows(len(t)))

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "AngleTrajectory":
        tr = _load_npz(cls, path)
        tr.coordinates = tuple(tr.coordinates)
        return tr

    def plot(self, out) -> None:
        plt = _pyplot()
        n = len(self.coordinates)
        fig, axes = plt.subplots(n + 1, 1, sharex=True, figsize=(7, 1.6 * (n + 1)))
        for k, (ax, name) in enumerate(zip(axes, self.coordinates)):
            ax.plot(self.t, np.asarray(self.q)[:, k], lw=1)
            ax.set_ylabel(f"{name} [rad]")
        E = np.asarray(self.E)
        axes[-1].plot(self.t, E - E[0], lw=1)
        axes[-1].set_ylabel("E - E(0)")
        axes[0].set_title(f"{self.title}, {self.method}", fontsize=9)
        axes[-1].set_xlabel("t [s]")
        fig.tight_layout()
        save_figure(fig, out)
        plt.close(fig)
