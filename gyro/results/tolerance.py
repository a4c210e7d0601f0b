"""A tolerance study: the distribution of each natural frequency over manufacturing spreads,
sampled and to first order, and the figures of it (histograms with the first-order normal
overlaid)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from gyro.results._io import Result, _finish, cell, mode_panels
from gyro.results.sensitivity import Sensitivities

QUANTILE_LEVELS = (0.01, 0.5, 0.99)
HOLDS = 0.05  # first order holds where its std is within 5 % of the sampled one (beyond sampling error)


def _num(v):
    return float(v) if v is not None and np.isfinite(v) else None


@dataclass
class ToleranceStudy(Result):
    model: str
    title: str
    samples: int
    seed: int
    spreads: list  # [{"name", "kind", "width"}]
    correlations: dict  # {"A,B": rho}
    nominal: np.ndarray  # (modes,) rad/s at the nominal set
    sensitivities: Sensitivities  # at the nominal set
    spread_index: np.ndarray  # indices of the spread parameters
    first_order_std: np.ndarray  # (modes,)
    failed: int
    mean: np.ndarray
    std: np.ndarray
    skewness: np.ndarray
    kurtosis: np.ndarray
    quantiles: np.ndarray  # (modes, 3)
    counts: np.ndarray  # (modes, bins)
    edges: np.ndarray  # (modes, bins + 1)
    harmonics: list = field(default_factory=list)
    band: float = 0.02
    band_probability: list | None = None
    method: str = "default"

    @property
    def answered(self) -> int:
        return self.samples - self.failed

    def sampling_error(self) -> np.ndarray:
        """Relative standard error of the sampled std: sqrt((kurtosis - 1) / (4 N))."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.sqrt((self.kurtosis - 1) / (4 * max(self.answered, 1)))

    def first_order_error(self) -> np.ndarray:
        """first_order_std / std - 1 per mode."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.first_order_std / self.std - 1

    def first_order_verdict(self) -> np.ndarray:
        """Per mode: 'holds' where the first-order std is within HOLDS of the sampled one with
        three standard errors of sampling to spare, 'fails' where it is beyond HOLDS by more
        than three of them (a difference sampling cannot explain: a nonlinearity first order
        misses), 'undecided' where the samples are too few to say (the sampling error
        admits both, or there is no sampled spread to compare with), 'none' where there is no
        first order (a double root)."""
        r = self.first_order_error()
        # the standard error of first_order_std / std - 1 is (1 + r) times the sampled
        # std's relative one
        with np.errstate(invalid="ignore"):
            se = 3 * np.abs(1 + r) * self.sampling_error()
        err = np.abs(r)
        out = np.full(err.shape, "undecided", object)  # e.g. one sample, or a zero sampled std
        out[~np.isfinite(self.first_order_std)] = "none"
        ok = np.isfinite(err) & np.isfinite(se)
        out[ok & (err + se <= HOLDS)] = "holds"
        out[ok & (err - se > HOLDS)] = "fails"
        return out

    def first_order_holds(self) -> np.ndarray:
        """Per mode: True where first order holds, False where it fails, None where the
        samples cannot say or there is no first order (first_order_verdict)."""
        v = self.first_order_verdict()
        return np.array([True if x == "holds" else False if x == "fails" else None for x in v], object)

    def to_dict(self) -> dict:
        """The `gyro tolerance --json` document (its keys are the contract)."""
        holds, verdict = self.first_order_holds(), self.first_order_verdict()
        err, se = self.first_order_error(), self.sampling_error()
        modes = []
        for i in range(len(self.nominal)):
            modes.append({"nominal": _num(self.nominal[i]), "mean": _num(self.mean[i]), "std": _num(self.std[i]),
                          "quantiles": {str(q): _num(v) for q, v in zip(QUANTILE_LEVELS, self.quantiles[i])},
                          "first_order_std": _num(self.first_order_std[i]),
                          "first_order_error": _num(err[i]), "std_sampling_error": _num(se[i]),
                          "first_order_holds": holds[i], "first_order": verdict[i],
                          "skewness": _num(self.skewness[i])})
        doc = {"model": self.model, "samples": self.samples, "seed": self.seed, "method": self.method,
               "spreads": self.spreads, "correlations": self.correlations, "frequencies": modes,
               "sensitivities": self.sensitivities.to_dict(0)["sensitivities"],
               "relative_sensitivities": self.sensitivities.to_dict(0)["relative_sensitivities"],
               "sensitivity_parameters": list(self.sensitivities.param_names), "failed": self.failed}
        if self.band_probability is not None:
            doc["band"] = self.band
            # a mode without a first order (a double root at the nominal set): null
            doc["band_probability"] = [[{**b, "first_order_probability": _num(b["first_order_probability"])}
                                        for b in row] for row in self.band_probability]
        return doc

    def table(self) -> str:
        lines = [f"{self.title} ({self.model}): {self.samples} samples (seed {self.seed}), "
                 f"{self.failed} without an answer; method '{self.method}'",
                 "spreads: " + ", ".join(f"{s['name']} {s['kind']} {100 * s['width']:g} %" for s in self.spreads),
                 f"{'':>4} {'nominal':>12} {'mean':>12} {'std':>11} {'1st-order std':>13} {'q 0.01':>12} "
                 f"{'q 0.99':>12}  first order"]
        verdicts, err = self.first_order_verdict(), self.first_order_error()
        for i in range(len(self.nominal)):
            if np.isfinite(self.first_order_std[i]):
                verdict = str(verdicts[i]) + (f" ({100 * err[i]:+.1f} %)" if np.isfinite(err[i]) else "")
            else:
                verdict = "none (a double root at the nominal set)"
            lines.append(f"{i + 1:>4} {cell(self.nominal[i], '>12.6g')} {cell(self.mean[i], '>12.6g')} "
                         f"{cell(self.std[i], '>11.4g')} {cell(self.first_order_std[i], '>13.4g')} "
                         f"{cell(self.quantiles[i, 0], '>12.6g')} {cell(self.quantiles[i, 2], '>12.6g')}  {verdict}")
        if self.band_probability is not None:
            ks = ", ".join(str(k) for k in self.harmonics)
            lines.append(f"probability within +-{100 * self.band:g} % of a harmonic k omega_c, k = {ks} "
                         "(sampled / first order):")
            shown = 0
            for i, row in enumerate(self.band_probability, 1):
                fo = [b["first_order_probability"] for b in row]
                cells = [f"k={b['harmonic']}: {b['probability']:.3g} / " + (f"{f:.3g}" if np.isfinite(f) else "none")
                         for b, f in zip(row, fo)]
                if any(b["probability"] > 0 or not f <= 1e-6 for b, f in zip(row, fo)):  # NaN: shown
                    lines.append(f"{i:>4}   " + "   ".join(cells))
                    shown += 1
            if not shown:
                lines.append("     none: every frequency stays clear (sampled 0, first order below 1e-6)")
            if self.failed:
                lines.append(f"     sampled: of the {self.answered} answered samples; over all {self.samples}, "
                             "between the JSON's probability_range (the failed ones all out of the band, or all in)")
        return "\n".join(lines)

    def plot(self, out, modes=None) -> None:
        """Histograms of each frequency (relative to nominal) with the first-order normal."""
        modes = list(range(len(self.nominal))) if modes is None else list(modes)
        fig, axes = mode_panels(out, len(modes), 2.5)
        for ax, i in zip(axes.flat, modes):
            w0 = self.nominal[i]
            e = self.edges[i]
            x = (e - w0) / w0 * 100
            widths = np.diff(e)
            dens = self.counts[i] / max(self.answered, 1) / widths
            ax.stairs(dens * w0 / 100, x, fill=True, color="0.75", label="sampled")
            s = self.first_order_std[i]
            if np.isfinite(s) and s > 0:
                grid = np.linspace(e[0], e[-1], 300)
                pdf = np.exp(-0.5 * ((grid - w0) / s) ** 2) / (s * np.sqrt(2 * np.pi))
                ax.plot((grid - w0) / w0 * 100, pdf * w0 / 100, color="tab:red", lw=1.2, label="first order")
            ax.set_title(f"omega{i + 1} = {w0:.5g} rad/s", fontsize=9)
            ax.tick_params(labelsize=7)
            ax.set_yticks([])
        axes.flat[0].legend(fontsize=7, loc="upper left")
        fig.supxlabel("frequency change from nominal [%]", fontsize=9)
        sp = ", ".join(f"{s['name']} {s['kind']} {100 * s['width']:g} %" for s in self.spreads)
        fig.suptitle(f"{self.title}: {self.samples:,} samples; {sp}", fontsize=9)
        _finish(fig, out)
