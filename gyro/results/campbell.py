"""The Campbell diagram: frequencies against spin, the formulas overlaid with their errors."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import _pyplot, _save_npz, save_figure
from gyro.results.spectrum import Spectrum, classify, nearest_error

FORMULA_BAD = 0.01  # a formula errs by more than 1 %: shaded in the Campbell diagram


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
