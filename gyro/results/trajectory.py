"""A motion of the gimbal gyroscope in time (closed form or integrator)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gyro.results._io import _load_npz, _more_rows, _pyplot, _save_npz, _shown_rows, save_figure


@dataclass
class Trajectory:
    """A motion of the gimbal gyroscope: theta, psi, phi at the times t, the method, the
    integrals at t = 0 and, from the closed form, the motion type and the period of theta."""

    model: str
    title: str
    method: str
    t: np.ndarray
    theta: np.ndarray
    psi: np.ndarray
    phi: np.ndarray
    integrals: dict
    motion_type: str | None = None
    period: float | None = None

    def to_dict(self) -> dict:
        """The `gyro simulate --json` document (its keys are the contract)."""
        return {"t": self.t.tolist(), "theta": self.theta.tolist(), "psi": self.psi.tolist(),
                "phi": self.phi.tolist(), "method": self.method, "integrals": self.integrals}

    def table(self) -> str:
        import math

        I, t = self.integrals, self.t
        lines = [f"{self.title} ({self.model}), method {self.method}",
                 f"integrals at t = 0: H = {I['H']:.9g}, L = {I['L']:.9g}, M = {I['M']:.9g}"]
        if self.motion_type is not None:
            period = ("none (stationary or on the separatrix)" if not math.isfinite(self.period)
                      else f"{self.period:.9g} s")
            lines.append(f"motion: {self.motion_type}; period of theta {period}")
        lines.append(f"{'t [s]':>14} {'theta [rad]':>18} {'psi [rad]':>18} {'phi [rad]':>18}")
        for i in _shown_rows(len(t)):
            lines.append(f"{t[i]:>14.6g} {self.theta[i]:>18.12g} {self.psi[i]:>18.12g} {self.phi[i]:>18.12g}")
        return "\n".join(lines + _more_rows(len(t)))

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "Trajectory":
        return _load_npz(cls, path)

    def plot(self, out) -> None:
        """theta, psi, phi against t, written whole or not at all."""
        plt = _pyplot()
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 6))
        for ax, y, name in zip(axes, (self.theta, self.psi, self.phi), ("theta", "psi", "phi")):
            ax.plot(self.t, y, lw=1)
            ax.set_ylabel(f"{name} [rad]")
        axes[0].set_title(f"gimbal gyroscope, {self.method}")
        axes[-1].set_xlabel("t [s]")
        fig.tight_layout()
        save_figure(fig, out)
        plt.close(fig)
