"""Sensitivities of the natural frequencies to the parameters, and a tornado chart of them."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gyro.results._io import Result, _finish, mode_panels
from gyro.results.spectrum import Spectrum


def _numbers(a) -> list:
    return [[float(v) if np.isfinite(v) else None for v in row] for row in a]


@dataclass
class Sensitivities(Result):
    """d omega_i / d p_j over a batch: `d` (sets, modes, parameters) in rad/s per unit of
    the parameter (phi: per degree), NaN where `double` (sets, modes) says the root is
    double or nearly double (no derivative) or could not be computed."""

    model: str
    param_names: list
    params: np.ndarray  # (sets, parameters)
    spectrum: Spectrum
    d: np.ndarray
    double: np.ndarray

    @property
    def relative(self) -> np.ndarray:
        """(p_j / omega_i) d omega_i / d p_j: the percent change of omega_i per percent of p_j."""
        with np.errstate(all="ignore"):
            return self.d * self.params[:, None, :] / self.spectrum.frequencies[:, :, None]

    def to_dict(self, k: int = 0) -> dict:
        """The keys `gyro frequencies --sensitivities` adds to its JSON (set k): for each
        frequency a list over the parameters in `gyro params` order, null for a double root."""
        return {"sensitivities": _numbers(self.d[k]), "relative_sensitivities": _numbers(self.relative[k]),
                "sensitivity_parameters": list(self.param_names),
                "double_root": [bool(b) for b in self.double[k]]}

    def table(self, k: int = 0, top: int = 3) -> str:
        """Per frequency, the parameters that move it most (relative sensitivity)."""
        rel = self.relative[k]
        lines = ["relative sensitivities (p/omega) d omega/d p, the largest three per frequency:"]
        # a root without an error bound (the method cannot tell) leaves every root's distance
        # to it unknown: no derivative, and not because the roots are known to be double
        unbounded = not np.all(np.isfinite(self.spectrum.error_estimate[k]))
        for i, row in enumerate(rel, 1):
            if self.double[k, i - 1] or not np.any(np.isfinite(row)):
                why = ("a root's error is unbounded (try --method default)" if unbounded
                       else "a double or nearly double root")
                lines.append(f"{i:>4}   {why}: no derivative")
                continue
            order = np.argsort(-np.abs(np.where(np.isfinite(row), row, 0.0)))[:top]
            lines.append(f"{i:>4}   " + "   ".join(f"{self.param_names[j]:>6} {row[j]:+.4f}" for j in order))
        return "\n".join(lines)

    def plot(self, out, k: int = 0, modes=None, top: int = 8, title: str = "") -> None:
        """A tornado chart of set k: per frequency, the relative sensitivities of the `top`
        parameters that move it most, largest at the top (into a file or a Figure)."""
        rel = self.relative[k]
        modes = list(range(rel.shape[0])) if modes is None else list(modes)
        fig, axes = mode_panels(out, len(modes), 2.6)
        for ax, i in zip(axes.flat, modes):
            w = self.spectrum.frequencies[k, i]
            ax.set_title(f"omega{i + 1} = {w:.5g} rad/s", fontsize=9)
            row = rel[i]
            if self.double[k, i] or not np.any(np.isfinite(row)):
                ax.text(0.5, 0.5, "double root:\nno derivative", ha="center", va="center", transform=ax.transAxes)
                ax.set_yticks([])
                continue
            order = np.argsort(-np.abs(np.where(np.isfinite(row), row, 0.0)))[:top][::-1]
            vals = row[order]
            ax.barh(range(len(order)), vals, color=np.where(vals > 0, "tab:red", "tab:blue"))
            ax.set_yticks(range(len(order)), [self.param_names[j] for j in order], fontsize=8)
            ax.axvline(0, color="k", lw=0.6)
            ax.tick_params(axis="x", labelsize=7)
            ax.grid(True, axis="x", alpha=0.3)
        fig.supxlabel("relative sensitivity (p / omega) d omega / d p", fontsize=9)
        if title:
            fig.suptitle(title, fontsize=10)
        _finish(fig, out)

