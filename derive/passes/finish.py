"""The derivation's steps with their times, and nothing of what the passes handed on."""
from __future__ import annotations

from types import SimpleNamespace

from derive.model import Model

ORDER = 1000
ROUTES = ("coordinates", "multipliers")


def run(model: Model, d):
    d.timings = d.work.steps.timings
    d.work = SimpleNamespace()
    return d
