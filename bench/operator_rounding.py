"""`python -m bench.operator_rounding [--sets N] [--seed S] [--timing-sets T]`: the operator's
rounding as the certificate takes it (gyro.rounding.operator_rounding: an enclosure) and as
the double eigen-methods estimate it (gyro.qep.equilibrium_moves: two probes), against the
exact operator at the exact equilibrium (the generated mpmath at 50 digits, the equilibrium
by Newton on equilibrium_system from the double one), entry by entry, on N random sets per
model, each parameter 0.05x..20x of the model's own values (log-uniform; bench.estimates'
draw), the gyrohorizoncompass also at its sets near epsilon0 = 89.99 deg: how many entries
each beats, and the enclosure's ratio bound / actual (median, max) over the entries with an
error. Then the cost per set of each on T sets of 0.5x..2x of the gyrohorizoncompass and the
torsion gyrocompass (the operator, the probes, the enclosure of the operator used, the
equilibrium's radius, the twin's operator with its bound as the certificate takes it:
interleaved, the best of five runs each, this shared machine's load moving single runs by
up to 2x), and of the frequencies' certificate with each (`certificate_timing`).
Writes bench/results/operator_rounding.json."""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import mpmath
import numpy as np

from gyro import qep, rounding
from gyro.equilibrium import equilibria, operators
from gyro.models import load

RESULTS = Path(__file__).resolve().parent / "results"
MODELS = ("gyrohorizoncompass", "torsion_gyrocompass", "gimbal_precession")
SLACK = 1e-35  # of a matrix's largest entry: the 50-digit reference's own error
# the gyrohorizoncompass near its pole (epsilon0 = 89.99 deg), where the probes were beaten
GHC_POLE = [[0.00891457345593651, 0.07687904974819619, 0.020726864493078076, 0.012161555614522012,
             39.25726238884601, 4811.424128502412, 8.158136360126162e-05, 2.1605031009658176e-06,
             0.0009753751426403708, 1.0000000470883692]]


def draw(model, n: int, seed: int, low=0.05, high=20.0) -> np.ndarray:
    """n sets, every parameter low..high times the model's own value, log-uniform."""
    rng = np.random.default_rng(seed)
    return model.vector()[None] * np.exp(rng.uniform(np.log(low), np.log(high), (n, len(model.param_names))))


def exact(model, p, q, digits: int = 50):
    """(the exact equilibrium near q: five Newton steps on the emitted equilibrium_system at
    `digits`, which take a double equilibrium's 1e-16 below 1e-40; the exact operator there),
    as mpmath numbers; call within mpmath.workdps(digits)."""
    ps, q = [mpmath.mpf(x) for x in p], [mpmath.mpf(x) for x in q]
    if q:
        for _ in range(5):
            r, Kn = model.mpmath.equilibrium_system(ps, q)
            dq = mpmath.lu_solve(Kn, r)
            q = [q[i] + dq[i] for i in range(len(q))]
    return q, model.mpmath.operator(ps, q)


def distance(X, Xe) -> np.ndarray:
    """|X - Xe| entrywise, X doubles and Xe an mpmath matrix."""
    n, m = X.shape
    return np.array([[float(abs(mpmath.mpf(X[i, j]) - Xe[i, j])) for j in range(m)] for i in range(n)])


def check(name: str, n: int, seed: int) -> dict:
    m = load(name)
    P = draw(m, n, seed)
    if name == "gyrohorizoncompass":
        P = np.vstack([P, GHC_POLE])
    qe, ok = equilibria(m, P)
    P, qe = P[ok], qe[ok]
    M, D, K = operators(m, P, qe)
    enc = rounding.operator_rounding(m, P, qe, M, D, K)
    probes = qep.equilibrium_moves(m, P, qe, M, D, K)
    beaten = {"enclosure": 0, "probes": 0}
    ratios, missed, entries, unproven = [], 0, 0, 0
    with mpmath.workdps(50):
        for k in range(len(P)):
            _, ops = exact(m, P[k], qe[k])
            for X, e, pr, Xe in zip((M, D, K), enc, probes, ops):
                act = distance(X[k], Xe)
                slack = SLACK * np.max(np.abs(X[k]))
                beaten["enclosure"] += int(np.sum(act > e[k] + slack))
                beaten["probes"] += int(np.sum(act > pr[k] + slack))
                missed += int(np.sum((act > slack) & (pr[k] == 0)))
                unproven += int(np.sum(~np.isfinite(e[k])))
                real = act > slack
                entries += act.size
                ratios += list(e[k][real] / act[real])
    r = np.array(ratios)
    return {"model": name, "sets": int(len(P)), "entries": entries, "beaten": beaten,
            "entries_the_probes_leave_at_zero_with_an_error": missed, "infinite_bounds": unproven,
            "ratio_bound_over_actual": {"median": float(np.median(r)), "max": float(np.max(r)),
                                        "min": float(np.min(r)), "entries": int(r.size)}}


