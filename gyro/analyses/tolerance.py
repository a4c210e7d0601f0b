"""Tolerance analysis: the distribution of every natural frequency when parameters are made
to a tolerance, first order from the exact sensitivities and sampled, side by side.

A spread is relative to the parameter's nominal value: normal with standard deviation
SIGMA, or uniform within +-HALFWIDTH; spreads may be correlated (a Gaussian copula: the
correlated standard normals z = L e, L the Cholesky factor of the correlation matrix; a
uniform parameter takes Phi(z)). Sampling runs over the sweep executor (gyro.executor) in
chunks of CHUNK samples; the samples come in blocks of STREAM, block b from the
generator seeded with (seed, b), whatever the chunks: a chunk is a pure function of its
inputs, and any executor and any chunk size give the same samples and the same bits. The frequencies are the default method's (the model hierarchy's selector of
the cheapest adequate level is not in this tree yet). A sample outside a parameter's
valid range, or without an answer, is counted in `failed`, never dropped silently.

First order: std_i = sqrt(S_i C S_i^T), S the sensitivities at the nominal set, C the
covariance of the parameters (the copula's correlation carried to uniform marginals:
(6/pi) asin(rho/2) between two uniforms, rho sqrt(3/pi) between a normal and a uniform).

The band probability: the chance that omega_i falls within +-band (relative) of a
harmonic k omega_c of the spin rate omega_c as the model declares it (Model.spin, the
emitted spin_rate: H/C, the rotor's angular momentum over its polar moment, for the torsion
gyrocompass; any model that declares its spin), sampled, and to first order from the
sensitivities of omega_i - k omega_c."""
from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gyro import executor, ladder
from gyro.analyses.sweep import model_ref, warm
from gyro.errors import ParameterError, terminable
from gyro.models import Model, load
from gyro.results import ToleranceStudy

CHUNK = 4096  # samples per chunk: the unit of work and of retry
STREAM = 4096  # samples per random stream: block b of the study draws from (seed, b)
QUANTILES = (0.01, 0.5, 0.99)
BINS = 60
IN_MEMORY = 1 << 28  # bytes: larger results go to .npy memory maps on disk


@dataclass(frozen=True)
class Spread:
    name: str
    kind: str  # "normal" or "uniform"
    width: float  # relative: sigma, or the half-width

    @property
    def std(self) -> float:
        """Relative standard deviation."""
        return self.width if self.kind == "normal" else self.width / np.sqrt(3.0)


def parse_spread(text: str) -> Spread:
    name, sep, rest = text.partition("=")
    kind, sep2, width = rest.partition(":")
    if not sep or not sep2 or kind not in ("normal", "uniform"):
        raise ParameterError(f"--spread {text!r}: expected NAME=normal:SIGMA or NAME=uniform:HALFWIDTH")
    try:
        w = float(width)
    except ValueError:
        raise ParameterError(f"--spread {text!r}: {width!r} is not a number") from None
    if not (np.isfinite(w) and 0 < w < 1):
        raise ParameterError(f"--spread {name}: the relative width must lie in (0, 1), got {width}")
    return Spread(name.strip(), kind, w)


def copula_correlation(spreads: list[Spread], corr: np.ndarray) -> np.ndarray:
    """The correlation of the parameters themselves from that of the copula's normals."""
    c = corr.copy()
    for i, a in enumerate(spreads):
        for j, b in enumerate(spreads):
            if i == j:
                continue
            if a.kind == b.kind == "uniform":
                c[i, j] = 6 / np.pi * np.arcsin(corr[i, j] / 2)
            elif a.kind != b.kind:
                c[i, j] = corr[i, j] * np.sqrt(3 / np.pi)
    return c


