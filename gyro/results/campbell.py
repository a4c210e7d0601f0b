"""The Campbell diagram: frequencies against spin, the formulas overlaid with their errors."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from gyro.results._io import _pyplot, _save_npz, save_figure
from gyro.results.spectrum import Spectrum, classify, nearest_error

FORMULA_BAD = 0.01  # a formula errs by more than 1 %: shaded in the Campbell diagram


@dataclass(frozen=True)
class Crossing:
    """Where the harmonic line k x spin rate meets the damped frequency of a tracked mode
    (1-based): a critical speed, at the swept parameter's `value` and `spin_rate` (rad/s);
    `frequency` = Im(lambda) there (rad/s)."""

    k: int
    mode: int
    value: float
    spin_rate: float
    frequency: float


@dataclass
class CampbellDiagram:
    """Frequencies against the spin rate (Omega: for the torsion gyrocompass omega_c = H/C of
    (2.4), the rotor's own rate): the exact operator (default method, `exact` ascending per
    point; `tracked` the same roots with each mode in its own column, followed by its
    eigenvector), whirl, harmonic lines and their crossings, and, where the model has them,
    the formulas with each one's relative error."""

    model: str
    title: str
    Omega: np.ndarray  # (points,) the spin rate, rad/s
    exact: Spectrum
    formulas: Spectrum | None
    values: dict  # the set the sweep scales
    Omega_example: float  # the paper example's spin rate, marked
    changed: dict = field(default_factory=dict)  # the parameters that differ from the defaults
    spin: str = ""  # the swept parameter
    values_swept: np.ndarray | None = None  # (points,) its values, in its unit
    tracked: Spectrum | None = None  # modes tracked by MAC (frequencies, growth, modes)
    whirl: np.ndarray | None = None  # (points, modes) 'forward', 'backward', 'mixed' or None
    harmonics: list = field(default_factory=list)  # the k of the lines k x spin rate
    crossings: list = field(default_factory=list)  # Crossing, by value
    rate_label: str = "spin rate [rad/s]"
    log: bool = True  # log axes (a geometric sweep)

    def to_dict(self) -> dict:
        """The `gyro campbell --json` document (its keys are the contract)."""
        t = self.tracked
        num = lambda a: [[float(x) if np.isfinite(x) else None for x in row] for row in a]  # noqa: E731
        return {"model": self.model, "spin": self.spin,
                "values": [float(v) for v in self.values_swept],
                "spin_rate": [float(v) for v in self.Omega],
                "frequencies": num(t.frequencies), "growth": num(t.growth),
                "damping_ratio": num(t.damping_ratio()), "log_dec": num(t.log_dec()),
                "whirl": [list(row) for row in self.whirl],
                "crossings": [asdict(c) for c in self.crossings],
                "harmonics": list(self.harmonics), "params": self.values}

    def crossings_table(self) -> str:
        if not self.crossings:
            return f"no crossing of the lines {', '.join(f'{k}x' for k in self.harmonics)} with a mode in the sweep"
        lines = [f"{'k':>3} {'mode':>5} {self.spin:>14} {'spin rate [rad/s]':>18} {'frequency [rad/s]':>18}"]
        for c in self.crossings:
            lines.append(f"{c.k:>3} {c.mode:>5} {c.value:>14.9g} {c.spin_rate:>18.9g} {c.frequency:>18.9g}")
        return "\n".join(lines)

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
        what = (f", {self.shaded_fraction:.0%} of the sweep has a formula off by more than 1%"
                if self.formulas is not None else "")
        if self.crossings:
            what += f", {len(self.crossings)} critical speed{'s' if len(self.crossings) > 1 else ''}"
        return (f"gyro: wrote {out} ({len(self.Omega)} spins{what}" + (f"; {failed} spins could not be computed"
                                                                       if failed else "") + ")")

    def plot(self, out) -> None:
        """Frequencies against spin (modes numbered at the right), the formulas dashed; below,
        each formula's relative error against spin on a log scale with the 1 % line."""
        plt = _pyplot()
        W = self.Omega
        panels = 2 if self.formulas is not None else 1
        fig, axes = plt.subplots(panels, 1, figsize=(8, 9 if panels == 2 else 6), sharex=True,
                                 layout="constrained", height_ratios=[3, 2][:panels], squeeze=False)
        ax = axes[0, 0]
        ex = self.exact.frequencies if self.tracked is None else self.tracked.frequencies
        for j in range(ex.shape[1]):
            ax.plot(W, ex[:, j], color="k", lw=1.4, label="exact operator (default method)" if j == 0 else None)
            if np.isfinite(ex[-1, j]):
                ax.annotate(f"{j + 1}", (W[-1], ex[-1, j]), xytext=(3, 0), textcoords="offset points",
                            fontsize=7, va="center")
        self._marks(ax, plt)
        if self.log:
            ax.set_xscale("log")
            ax.set_yscale("log")
        elif self.harmonics and np.any(np.isfinite(ex)):  # the lines would squeeze the modes
            ax.set_ylim(0, 1.3 * float(np.nanmax(ex)))
        if self.formulas is not None:
            fo, err = self.formulas.frequencies, self.formula_error
            with np.errstate(all="ignore"):
                near = np.take_along_axis(ex, np.argmin(np.abs(fo[:, :, None] / ex[:, None, :] - 1), axis=2), 1)
            for j in range(fo.shape[1]):
                ax.plot(W, fo[:, j], color="tab:blue", lw=1.0, ls="--",
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
            eax.set_xlabel(self.rate_label)
            eax.grid(True, which="both", alpha=0.25)
            eax.legend(fontsize=6.5, ncol=4, loc="best")
            eax.axvline(self.Omega_example, color="0.5", lw=0.8, ls=":")
        else:
            ax.set_xlabel(self.rate_label)
        ax.axvline(self.Omega_example, color="0.5", lw=0.8, ls=":", label="the model's default")
        ax.set_ylabel("natural frequency omega [rad/s]")
        changed = "" if not self.changed else "\n(" + ", ".join(f"{k} = {v:g}" for k, v in self.changed.items()) + ")"
        ax.set_title(f"Campbell diagram: {self.title}{changed}", fontsize=10)
        ax.grid(True, which="both", alpha=0.25)
        ax.legend(fontsize=8, loc="upper left")
        save_figure(fig, out)
        plt.close(fig)

    def _marks(self, ax, plt) -> None:
        """Whirl by marker shape (forward ^, backward v, mixed o), the damping ratio by colour,
        the harmonic lines k x spin rate dashed, and their crossings circled."""
        t, W = self.tracked, self.Omega
        if t is None:
            return
        zeta = t.damping_ratio()
        damped = t.damped and np.any(np.nan_to_num(np.abs(zeta)) > 0)
        shapes = {"forward": "^", "backward": "v", "mixed": "o"}
        every = max(1, len(W) // 40)  # markers at about 40 spins
        sc = None
        for kind, marker in shapes.items():
            sel = (self.whirl == kind) if self.whirl is not None else np.zeros(t.frequencies.shape, bool)
            sel[np.arange(len(W)) % every != 0] = False
            ii, jj = np.nonzero(sel)
            if not ii.size:
                continue
            c = zeta[ii, jj] if damped else "k"
            sc = ax.scatter(W[ii], t.frequencies[ii, jj], c=c, marker=marker, s=22, cmap="viridis",
                            vmin=float(np.nanmin(zeta)) if damped else None,
                            vmax=float(np.nanmax(zeta)) if damped else None, zorder=3,
                            edgecolors="none", label=f"{kind} whirl")
        if damped and sc is not None:
            plt.colorbar(sc, ax=ax, label="damping ratio zeta", shrink=0.8)
        for k in self.harmonics:
            ax.plot(W, k * W, color="tab:orange", lw=1.0, ls="--")
            ax.annotate(f"{k}x", (W[-1], k * W[-1]), xytext=(3, 0), textcoords="offset points",
                        fontsize=7, color="tab:orange", va="center")
        if self.crossings:
            ax.scatter([c.spin_rate for c in self.crossings], [c.frequency for c in self.crossings],
                       s=70, facecolors="none", edgecolors="tab:red", lw=1.4, zorder=4,
                       label="critical speeds (crossings)")
        if self.harmonics:
            ax.plot([], [], color="tab:orange", lw=1.0, ls="--", label="k x spin rate")

    def save(self, path) -> None:
        _save_npz(self, path)
