"""Each kink its function again (derive/nonsmooth.py): in the nonlinear equations as they
are, in what is taken at the reference with its argument there; the operator NaN where it
does not exist (nonsmooth.undefined_where). B was thawed where it was made. The derivation
is then of the model as it came, its kinks the model's functions."""
from __future__ import annotations

from derive import mechanics as mech
from derive.model import Model

ORDER = 130
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    kinks, reference = d.work.kinks, d.work.reference
    if kinks.kinks:
        if d.varying:  # a kink's argument with the parameter time-varying too
            for key in ("mass_matrix", "forcing"):
                d.varying[key] = kinks.thaw(d.varying[key]).xreplace(d.varying["sub"])
        d.mass_matrix, d.forcing = kinks.thaw(d.mass_matrix), kinks.thaw(d.forcing)
        d.routhian = kinks.thaw(d.routhian)
        d.equilibrium_residual = kinks.thaw(d.equilibrium_residual, reference)
        op = d.operator
        M, D, K = (kinks.thaw(X, reference) + U for X, U in zip((op.M, op.D, op.K), d.work.undefined))
        d.operator = mech.LinearOperator(M, D, K)
        for v in d.variants.values():
            v.operator = v.operator.applyfunc(lambda e: kinks.thaw(e, reference))
            v.charpoly = [[kinks.thaw(c, reference) for c in block] for block in v.charpoly]
            v.scaled = kinks.thaw(v.scaled, reference)
    d.model = d.work.source
    d.nondifferentiable = dict(kinks.nondifferentiable)
    return d
