"""What every result shares: atomic saving (npz, figures), JSON-ready values, table rows."""
from __future__ import annotations

import json
import os
from contextlib import contextmanager
from dataclasses import fields, is_dataclass
from pathlib import Path

import numpy as np

class Result:
    """The contract of every result in gyro.results:

    - `save(path)`: every field into one .npz, written atomically (whole or not at all);
      `load(path)` (a classmethod): the same result back, nested results (a sweep's
      Spectrum, a tolerance study's Sensitivities, a Campbell diagram's crossings, a scene's
      trials) rebuilt in their own types. ModalResult writes its JSON document instead (a
      .json, as it always has).
    - `to_dict()`: a JSON-ready document: the command's --json document where a command
      prints the result (its keys are the contract), every field otherwise.
    - `table()`: the text the command prints; a per-set result (Spectrum, Sensitivities,
      Scene, ForcedResponse) takes the set `k` (default 0), and a Spectrum the model whose
      names it prints.
    - `plot(out)`: the figure into `out`, a file (PNG, written atomically) or matplotlib
      axes (a figure for the results of several panels: Motion, CampbellDiagram,
      ToleranceStudy, Sensitivities, HarmonicResponse, ForcedResponse).

    Without a plot (`plot` raises NotImplementedError saying so; NO_PLOT the reason):
    Verdict and Stability (a label per set: the figure of what holds them draws them, a
    map or a Campbell diagram), Crossing (a point of its Campbell diagram), Trial and Scene
    (the selector's bookkeeping, and an answer per set whose figure is its question's
    result), ModalResult (one set's frequencies: `gyro frequencies` lists them) and
    EquilibriumStability (one set's margins and eigenvalues: `gyro stability` lists them;
    the condition Map draws the regions)."""

    NO_PLOT = ""

    def save(self, path) -> None:
        _save_npz(self, path)

    @classmethod
    def load(cls, path):
        return cls._loaded(_load_npz(cls, path))

    @classmethod
    def _loaded(cls, obj):
        """What JSON cannot carry rebuilt after loading (object arrays, tuples)."""
        return obj

    def to_dict(self) -> dict:
        """Every field, JSON-ready (a result with a command's document overrides this)."""
        return {f.name: _jsonable(getattr(self, f.name)) for f in fields(self)}

    def table(self) -> str:
        raise NotImplementedError(f"{type(self).__name__}: no table")

    def plot(self, out):
        raise NotImplementedError(f"{type(self).__name__} has no plot: {self.NO_PLOT}")


def _save_npz(obj, path) -> None:
    """Every field of a dataclass of arrays and scalars into one .npz (objects as JSON)."""
    data = {}
    for f in fields(obj):
        v = getattr(obj, f.name)
        if isinstance(v, np.ndarray) and v.dtype != object and v.ndim > 0:
            data[f.name] = v
        else:
            data[f.name] = np.array(json.dumps(_jsonable(v)))
    path = Path(path)
    _clean_stale(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}{TMP_TAG}")
    try:
        with open(tmp, "wb") as fh:
            np.savez(fh, **data)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _write_text(path, text: str) -> None:
    """A text file written atomically: a temporary beside it, renamed."""
    path = Path(path)
    _clean_stale(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}{TMP_TAG}")
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def _load_npz(cls, path):
    hints = _hints(cls)
    with np.load(path, allow_pickle=False) as z:
        kw = {}
        for f in fields(cls):
            if f.name not in z:
                continue
            v = z[f.name]
            # a field that is no array of numbers was saved as JSON, a 0-d string
            json_ = v.dtype.kind == "U" and v.ndim == 0
            kw[f.name] = _rebuild(hints.get(f.name), json.loads(v.item())) if json_ else v
    return cls(**kw)


def _hints(cls) -> dict:
    import typing

    try:
        return typing.get_type_hints(cls)
    except Exception:  # an annotation that does not resolve: fields load as JSON gives them
        return {}


def _rebuild(tp, value):
    """A field saved as JSON back in its declared type: a nested result (a dataclass, e.g.
    a sweep's Spectrum) field by field, a list[X] entry by entry, an array from its list
    (complex from re/im)."""
    import types
    import typing

    if value is None or tp is None:
        return value
    args = [a for a in typing.get_args(tp) if a is not type(None)]
    if typing.get_origin(tp) in (typing.Union, types.UnionType) and args:  # X | None: X
        tp = args[0]
    if typing.get_origin(tp) is list and isinstance(value, list) and typing.get_args(tp):
        item = typing.get_args(tp)[0]  # list[X]: each entry rebuilt as an X (a Campbell crossing)
        return [_rebuild(item, v) for v in value]
    if is_dataclass(tp) and isinstance(value, dict):
        hints = _hints(tp)
        names = {f.name for f in fields(tp)}
        obj = tp(**{k: _rebuild(hints.get(k), v) for k, v in value.items() if k in names})
        return tp._loaded(obj) if isinstance(obj, Result) else obj
    if tp is np.ndarray:
        if isinstance(value, dict) and set(value) == {"re", "im"}:
            return np.asarray(value["re"]) + 1j * np.asarray(value["im"])
        arr = np.asarray(value)
        return arr if arr.dtype != object or not arr.size else np.array(value, dtype=object)
    return value


