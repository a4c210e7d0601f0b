"""A motion of the image point by one level of the precession hierarchy (gimbal_precession)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _more_rows, _pyplot, _shown_rows, save_figure


@dataclass
class ImagePointMotion(Result):
    """The image point x, y (22) and the gimbal angles alpha, beta (rad) at the times t, and
    the rotor momentum H (N m s), computed by one level (`full`, `rigorous`, `image`,
    `small`, `elementary`). `params` are the parameter values by their command-line names."""

    model: str
    level: str
    params: dict
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    H: np.ndarray
    seconds: float = 0.0  # CPU time of the integration
    changed: dict = field(default_factory=dict)
    # a time-varying base: its description (the command line's {u_NAME: [{amplitude,
    # frequency, phase}, ...]} about the parameters' constants); None for a constant base
    base_rate: dict | None = None

    def to_dict(self) -> dict:
        """The `gyro simulate gimbal_precession --json` document (its keys are the contract;
        H and seconds are added)."""
        out = {"model": self.model, "level": self.level, "params": self.params, "t": self.t.tolist(),
               "x": self.x.tolist(), "y": self.y.tolist(), "alpha": self.alpha.tolist(),
               "beta": self.beta.tolist(), "H": self.H.tolist(), "seconds": self.seconds}
        if self.base_rate is not None:
            out["base_rate"] = self.base_rate
        return out

    def table(self) -> str:
        lines = [f"gimbal gyroscope on a rotating base ({self.model}), level {self.level}"]
        for name, terms in (self.base_rate or {}).items():
            waves = " + ".join(f"{o['amplitude']:g} sin({o['frequency']:g} t + {o['phase']:g})" for o in terms)
            lines.append(f"base rate {name}(t) = {name} + {waves} rad/s")
        lines.append(f"{'t [s]':>12} {'x':>16} {'y':>16} {'alpha [rad]':>16} {'beta [rad]':>16} {'H [N m s]':>14}")
        for i in _shown_rows(len(self.t)):
            lines.append(f"{self.t[i]:>12.6g} {self.x[i]:>16.10g} {self.y[i]:>16.10g} {self.alpha[i]:>16.10g} "
                         f"{self.beta[i]:>16.10g} {self.H[i]:>14.9g}")
        return "\n".join(lines + _more_rows(len(self.t)))


    def plot(self, out) -> None:
        """The image point's path in the picture plane, and x, y against t; written whole or
        not at all."""
        plt = _pyplot()
        fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
        ax0.plot(self.x, self.y, lw=1)
        ax0.plot(self.x[:1], self.y[:1], "o", ms=4, label="t = 0")
        ax0.set_xlabel("x"), ax0.set_ylabel("y"), ax0.set_aspect("equal", adjustable="datalim")
        ax0.set_title("image point in the picture plane z = 1")
        ax0.legend(loc="best", fontsize=8)
        ax1.plot(self.t, self.x, lw=1, label="x")
        ax1.plot(self.t, self.y, lw=1, label="y")
        ax1.set_xlabel("t [s]"), ax1.legend(fontsize=8)
        ax1.set_title(f"level {self.level}")
        save_figure(fig, out)
        plt.close(fig)