def timing(name: str, n: int) -> dict:
    m = load(name)
    P = draw(m, n, 1, 0.5, 2.0)
    qe, ok = equilibria(m, P)
    P, qe = P[ok], qe[ok]
    M, D, K = operators(m, P, qe)
    rounding.operator_rounding(m, P[:8], qe[:8], M[:8], D[:8], K[:8])  # compiled before timing
    runs = {"operator": lambda: operators(m, P, qe),
            "probes": lambda: qep.equilibrium_moves(m, P, qe, M, D, K),
            "enclosure": lambda: rounding.operator_rounding(m, P, qe, M, D, K),
            "equilibrium_radius": lambda: rounding.equilibrium_radius(m, P, qe),
            "operator_enclosed": lambda: rounding.operator_enclosed(m, P, qe)}
    best = {k: np.inf for k in runs}
    for _ in range(5):
        for k, f in runs.items():
            t = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t)
    out = {f"{k}_us_per_set": v / len(P) * 1e6 for k, v in best.items()}
    out["sets"] = int(len(P))
    out["enclosure_over_probes"] = best["enclosure"] / best["probes"]
    return out


def certificate_timing(n: int, seed: int = 36) -> dict:
    """The frequencies' certificate's shared part per set (gyro.questions.frequencies._exact:
    the equilibrium, the operator and its rounding, the count at 0), with the enclosure
    (rounding.operator_enclosed: the twin's operator and its bound) and, in the same run, with
    the runtime's operator and the two probes in its place, beside the exact level (the default
    method) on the same sets: n sets of bench.levels' joint spread of the torsion
    gyrocompass, interleaved, the best of five runs each."""
    from bench.levels import joint
    from gyro import ladder
    from gyro.questions import frequencies as F

    m = load("torsion_gyrocompass")
    P = joint(n, seed)

    def probes(model, P, qe):  # the runtime's operator and the two probes in its place
        M, D, K = (np.ascontiguousarray(X, dtype=float) for X in operators(model, P, qe))
        return (M, D, K, *qep.equilibrium_moves(model, P, qe, M, D, K))

    enclosure = rounding.operator_enclosed
    F._exact(m, P[:8])
    runs = {"with_enclosure": lambda: F._exact(m, P), "with_probes": lambda: F._exact(m, P),
            "exact_level": lambda: ladder.spectrum(m, P, "default")}
    best = {k: np.inf for k in runs}
    for _ in range(5):
        for k, f in runs.items():
            rounding.operator_enclosed = probes if k == "with_probes" else enclosure
            try:
                t = time.perf_counter()
                f()
                best[k] = min(best[k], time.perf_counter() - t)
            finally:
                rounding.operator_enclosed = enclosure
    out = {f"{k}_us_per_set": v / n * 1e6 for k, v in best.items()}
    out["sets"] = n
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(prog="python -m bench.operator_rounding", description=__doc__.split("\n\n")[0])
    ap.add_argument("--sets", type=int, default=100)
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--timing-sets", type=int, default=4000)
    a = ap.parse_args(argv)
    out = {"seed": a.seed, "checks": [], "timing": {}}
    for name in MODELS:
        c = check(name, a.sets, a.seed)
        print(json.dumps(c), flush=True)
        out["checks"].append(c)
    for name in MODELS[:2]:  # gimbal_precession's sets of 0.5x..2x have no equilibrium to time
        t = timing(name, a.timing_sets)
        print(name, json.dumps(t), flush=True)
        out["timing"][name] = t
    out["certificate"] = certificate_timing(a.timing_sets)
    print("certificate", json.dumps(out["certificate"]), flush=True)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "operator_rounding.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
