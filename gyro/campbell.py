"""Sweeps and their pictures: the Campbell diagram (frequencies against spin) and the
stability map over two parameters. Figures are written atomically (a temporary file
renamed), so a failed run leaves nothing half-written."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from gyro import ladder
from gyro.models import Model, ParameterError

CHUNK = 256  # parameter sets per call of the default method (the progress bar's step)
FORMULA_BAD = 0.01  # a formula errs by more than 1 %: shaded


def check_output(path) -> Path:
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise ParameterError(f"--out {path!r}: the figure is written as PNG; name it *.png")
    parent = out.resolve().parent
    if not parent.is_dir():
        raise ParameterError(f"--out {path!r}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise ParameterError(f"--out {path!r}: folder {parent} is not writable")
    return out


def _progress(total, enabled, desc):
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, desc=desc, unit="set", leave=False)


def batch_default(model: Model, P: np.ndarray, progress=False, desc="default") -> ladder.Spectrum:
    """The default method over a large batch, in chunks, with a progress bar."""
    parts = []
    with _progress(len(P), progress, desc) as bar:
        for s in range(0, len(P), CHUNK):
            parts.append(ladder.spectrum(model, P[s:s + CHUNK], "default"))
            bar.update(min(CHUNK, len(P) - s))
    cat = lambda a: np.concatenate([getattr(p, a) for p in parts])  # noqa: E731
    return ladder.Spectrum("default", cat("frequencies"), cat("growth"), cat("error_estimate"),
                           cat("equilibrium"), cat("route"))


def nearest_error(approx: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """Relative distance of each approximate frequency to the nearest exact one."""
    with np.errstate(all="ignore"):
        return np.min(np.abs(approx[:, :, None] / exact[:, None, :] - 1), axis=2)


def sweep(model: Model, values: dict, lo: float, hi: float, points: int, progress=False) -> dict:
    """Frequencies against spin: H from lo to hi times the set's H (log-spaced)."""
    scale = np.geomspace(lo, hi, points)
    P = np.tile(model.vector(values), (points, 1))
    iH = model.param_names.index("H")
    if values["H"] <= 0:
        raise ParameterError("H: the Campbell diagram scales the spin; give H > 0")
    P[:, iH] = values["H"] * scale
    exact = batch_default(model, P, progress, desc="Campbell")
    approx = ladder.spectrum(model, P, "formulas") if "mode_formulas" in model.meta["functions"] else None
    Omega = P[:, iH] / P[:, model.param_names.index("A")] if "A" in model.param_names else P[:, iH]
    err = nearest_error(approx.frequencies, exact.frequencies) if approx is not None else None
    bad = np.any(~(err <= FORMULA_BAD), axis=1) if err is not None else np.zeros(points, bool)
    return {"Omega": Omega, "exact": exact, "formulas": approx, "formula_error": err,
            "bad": bad, "shaded_fraction": float(np.mean(bad)), "values": values}


def _save(fig, out: Path):
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=Path(out).resolve().parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=130)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # as an ordinary new file (mkstemp makes it private)
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def plot(model: Model, data: dict, out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    W = data["Omega"]
    fig, ax = plt.subplots(figsize=(8, 6), layout="constrained")
    ex = data["exact"].frequencies
    for j in range(ex.shape[1]):
        ax.loglog(W, ex[:, j], color="k", lw=1.4, label="exact operator (default method)" if j == 0 else None)
    if data["formulas"] is not None:
        fo = data["formulas"].frequencies
        with np.errstate(all="ignore"):
            near = np.take_along_axis(ex, np.argmin(np.abs(fo[:, :, None] / ex[:, None, :] - 1), axis=2), 1)
        for j in range(fo.shape[1]):
            ax.loglog(W, fo[:, j], color="tab:blue", lw=1.0, ls="--",
                      label="formulas (3.2)-(3.28)" if j == 0 else None)
            bad = ~(data["formula_error"][:, j] <= FORMULA_BAD)
            # the band between a formula and the exact curve it approximates, where it errs > 1 %
            ax.fill_between(W, np.where(np.isfinite(fo[:, j]), fo[:, j], near[:, j]), near[:, j],
                            where=bad, color="tab:red", alpha=0.35, lw=0)
    ax.axvline(model.defaults["H"] / model.defaults["A"], color="0.5", lw=0.8, ls=":",
               label="paper example")
    ax.fill_between([], [], color="tab:red", alpha=0.35, label="a formula errs by more than 1% (band to the exact curve)")
    ax.set_xlabel("spin Omega = H/A [rad/s]")
    ax.set_ylabel("natural frequency omega [rad/s]")
    ax.set_title(f"Campbell diagram: {model.meta['title']}", fontsize=10)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=8, loc="upper left")
    _save(fig, out)
    plt.close(fig)


