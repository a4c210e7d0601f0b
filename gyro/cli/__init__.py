"""The `gyro` command line: one module per command, each with `register(subparsers)` and
`run(args)`, found here without a list (ORDER sets the help's order).

    gyro frequencies MODEL [--set NAME=VALUE]... [--method NAME] [--json]
    gyro campbell MODEL [--set NAME=VALUE]... --out FILE.png [--range LO HI] [--points N]
    gyro stability-map MODEL --x NAME --x-range LO HI --y NAME --y-range LO HI [--x-log] [--y-log] --out FILE.png
    gyro params MODEL
    gyro simulate gimbal_gyroscope [--set NAME=VALUE]... --t-end T [--points N] [--method NAME] [--json] [--out FILE.png]

Bad input prints one line on stderr naming the parameter and exits with code 2; a
numerical failure at valid input one line and exit 1.
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from gyro.cli.common import EXIT_USAGE, Parser
from gyro.errors import ParameterError


def commands() -> list:
    mods = [importlib.import_module(f"{__name__}.{m.name}") for m in pkgutil.iter_modules(__path__)
            if m.name != "common" and not m.name.startswith("_")]
    return sorted((m for m in mods if hasattr(m, "register")), key=lambda m: m.ORDER)


class _Version(argparse.Action):
    """--version, looking the version up only when asked (importlib.metadata is slow)."""

    def __init__(self, option_strings, dest, help=None):
        super().__init__(option_strings, dest, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from importlib.metadata import PackageNotFoundError, version

        try:
            v = version("gyro-dynamics")
        except PackageNotFoundError:  # a source tree that was never installed
            v = "unknown (not installed)"
        print(f"gyro {v}")
        parser.exit()


def build_parser() -> Parser:
    ap = Parser(prog="gyro", description="Gyroscope dynamics from generated models.")
    ap.add_argument("--version", action=_Version, help="print the installed version and exit")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=Parser)
    for cmd in commands():
        cmd.register(sub)
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    import numpy as np  # after parsing: `gyro --help` and usage errors import no NumPy

    from gyro.equilibrium import EquilibriumError

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
