"""The stability of an equilibrium by any model's declared sufficient conditions against its
spectrum (gyro/analyses/conditions.py): one set's verdict, and the map of the regions over
two parameters."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _edges, _pyplot, save_figure


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


@dataclass
class ConditionMap(Result):
    """Over a grid of two axes (arrays (y, x)): 2 where the sufficient condition (the model's
    declared one, gyro/analyses/conditions.py) holds, 1 where the linearisation is spectrally stable outside it
    (gyroscopic stabilisation), 0 where it is unstable."""

    model: str
    title: str
    xname: str
    yname: str
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray  # (y, x) int: 2, 1, 0, BOUNDARY (-1), MARGINAL (-2)
    growth: np.ndarray  # (y, x) largest real part, 1/s, of a certainly unstable point (0 elsewhere)
    orbit: bool = False
    base: dict = field(default_factory=dict)  # the other parameters (declared names)
    boundary: np.ndarray | None = None  # (y, x) bool: rounding could change the verdict
    reasons: np.ndarray | None = None  # (y, x) object: why a point is a boundary (None elsewhere)
    condition: str = ""  # the sufficient condition's name ("(3.6)", "(4.3)" the gyrohorizoncompass's)

    KIND = ("2: {c} holds, 1: spectrally stable outside {c}, 0: unstable, -1: boundary (rounding "
            "could change the verdict), -2: marginal (an exact zero root)")
    BOUNDARY, MARGINAL = -1, -2

    def __post_init__(self):
        if self.boundary is None:
            self.boundary = np.asarray(self.values) == self.BOUNDARY
        self.boundary = np.asarray(self.boundary, bool)

    @property
    def kind(self) -> str:
        return self.KIND.format(c=self.condition)

    def counts(self) -> dict:
        """Points per class; a boundary point counts as none of the others (never stable,
        never stabilised)."""
        v = np.asarray(self.values)
        out = {"sufficient": int(np.sum(v == 2)), "gyroscopic": int(np.sum(v == 1)), "unstable": int(np.sum(v == 0)),
               "boundary": int(np.sum(v == self.BOUNDARY))}
        if np.any(v == self.MARGINAL):
            out["marginal"] = int(np.sum(v == self.MARGINAL))
        return out

    def to_dict(self) -> dict:
        """The `gyro map --json` document (its keys are the contract)."""
        return {"x": {"name": self.xname, "values": np.asarray(self.x).tolist()},
                "y": {"name": self.yname, "values": np.asarray(self.y).tolist()},
                "values": np.asarray(self.values).astype(int).tolist(), "kind": self.kind,
                "boundary": np.asarray(self.boundary, bool).tolist()}

    def summary(self, out) -> str:
        c = self.counts()
        which = self.condition
        extra = f", {c['marginal']} marginal" if "marginal" in c else ""
        return (f"gyro: wrote {out} ({self.values.size} points: {c['sufficient']} where {which} holds, "
                f"{c['gyroscopic']} spectrally stable outside it, {c['unstable']} unstable, "
                f"{c['boundary']} within rounding of a boundary{extra})")


    @classmethod
    def _loaded(cls, m) -> "ConditionMap":
        m.values = np.asarray(m.values, int)
        m.boundary = np.asarray(m.boundary, bool)
        m.reasons = None if m.reasons is None else np.array(m.reasons, dtype=object)
        return m

    def plot(self, out) -> None:
        plt = _pyplot()
        from matplotlib.colors import ListedColormap

        which = self.condition
        colors = ["#7a6fb0", "#222222", "#f2b8b0", "#f3e3a1", "#cfe8cf"]  # codes -2 .. 2
        names = {2: f"{which} holds", 1: f"spectrally stable outside {which} (gyroscopic stabilisation)",
                 0: "unstable", -1: "boundary: rounding could change the verdict",
                 -2: "marginal: an exact zero root"}
        fig, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
        ax.pcolormesh(_edges(np.asarray(self.x), False), _edges(np.asarray(self.y), False), self.values,
                      cmap=ListedColormap(colors), vmin=-2.5, vmax=2.5, shading="flat")
        for code in (2, 1, 0, -1, -2):
            if np.any(self.values == code):
                ax.fill_between([], [], color=colors[code + 2],
                                label=f"{names[code]}: {int(np.sum(self.values == code))}")
        ax.set_xlim(_edges(np.asarray(self.x), False)[[0, -1]])
        ax.set_ylim(_edges(np.asarray(self.y), False)[[0, -1]])
        ax.set_xlabel(self.xname)
        ax.set_ylabel(self.yname)
        fixed = ", ".join(f"{k} = {v:.3g}" for k, v in self.base.items() if k not in ("theta", "chi"))
        ax.set_title(f"{self.title}: {which} against the spectrum\n({fixed})", fontsize=8)
        ax.legend(fontsize=8, loc="best")
        save_figure(fig, out)
        plt.close(fig)
