"""The exact linear operator about the reference: M q'' + D q' + K q = 0, J(p), and for a
system with forces or explicit time its parts G (skew), D_s (symmetric), K_s, K_c."""
from __future__ import annotations

import sympy as sp

from derive.model import Function

ORDER = 20
P_SYMBOL = sp.Symbol("p")
MATRICES = ("M", "D", "K", "J", "J_re", "J_im", "Mq", "G", "Ds", "Ks", "Kc", "B")


# an entry of more operations than this is emitted as it comes, not expanded: expand has no
# bound on its work, and a four-bar on sympy's joints (relative angles, two multipliers) has
# a K of 7,370 operations whose expansion took 85 s; the parts' cancellations it would find
# are exact zeros that rounding gives as 1e-16 of the entry instead (the paper models'
# largest entry, the torsion gyrocompass's K_s, has 1,125: expanded as before)
EXPAND_OPS = 2000


def _tidy(X: sp.Matrix) -> sp.Matrix:
    return X.applyfunc(lambda e: sp.expand(e) if sp.count_ops(e) <= EXPAND_OPS else e)


def functions(d) -> list[Function]:
    state, op = d.state(), d.operator
    coords = ", ".join(d.order)
    conservative = not (d.model.has_forces or d.time_dependent or d.model.signals)
    what = ("M, K symmetric, D skew." if conservative else
            "D = G + D_s (gyroscopic, dissipative), K = K_s + K_c (potential, circulatory).")
    fns = [Function("operator", state, [("M", op.M), ("D", op.D), ("K", op.K)],
                    "Exact linear operator about the equilibrium qe: M q'' + D q' + K q = 0 "
                    f"over q = ({coords}); {what}", MATRICES),
           Function("operator_J", state + [("pval", [P_SYMBOL])], [("J", op.J(P_SYMBOL))],
                    "J(p) = M p^2 + D p + K of the exact operator at a real p.", MATRICES)]
    pr, pi = sp.symbols("p_re p_im")
    fns.append(Function("operator_J_complex", state + [("pval", [pr, pi])],
                        [("J_re", op.M * (pr**2 - pi**2) + op.D * pr + op.K),
                         ("J_im", op.M * (2 * pr * pi) + op.D * pi)],
                        "J(p) at a complex p = p_re + i p_im, as real and imaginary parts; "
                        "J(i omega) at p = (0, omega).", MATRICES))
    if not conservative:
        half = sp.Rational(1, 2)
        G, Ds = half * (op.D - op.D.T), half * (op.D + op.D.T)
        Ks, Kc = half * (op.K + op.K.T), half * (op.K - op.K.T)
        fns.append(Function("operator_parts", state,
                            [("G", _tidy(G)), ("Ds", _tidy(Ds)), ("Ks", _tidy(Ks)), ("Kc", _tidy(Kc))],
                            "Parts of the operator: D = G + Ds with G skew (gyroscopic, Coriolis) "
                            "and Ds symmetric (dissipation), K = Ks + Kc with Ks symmetric "
                            "(potential) and Kc skew (circulatory).", MATRICES))
    return fns
