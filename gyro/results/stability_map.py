"""Stability of the equilibrium over a grid of two parameters."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _edges, _pyplot, save_figure


@dataclass
class StabilityMap(Result):
    """Stability of the equilibrium over a grid of two parameters (arrays (y, x))."""

    model: str
    title: str
    units: dict  # parameter -> unit
    x: np.ndarray
    y: np.ndarray
    xname: str
    yname: str
    label: np.ndarray  # gyro.results.verdict.LABELS: 'stable', 'marginal', 'unstable', 'boundary', ...
    growth: np.ndarray  # fastest growth rate, 1/s
    unstable_roots: np.ndarray
    slowest: np.ndarray  # slowest growing rate, 1/s
    xlog: bool = False
    ylog: bool = False
    changed: dict = field(default_factory=dict)  # parameters that differ from the defaults
    reasons: np.ndarray | None = None  # (y, x) object: why a point is a boundary (None elsewhere)

    # the figure's classes, in its order: (name in the legend, colour); `values` of the JSON
    # are the first word of each, the verdict's label
    CLASSES = (("stable", "#cfe8cf"), ("marginal", "#f3e3a1"), ("unstable: one growing mode", "#f2b8b0"),
               ("unstable: two or more", "#d9786c"), ("unknown (error unbounded)", "#9a9a9a"),
               ("failed", "#5a5a5a"), ("boundary (rounding could change the verdict)", "#222222"))

    def __getitem__(self, key):  # the grid as a mapping, as sweeps and tests read it
        return getattr(self, key)

    def get(self, key, default=None):
        return getattr(self, key, default)

    def counts(self) -> dict:
        out = {k: int(np.sum(self.label == k)) for k in ("stable", "marginal", "unstable")}
        out.update({k: int(np.sum(self.label == k)) for k in ("boundary", "unknown", "failed")
                    if np.any(self.label == k)})
        return out

    @property
    def boundary(self) -> np.ndarray:
        return np.asarray(self.label == "boundary", bool)

    def codes(self) -> np.ndarray:
        """(y, x) int: the index of each point's class in CLASSES (the figure's colours)."""
        degree = np.minimum(self.unstable_roots, 2)
        code = np.where(self.label == "unstable", degree + 1, 0)
        for k, name in ((1, "marginal"), (4, "unknown"), (5, "failed"), (6, "boundary")):
            code = np.where(self.label == name, k, code)
        return code

    def to_dict(self) -> dict:
        """The `gyro stability-map --json` document (its keys are the contract): the axes as
        `gyro map` gives them, `values` the class per point as the figure shows it (the
        verdict's label: stable, marginal, unstable, boundary, unknown, failed), `boundary`
        (true where rounding could change the verdict), and per point the number of growing
        modes and the fastest growth rate (1/s), which split and contour the unstable class."""
        from gyro.results._io import _finite_or_none

        return {"model": self.model,
                "x": {"name": self.xname, "values": np.asarray(self.x).tolist(), "log": bool(self.xlog)},
                "y": {"name": self.yname, "values": np.asarray(self.y).tolist(), "log": bool(self.ylog)},
                "values": [[str(v) for v in row] for row in self.label],
                "boundary": self.boundary.tolist(),
                "unstable_roots": np.asarray(self.unstable_roots).astype(int).tolist(),
                "growth_rate": _finite_or_none(self.growth),
                "reasons": [[None if r is None else str(r) for r in row] for row in
                            (self.reasons if self.reasons is not None else np.full(self.label.shape, None))],
                "changed": {k: float(v) for k, v in self.changed.items()}}

    def summary(self, out) -> str:
        return f"gyro: wrote {out} ({', '.join(f'{v} {k}' for k, v in self.counts().items())})"


    @classmethod
    def _loaded(cls, m) -> "StabilityMap":
        m.label = np.array(m.label, dtype=object)
        m.reasons = None if m.reasons is None else np.array(m.reasons, dtype=object)
        return m

    def plot(self, out, lines=()) -> None:
        """Regions by class (CLASSES: stable, marginal, unstable by the number of growing
        modes, one or two and more, unknown, failed, boundary),
        solid contours of the fastest growth rate and dashed ones of the slowest where two or
        more pairs grow (a growth that gyroscopic coupling slows down shows there, not in the
        fastest). `lines`: (xs, ys, label) curves to overlay, such as an analytic boundary."""
        plt = _pyplot()
        from matplotlib.colors import ListedColormap

        code = self.codes()
        names, colors = zip(*self.CLASSES)
        fig, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
        ax.pcolormesh(_edges(self.x, self.xlog), _edges(self.y, self.ylog), code,
                      cmap=ListedColormap(colors), vmin=-0.5, vmax=len(colors) - 0.5, shading="flat")
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

