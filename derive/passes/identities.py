"""The model's own identities (Model.identities), each a residual that must vanish."""
from __future__ import annotations

from derive.model import Model

ORDER = 50
ROUTES = ("coordinates", "multipliers")  # a declared check runs on either route


def run(model: Model, d):
    for name, identity in model.identities.items():
        with d.work.steps(f"identity: {name}"):
            residual = identity()
            bad = [r for r in residual if r != 0]
            if bad:
                raise AssertionError(f"identity failed: {name}: {bad[0]}")
    return d
