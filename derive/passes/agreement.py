"""The two routes' comparison, where it ran beside the passes since the operator's
(derive/passes/operator.py): a disagreement stops the derivation all the same."""
from __future__ import annotations

from derive.model import Model
from derive.passes.operator import agree

ORDER = 120
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    if d.work.check is not None and d.work.check.beside:
        with d.work.steps("the two routes agree: the check beside the steps above"):
            d.route_agreement = agree(d.work.check.result())
    return d