def correlation(spreads: list[Spread], pairs: dict) -> np.ndarray:
    """The copula's correlation matrix from {(A, B): rho}; positive definite or refused."""
    names = [s.name for s in spreads]
    c = np.eye(len(spreads))
    seen = set()
    for (a, b), rho in pairs.items():
        if frozenset((a, b)) in seen:  # A,B and B,A: two values for one correlation
            raise ParameterError(f"--correlate {a},{b}: the pair is given twice")
        seen.add(frozenset((a, b)))
        for x in (a, b):
            if x not in names:
                raise ParameterError(f"--correlate {a},{b}: {x} has no --spread")
        if a == b or not -1 < rho < 1:
            raise ParameterError(f"--correlate {a},{b}={rho}: need two parameters and -1 < RHO < 1")
        i, j = names.index(a), names.index(b)
        c[i, j] = c[j, i] = rho
    if np.min(np.linalg.eigvalsh(c)) <= 1e-12:
        raise ParameterError("--correlate: the correlations are not positive definite (no such joint spread)")
    return c


def spin_rate(model: Model, P: np.ndarray) -> np.ndarray | None:
    """The spin rate omega_c in rad/s per set, as the model declares it (Model.spin, the
    emitted spin_rate: H/C for the torsion gyrocompass), or None for a model that declares
    no spin."""
    from gyro.analyses.spin import spin_rates

    declared = model.meta.get("spin", {}).get("parameter")
    if declared is None:
        return None
    return spin_rates(model, declared, np.atleast_2d(P))


def spin_rate_gradient(model: Model, p0: np.ndarray) -> np.ndarray:
    """d omega_c / d p at the set p0: the emitted derivatives of the declared spin rate."""
    from gyro.kernels import function

    if "spin_rate_gradient" not in model.meta["functions"]:
        raise ParameterError(f"--harmonics: {model.name} was emitted without spin_rate_gradient "
                             "(derive it again with this version)")
    with np.errstate(all="ignore"):
        return np.asarray(function(model, "spin_rate_gradient")(np.asarray(p0, float)[None])[0], float).reshape(-1)


def samples(nominal, index, relwidth, uniform, chol, seed, start, stop):
    """The parameter sets start..stop of the study: the rows start..stop of the blocks of
    STREAM draws, block b from the generator seeded with (seed, b), so that they do not
    depend on how the study is cut into chunks."""
    from scipy.special import ndtr

    first, last = start // STREAM, max(stop - 1, start) // STREAM
    e = np.concatenate([np.random.default_rng([seed, b]).standard_normal((STREAM, len(index)))
                        for b in range(first, last + 1)])
    z = e[start - first * STREAM: stop - first * STREAM] @ chol.T
    dev = np.where(uniform, 2 * ndtr(z) - 1, z) * relwidth
    P = np.tile(nominal, (stop - start, 1))
    P[:, index] *= 1 + dev
    return P


def valid(model: Model, P: np.ndarray) -> np.ndarray:
    """Sets whose every parameter is within its valid range (Param.check, vectorised)."""
    ok = np.all(np.isfinite(P), axis=1)
    for j, p in enumerate(model.params):
        v = P[:, j]
        if p.kind == "positive":
            ok &= v > 0
        elif p.kind == "nonnegative":
            ok &= v >= 0
        lo, hi = p.bounds
        if lo is not None:
            ok &= v >= lo
        if hi is not None:
            ok &= v <= hi
    return ok


def chunk(start, stop, model_ref, nominal, index, relwidth, uniform, chol, seed):
    """One chunk of the study: the samples' frequencies (NaN where failed) and spin rates."""
    model = load(model_ref)
    P = samples(nominal, index, relwidth, uniform, chol, seed, start, stop)
    ok = valid(model, P)
    n = len(model.meta["reduced"])
    freq = np.full((stop - start, n), np.nan)
    if ok.any():
        spec = ladder.spectrum(model, P[ok], "default")
        freq[ok] = spec.frequencies
    spin = spin_rate(model, P)
    out = {"frequencies": freq}
    if spin is not None:
        out["spin"] = spin
    return out


