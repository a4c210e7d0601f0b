"""The stability of an equilibrium by any model's declared sufficient conditions against its
spectrum (gyro/analyses/conditions.py): one set's verdict (the map of the regions over two
parameters is a condition Map, gyro/results/map.py)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result


@dataclass
class EquilibriumStability(Result):
    """The equilibrium of one parameter set: its conditions (margins, > 0 when satisfied),
    whether the sufficient one holds, and the spectrum of the linearisation (any model that
    declares conditions: gyro/analyses/conditions.py)."""

    model: str
    title: str
    params: dict  # the declared names
    equilibrium: dict
    conditions: dict = field(default_factory=dict)  # name -> margin
    sufficient: bool = False
    orbit: bool = False
    eigenvalues: np.ndarray | None = None  # (2n, 2): re, im
    spectrally_stable: bool = False
    verdict: str = "stable"  # gyro.results.verdict.LABELS
    boundary_reason: str | None = None  # one line where the verdict is 'boundary' (or 'marginal')
    margin_bounds: dict = field(default_factory=dict)  # name -> rounding bound of the margin
    radii: np.ndarray | None = None  # (2n,) error radius of each eigenvalue
    # {another name: the declared one} (lambda for lam): the JSON's params carry both, as
    # they carried lambda before the commands printed the declared name
    aliases: dict = field(default_factory=dict)
    # what the model's system adds: JSON keys after `equilibrium` (the gyrohorizoncompass's
    # theta and chi), the lines the table prints after the parameters (the equilibrium and
    # those), and the name of the sufficient condition in force
    extra: dict = field(default_factory=dict)
    lines: list = field(default_factory=list)
    condition: str = ""

    NO_PLOT = ("one set's margins and eigenvalues: `gyro stability` lists them (the condition Map draws the "
               "regions over two parameters)")

    @property
    def boundary(self) -> bool:
        """Rounding could change the verdict: neither stable nor stabilised nor unstable."""
        return self.verdict == "boundary"

    def to_dict(self) -> dict:
        """The `gyro stability --json` document (its keys are the contract)."""
        params = dict(self.params) | {a: self.params[n] for a, n in self.aliases.items() if n in self.params}
        return {"model": self.model, "params": params, "equilibrium": dict(self.equilibrium),
                **{k: float(v) for k, v in self.extra.items()},
                "conditions": {k: float(v) for k, v in self.conditions.items()},
                "sufficient": bool(self.sufficient),
                "eigenvalues": [[float(a), float(b)] for a, b in np.asarray(self.eigenvalues)],
                "spectrally_stable": bool(self.spectrally_stable),
                "boundary": self.boundary, "boundary_reason": self.boundary_reason if self.boundary else None,
                "verdict": self.verdict,
                "margin_bounds": {k: float(v) for k, v in self.margin_bounds.items()}}

    @property
    def gyroscopically_stabilised(self) -> bool:
        return self.spectrally_stable and not self.sufficient and not self.boundary

    def table(self) -> str:
        lines = [f"{self.title} ({self.model})",
                 "parameters: " + ", ".join(f"{k} = {v:.6g}" for k, v in self.params.items()),
                 *self.lines,
                 f"{'condition (margin > 0 when it holds)':<48} {'margin':>14}"]
        for k, v in self.conditions.items():
            b = self.margin_bounds.get(k, 0.0)
            lines.append(f"{k:<48} {v:>14.6g}" + ("" if v > b else "  within rounding of 0" if v >= -b else "  fails"))
        lines.append(f"{'eigenvalues':<22} {'re':>16} {'im':>16}")
        for re, im in np.asarray(self.eigenvalues):
            lines.append(f"{'':<22} {re:>16.6g} {im:>16.9g}")
        if self.boundary:
            lines.append(f"boundary: rounding could change the verdict ({self.boundary_reason})")
            return "\n".join(lines)
        if self.verdict == "marginal":
            lines.append(f"marginal: {self.boundary_reason}")
            return "\n".join(lines)
        verdict = ("stable: the sufficient condition holds" if self.sufficient else
                   "spectrally stable outside the sufficient condition (gyroscopic stabilisation)"
                   if self.spectrally_stable else "unstable")
        lines.append(f"sufficient {self.condition}: {'yes' if self.sufficient else 'no'}; "
                     f"spectrally stable: {'yes' if self.spectrally_stable else 'no'}; {verdict}")
        return "\n".join(lines)


    @classmethod
    def _loaded(cls, s) -> "EquilibriumStability":
        s.eigenvalues = np.asarray(s.eigenvalues, float)
        s.radii = None if s.radii is None else np.asarray(s.radii, float)
        return s
