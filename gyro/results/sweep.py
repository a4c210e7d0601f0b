"""Natural frequencies against one parameter."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gyro.results._io import Result, _axes, _finite_or_none
from gyro.results.spectrum import Spectrum, classify


@dataclass
class FrequencySweep(Result):
    """Natural frequencies against one parameter (a Campbell diagram over any parameter)."""

    model: str
    title: str
    xname: str
    xunit: str
    x: np.ndarray
    spectrum: Spectrum
    xlog: bool = False

    def to_dict(self) -> dict:
        """The `gyro sweep --json` document. Per value: `stability` (the class, as `gyro
        frequencies` states it), `growing_modes`, `growth_rate` (1/s, the fastest growing
        root's, 0 when none grows) and `stability_reason` (null, or why there is no plain
        verdict)."""
        s = self.spectrum
        st = classify(s)
        reason = st.reason if st.reason is not None else [None] * len(st.label)
        return {"model": self.model, "x": {"name": self.xname, "unit": self.xunit, "values": self.x.tolist()},
                "method": s.method, "frequencies": _finite_or_none(s.frequencies),
                "eigenvalues_re": _finite_or_none(s.growth),
                "error_estimate": [[float(e) if np.isfinite(e) else None for e in row] for row in s.error_estimate],
                "stability": [str(c) for c in st.label], "growing_modes": [int(n) for n in st.unstable_roots],
                "growth_rate": [float(g) for g in st.growth_rate], "stability_reason": list(reason)}

    def table(self) -> str:
        """The `gyro sweep` text: the frequencies per value and the verdict there (stable,
        marginal, unstable with its number of growing modes and the fastest rate, boundary, unknown, failed); a
        frequency that could not be computed is '-'."""
        f, st = self.spectrum.frequencies, classify(self.spectrum)
        lines = [f"{'':>4} {self.xname + ' [' + self.xunit + ']':>16} "
                 + " ".join(f"{'omega' + str(j + 1):>12}" for j in range(f.shape[1])) + "  stability"]
        for i, xv in enumerate(self.x):
            label = str(st.label[i])
            if label == "unstable":
                n = int(st.unstable_roots[i])
                label += f" ({n} growing mode{'s' if n != 1 else ''}, the fastest at {st.growth_rate[i]:.4g} 1/s)"
            lines.append(f"{i + 1:>4} {xv:>16.8g} " + " ".join(f"{w:>12.6g}" if np.isfinite(w) else f"{'-':>12}"
                                                             for w in f[i]) + f"  {label}")
        return "\n".join(lines)

    def summary(self, out) -> str:
        c = classify(self.spectrum).label
        rest = "".join(f", {int(np.sum(c == k))} {k}" for k in ("boundary", "unknown", "failed") if np.any(c == k))
        return (f"gyro: wrote {out} ({len(self.x)} values of {self.xname}: "
                f"{int(np.sum(c == 'stable'))} stable, {int(np.sum(c == 'marginal'))} marginal, "
                f"{int(np.sum(c == 'unstable'))} unstable{rest})")

    def plot(self, out) -> None:
        """The frequencies against the swept parameter, into `out` (a file or axes)."""
        with _axes(out, figsize=(8, 6)) as ax:
            self.spectrum.plot(x=self.x, ax=ax, label=f"method '{self.spectrum.method}'")
            ax.set_xscale("log" if self.xlog else "linear")
            ax.set_xlabel(f"{self.xname} [{self.xunit}]")
            ax.set_title(f"Natural frequencies against {self.xname}: {self.title}", fontsize=10)
            ax.grid(True, which="both", alpha=0.25)
            ax.legend(fontsize=8)


# --------------------------------------------------------------------------- gyrohorizoncompass