def _jsonable(v):
    if isinstance(v, np.ndarray) and np.iscomplexobj(v):
        return {"re": v.real.tolist(), "im": v.imag.tolist()}
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if is_dataclass(v) and not isinstance(v, type):
        return {f.name: _jsonable(getattr(v, f.name)) for f in fields(v)}
    return v


TMP_TAG = ".gyro-tmp"  # temporaries beside an output: .<name>.<pid>.gyro-tmp<suffix>


def _clean_stale(out: Path) -> None:
    """Remove temporaries that a killed run left beside `out` (their process is gone)."""
    for tmp in out.parent.glob(f".{out.name}.*{TMP_TAG}*"):
        try:
            pid = int(tmp.name[len(out.name) + 2:].split(".", 1)[0])
            os.kill(pid, 0)  # alive: a concurrent run's, left alone
        except (ValueError, ProcessLookupError):
            tmp.unlink(missing_ok=True)
        except PermissionError:
            pass


def _shown_rows(n: int):
    """The rows a text table of a motion shows: all up to 21, else 11 spread evenly."""
    return range(n) if n <= 21 else np.unique(np.linspace(0, n - 1, 11).round().astype(int))


def _more_rows(n: int) -> list[str]:
    return [f"({n} points; 11 shown; --json prints all)"] if n > 21 else []


def save_figure(fig, out) -> None:
    """A figure written atomically: a temporary file in the same folder, renamed. A failed
    run leaves nothing half-written; a killed one leaves a temporary named after the output
    and its process, which the next run that writes the same output removes."""
    out = Path(out)
    _clean_stale(out)
    tmp = out.with_name(f".{out.name}.{os.getpid()}{TMP_TAG}{out.suffix or '.png'}")
    try:
        fig.savefig(tmp, dpi=130)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)


@contextmanager
def _canvas(out, **figkw):
    """The figure a plot draws into: `out` a matplotlib Figure (drawn into and left open),
    or a path (a new figure, written there whole or not at all, then closed)."""
    from matplotlib.figure import Figure

    if isinstance(out, Figure):
        yield out
        return
    plt = _pyplot()
    fig = plt.figure(**{"layout": "constrained", **figkw})
    try:
        yield fig
        save_figure(fig, out)
    finally:
        plt.close(fig)


@contextmanager
def _axes(out, **figkw):
    """The axes a one-panel plot draws into: `out` a matplotlib Axes, a Figure (a panel
    added) or a path (as _canvas)."""
    from matplotlib.axes import Axes

    if isinstance(out, Axes):
        yield out
        return
    with _canvas(out, **figkw) as fig:
        yield fig.add_subplot()


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt




def _edges(v: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid points: midpoints, geometric ones on a log axis."""
    u = np.log(v) if log else v
    mid = (u[1:] + u[:-1]) / 2
    e = np.concatenate([[2 * u[0] - mid[0]], mid, [2 * u[-1] - mid[-1]]])
    return np.exp(e) if log else e



def _finite_or_none(a) -> list:
    """Rows of numbers for strict JSON: a value that could not be computed is null."""
    return [[float(v) if np.isfinite(v) else None for v in row] for row in np.asarray(a, float)]



def _subplots(out, *args, **kw):
    """(figure, axes) of a plot of several panels into `out`: the panels added to a
    matplotlib Figure given as `out`, or a new figure (for a file)."""
    from matplotlib.figure import Figure

    if isinstance(out, Figure):
        kw.pop("figsize", None), kw.pop("layout", None)
        return out, out.subplots(*args, **kw)
    return _pyplot().subplots(*args, **kw)


def _finish(fig, out) -> None:
    """A new figure written to the file `out` whole or not at all, and closed; a Figure
    given as `out` is left open to its owner."""
    from matplotlib.figure import Figure

    if not isinstance(out, Figure):
        try:
            save_figure(fig, out)
        finally:
            _pyplot().close(fig)


def mode_panels(out, n: int, height: float):
    """A figure of n panels, one a mode, five to a row; unused panels hidden."""
    cols = min(n, 5)
    rows = -(-n // cols)
    fig, axes = _subplots(out, rows, cols, figsize=(3.1 * cols, height * rows), layout="constrained", squeeze=False)
    for ax in axes.flat[n:]:
        ax.axis("off")
    return fig, axes


def cell(x, spec: str, none: str = "none") -> str:
    """One number of a text table formatted by `spec` (as '>12.6g'), or, where it is NaN or
    infinite, the word `none` in the same width: a table never prints nan or inf as if it
    were a number (the caller says in a note what the word means)."""
    import math

    if x is not None and math.isfinite(x):
        return format(x, spec)
    width = "".join(ch for ch in spec.split(".")[0] if ch.isdigit())
    align = "<" if spec.startswith("<") else ">"
    return format(none, f"{align}{width}") if width else none
