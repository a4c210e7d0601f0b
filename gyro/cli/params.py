"""`gyro params MODEL`"""
from __future__ import annotations

from gyro.cli.common import add_model

ORDER = 40


def register(sub) -> None:
    p = sub.add_parser("params", help="list a model's parameters with the paper example's values")
    add_model(p)
    p.set_defaults(run=run)


def run(args) -> int:
    from gyro.models import load

    model = load(args.model)
    print(f"{'name':<8} {'default':>14} {'unit':<10} description")
    for p in model.params:
        print(f"{p.name:<8} {p.default:>14.8g} {p.unit:<10} {p.description}")
    if model.aliases:  # every command prints the name above and takes these for it too
        print("also taken: " + ", ".join(f"{a} for {n}" for a, n in model.aliases.items()))
    own = model.meta.get("simulate")  # a motion of the model's own (Model.simulate)
    if own and own.get("initial"):  # its initial conditions, taken by gyro simulate as --set
        from gyro.catalog import declared_module

        print(f"initial conditions (gyro simulate; {own['initial']}):")
        for name, (unit, default, description) in declared_module(own["module"], f"{model.name}'s motion", model).INITIAL.items():
            print(f"{name:<8} {default:>14.8g} {unit:<10} {description}")
    if own and own.get("usage"):
        print(f"gyro simulate {model.name}: {own['usage']}")
    return 0
