"""A map: one quantity over a grid of two axes (arrays (y, x)), of one of three kinds:

- `verdict`: the verdict of the equilibrium's spectrum per point (gyro.results.verdict:
  stable, marginal, unstable, boundary, unknown, failed), with the number of growing modes
  and the fastest and slowest growth rates (`gyro stability-map`, gyro/analyses/stability_map.py);
- `condition`: a model's declared sufficient condition against its spectrum, 2 where it
  holds, 1 spectrally stable outside it (gyroscopic stabilisation), 0 unstable, -1 a
  boundary (rounding could change the verdict), -2 marginal (an exact zero root) (`gyro
  map`, gyro/analyses/conditions.py);
- `error`: the relative error of one level of a hierarchy against a more exact one, NaN
  where it could not be computed (`gyro level-map`, gyro/analyses/level_map.py).

What a producer adds is data (`info`): the parameters changed from the defaults, the name
of the condition, the levels, the tolerance, the measure, ..."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _axes, _edges, _finite_or_none, cell

KINDS = ("verdict", "condition", "error")

# a verdict map's classes in the figure's order: (name in the legend, colour); the first word
# of each is the verdict's label
VERDICT_CLASSES = (("stable", "#cfe8cf"), ("marginal", "#f3e3a1"), ("unstable: one growing mode", "#f2b8b0"),
                   ("unstable: two or more", "#d9786c"), ("unknown (error unbounded)", "#9a9a9a"),
                   ("failed", "#5a5a5a"), ("boundary (rounding could change the verdict)", "#222222"))
# a condition map's codes -2 .. 2 and their colours
CONDITION_COLORS = ("#7a6fb0", "#222222", "#f2b8b0", "#f3e3a1", "#cfe8cf")
BOUNDARY, MARGINAL = -1, -2
CONDITION_KIND = ("2: {c} holds, 1: spectrally stable outside {c}, 0: unstable, -1: boundary (rounding "
                  "could change the verdict), -2: marginal (an exact zero root)")


@dataclass
class Map(Result):
    """`values[i, j]` at y[i], x[j]: a verdict's label (kind `verdict`), a condition's code
    (`condition`) or a relative error (`error`). `layers`: other (y, x) arrays (`growth`,
    `unstable_roots`, `slowest` growth rates in 1/s, `reasons` why a point is a boundary,
    `boundary`); `info`: what the producer adds. A layer or an entry of `info` reads as an
    attribute (`m.growth`, `m.tol`) or an item (`m["growth"]`); a verdict map's values are
    also its `label`."""

    kind: str
    model: str
    title: str
    xname: str
    yname: str
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray
    layers: dict = field(default_factory=dict)
    xlog: bool = False
    ylog: bool = False
    units: dict = field(default_factory=dict)  # parameter -> unit
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"not a kind of map: {self.kind!r}; known: {', '.join(KINDS)}")

    def __getattr__(self, name):
        d = self.__dict__  # not through getattr: an instance half-built (unpickling) has none yet
        if name == "label" and d.get("kind") == "verdict":
            return d["values"]
        for where in ("layers", "info"):
            if where in d and name in d[where]:
                return d[where][name]
        raise AttributeError(name)

    def __getitem__(self, key):  # the grid as a mapping, as sweeps and tests read it
        return getattr(self, key)

    def get(self, key, default=None):
        return getattr(self, key, default)

    @property
    def boundary(self) -> np.ndarray:
        """(y, x) bool: rounding could change the verdict there."""
        if "boundary" in self.layers:
            return np.asarray(self.layers["boundary"], bool)
        if self.kind == "verdict":
            return np.asarray(self.values == "boundary", bool)
        return np.zeros(np.shape(self.values), bool)

    def counts(self) -> dict:
        """Points per class: a verdict map's labels (stable, marginal, unstable, and boundary,
        unknown, failed where there are any); a condition map's sufficient, gyroscopic,
        unstable, boundary (a boundary point counts as none of the others) and marginal
        where there is one; an error map's points within its tolerance, beyond it, failed."""
        v = np.asarray(self.values)
        if self.kind == "verdict":
            out = {k: int(np.sum(v == k)) for k in ("stable", "marginal", "unstable")}
            out.update({k: int(np.sum(v == k)) for k in ("boundary", "unknown", "failed") if np.any(v == k)})
            return out
        if self.kind == "condition":
            out = {"sufficient": int(np.sum(v == 2)), "gyroscopic": int(np.sum(v == 1)),
                   "unstable": int(np.sum(v == 0)), "boundary": int(np.sum(v == BOUNDARY))}
            if np.any(v == MARGINAL):
                out["marginal"] = int(np.sum(v == MARGINAL))
            return out
        k, failed = int(self.within().sum()), int(np.sum(~np.isfinite(v)))
        return {"within": k, "beyond": v.size - k - failed, "failed": failed}

    def within(self) -> np.ndarray:
        """An error map: True where the level meets the tolerance (NaN: not)."""
        return np.where(np.isfinite(self.values), self.values <= self.info["tol"], False)

    @property
    def condition_kind(self) -> str:
        """A condition map: what its codes mean."""
        return CONDITION_KIND.format(c=self.info.get("condition", ""))

    def codes(self) -> np.ndarray:
        """(y, x) int: a verdict map's class per point, the index in VERDICT_CLASSES (the
        figure's colours); a condition map's codes."""
        if self.kind != "verdict":
            return np.asarray(self.values, int)
        degree = np.minimum(self.layers["unstable_roots"], 2)
        code = np.where(self.values == "unstable", degree + 1, 0)
        for k, name in ((1, "marginal"), (4, "unknown"), (5, "failed"), (6, "boundary")):
            code = np.where(self.values == name, k, code)
        return code

    def to_dict(self) -> dict:
        """The command's JSON document (its keys are the contract). `gyro stability-map`:
        the axes (name, values, log), `values` the verdict's label per point, `boundary`,
        per point the number of growing modes and the fastest growth rate (1/s), `reasons`,
        `changed`. `gyro map`: the axes (name, values), `values` the codes, `kind` what they
        mean, `boundary`. `gyro level-map`: model, level, against, tol, x_name, y_name, x, y,
        values (null where a level could not answer), measure, changed, failed, seconds."""
        x, y = np.asarray(self.x).tolist(), np.asarray(self.y).tolist()
        if self.kind == "verdict":
            reasons = self.layers.get("reasons")
            return {"model": self.model,
                    "x": {"name": self.xname, "values": x, "log": bool(self.xlog)},
                    "y": {"name": self.yname, "values": y, "log": bool(self.ylog)},
                    "values": [[str(v) for v in row] for row in self.values],
                    "boundary": self.boundary.tolist(),
                    "unstable_roots": np.asarray(self.layers["unstable_roots"]).astype(int).tolist(),
                    "growth_rate": _finite_or_none(self.layers["growth"]),
                    "reasons": [[None if r is None else str(r) for r in row] for row in
                                (reasons if reasons is not None else np.full(self.values.shape, None))],
                    "changed": {k: float(v) for k, v in self.info.get("changed", {}).items()}}
        if self.kind == "condition":
            return {"x": {"name": self.xname, "values": x}, "y": {"name": self.yname, "values": y},
                    "values": np.asarray(self.values).astype(int).tolist(), "kind": self.condition_kind,
                    "boundary": self.boundary.tolist()}
        i = self.info
        return {"model": self.model, "level": i["level"], "against": i["against"], "tol": i["tol"],
                "x_name": self.xname, "y_name": self.yname, "x": x, "y": y,
                "values": _finite_or_none(self.values), "measure": i["measure"], "changed": i["changed"],
                "failed": i["failed"], "seconds": i["seconds"]}

    def summary(self, out) -> str:
        """The command's line after writing the figure `out`."""
        c = self.counts()
        if self.kind == "verdict":
            return f"gyro: wrote {out} ({', '.join(f'{v} {k}' for k, v in c.items())})"
        if self.kind == "condition":
            which = self.info.get("condition", "")
            extra = f", {c['marginal']} marginal" if "marginal" in c else ""
            return (f"gyro: wrote {out} ({self.values.size} points: {c['sufficient']} where {which} holds, "
                    f"{c['gyroscopic']} spectrally stable outside it, {c['unstable']} unstable, "
                    f"{c['boundary']} within rounding of a boundary{extra})")
        i = self.info
        finite = np.asarray(self.values)[np.isfinite(self.values)]
        largest = f"largest error {finite.max():.3g}" if finite.size else "no point could be computed"
        return (f"gyro: wrote {out} ({c['within']} of {self.values.size} points within tol {i['tol']:g}: "
                f"{i['level']} against {i['against']}; {largest})")

    def table(self) -> str:
        """The grid as text: a row per y, a column per x (an error to 3 digits, 'none' where
        it could not be computed; a class by its label or code)."""
        i = self.info
        head = {"verdict": f"{self.model}: stability of the equilibrium ({', '.join(f'{v} {k}' for k, v in self.counts().items())})",
                "condition": f"{self.model}: {self.condition_kind}",
                "error": f"{self.model}: {i.get('measure')} of {i.get('level')} against {i.get('against')} "
                         f"(tol {i.get('tol', 0):g})"}[self.kind]
        # an error that could not be computed is 'none', never nan
        show = (lambda v: cell(v, ">10.3g")) if self.kind == "error" else (lambda v: f"{str(v):>10}")  # noqa: E731
        corner = f"{self.yname} \\ {self.xname}"
        lines = [head, f"{corner:>22} " + " ".join(f"{v:>10.4g}" for v in self.x)]
        for k, yv in enumerate(self.y):
            lines.append(f"{yv:>22.6g} " + " ".join(show(v) for v in self.values[k]))
        return "\n".join(lines)

    @classmethod
    def _loaded(cls, m) -> "Map":
        m.values = (np.array(m.values, dtype=object) if m.kind == "verdict" else
                    np.asarray(m.values, int) if m.kind == "condition" else np.asarray(m.values, float))
        types = {"reasons": object, "boundary": bool, "unstable_roots": int}
        m.layers = {k: np.array(v, dtype=types.get(k, float)) for k, v in m.layers.items()}
        return m

    def _axis_label(self, name: str) -> str:
        unit = self.units.get(name, "")
        return f"{name} [{unit}]" if unit else name

    def plot(self, out, lines=()) -> None:
        """Into `out`, a file (written whole or not at all) or a matplotlib Axes. A verdict
        map: regions by class (VERDICT_CLASSES: unstable split by the number of growing
        modes), solid contours of the fastest growth rate and dashed ones of the slowest
        where two or more pairs grow (a growth that gyroscopic coupling slows down shows
        there, not in the fastest); `lines`: (xs, ys, label) curves to overlay, such as an
        analytic boundary. A condition map: regions by code, counted in the legend. An error
        map: log10 of the error as colour, the contour at tol as a thick line (where the
        level stops being enough), cells that could not be computed grey."""
        size = (7.2, 5.6) if self.kind == "error" else (7.5, 5.8)
        with _axes(out, figsize=size) as ax:
            {"verdict": self._draw_verdicts, "condition": self._draw_conditions,
             "error": self._draw_errors}[self.kind](ax)
            for xs, ys, label in lines:
                ax.plot(xs, ys, color="tab:blue", lw=1.2, ls=":", label=label)
            if self.kind != "error":
                ax.legend(fontsize=8, loc="best")

    def _classes(self, ax, code, colors, names, low: int, count: bool = False) -> None:
        """Regions coloured by code (low .. low + len(colors) - 1), a legend entry each present."""
        from matplotlib.colors import ListedColormap

        xlog, ylog = self.xlog, self.ylog
        ax.pcolormesh(_edges(np.asarray(self.x), xlog), _edges(np.asarray(self.y), ylog), code,
                      cmap=ListedColormap(colors), vmin=low - 0.5, vmax=low + len(colors) - 0.5, shading="flat")
        for k in sorted(names, reverse=low < 0):
            if np.any(code == k):
                n = f": {int(np.sum(code == k))}" if count else ""
                ax.fill_between([], [], color=colors[k - low], label=f"{names[k]}{n}")

    def _draw_verdicts(self, ax) -> None:
        names, colors = zip(*VERDICT_CLASSES)
        self._classes(ax, self.codes(), colors, dict(enumerate(names)), 0)
        roots = self.layers["unstable_roots"]
        for key, style, where in (("growth", "-", roots > 0), ("slowest", "--", roots > 1)):
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
        ax.set_xscale("log" if self.xlog else "linear")
        ax.set_yscale("log" if self.ylog else "linear")
        ax.set_xlim(self.x[0], self.x[-1])
        ax.set_ylim(self.y[0], self.y[-1])
        ax.set_xlabel(self._axis_label(self.xname))
        ax.set_ylabel(self._axis_label(self.yname))
        changed = self.info.get("changed", {})
        changed = "" if not changed else "; " + ", ".join(f"{k} = {v:g}" for k, v in changed.items())
        ax.set_title(f"Stability of the equilibrium: {self.title}\n(contours: growth rate, "
                     f"solid the fastest, dashed the slowest growing root{changed})", fontsize=9)

    def _draw_conditions(self, ax) -> None:
        which = self.info.get("condition", "")
        names = {2: f"{which} holds", 1: f"spectrally stable outside {which} (gyroscopic stabilisation)",
                 0: "unstable", -1: "boundary: rounding could change the verdict",
                 -2: "marginal: an exact zero root"}
        self._classes(ax, self.codes(), CONDITION_COLORS, names, -2, count=True)
        ax.set_xlim(_edges(np.asarray(self.x), False)[[0, -1]])
        ax.set_ylim(_edges(np.asarray(self.y), False)[[0, -1]])
        ax.set_xlabel(self.xname)
        ax.set_ylabel(self.yname)
        fixed = ", ".join(f"{k} = {v:.3g}" for k, v in self.info.get("base", {}).items() if k not in ("theta", "chi"))
        ax.set_title(f"{self.title}: {which} against the spectrum\n({fixed})", fontsize=8)

    def _draw_errors(self, ax) -> None:
        i = self.info
        v = np.where(self.values > 0, self.values, np.nan)
        lv = np.log10(v)
        ex, ey = _edges(np.asarray(self.x), False), _edges(np.asarray(self.y), False)
        mesh = ax.pcolormesh(ex, ey, lv, cmap="viridis", shading="flat")
        ax.figure.colorbar(mesh, ax=ax, label=f"log10 {i['measure']}")
        bad = ~np.isfinite(self.values)
        if bad.any():
            ax.pcolormesh(ex, ey, np.where(bad, 1.0, np.nan), cmap="Greys", vmin=0, vmax=2, shading="flat")
        tol = i["tol"]
        if np.isfinite(lv).sum() > 3 and np.nanmin(lv) < np.log10(tol) < np.nanmax(lv):
            cs = ax.contour(self.x, self.y, lv, levels=[np.log10(tol)], colors="r", linewidths=2)
            ax.clabel(cs, fmt={cs.levels[0]: f"tol {tol:g}"}, fontsize=8)
        ax.set_xlabel(self._axis_label(self.xname))
        ax.set_ylabel(self._axis_label(self.yname))
        extra = ", ".join(f"{k} = {v:g}" for k, v in i.get("changed", {}).items())
        ax.set_title(f"{self.model}: {i['level']} against {i['against']}" + (f"\n({extra})" if extra else ""),
                     fontsize=10)
