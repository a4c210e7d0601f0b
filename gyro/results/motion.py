"""A motion in time: named series sampled at the times t, from whatever computed it (the
generic motion of any model from its reference, gyro/analyses/motion.py; a motion a model
declares of its own: the gimbal gyroscope's closed form, the gyrohorizoncompass's projected
integrator, a level of gimbal_precession). What belongs to the producer is data here: the
series' names, units and descriptions, the document's keys in their order, the lines above
the table's columns and the columns' formats."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _canvas, _more_rows, _shown_rows, cell


@dataclass
class Motion(Result):
    """`values[:, j]` is the series `names[j]` (unit `units[j]`, `descriptions[j]` one line)
    at the times `t` (s), computed by `method`. A series reads as an attribute or an item
    (`m.theta`, `m["theta"]`), and so does an entry of `info`, what the producer adds (the
    parameters, the integrals, the level, the CPU seconds, ...).

    - `to_dict()`: the `gyro simulate --json` document, its keys `keys` in order: `t`,
      `method`, `model`, a key of `groups` ({series: list} of the series it names, as
      `rates`), a key of `info`, or a series (its list);
    - `table()`: `heading` (the producer's lines), then the series `shown` (default all) as
      columns formatted by `formats` (a format spec per series and for "t", as '>18.12g'),
      joined by `gap` (a value that is not finite as 'none'); up to 21 rows, else 11 spread
      evenly;
    - `plot(out)`: one panel a series against t (an `invariants` one as its change from
      t = 0), after the path of the pair `path` (as the image point's x, y) where given."""

    model: str
    title: str
    method: str
    t: np.ndarray
    names: list
    values: np.ndarray  # (times, series)
    units: list
    descriptions: list = field(default_factory=list)
    info: dict = field(default_factory=dict)
    keys: list = field(default_factory=list)
    groups: dict = field(default_factory=dict)
    heading: list = field(default_factory=list)
    shown: list = field(default_factory=list)
    formats: dict = field(default_factory=dict)
    gap: str = " "
    path: list = field(default_factory=list)
    invariants: list = field(default_factory=list)

    def __getattr__(self, name):
        d = self.__dict__  # not through getattr: an instance half-built (unpickling) has none yet
        if "names" in d and name in d["names"]:
            return d["values"][:, d["names"].index(name)]
        if "info" in d and name in d["info"]:
            return d["info"][name]
        raise AttributeError(name)

    def __getitem__(self, name):
        return self.__getattr__(name)

    def block(self, names) -> np.ndarray:
        """(times, len(names)): the series `names`, in that order."""
        return self.values[:, [self.names.index(n) for n in names]]

    def to_dict(self) -> dict:
        """The `gyro simulate --json` document (its keys, `keys`, are the contract)."""
        out = {}
        for key in self.keys or ["t", *self.names, "method"]:
            if key == "t":
                out[key] = np.asarray(self.t).tolist()
            elif key in ("method", "model"):
                out[key] = getattr(self, key)
            elif key in self.groups:
                out[key] = {n: self[n].tolist() for n in self.groups[key]}
            elif key in self.info:
                out[key] = self.info[key]
            else:
                out[key] = self.values[:, self.names.index(key)].tolist()
        return out

    def _label(self, name: str) -> str:
        unit = self.units[self.names.index(name)]
        return f"{name} [{unit}]" if unit else name

    def table(self) -> str:
        """The `gyro simulate` text."""
        shown = self.shown or self.names
        spec = lambda key: self.formats.get(key, ">18.12g" if key != "t" else ">14.6g")  # noqa: E731
        width = lambda key: spec(key).split(".")[0]  # noqa: E731
        lines = list(self.heading) or [f"{self.title} ({self.model}), method {self.method}"]
        lines.append(f"{'t [s]':{width('t')}}" + "".join(f"{self.gap}{self._label(n):{width(n)}}" for n in shown))
        cols = self.block(shown)
        for i in _shown_rows(len(self.t)):
            lines.append(cell(self.t[i], spec("t")) + "".join(self.gap + cell(v, spec(n)) for n, v in zip(shown, cols[i])))
        return "\n".join(lines + _more_rows(len(self.t)))

    def plot(self, out):
        """The path of `path` in its plane (where given), then each series against t, an
        invariant as its change from t = 0; into `out`, a file (written whole or not at
        all) or a matplotlib Figure."""
        names = [n for n in self.names if n not in self.path or not self.path]
        n = len(names) + (1 if self.path else 0)
        with _canvas(out, figsize=(7, min(1.6 * n + 1, 14))) as fig:
            axes = fig.subplots(n, 1, squeeze=False)[:, 0]
            if self.path:
                a, b = self.path
                axes[0].plot(self[a], self[b], lw=1)
                axes[0].plot(self[a][:1], self[b][:1], "o", ms=4, label="t = 0")
                axes[0].set_xlabel(self._label(a), fontsize=8), axes[0].set_ylabel(self._label(b), fontsize=8)
                axes[0].legend(loc="best", fontsize=8)
                axes = axes[1:]
            for ax, name in zip(axes, names):
                y = self[name]
                if name in self.invariants:
                    ax.plot(self.t, y - y[0], lw=1)
                    ax.set_ylabel(f"{name} - {name}(0)", fontsize=8)
                else:
                    ax.plot(self.t, y, lw=1)
                    ax.set_ylabel(self._label(name), fontsize=8)
                if ax is not axes[-1]:
                    ax.tick_params(labelbottom=False)
            fig.axes[0].set_title(f"{self.title}, {self.method}", fontsize=9)
            axes[-1].set_xlabel("t [s]")
