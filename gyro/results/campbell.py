"""The Campbell diagram: frequencies against spin, the formulas overlaid with their errors."""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from gyro.results._io import Result, _finish, _pyplot, _subplots
from gyro.results.spectrum import Spectrum, Stability, classify, nearest_error

FORMULA_BAD = 0.01  # a formula errs by more than 1 %: shaded in the Campbell diagram


@dataclass(frozen=True)
class Crossing(Result):
    """Where the harmonic line k x spin rate meets the damped frequency of a mode: a critical
    speed, at the swept parameter's `value` and `spin_rate` (rad/s); `frequency` =
    Im(lambda) there (rad/s). `mode` numbers the root as `gyro frequencies` does at that
    spin (1-based, ascending |lambda| of that set); `branch` is its tracked column
    (1-based: the column of the diagram's `frequencies`)."""

    k: int
    mode: int
    value: float
    spin_rate: float
    frequency: float
    branch: int = 0

    NO_PLOT = "a point of its Campbell diagram, which draws it"

    def to_dict(self) -> dict:
        return asdict(self)

    def table(self) -> str:
        """Its row of the diagram's table of crossings."""
        return f"{self.k:>3} {self.mode:>5} {self.value:>14.9g} {self.spin_rate:>18.9g} {self.frequency:>18.9g}"


