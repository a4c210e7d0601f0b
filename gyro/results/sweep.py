"""Natural frequencies against one parameter."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gyro.results._io import _finite_or_none, _pyplot, _save_npz, save_figure
from gyro.results.spectrum import Spectrum, classify


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
        rest = "".join(f", {int(np.sum(c == k))} {k}" for k in ("boundary", "unknown", "failed") if np.any(c == k))
        return (f"gyro: wrote {out} ({len(self.x)} values of {self.xname}: "
                f"{int(np.sum(c == 'stable'))} stable, {int(np.sum(c == 'marginal'))} marginal, "
                f"{int(np.sum(c == 'unstable'))} unstable{rest})")

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
