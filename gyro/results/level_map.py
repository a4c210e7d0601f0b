"""The error of one level of a hierarchy against a more exact one over two parameters."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _edges, _finite_or_none, _pyplot, save_figure


@dataclass
class LevelMap(Result):
    """values[i, j]: the relative error of `level` against `against` at y[i], x[j] (what the
    error measures: `measure`); NaN where it could not be computed (then `failed` says why)."""

    model: str
    level: str
    against: str
    xname: str
    yname: str
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray
    tol: float
    measure: str
    units: dict = field(default_factory=dict)
    changed: dict = field(default_factory=dict)
    failed: dict = field(default_factory=dict)  # "i,j" -> reason
    seconds: float = 0.0

    def to_dict(self) -> dict:
        """The `gyro level-map --json` document: x, y, values, level, against, tol (the
        contract), and model, x_name, y_name, measure, changed, failed, seconds."""
        return {"model": self.model, "level": self.level, "against": self.against, "tol": self.tol,
                "x_name": self.xname, "y_name": self.yname, "x": self.x.tolist(), "y": self.y.tolist(),
                "values": _finite_or_none(self.values), "measure": self.measure, "changed": self.changed,
                "failed": self.failed, "seconds": self.seconds}

    def within(self) -> np.ndarray:
        """True where the level meets the tolerance (NaN: not)."""
        return np.where(np.isfinite(self.values), self.values <= self.tol, False)

    def summary(self, out) -> str:
        n, k = self.values.size, int(self.within().sum())
        return (f"gyro: wrote {out} ({k} of {n} points within tol {self.tol:g}: {self.level} against "
                f"{self.against}; largest error {np.nanmax(self.values):.3g})")

    def table(self) -> str:
        head = f"{self.yname} \\ {self.xname}"
        lines = [f"{self.model}: {self.measure} of {self.level} against {self.against} (tol {self.tol:g})",
                 f"{head:>22} " + " ".join(f"{v:>10.4g}" for v in self.x)]
        for i, yv in enumerate(self.y):
            lines.append(f"{yv:>22.6g} " + " ".join(f"{v:>10.3g}" for v in self.values[i]))
        return "\n".join(lines)


    def plot(self, out) -> None:
        """log10 of the error as colour, the contour at tol as a thick line (where the level
        stops being enough), cells that could not be computed grey."""
        plt = _pyplot()
        fig, ax = plt.subplots(figsize=(7.2, 5.6), layout="constrained")
        v = np.where(self.values > 0, self.values, np.nan)
        lv = np.log10(v)
        mesh = ax.pcolormesh(_edges(self.x, False), _edges(self.y, False), lv, cmap="viridis", shading="flat")
        fig.colorbar(mesh, ax=ax, label=f"log10 {self.measure}")
        bad = ~np.isfinite(self.values)
        if bad.any():
            ax.pcolormesh(_edges(self.x, False), _edges(self.y, False), np.where(bad, 1.0, np.nan),
                          cmap="Greys", vmin=0, vmax=2, shading="flat")
        if np.isfinite(lv).sum() > 3 and np.nanmin(lv) < np.log10(self.tol) < np.nanmax(lv):
            cs = ax.contour(self.x, self.y, lv, levels=[np.log10(self.tol)], colors="r", linewidths=2)
            ax.clabel(cs, fmt={cs.levels[0]: f"tol {self.tol:g}"}, fontsize=8)
        ux, uy = self.units.get(self.xname, ""), self.units.get(self.yname, "")
        ax.set_xlabel(f"{self.xname} [{ux}]" if ux else self.xname)
        ax.set_ylabel(f"{self.yname} [{uy}]" if uy else self.yname)
        extra = ", ".join(f"{k} = {v:g}" for k, v in self.changed.items())
        ax.set_title(f"{self.model}: {self.level} against {self.against}" + (f"\n({extra})" if extra else ""),
                     fontsize=10)
        save_figure(fig, out)
        plt.close(fig)