@dataclass
class CampbellDiagram(Result):
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
    crossings: list[Crossing] = field(default_factory=list)
    rate_label: str = "spin rate [rad/s]"
    log: bool = True  # log axes (a geometric sweep)
    # (points, modes): tracked column j at point i is root order[i, j] of `exact` (0-based),
    # the number `gyro frequencies` gives it there, less one; None: the columns are `exact`'s
    order: np.ndarray | None = None

    def stability(self) -> Stability:
        """The verdict at each spin (gyro.results.spectrum.classify of the exact spectrum, as
        `gyro frequencies` states it)."""
        return classify(self.exact)

    def growing(self) -> np.ndarray:
        """(points, modes) bool: the tracked root grows, by the verdict's own test of a root
        (each root classified alone: 'unstable' when it grows beyond its error bound)."""
        t = self.tracked if self.tracked is not None else self.exact
        one = Spectrum(t.method, t.frequencies.reshape(-1, 1), t.growth.reshape(-1, 1),
                       np.asarray(t.error_estimate, float).reshape(-1, 1), growth_known=t.growth_known)
        return (classify(one).label == "unstable").reshape(t.frequencies.shape)

    def numbers(self, i: int) -> np.ndarray:
        """The number `gyro frequencies` gives each tracked column at point i (1-based)."""
        n = self.exact.frequencies.shape[1]
        return (self.order[i] if self.order is not None else np.arange(n)) + 1

    def to_dict(self) -> dict:
        """The `gyro campbell --json` document (its keys are the contract). Per spin, its
        verdict: `stability` (stable, marginal, unstable, boundary, unknown, failed),
        `growing_modes`, `growth_rate` (1/s, of the fastest growing root, 0 when none grows),
        `stability_reason` (null, or why no plain verdict); per spin and tracked column,
        `growing` (that root grows) and `mode_number` (the number `gyro frequencies` gives
        it at that spin)."""
        t = self.tracked
        num = lambda a: [[float(x) if np.isfinite(x) else None for x in row] for row in a]  # noqa: E731
        st = self.stability()
        reason = st.reason if st.reason is not None else [None] * len(st.label)
        return {"model": self.model, "spin": self.spin,
                "values": [float(v) for v in self.values_swept],
                "spin_rate": [float(v) for v in self.Omega],
                "frequencies": num(t.frequencies), "growth": num(t.growth),
                "damping_ratio": num(t.damping_ratio()), "log_dec": num(t.log_dec()),
                "whirl": [list(row) for row in self.whirl],
                "crossings": [asdict(c) for c in self.crossings],
                "harmonics": list(self.harmonics), "params": self.values,
                "stability": [str(c) for c in st.label], "growing_modes": [int(n) for n in st.unstable_roots],
                "growth_rate": [float(g) for g in st.growth_rate], "stability_reason": list(reason),
                "growing": [[bool(b) for b in row] for row in self.growing()],
                "mode_number": [[int(j) for j in self.numbers(i)] for i in range(len(self.Omega))]}

    def table(self) -> str:
        """The `gyro campbell` text after its summary line (with --harmonics): the critical
        speeds, each mode numbered as `gyro frequencies` numbers it at the crossing's spin."""
        if not self.crossings:
            return f"no crossing of the lines {', '.join(f'{k}x' for k in self.harmonics)} with a mode in the sweep"
        lines = [f"{'k':>3} {'mode':>5} {self.spin:>14} {'spin rate [rad/s]':>18} {'frequency [rad/s]':>18}"]
        return "\n".join(lines + [c.table() for c in self.crossings])

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

    def unstable_spins(self) -> str:
        """', unstable at N of M spins, from X rad/s' (the first unstable spin of the sweep),
        and the spins without a plain verdict; '' when every spin has one and none grows."""
        label = self.stability().label
        bad = np.flatnonzero(label == "unstable")
        out = (f", unstable at {bad.size} of {len(label)} spins, from {self.Omega[bad[0]]:.6g} rad/s"
               if bad.size else "")
        for k, what in (("boundary", "on a stability boundary (rounding could change the verdict)"),
                        ("unknown", "without a verdict (a root's error is unbounded)")):
            n = int(np.sum(label == k))
            if n:
                out += f", {n} spin{'s' if n > 1 else ''} {what}"
        return out

    def summary(self, out) -> str:
        failed = int(np.sum(classify(self.exact).label == "failed"))
        what = self.unstable_spins() + (f", {self.shaded_fraction:.0%} of the sweep has a formula off by more than 1%"
                                        if self.formulas is not None else "")
        if self.crossings:
            what += f", {len(self.crossings)} critical speed{'s' if len(self.crossings) > 1 else ''}"
        return (f"gyro: wrote {out} ({len(self.Omega)} spins{what}" + (f"; {failed} spins could not be computed"
                                                                       if failed else "") + ")")

    def plot(self, out) -> None:
        """Frequencies against spin (modes numbered at the right as `gyro frequencies` numbers
        them at the last spin), growing branches in red over red bands of unstable spins (grey
        hatched: spins without a plain verdict), the formulas dashed; below, each formula's
        relative error against spin on a log scale with the 1 % line."""
        plt = _pyplot()
        W = self.Omega
        panels = 2 if self.formulas is not None else 1
        fig, axes = _subplots(out, panels, 1, figsize=(8, 9 if panels == 2 else 6), sharex=True,
                                 layout="constrained", height_ratios=[3, 2][:panels], squeeze=False)
        ax = axes[0, 0]
        ex = self.exact.frequencies if self.tracked is None else self.tracked.frequencies
        number = self.numbers(-1)
        for j in range(ex.shape[1]):
            ax.plot(W, ex[:, j], color="k", lw=1.4, label="exact operator (default method)" if j == 0 else None)
            if np.isfinite(ex[-1, j]):
                ax.annotate(f"{number[j]}", (W[-1], ex[-1, j]), xytext=(3, 0), textcoords="offset points",
                            fontsize=7, va="center")
        self._unstable(ax, ex)
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
        _finish(fig, out)

    def _unstable(self, ax, ex) -> None:
        """Growing branches drawn red and thick (a lone growing point as a red cross); the
        unstable spins shaded red, the spins without a plain verdict (boundary, unknown,
        failed) hatched grey."""
        W, grow = self.Omega, self.growing()
        label = "growing branch (unstable)"
        for j in range(ex.shape[1]):
            g = grow[:, j]
            if not g.any():
                continue
            ax.plot(W, np.where(g, ex[:, j], np.nan), color="tab:red", lw=2.6, zorder=2.5, label=label)
            lone = g & ~np.r_[False, g[:-1]] & ~np.r_[g[1:], False]
            if lone.any():
                ax.scatter(W[lone], ex[lone, j], marker="x", color="tab:red", s=30, zorder=2.5,
                           label=label if not g[~lone].any() else None)
            label = None
        flat = int(np.sum(np.any(grow & ~(ex > 0), axis=0)))
        if flat and self.log:  # omega = 0 has no place on a log axis: said in the figure
            ax.text(0.99, 0.01, f"{flat} growing root{'s' if flat > 1 else ''} without oscillation (omega = 0): "
                    "below the log axis", transform=ax.transAxes, ha="right", va="bottom", color="tab:red",
                    fontsize=8)
        verdict = self.stability().label
        for which, style, text in ((verdict == "unstable", dict(color="tab:red", alpha=0.12), "unstable spins"),
                                   (np.isin(verdict, ("boundary", "unknown", "failed")),
                                    dict(facecolor="none", edgecolor="0.5", hatch="//", alpha=0.5),
                                    "no plain verdict (boundary, unknown or failed)")):
            for i0, i1 in _runs(which):
                if i0 == i1:
                    ax.axvline(W[i0], lw=1.2, color=style.get("color", "0.5"), alpha=0.35, label=text)
                else:
                    ax.axvspan(W[i0], W[i1], lw=0, zorder=0, label=text, **style)
                text = None

    def _marks(self, ax, plt) -> None:
        """Whirl by marker shape (forward ^, backward v, mixed o), the damping ratio by colour,
        the harmonic lines k x spin rate dashed, and their crossings circled."""
        t, W = self.tracked, self.Omega
        if t is None:
            return
        zeta = t.damping_ratio()
        grows, labelled = self.growing().any(), set()
        damped = (t.damped or grows) and np.any(np.nan_to_num(np.abs(zeta)) > 0)
        norm, cmap = None, "viridis"
        if damped and grows:  # a scale through zero: growing roots (zeta < 0) red, decaying blue
            from matplotlib.colors import TwoSlopeNorm

            lo, hi = float(np.nanmin(zeta)), float(np.nanmax(zeta))
            norm, cmap = TwoSlopeNorm(0.0, lo, hi if hi > 0 else -1e-3 * lo), "RdBu"
        shapes = {"forward": "^", "backward": "v", "mixed": "o"}
        every = max(1, len(W) // 40)  # markers at about 40 spins
        sc = None
        growing = self.growing()
        # the growing roots' markers last, over a decaying root at the same frequency
        for top, (kind, marker) in [(g, km) for g in (False, True) for km in shapes.items()]:
            sel = (self.whirl == kind) if self.whirl is not None else np.zeros(t.frequencies.shape, bool)
            sel &= growing if top else ~growing
            sel[np.arange(len(W)) % every != 0] = False
            ii, jj = np.nonzero(sel)
            if not ii.size:
                continue
            c = zeta[ii, jj] if damped else "k"
            sc = ax.scatter(W[ii], t.frequencies[ii, jj], c=c, marker=marker, s=22, cmap=cmap, norm=norm,
                            vmin=float(np.nanmin(zeta)) if damped and norm is None else None,
                            vmax=float(np.nanmax(zeta)) if damped and norm is None else None, zorder=3.5 if top else 3,
                            edgecolors="none", label=f"{kind} whirl" if kind not in labelled else None)
            labelled.add(kind)
        if damped and sc is not None:
            bar = ax.figure.colorbar(sc, ax=ax, label="damping ratio zeta" + (" (< 0: the root grows)" if grows else ""),
                               shrink=0.8)
            if norm is not None:  # ticks on both sides of zero (each side has half the bar)
                bar.set_ticks(np.unique(np.r_[np.linspace(norm.vmin, 0, 3), np.linspace(0, norm.vmax, 4)]))
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


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """The (first, last) indices of each run of True in a 1-d mask."""
    m = np.r_[False, np.asarray(mask, bool), False].astype(int)
    starts, stops = np.flatnonzero(np.diff(m) == 1), np.flatnonzero(np.diff(m) == -1) - 1
    return list(zip(starts.tolist(), stops.tolist()))