def stability_grid(model: Model, values: dict, xname, xrange, yname, yrange, points, progress=False,
                   xlog=False, ylog=False):
    """Stability over a grid of two parameters (log-spaced where asked), by the default method."""
    xs = (np.geomspace if xlog else np.linspace)(*xrange, points)
    ys = (np.geomspace if ylog else np.linspace)(*yrange, points)
    X, Y = np.meshgrid(xs, ys)
    P = np.tile(model.vector(values), (X.size, 1))
    P[:, model.param_names.index(xname)] = X.ravel()
    P[:, model.param_names.index(yname)] = Y.ravel()
    spec = batch_default(model, P, progress, desc="stability map")
    st = ladder.classify(spec)
    return {"x": xs, "y": ys, "xname": xname, "yname": yname, "xlog": xlog, "ylog": ylog,
            "label": st.label.reshape(X.shape), "growth": st.growth_rate.reshape(X.shape),
            "unstable_roots": st.unstable_roots.reshape(X.shape), "slowest": st.slowest_growth.reshape(X.shape)}


def _edges(v: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around grid points: midpoints, geometric ones on a log axis."""
    u = np.log(v) if log else v
    mid = (u[1:] + u[:-1]) / 2
    e = np.concatenate([[2 * u[0] - mid[0]], mid, [2 * u[-1] - mid[-1]]])
    return np.exp(e) if log else e


def plot_stability(model: Model, grid: dict, out: Path, lines=()):
    """The stability map: regions by the number of growing modes (stable, marginal, one, two
    or more), solid contours of the fastest growth rate and dashed ones of
    the slowest where two or more pairs grow (a growth that gyroscopic coupling slows down
    shows there, not in the fastest). `lines`: (xs, ys, label) curves to overlay, such as an
    analytic stability boundary."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap

    degree = np.minimum(grid["unstable_roots"], 2)
    code = np.where(grid["label"] == "marginal", 1, np.where(degree > 0, degree + 1, 0))
    colors = ["#cfe8cf", "#f3e3a1", "#f2b8b0", "#d9786c"]
    names = ["stable", "marginal", "unstable: one growing mode", "unstable: two or more"]
    fig, ax = plt.subplots(figsize=(7.5, 5.8), layout="constrained")
    units = {p.name: p.unit for p in model.params}
    ax.pcolormesh(_edges(grid["x"], grid.get("xlog")), _edges(grid["y"], grid.get("ylog")), code,
                  cmap=ListedColormap(colors), vmin=-0.5, vmax=3.5, shading="flat")
    for key, style, where in (("growth", "-", grid["unstable_roots"] > 0),
                              ("slowest", "--", grid["unstable_roots"] > 1)):
        g = np.where(where & (grid[key] > 0), grid[key], np.nan)
        if np.sum(np.isfinite(g)) > 3 and np.nanmax(g) > np.nanmin(g):
            lo, hi = np.log10(np.nanmin(g)), np.log10(np.nanmax(g))
            step = 0.5 if hi - lo > 1.5 else 0.1  # half decades, or tenths of one
            levels = np.arange(np.ceil(lo / step) * step, hi, step)
            if levels.size == 0:
                continue
            cs = ax.contour(grid["x"], grid["y"], np.log10(g), levels=levels, colors="k", linewidths=0.6,
                            linestyles=style)
            ax.clabel(cs, fmt=lambda v: f"{10**v:.2g}/s", fontsize=7)
    for xs, ys, label in lines:
        ax.plot(xs, ys, color="tab:blue", lw=1.2, ls=":", label=label)
    for code_, (name, color) in enumerate(zip(names, colors)):
        if np.any(code == code_):
            ax.fill_between([], [], color=color, label=name)
    ax.set_xscale("log" if grid.get("xlog") else "linear")
    ax.set_yscale("log" if grid.get("ylog") else "linear")
    ax.set_xlim(grid["x"][0], grid["x"][-1])
    ax.set_ylim(grid["y"][0], grid["y"][-1])
    ax.set_xlabel(f"{grid['xname']} [{units[grid['xname']]}]")
    ax.set_ylabel(f"{grid['yname']} [{units[grid['yname']]}]")
    ax.set_title(f"Stability of the equilibrium: {model.meta['title']}\n(contours: growth rate, "
                 "solid the fastest, dashed the slowest growing root)", fontsize=9)
    ax.legend(fontsize=8, loc="best")
    _save(fig, out)
    plt.close(fig)
