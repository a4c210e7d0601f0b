"""The gyrohorizoncompass: a motion in its angles (its stability by conditions is any model's:
gyro/results/conditions.py)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _more_rows, _pyplot, _shown_rows, save_figure


@dataclass
class AngleTrajectory(Result):
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


    @classmethod
    def _loaded(cls, tr) -> "AngleTrajectory":
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
