"""A scene: a question answered at a tolerance by the cheapest adequate level of a model's
hierarchy, per parameter set (gyro.analyses.scene). The bookkeeping is arrays (a code and
a value per set and level tried), the reasons' text is made only for the sets shown, so
that a million sets cost the selector little beside its levels."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from gyro.results._io import Result


# why a level was or was not enough for a set: the code of Trial.code
NOT_REACHED, NOT_ANSWERED, EDGE, APRIORI, FAILED, QUESTION_EDGE, BOUND, ACCEPTED = range(8)


@dataclass
class Trial(Result):
    """One level tried on the sets still open: per set, its code, the bound concerned, and
    the text of an edge or failure (None where there is none)."""

    level: str
    code: np.ndarray  # int8 (sets,)
    value: np.ndarray  # (sets,) the a-priori part or the whole bound
    text: np.ndarray | None = None  # object (sets,): edge name, failure, question edge
    missing: str = ""  # the requested quantities the level does not answer
    tol: float = float("nan")  # the tolerance it was tried at (its reasons' right-hand side)

    NO_PLOT = "the selector's bookkeeping of one level: `gyro scene` lists it as the levels tried"

    def to_dict(self) -> dict:
        """The level, and per set the reason it was or was not enough (null: not reached);
        refused for a trial without its tolerance (its reasons compare with it)."""
        if not np.isfinite(self.tol):
            raise ValueError(f"Trial {self.level}: no tolerance recorded, which its reasons compare with")
        return {"level": self.level, "reasons": [self.reason(k, self.tol) for k in range(len(self.code))]}

    def table(self) -> str:
        return "\n".join(f"{self.level}, set {k + 1}: {r}" for k, r in enumerate(self.to_dict()["reasons"])
                         if r is not None)

    @classmethod
    def _loaded(cls, t) -> "Trial":
        t.code = np.asarray(t.code, np.int8)
        t.value = np.asarray(t.value, float)
        t.text = None if t.text is None else np.array(t.text, dtype=object)
        return t

    def say(self, sets: np.ndarray, texts: np.ndarray) -> None:
        """The text of an edge or failure at these sets (the array made at the first)."""
        if self.text is None:
            self.text = np.full(self.code.shape[0], None, object)
        self.text[sets] = texts

    def reason(self, k: int, tol: float) -> str | None:
        c, v = int(self.code[k]), float(self.value[k])
        if c == NOT_REACHED:
            return None
        if c == NOT_ANSWERED:
            return f"does not answer {self.missing}"
        if c == EDGE:
            return f"edge of validity: {self.text[k]}"
        if c == APRIORI:
            return f"a-priori bound {v:.2e} > {tol:.2e}" if np.isfinite(v) else "a-priori bound not finite"
        if c in (FAILED, QUESTION_EDGE):
            return str(self.text[k])
        if c == BOUND:
            return f"bound {v:.2e} > {tol:.2e}" if np.isfinite(v) else "bound not finite"
        return f"bound {v:.2e} <= {tol:.2e}"


@dataclass
class Scene(Result):
    """Per set k: `level[k]` the level that answered ('' where none could), `bound[k]` its
    relative bound per requested quantity, `tried(k)` the levels tried cheapest first,
    each (level, reason), `document(k)` the question's own keys; `best(k)` the smallest
    bound any level promised where none met the tolerance, and by which level."""

    model: str
    question: str
    tol: float
    quantities: list
    level: np.ndarray
    bound: np.ndarray  # (sets, requested quantities)
    trials: list[Trial]
    seconds: float
    answers: dict = field(default_factory=dict)  # level -> (question module, model, Answer, idx)
    row: np.ndarray | None = None  # per set: its row in its level's answer
    # a loaded scene's answers: per set its question's document, and per level the key of
    # its per-quantity values (the question's VALUES), as `save` wrote them
    documents: list | None = None
    values_keys: dict = field(default_factory=dict)

    NO_PLOT = "an answer per set and the levels tried: the figure of an answer is its question's result"

    def save(self, path) -> None:
        """Every field, the answers as the documents of every set (and the key of their
        values) rather than the levels' objects: what to_dict and table print, loaded."""
        docs = [self.document(k) for k in range(len(self))]
        keys = {lv: getattr(a[0], "VALUES", None) for lv, a in self.answers.items()} or self.values_keys
        super(Scene, replace(self, answers={}, documents=docs, values_keys=keys)).save(path)

    @classmethod
    def _loaded(cls, s) -> "Scene":
        s.level = np.asarray(s.level, dtype=str)
        s.bound = np.asarray(s.bound, float)
        return s

    def __len__(self) -> int:
        return len(self.level)

    @property
    def answered(self) -> np.ndarray:
        return self.level != ""

    def tried(self, k: int) -> list:
        return [(t.level, r) for t in self.trials if (r := t.reason(k, self.tol)) is not None]

    def best(self, k: int) -> tuple:
        out = (np.inf, "")
        for t in self.trials:
            if t.code[k] in (APRIORI, BOUND) and t.value[k] < out[0]:
                out = (float(t.value[k]), t.level)
        return out

    def document(self, k: int) -> dict:
        if not self.level[k]:
            return {}
        if self.documents is not None and self.level[k] not in self.answers:
            return self.documents[k]
        q, model, ans, idx = self.answers[self.level[k]]
        return q.document(model, ans, int(self.row[k]), idx)

    def to_dict(self, k: int = 0) -> dict:
        """The `gyro scene --json` document of set k (its keys are the contract)."""
        out = {"model": self.model, "question": self.question, "tol": self.tol, "level": str(self.level[k]),
               "tried": [{"level": lv, "reason": r} for lv, r in self.tried(k)]}
        out.update(self.document(k))
        out["quantities"] = list(self.quantities)
        out["error_bound"] = [float(b) for b in self.bound[k]]
        out["seconds"] = self.seconds
        return out

    def table(self, k: int = 0) -> str:
        d = self.to_dict(k)
        lines = [f"{self.model}: {self.question} to a relative {self.tol:g}: level {d['level']}",
                 "levels tried, cheapest first:"]
        lines += [f"  {t['level']:<24} {t['reason']}" for t in d["tried"]]
        # the per-quantity answer where the question names one (its module's VALUES key)
        level = self.level[k]
        vkey = (None if not level else getattr(self.answers[level][0], "VALUES", None) if level in self.answers
                else self.values_keys.get(level))
        values = d.get(vkey) if vkey else None
        lines.append(f"{'quantity':>12} {'value':>22} {'bound':>10}")
        for j, name in enumerate(self.quantities):
            v = f"{values[j]:22.15g}" if values is not None else f"{'':>22}"
            lines.append(f"{name:>12} {v} {self.bound[k][j]:10.2e}")
        for key, val in d.items():
            if key not in ("model", "question", "tol", "level", "tried", "frequencies", vkey, "quantities",
                           "error_bound", "seconds", "t", *self._long_keys(d)):
                lines.append(f"{key}: {val}")
        lines.append(f"answered in {self.seconds:.3g} s")
        return "\n".join(lines)

    @staticmethod
    def _long_keys(d: dict) -> list:
        """Keys whose values are long lists (a motion's samples): JSON only."""
        return [k for k, v in d.items() if isinstance(v, list) and len(v) > 12 and k != "tried"]
