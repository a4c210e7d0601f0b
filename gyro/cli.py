"""The `gyro` command line.

    gyro frequencies MODEL [--set NAME=VALUE]... [--method NAME] [--json]
    gyro campbell MODEL [--set NAME=VALUE]... --out FILE.png [--range LO HI] [--points N]
    gyro stability-map MODEL --x NAME --x-range LO HI --y NAME --y-range LO HI [--x-log] [--y-log] --out FILE.png
    gyro params MODEL
    gyro simulate gimbal_gyroscope [--set NAME=VALUE]... --t-end T [--points N] [--method NAME] [--json] [--out FILE.png]

Bad input prints one line on stderr naming the parameter and exits with code 2.
"""
from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from gyro import ladder
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


def _model_with_equilibrium(name):
    model = load(name)
    if model.meta.get("momenta"):
        raise ParameterError(f"{model.name}: its operator depends on the momenta "
                             f"{', '.join(model.meta['momenta'])} of a stationary motion; "
                             "this command covers models with a relative equilibrium")
    return model


def _frequencies(args) -> int:
    model = _model_with_equilibrium(args.model)
    values = model.parameters(_parse_sets(args.set))
    if args.method == "formulas" and "mode_formulas" not in model.meta["functions"]:
        raise ParameterError(f"--method formulas: {model.name} has no approximate formulas")
    spec = ladder.spectrum(model, model.vector(values), args.method)
    freqs, growth, est = spec.frequencies[0], spec.growth[0], spec.error_estimate[0]
    if not np.all(np.isfinite(freqs)):
        raise FloatingPointError("a frequency is not finite")
    stab = ladder.classify(spec)
    eq = (None if spec.equilibrium is None else
          dict(zip(model.meta["equilibrium_coordinates"], map(float, spec.equilibrium[0]))))
    if args.json:
        print(json.dumps({
            "model": model.name,
            "params": values,
            "frequencies": [float(w) for w in freqs],
            "equilibrium": eq,
            "eigenvalues_re": [float(g) for g in growth],
            "method": args.method,
            "error_estimate": [float(e) if np.isfinite(e) else None for e in est],
            "stability": {"class": str(stab.label[0]), "growth_rate": float(stab.growth_rate[0]),
                          "unstable_roots": int(stab.unstable_roots[0])},
        }, allow_nan=False))
        return 0
    print(f"{model.meta['title']} ({model.name})")
    print(f"natural frequencies by the method '{args.method}'"
          + (f" (answered by its {spec.route[0]} rung)" if spec.route is not None else "") + ":")
    print(f"{'':>4} {'omega [rad/s]':>16} {'f [Hz]':>14} {'period [s]':>14} {'rel. error <=':>14}")
    for i, (w, e) in enumerate(zip(freqs, est), 1):
        period = 2 * np.pi / w if w > 0 else float("inf")
        print(f"{i:>4} {w:>16.9g} {w / (2 * np.pi):>14.6g} {period:>14.6g} {e:>14.2g}")
    label = stab.label[0]
    print(f"equilibrium: {label}" + (f", {stab.unstable_roots[0]} growing root(s), the fastest at "
                                     f"{stab.growth_rate[0]:.6g} 1/s" if label == "unstable" else ""))
    return 0


def _campbell(args) -> int:
    from gyro import campbell

    model = _model_with_equilibrium(args.model)
    values = model.parameters(_parse_sets(args.set))
    lo, hi = args.range
    if not (0 < lo < hi):
        raise ParameterError(f"--range: need 0 < LO < HI, got {lo} {hi}")
    if args.points < 2:
        raise ParameterError(f"--points: need at least 2, got {args.points}")
    out = campbell.check_output(args.out)
    data = campbell.sweep(model, values, lo, hi, args.points, progress=not args.quiet)
    campbell.plot(model, data, out)
    print(f"gyro: wrote {out} ({args.points} spins, {data['shaded_fraction']:.0%} of the sweep "
          "has a formula off by more than 1%)")
    return 0


def _stability_map(args) -> int:
    from gyro import campbell

    model = _model_with_equilibrium(args.model)
    values = model.parameters(_parse_sets(args.set))
    for axis, name, (lo, hi), log in (("--x", args.x, args.x_range, args.x_log),
                                      ("--y", args.y, args.y_range, args.y_log)):
        if name not in model.param_names:
            raise ParameterError(f"{axis} {name!r}: unknown parameter; known: {' '.join(model.param_names)}")
        if not lo < hi:
            raise ParameterError(f"{axis}-range: need LO < HI, got {lo} {hi}")
        if log and not lo > 0:
            raise ParameterError(f"{axis}-range: {axis}-log needs 0 < LO, got {lo}")
        for v in (lo, hi):
            model.parameters({name: v})  # validates the ends of the range
    if args.points < 2:
        raise ParameterError(f"--points: need at least 2, got {args.points}")
    out = campbell.check_output(args.out)
    grid = campbell.stability_grid(model, values, args.x, args.x_range, args.y, args.y_range,
                                   args.points, progress=not args.quiet, xlog=args.x_log, ylog=args.y_log)
    campbell.plot_stability(model, grid, out)
    counts = {k: int(np.sum(grid["label"] == k)) for k in ("stable", "marginal", "unstable")}
    print(f"gyro: wrote {out} ({', '.join(f'{v} {k}' for k, v in counts.items())})")
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
    f.add_argument("--method", default="default", choices=ladder.METHODS,
                   help="rung of the ladder (default: %(default)s; docs/methods.md)")
    f.set_defaults(run=_frequencies)
    c = sub.add_parser("campbell", help="Campbell diagram: frequencies against spin, formulas overlaid")
    c.add_argument("model")
    c.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="parameter value in SI units (phi in degrees); repeat as needed")
    c.add_argument("--out", required=True, metavar="FILE.png", help="image to write")
    c.add_argument("--range", nargs=2, type=float, default=(0.1, 10.0), metavar=("LO", "HI"),
                   help="spin range as multiples of the set's H (default: 0.1 10)")
    c.add_argument("--points", type=int, default=200, help="spins in the sweep (default: 200)")
    c.add_argument("--quiet", action="store_true", help="no progress bar")
    c.set_defaults(run=_campbell)
    s = sub.add_parser("stability-map", help="stability of the equilibrium over two parameters")
    s.add_argument("model")
    s.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    s.add_argument("--x", required=True, metavar="NAME")
    s.add_argument("--x-range", nargs=2, type=float, required=True, metavar=("LO", "HI"))
    s.add_argument("--y", required=True, metavar="NAME")
    s.add_argument("--y-range", nargs=2, type=float, required=True, metavar=("LO", "HI"))
    s.add_argument("--points", type=int, default=60, help="grid points per axis (default: 60)")
    s.add_argument("--x-log", action="store_true", help="log-spaced x axis (needs 0 < LO)")
    s.add_argument("--y-log", action="store_true", help="log-spaced y axis (needs 0 < LO)")
    s.add_argument("--out", required=True, metavar="FILE.png")
    s.add_argument("--quiet", action="store_true", help="no progress bar")
    s.set_defaults(run=_stability_map)
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
    except (np.linalg.LinAlgError, ArithmeticError, ValueError) as exc:
        # valid input whose numbers the double-precision solvers cannot handle (e.g. 1e300)
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"gyro: error: numerical failure at these parameters ({msg})", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output closed early (e.g. piped into head)
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
