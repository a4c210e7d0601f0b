"""Steady harmonic responses: complex amplitudes of the reduced coordinates, one forcing
frequency per parameter set (`HarmonicResponse`: a Bode curve over a sweep, an unbalance
response), and the bearing imperfections' harmonics of the torsion gyrocompass kept apart
(`ForcedResponse`: an amplitude spectrum, their sum as a time series)."""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from gyro.results._io import Result, _finish, _finite_or_none, _more_rows, _shown_rows, _subplots, cell


class _Amplitudes:
    """Peak amplitudes and phases of complex amplitudes X (x = Re(X e^{i w t}))."""

    X: np.ndarray
    PHASE_SHIFT = 0.0  # pi/2: the phase of the sine form |X| sin(w t + phase)

    @property
    def amplitudes(self) -> np.ndarray:
        """Peak amplitude |X| of each coordinate (inf at a resonance, NaN without equilibrium)."""
        return np.abs(self.X)

    @property
    def phases(self) -> np.ndarray:
        """In (-pi, pi]: arg X (cosine form) plus PHASE_SHIFT; NaN where |X| is not finite, or
        exactly zero (a coordinate the input does not reach has no phase: printed '-', null
        in JSON)."""
        with np.errstate(invalid="ignore"):
            a = np.angle(self.X) + self.PHASE_SHIFT
            return np.where(np.isfinite(self.X) & (self.X != 0), np.pi - np.mod(np.pi - a, 2 * np.pi), np.nan)


@dataclass
class HarmonicResponse(_Amplitudes, Result):
    """x(t) = Re(X e^{i omega t}) about the equilibrium for the inputs w(t) = Re(u e^{i omega t}),
    one row per parameter set. `resonance` marks sets driven at a natural frequency of an
    undamped model (X inf); NaN rows had no equilibrium."""

    model: str
    title: str
    coordinates: list
    units: list
    inputs: list
    param_names: list
    params: np.ndarray  # (sets, n_params)
    omega: np.ndarray  # (sets,) rad/s
    u: np.ndarray  # (sets, n_inputs) complex
    X: np.ndarray  # (sets, n_q) complex
    resonance: np.ndarray  # (sets,) bool
    equilibrium: np.ndarray  # (sets, equilibrium coordinates)
    x: np.ndarray  # (sets,) the swept axis (omega unless a parameter was swept)
    xname: str = "omega"
    xunit: str = "rad/s"
    # what the inputs are, after the title in the table (an unbalance: its m e and inputs)
    heading: str = "steady response to harmonic inputs; peak amplitudes |X|, x(t) = Re(X e^(i W t))"

    def __len__(self) -> int:
        return self.X.shape[0]

    def table(self) -> str:
        """The `gyro unbalance` text: per value of the swept axis, the rate W and each
        coordinate's peak amplitude (up to 21 rows, else 11 spread evenly)."""
        amp = self.amplitudes
        lines = [f"{self.title} ({self.model}): {self.heading}",
                 f"{'':>4} {self.xname:>12} {'W [rad/s]':>12} " + " ".join(f"{c + ' [' + u + ']':>14}"
                                                                         for c, u in zip(self.coordinates, self.units))]
        for i in _shown_rows(len(self)):
            cells = ["resonance" if self.resonance[i] else cell(a, ".6g") for a in amp[i]]
            lines.append(f"{i + 1:>4} {self.x[i]:>12.6g} {cell(self.omega[i], '>12.6g')} "
                         + " ".join(f"{c:>14}" for c in cells))
        return "\n".join(lines + _more_rows(len(self)))

    @classmethod
    def concat(cls, parts: list["HarmonicResponse"]) -> "HarmonicResponse":
        first = parts[0]
        kw = {}
        for f in fields(cls):
            v = getattr(first, f.name)
            kw[f.name] = np.concatenate([getattr(p, f.name) for p in parts]) if isinstance(v, np.ndarray) else v
        return cls(**kw)

    def time_series(self, t, k: int = 0) -> np.ndarray:
        """x(t) of set k about its equilibrium, (len(t), n_q)."""
        t = np.asarray(t, dtype=float)
        return (np.exp(1j * self.omega[k] * t)[:, None] * self.X[k][None, :]).real

    def to_dict(self) -> dict:
        """The `gyro unbalance --json` document (keys of its contract), plus `resonance`."""
        return {"model": self.model, "spin": self.xname, "values": self.x.tolist(),
                "spin_rate": _finite_or_none(self.omega[None])[0], "coordinates": list(self.coordinates),
                "units": list(self.units),
                "amplitudes": _finite_or_none(np.where(self.resonance[:, None], np.nan, self.amplitudes)),
                "phases": _finite_or_none(self.phases),
                "resonance": [bool(r) for r in self.resonance]}

    def summary(self, out) -> str:
        r = int(np.sum(self.resonance))
        return (f"gyro: wrote {out} ({len(self)} values of {self.xname}"
                + (f"; {r} at a resonance (amplitude inf)" if r else "") + ")")

    def plot(self, out, coordinates=None) -> None:
        """Bode figure: amplitude (log) and phase of the chosen coordinates (default: those
        with the largest response) against the swept axis; resonances as vertical lines."""
        amp = self.amplitudes
        if coordinates is None:
            peak = np.nanmax(np.where(np.isfinite(amp), amp, np.nan), axis=0, initial=0.0)
            rel = {"m": 1.0, "rad": 1.0}
            order = np.argsort(-np.nan_to_num(peak * [rel.get(u, 1.0) for u in self.units]))
            coordinates = [self.coordinates[i] for i in order[:4] if np.nan_to_num(peak[i]) > 0]
        fig, (a1, a2) = _subplots(out, 2, 1, figsize=(8, 7), sharex=True, layout="constrained")
        for c in coordinates:
            i = self.coordinates.index(c)
            a1.semilogy(self.x, np.where(np.isfinite(amp[:, i]), amp[:, i], np.nan), label=f"{c} [{self.units[i]}]")
            a2.plot(self.x, self.phases[:, i], ".", ms=2)
        for xr in self.x[self.resonance]:
            for ax in (a1, a2):
                ax.axvline(xr, color="r", lw=0.8, ls="--")
        a1.set_ylabel("peak amplitude |X|")
        a2.set_ylabel("phase arg X [rad]")
        a2.set_xlabel(f"{self.xname} [{self.xunit}]")
        a1.set_title(f"Harmonic response: {self.title}", fontsize=10)
        a1.legend(fontsize=8)
        for ax in (a1, a2):
            ax.grid(True, which="both", alpha=0.25)
        _finish(fig, out)