def tolerance(model: Model, values: dict, spreads: list[Spread], n: int, seed: int = 0,
              pairs: dict | None = None, scheduler=None, harmonics=(), band: float = 0.02,
              store: Path | None = None, progress: bool = False, size: int = CHUNK) -> ToleranceStudy:
    """The study over n samples, `size` samples a chunk (the samples and the answer do not
    depend on it: the random streams come in blocks of STREAM)."""
    from gyro.analyses.sensitivity import sensitivities

    # by the declared names (another name taken for a parameter, as lambda for lam, too)
    spreads = [Spread(model.param_name(s.name, "--spread"), s.kind, s.width) for s in spreads]
    pairs = {(model.canonical(a), model.canonical(b)): rho for (a, b), rho in (pairs or {}).items()}
    names = [s.name for s in spreads]
    if not 2 <= n:
        raise ParameterError(f"--samples: need at least 2 (one sample has no standard deviation), got {n}")
    for s in spreads:
        if values[s.name] == 0:
            raise ParameterError(f"--spread {s.name}: its value is 0, so a relative spread moves nothing")
    if len(set(names)) != len(names):
        raise ParameterError("--spread: a parameter is given twice")
    if harmonics and spin_rate(model, model.vector(values)[None]) is None:
        raise ParameterError(f"--harmonics: {model.name} declares no spin (Model.spin: the parameter that "
                             "sets it and its rate): no harmonic k omega_c to fall on")
    if harmonics and not spin_rate(model, model.vector(values)[None])[0] > 0:
        raise ParameterError(f"--harmonics: the rotor does not spin at this set ({model.meta['spin']['parameter']} "
                             "gives a spin rate of 0): no harmonic k omega_c to fall on")
    corr = correlation(spreads, pairs or {})
    chol = np.linalg.cholesky(corr)
    nominal = model.vector(values)
    index = np.array([model.param_names.index(x) for x in names])
    relwidth = np.array([s.width for s in spreads])
    uniform = np.array([s.kind == "uniform" for s in spreads])
    nomspec = ladder.spectrum(model, nominal, "default")
    ladder.require_finite(model, nomspec, "the nominal set")  # nothing to spread: refused before sampling
    sens = sensitivities(model, nominal, nomspec)
    # first order
    sd = np.array([s.std for s in spreads]) * nominal[index]
    cov = copula_correlation(spreads, corr) * np.outer(sd, sd)
    S = sens.d[0][:, index]
    first_std = np.sqrt(np.einsum("ij,jk,ik->i", S, cov, S))
    nmodes = nomspec.frequencies.shape[1]
    folder, tmp, out, F = store, None, None, None
    with terminable():  # SIGTERM as Ctrl-C here: the chunks return to Python often
        try:  # the temporary folder made inside: Ctrl-C, SIGTERM or MemoryError after finds it
            if folder is None and n * (nmodes + 1) * 8 > IN_MEMORY:
                tmp = tempfile.TemporaryDirectory(prefix="gyro-tolerance-")
                folder = Path(tmp.name)
            ref = model_ref(model)
            out = executor.run(chunk, n, size, (ref, nominal, index, relwidth, uniform, chol, seed), scheduler,
                               folder, progress, "tolerance", warm=warm, warm_args=(ref,))
            F = out["frequencies"]
            ok = np.all(np.isfinite(F), axis=1)
            stats = _stats(F, ok)
            bands = None
            if harmonics:
                spin = out["spin"]
                bands = _bands(F, ok, spin, harmonics, band, nomspec.frequencies[0], sens.d[0], model, nominal, cov,
                               index)
        finally:
            if tmp is not None:
                out = F = None  # the memory maps closed before their folder goes
                tmp.cleanup()
    return ToleranceStudy(model.name, model.meta["title"], n, seed, [s.__dict__ for s in spreads],
                          {f"{a},{b}": r for (a, b), r in (pairs or {}).items()},
                          nomspec.frequencies[0], sens, index, first_std, int(np.sum(~ok)), *stats,
                          harmonics=list(harmonics), band=band, band_probability=bands,
                          method="default")


