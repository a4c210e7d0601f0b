"""A scene: a question answered at a tolerance by the cheapest adequate level of a model's
hierarchy, per parameter set (gyro.analyses.scene)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Scene:
    """Per set k: `level[k]` the level that answered ('' where none could), `bound[k]` its
    relative bound per requested quantity, `tried[k]` the levels tried cheapest first, each
    (level, reason), `documents[k]` the question's own keys; `best[k]` the smallest bound
    any level promised where none met the tolerance (and by which level)."""

    model: str
    question: str
    tol: float
    quantities: list
    level: np.ndarray
    bound: np.ndarray  # (sets, requested quantities)
    tried: list
    documents: list
    best: list
    seconds: float

    def __len__(self) -> int:
        return len(self.level)

    @property
    def answered(self) -> np.ndarray:
        return self.level != ""

    def to_dict(self, k: int) -> dict:
        """The `gyro scene --json` document of set k (its keys are the contract)."""
        out = {"model": self.model, "question": self.question, "tol": self.tol, "level": str(self.level[k]),
               "tried": [{"level": lv, "reason": r} for lv, r in self.tried[k]]}
        out.update(self.documents[k])
        out["quantities"] = list(self.quantities)
        out["error_bound"] = [float(b) for b in self.bound[k]]
        out["seconds"] = self.seconds
        return out

    def table(self, k: int) -> str:
        d = self.to_dict(k)
        lines = [f"{self.model}: {self.question} to a relative {self.tol:g}: level {d['level']}",
                 "levels tried, cheapest first:"]
        lines += [f"  {t['level']:<28} {t['reason']}" for t in d["tried"]]
        values = d.get("frequencies") if self.question == "frequencies" else None
        lines.append(f"{'quantity':>12} {'value':>22} {'bound':>10}")
        for j, name in enumerate(self.quantities):
            v = f"{values[j]:22.15g}" if values is not None else f"{'':>22}"
            lines.append(f"{name:>12} {v} {self.bound[k][j]:10.2e}")
        for key, val in d.items():
            if key not in ("model", "question", "tol", "level", "tried", "frequencies", "quantities",
                           "error_bound", "seconds"):
                lines.append(f"{key}: {val}")
        lines.append(f"answered in {self.seconds:.3g} s")
        return "\n".join(lines)
