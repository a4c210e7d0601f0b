"""Independent anchor frequencies for the tests: `python -m bench.anchor_fixture`.

The ten natural frequencies of the torsion gyrocompass computed only with the baseline
derivation of bench/baseline_mechanics.py (sympy.physics.mechanics: frames, bodies,
LagrangesMethod, Linearizer), which shares no code with this project's derivation
(derive/) or runtime (gyro/). Nothing of either is imported here. For each parameter set:

1. the relative equilibrium is solved from the baseline's own Lagrange equations: Newton
   on the static forcing vector (all velocities zero except the spin, whose rate follows
   from C r2 = H), with the baseline's reduced stiffness K as the Jacobian, started from
   the first-order estimate (2.2);
2. the baseline operator M, D, K (10x10, spin eliminated) is formed there;
3. the roots of det(M p^2 + D p + K) are taken from the generalized eigenproblem and each
   is polished by the secant method on the determinant in 40-digit arithmetic (the roots
   of the double-precision matrices, without the eigensolver's rounding).

The parameter sets move every block of the operator: the paper example, the spin H, the
latitude phi, the three bearing stiffnesses, a light casing, and all parameters at once.
The result is written to tests/fixtures/anchor_frequencies.json, which tests/paper/test_anchors.py
reads (the tests never rerun this: the baseline takes minutes).

    .venv/bin/python -m bench.anchor_fixture            # write the fixture
    .venv/bin/python -m bench.anchor_fixture --out F    # elsewhere

It takes about 3.5 minutes on one core (measured 204 s: the baseline's Lagrange equations
71 s, the first parameter set 95 s because the linearizer forms its Jacobians there, then
about 7 s per set).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import mpmath
import numpy as np
import sympy as sp
import sympy.physics.mechanics as me

from bench import baseline_mechanics as bl

ROOT = Path(__file__).resolve().parent.parent
FIXTURE = ROOT / "tests" / "fixtures" / "anchor_frequencies.json"
COMMAND = ".venv/bin/python -m bench.anchor_fixture"
POLISH_DPS = 40


def parameter_sets() -> dict[str, dict]:
    """Name -> overrides of the paper example (bench.baseline_mechanics.paper_params)."""
    p = bl.paper_params()
    A = p["A"]
    return {
        "paper example": {},
        "spin H x 0.3": {"H": 0.3 * p["H"]},
        "latitude 20 deg": {"phi": 20.0},
        "bearings K0 x 0.2, Kp x 3, Kgamma x 0.5": {
            "K0": 0.2 * p["K0"], "Kp": 3.0 * p["Kp"], "Kgamma": 0.5 * p["Kgamma"]},
        "light casing": {"M": 0.2, "I1": A, "I2": A + 2e-4, "I3": 1e-4},
        "all parameters moved": {
            "m": 0.5, "M": 0.8, "l": 0.2, "l1": 0.1, "l2": 0.3, "A": 1.5e-4, "C": 2.5e-4,
            "I1": 8e-3, "I2": 9e-3, "I3": 5e-4, "K0": 5e4, "Kp": 4e5, "Kgamma": 60.0,
            "H": 0.8, "u": 7.2921e-5, "phi": 45.0, "g": 9.80665},
    }


# --------------------------------------------------------------------------- equilibrium


class Statics:
    """The baseline's forcing vector at rest in the rotating frame (all velocities zero
    except the spin rate), evaluated numerically."""

    def __init__(self, system: bl.BaselineSystem):
        self.system = system
        self.spin = system.qd[bl.COORD_NAMES_11.index("gamma3")]
        others = {qd: 0 for qd in system.qd if qd != self.spin}
        # LagrangesMethod: mass_matrix q'' = forcing; at rest q'' = 0 and the forcing is the
        # static (gravity, bearings, centrifugal, gyroscopic with the spin) generalised force
        self.forcing = me.msubs(system.lagranges_method.forcing, others)

    def spin_rate(self, params: dict, q_op: dict) -> float:
        par = bl._numeric_substitutions(self.system, params)
        qd0 = {qd: 0.0 for qd in self.system.qd}
        transport = float(me.msubs(self.system.r2, q_op, qd0, par))
        return float(params["H"]) / float(params["C"]) - transport

    def residual(self, params: dict, q_op: dict) -> np.ndarray:
        """The 11 generalised forces (order COORD_NAMES_11) at the steady motion q_op."""
        par = bl._numeric_substitutions(self.system, params)
        f = me.msubs(self.forcing, q_op, {self.spin: self.spin_rate(params, q_op)}, par)
        return np.array([float(x) for x in f], dtype=float)


def _q_op(system: bl.BaselineSystem, q0: dict) -> dict:
    q_op = {qi: 0.0 for qi in system.q}
    for name, value in q0.items():
        q_op[system.q[bl.COORD_NAMES_11.index(name)]] = float(value)
    return q_op


def solve_equilibrium(system, statics: Statics, params: dict, progress=print,
                      tol: float = 1e-13, max_iter: int = 8):
    """Newton on the baseline's static forces, with its reduced K (at fixed H) as Jacobian.

    Returns (q0, report): q0 maps EQUILIBRIUM_NAMES to values; report holds the final
    residuals (scaled) and the size of the update of the coordinates that must stay zero.
    """
    q0 = bl.approximate_equilibrium(params)
    keep = [bl.COORD_NAMES_11.index(n) for n in bl.COORD_NAMES_10]
    eq_idx = [bl.COORD_NAMES_10.index(n) for n in bl.EQUILIBRIUM_NAMES]
    zero_idx = [i for i in range(10) if i not in eq_idx]
    s = bl.COORD_NAMES_11.index("gamma3")
    report = {"iterations": 0}
    for it in range(1, max_iter + 1):
        f = statics.residual(params, _q_op(system, q0))
        _, _, K10 = bl.baseline_operator(params, q0, system=system)
        # M q'' = f(q) and K = -df/dq at fixed H:  f(q0 + dq) = f(q0) - K dq = 0
        dq = np.linalg.solve(K10, f[keep])
        step = {n: float(dq[i]) for n, i in zip(bl.EQUILIBRIUM_NAMES, eq_idx)}
        q0 = {n: q0[n] + step[n] for n in bl.EQUILIBRIUM_NAMES}
        report.update(iterations=it, spin_equation_residual=float(f[s]),
                      max_update_of_zero_coordinates=float(np.max(np.abs(dq[zero_idx]))))
        rel = max(abs(step[n]) / max(abs(q0[n]), 1e-300) for n in step)
        progress(f"    Newton {it}: largest relative update {rel:.1e}")
        if rel <= tol:
            break
    else:
        raise RuntimeError(f"equilibrium: no convergence in {max_iter} steps")
    f = statics.residual(params, _q_op(system, q0))
    report["final_force_residual"] = [float(x) for x in f[keep]]
    return q0, report


# --------------------------------------------------------------------------- roots


def polished_frequencies(M, D, K, dps: int = POLISH_DPS) -> tuple[np.ndarray, float]:
    """Frequencies of det(M p^2 + D p + K) = 0: eigenvalues, then each root polished by the
    secant method on the determinant in `dps` digits. Returns (frequencies, largest relative
    change made by the polishing)."""
    w0 = bl.natural_frequencies(M, D, K)
    if len(w0) != 10:
        raise RuntimeError(f"expected ten frequencies, got {len(w0)}")
    with mpmath.workdps(dps):
        Mm, Dm, Km = (mpmath.matrix(X.tolist()) for X in (M, D, K))

        def det(p):
            return mpmath.det(Mm * p**2 + Dm * p + Km)

        out = []
        for w in w0:
            a, b = mpmath.mpc(0, w), mpmath.mpc(0, w * (1 + 1e-9))
            fa, fb = det(a), det(b)
            for _ in range(50):  # secant; the determinant's scale does not matter
                if fb == fa:
                    break
                a, b, fa = b, b - fb * (b - a) / (fb - fa), fb
                fb = det(b)
                if abs(b - a) <= abs(b) * mpmath.mpf(10) ** (-dps + 5):
                    break
            else:
                raise RuntimeError(f"secant did not converge near {w}")
            if abs(mpmath.re(b)) > 1e-12 * abs(b):
                raise RuntimeError(f"root {b} is not on the imaginary axis")
            out.append(float(mpmath.im(b)))
    out = np.array(out)
    if np.any(np.diff(out) <= 0):
        raise RuntimeError("polishing merged or reordered roots")
    return out, float(np.max(np.abs(out / w0 - 1)))


# --------------------------------------------------------------------------- main


def build(progress=print) -> dict:
    t0 = time.perf_counter()
    system = bl.derive_baseline(progress)
    statics = Statics(system)
    progress(f"baseline derived in {time.perf_counter() - t0:.1f} s")
    base = bl.paper_params()
    sets = []
    for name, over in parameter_sets().items():
        t1 = time.perf_counter()
        params = {**base, **over}
        progress(f"{name}:")
        q0, report = solve_equilibrium(system, statics, params, progress)
        M, D, K = bl.baseline_operator(params, q0, system=system)
        w, polish = polished_frequencies(M, D, K)
        sets.append({
            "name": name, "overrides": over, "params": params,
            "equilibrium": q0, "equilibrium_report": report,
            "frequencies": [float(x) for x in w],
            "polishing_max_rel_change": polish,
            "M_symmetry_error": float(np.max(np.abs(M - M.T))),
        })
        progress(f"    {time.perf_counter() - t1:.1f} s; frequencies "
                 + ", ".join(f"{x:.10g}" for x in w))
    return {
        "description": (
            "Natural frequencies (rad/s, ascending) of the torsion gyrocompass at its exact "
            "relative equilibrium, from the independent sympy.physics.mechanics baseline "
            "(bench/baseline_mechanics.py) only; no code of derive/ or gyro/ is used. "
            "Parameters in SI units, phi in degrees; equilibrium coordinates in m and rad."),
        "command": COMMAND,
        "sympy": sp.__version__,
        "numpy": np.__version__,
        "seconds": round(time.perf_counter() - t0, 1),
        "sets": sets,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m bench.anchor_fixture", description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=FIXTURE, help=f"output JSON (default {FIXTURE.relative_to(ROOT)})")
    args = ap.parse_args(argv)
    data = build()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp = args.out.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(args.out)
    print(f"written {args.out} in {data['seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
