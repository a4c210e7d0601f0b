"""The `gyro` command line.

    gyro frequencies MODEL [--set NAME=VALUE]... [--json]
    gyro params MODEL
    gyro simulate gimbal_gyroscope [--set NAME=VALUE]... --t-end T [--points N] [--method NAME] [--json] [--out FILE.png]

Bad input prints one line on stderr naming the parameter and exits with code 2.
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from gyro.models import ParameterError, load
from gyro.simulate import add_parser as add_simulate

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """argparse that reports a usage error in one line and exits with 2."""

    def error(self, message):
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def _parse_sets(items: list[str]) -> dict[str, str]:
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError(f"--set {item!r}: expected NAME=VALUE")
        out[name.strip()] = value.strip()
    return out


def _frequencies(args) -> int:
    from gyro.modal import natural_frequencies

    model = load(args.model)
    if model.meta.get("momenta"):
        raise ParameterError(f"{model.name}: its operator depends on the momenta "
                             f"{', '.join(model.meta['momenta'])} of a stationary motion; "
                             "'frequencies' covers models with a relative equilibrium")
    values = model.parameters(_parse_sets(args.set))
    result = natural_frequencies(model, values)
    if not np.all(np.isfinite(result.frequencies + result.eigenvalues_re)):
        raise FloatingPointError("a frequency is not finite")
    if args.json:
        print(json.dumps({
            "model": model.name,
            "params": values,
            "frequencies": result.frequencies,
            "equilibrium": result.equilibrium,
            "eigenvalues_re": result.eigenvalues_re,
        }, allow_nan=False))
        return 0
    print(f"{model.meta['title']} ({model.name})")
    print("natural frequencies of the exact operator about the exact equilibrium:")
    print(f"{'':>4} {'omega [rad/s]':>16} {'f [Hz]':>14} {'period [s]':>14}")
    for i, w in enumerate(result.frequencies, 1):
        period = 2 * 3.141592653589793 / w if w > 0 else float("inf")
        print(f"{i:>4} {w:>16.9g} {w / (2 * 3.141592653589793):>14.6g} {period:>14.6g}")
    return 0


def _params(args) -> int:
    model = load(args.model)
    print(f"{'name':<8} {'default':>14} {'unit':<10} description")
    for p in model.params:
        print(f"{p.name:<8} {p.default:>14.8g} {p.unit:<10} {p.description}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="gyro", description="Gyroscope dynamics from generated models.")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    f = sub.add_parser("frequencies", help="natural frequencies of a model's exact linear operator")
    f.add_argument("model")
    f.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="parameter value in SI units (phi in degrees); repeat as needed")
    f.add_argument("--json", action="store_true", help="print one JSON object")
    f.set_defaults(run=_frequencies)
    p = sub.add_parser("params", help="list a model's parameters with the paper example's values")
    p.add_argument("model")
    p.set_defaults(run=_params)
    add_simulate(sub)
    return ap


def main(argv=None) -> int:
    from gyro.modal import EquilibriumError

    args = build_parser().parse_args(argv)
    try:
        with np.errstate(all="ignore"):  # failures are caught below, one line each
            return args.run(args)
    except ParameterError as exc:
        print(f"gyro: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except EquilibriumError as exc:
        print(f"gyro: error: no equilibrium found: {exc}", file=sys.stderr)
        return 1
    except (np.linalg.LinAlgError, FloatingPointError, ValueError, OverflowError) as exc:
        # valid input whose numbers the double-precision solvers cannot handle (e.g. 1e300)
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"gyro: error: numerical failure at these parameters ({msg})", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output closed early (e.g. piped into head)
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