@dataclass
class ForcedResponse(_Amplitudes, Result):
    """The steady response of the torsion gyrocompass to harmonics of its bearing
    imperfections f_s = a sin(k gamma3 + phi), gamma3 = omega_c t (1.11), each kept apart:
    arrays (sets, harmonics, ...). x_j(t) = amplitudes_j sin(k omega_c t + phases_j) about
    the equilibrium, in the form of the forcing; superposition gives the sum."""

    model: str
    title: str
    coordinates: list
    units: list
    param_names: list
    params: np.ndarray  # (sets, n_params)
    spin_rate: np.ndarray  # (sets,) omega_c, rad/s
    s: np.ndarray  # (harmonics,) index of f_s, 1..n (the model's harmonic inputs)
    k: np.ndarray  # (harmonics,) order
    amplitude: np.ndarray  # (harmonics,) a, in input_unit
    phase: np.ndarray  # (harmonics,) phi, rad
    X: np.ndarray  # (sets, harmonics, n_q) complex, x(t) = Re(X e^{i k omega_c t})
    resonance: np.ndarray  # (sets, harmonics) bool
    natural: np.ndarray  # (sets, modes) natural frequencies, rad/s
    natural_error: np.ndarray  # (sets, modes) their relative error estimates
    equilibrium: np.ndarray  # (sets, equilibrium coordinates)
    label: str = "bearing imperfections"  # what the harmonic inputs are (Model.spin "harmonics")
    input_unit: str = "N"  # their unit
    PHASE_SHIFT = np.pi / 2  # phases of the sine form, as the forcing (1.11) is written

    @property
    def frequency(self) -> np.ndarray:
        """(sets, harmonics): k omega_c, rad/s."""
        return self.spin_rate[:, None] * self.k[None, :]

    @property
    def nearest_mode(self) -> np.ndarray:
        """(sets, harmonics): 0-based index of the natural frequency nearest to k omega_c."""
        d = np.abs(self.frequency[:, :, None] - self.natural[:, None, :])
        return np.argmin(np.where(np.isfinite(d), d, np.inf), axis=2)

    @property
    def nearest_natural_frequency(self) -> np.ndarray:
        return np.take_along_axis(self.natural, self.nearest_mode, axis=1)

    @property
    def relative_distance(self) -> np.ndarray:
        """|k omega_c - omega_j| / omega_j to the nearest natural frequency."""
        wn = self.nearest_natural_frequency
        with np.errstate(all="ignore"):
            return np.abs(self.frequency - wn) / wn

    def time_series(self, t, k: int = 0, harmonics=None) -> np.ndarray:
        """The sum over the chosen harmonics (default all) as x(t) about the equilibrium of
        set k, (len(t), n_q): exact superposition of the linear model."""
        t = np.asarray(t, dtype=float)
        hs = range(len(self.s)) if harmonics is None else harmonics
        out = np.zeros((len(t), self.X.shape[-1]))
        for h in hs:
            out += (np.exp(1j * self.frequency[k, h] * t)[:, None] * self.X[k, h][None, :]).real
        return out

    def to_dict(self, k: int = 0) -> dict:
        """The `gyro forced --json` document of set k (keys of its contract)."""
        near, wn, dist = self.nearest_mode[k], self.nearest_natural_frequency[k], self.relative_distance[k]
        hs = []
        for h in range(len(self.s)):
            res = bool(self.resonance[k, h])
            amp = np.full(self.X.shape[-1], np.inf) if res else self.amplitudes[k, h]
            hs.append({"s": int(self.s[h]), "k": int(self.k[h]), "amplitude": float(self.amplitude[h]),
                       "phase": float(self.phase[h]), "frequency": float(self.frequency[k, h]),
                       "amplitudes": [float(a) if np.isfinite(a) else None for a in amp],
                       "phases": [float(p) if np.isfinite(p) else None for p in self.phases[k, h]],
                       "nearest_natural_frequency": float(wn[h]) if np.isfinite(wn[h]) else None,
                       "nearest_mode": int(near[h]) + 1,
                       "relative_distance": float(dist[h]) if np.isfinite(dist[h]) else None,
                       "resonance": res})
        return {"model": self.model, "params": dict(zip(self.param_names, map(float, self.params[k]))),
                "coordinates": list(self.coordinates), "units": list(self.units),
                "spin_rate": float(self.spin_rate[k]), "harmonics": hs}

    def table(self, k: int = 0) -> str:
        d = self.to_dict(k)
        lines = [f"{self.title} ({self.model}): steady response to {self.label}",
                 f"spin rate omega_c = {d['spin_rate']:.8g} rad/s; x = amplitude sin(k omega_c t + phase) "
                 "about the equilibrium"]
        for h in d["harmonics"]:
            unit = f" {self.input_unit}" if self.input_unit else ""
            head = (f"f{h['s']}: a = {h['amplitude']:.6g}{unit}, k = {h['k']}, phase {h['phase']:.6g} rad, "
                    f"frequency {h['frequency']:.8g} rad/s; nearest natural frequency omega{h['nearest_mode']} = "
                    f"{h['nearest_natural_frequency']:.8g} rad/s")
            if h["resonance"]:
                head += " -- RESONANCE (undamped: amplitude inf)"
            elif h["relative_distance"] is not None:
                head += f" (relative distance {h['relative_distance']:.3g})"
            lines.append(head)
            lines.append(f"{'':>4} {'coordinate':>10} {'amplitude':>14} {'unit':>5} {'phase [rad]':>12}")
            for c, unit, a, p in zip(self.coordinates, self.units, h["amplitudes"], h["phases"]):
                lines.append(f"{'':>4} {c:>10} {('inf' if a is None else f'{a:.6g}'):>14} {unit:>5} "
                             f"{('-' if p is None else f'{p:.6f}'):>12}")
        return "\n".join(lines)

    def plot(self, out, k: int = 0) -> None:
        """Amplitude spectrum: each harmonic's peak amplitude per coordinate (stems at k
        omega_c, translations and angles on two axes), the natural frequencies marked."""
        fig, axes = _subplots(out, 2, 1, figsize=(8, 7), sharex=True, layout="constrained")
        wmax = max(np.nanmax(self.frequency[k]), np.nanmax(self.natural[k])) * 1.08
        for ax, unit in zip(axes, ("m", "rad")):
            cols = [i for i, u in enumerate(self.units) if u == unit]
            for n, i in enumerate(cols):
                for h in range(len(self.s)):
                    a = self.amplitudes[k, h, i]
                    f = self.frequency[k, h] * (1 + 0.004 * (n - len(cols) / 2))
                    if self.resonance[k, h]:
                        ax.axvline(self.frequency[k, h], color="r", lw=1.5)
                        continue
                    if a > 0:
                        ax.semilogy([f, f], [1e-300, a], color=f"C{n}", lw=1.2)
                        ax.semilogy([f], [a], "o", color=f"C{n}", ms=4, label=self.coordinates[i] if h == 0 else None)
            for w in self.natural[k]:
                ax.axvline(w, color="0.6", lw=0.6, ls=":")
            finite = self.amplitudes[k][:, cols]
            finite = finite[np.isfinite(finite) & (finite > 0)]
            if finite.size:
                ax.set_ylim(finite.min() / 10, finite.max() * 10)
            ax.set_ylabel(f"peak amplitude [{unit}]")
            ax.grid(True, which="both", alpha=0.25)
            ax.legend(fontsize=7, ncol=3)
        axes[1].set_xlim(0, wmax)
        axes[1].set_xlabel("frequency k omega_c [rad/s] (dotted: natural frequencies; red: resonance)")
        axes[0].set_title(f"Amplitude spectrum of the response to {self.label}: {self.title}", fontsize=10)
        _finish(fig, out)


