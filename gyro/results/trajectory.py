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


@dataclass
class CoordinateMotion:
    """A motion of any model from its reference (gyro/analyses/motion.py): every coordinate
    and its rate at the times t, in the model's units, by one integrator."""

    model: str
    title: str
    method: str
    t: np.ndarray
    coordinates: list
    units: list
    q: np.ndarray  # (times, coordinates), absolute values
    qd: np.ndarray
    params: dict
    perturb: dict
    equilibrium: dict
    seconds: float = 0.0

    def to_dict(self) -> dict:
        """The `gyro simulate --json` document of the generic motion: `t`, one list per
        coordinate under its name, `method`, and `rates` ({NAME_d: list}), `coordinates`,
        `units`, `params`, `perturb`, `equilibrium`, `model`, `seconds`."""
        out = {"model": self.model, "method": self.method, "params": self.params, "perturb": self.perturb,
               "equilibrium": self.equilibrium, "coordinates": self.coordinates,
               "units": dict(zip(self.coordinates, self.units)), "t": self.t.tolist(),
               "rates": {f"{c}_d": self.qd[:, i].tolist() for i, c in enumerate(self.coordinates)},
               "seconds": self.seconds}
        for i, c in enumerate(self.coordinates):
            out.setdefault(c, self.q[:, i].tolist())
        return out

    def table(self) -> str:
        head = f"{'t [s]':>12}" + "".join(f"{c + (' [' + u + ']' if u else ''):>16}"
                                          for c, u in zip(self.coordinates, self.units))
        lines = [f"{self.title} ({self.model}), method {self.method}, from the reference"
                 + (" with " + ", ".join(f"{k} {v:+g}" for k, v in self.perturb.items()) if self.perturb else ""),
                 head]
        for i in _shown_rows(len(self.t)):
            lines.append(f"{self.t[i]:>12.6g}" + "".join(f"{x:>16.9g}" for x in self.q[i]))
        return "\n".join(lines + _more_rows(len(self.t)))

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path) -> "CoordinateMotion":
        return _load_npz(cls, path)

    def plot(self, out) -> None:
        """Each coordinate against t, written whole or not at all."""
        plt = _pyplot()
        n = len(self.coordinates)
        fig, axes = plt.subplots(n, 1, sharex=True, figsize=(7, min(1.6 * n + 1, 14)), squeeze=False)
        for ax, name, unit, y in zip(axes[:, 0], self.coordinates, self.units, self.q.T):
            ax.plot(self.t, y, lw=1)
            ax.set_ylabel(f"{name} [{unit}]" if unit else name, fontsize=8)
        axes[0, 0].set_title(f"{self.title}, {self.method}", fontsize=9)
        axes[-1, 0].set_xlabel("t [s]")
        fig.tight_layout()
        save_figure(fig, out)
        plt.close(fig)