def _stats(F, ok):
    """Per mode over the sets with an answer: mean, std, quantiles, histogram."""
    nm = F.shape[1]
    mean, std, skew = np.full(nm, np.nan), np.full(nm, np.nan), np.full(nm, np.nan)
    q = np.full((nm, len(QUANTILES)), np.nan)
    counts, edges = np.zeros((nm, BINS), int), np.zeros((nm, BINS + 1))
    kurt = np.full(nm, np.nan)
    idx = np.flatnonzero(ok)
    for i in range(nm):
        if idx.size == 0:
            break
        col = np.asarray(F[:, i])[idx]  # one column at a time: a memory map is read in strides
        mean[i] = col.mean()
        dev = col - mean[i]
        # one answered sample has no spread: its std stays NaN (shown as none), never 0
        std[i] = np.sqrt(np.mean(dev**2) * idx.size / (idx.size - 1)) if idx.size > 1 else np.nan
        if std[i] > 0:
            skew[i] = np.mean(dev**3) / std[i] ** 3
            kurt[i] = np.mean(dev**4) / std[i] ** 4
        q[i] = np.quantile(col, QUANTILES)
        lo, hi = np.quantile(col, (0.0005, 0.9995))
        if not hi - lo > 1e-9 * max(abs(lo), abs(hi)):
            # a frequency the spreads do not move (omega_p = sqrt(Kp/m) under a spread of H):
            # its samples differ by rounding only, too little for BINS bins of their own
            mid = 0.5 * (lo + hi)
            half = 1e-6 * abs(mid) if mid != 0 else 0.5
            lo, hi = min(mid - half, col.min()), max(mid + half, col.max())
        counts[i], edges[i] = np.histogram(col, bins=BINS, range=(lo, hi))
    return mean, std, skew, kurt, q, counts, edges


def _bands(F, ok, spin, harmonics, band, nominal_freq, dfreq, model, nominal, cov, index):
    """[mode][harmonic]: sampled probability of |omega_i / (k omega_c) - 1| < band, and the
    first-order one (a normal omega_i - k omega_c)."""
    from scipy.special import ndtr

    wc0 = float(spin_rate(model, np.asarray(nominal, float)[None])[0])
    dwc = spin_rate_gradient(model, np.asarray(nominal, float))
    out = []
    n_ok = max(int(ok.sum()), 1)
    for i in range(F.shape[1]):
        col = np.asarray(F[:, i])
        row = []
        for k in harmonics:
            with np.errstate(invalid="ignore"):
                inside = ok & (np.abs(col / (k * spin) - 1) < band)
            # first order: the band is (1 - band) k omega_c < omega_i < (1 + band) k omega_c,
            # both edges moving with omega_c; with y_e = omega_i - e k omega_c linearised
            # (normal, mean mu_e, std s_e) and y_lower > y_upper, P = P(y_lower > 0) -
            # P(y_upper > 0). Each edge has its own std: omega_c enters it with the factor
            # e k, not k (a band of 55 % and a 1 % spread of C: 0.25 against the sampled
            # 0.066 with k alone)
            fo = 0.0
            for e, sign in ((1 - band, 1.0), (1 + band, -1.0)):
                g = dfreq[i][index] - e * k * dwc[index]
                s = float(np.sqrt(g @ cov @ g))
                mu = nominal_freq[i] - e * k * wc0
                # no sensitivities (a double root at the nominal set): no first order, NaN
                fo += sign * (float(ndtr(mu / s)) if s > 0 else float(mu > 0) if s == 0 else np.nan)
            hit, n_all = int(inside.sum()), len(ok)
            # the sampled probability is conditional on the answered samples; over all of
            # them it lies between "no failed sample was in the band" and "every one was"
            row.append({"harmonic": k, "omega": k * wc0, "probability": hit / n_ok,
                        "probability_range": [hit / n_all, (hit + n_all - int(ok.sum())) / n_all],
                        "first_order_probability": fo})
        out.append(row)
    return out
