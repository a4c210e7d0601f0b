"""The `gyro` command line: one module per command, each with `register(subparsers)` and
`run(args)`, found here without a list (ORDER sets the help's order).

    gyro frequencies MODEL [--set NAME=VALUE]... [--method NAME] [--json]
    gyro campbell MODEL [--spin NAME] [--spin-range LO HI] [--points N] [--harmonics K1,K2,...] [--set ...] [--json] [--out FILE.png]
    gyro stability-map MODEL --x NAME --x-range LO HI --y NAME --y-range LO HI [--x-log] [--y-log] --out FILE.png
    gyro params MODEL
    gyro simulate MODEL [--set NAME=VALUE]... --t-end T [--points N] [--perturb NAME=VALUE]... [--method NAME] [--level L] [--base-rate ...] [--json] [--out FILE.png]
    gyro sweep MODEL --x NAME --x-range LO HI [--x-log] [--points N] [--method NAME] [--json] [--out FILE.png]
    gyro stability MODEL [--set NAME=VALUE]... [--orbit] [--json]
    gyro map MODEL --x NAME=LO:HI:N --y NAME=LO:HI:N --out FILE.png [--json]
    gyro forced MODEL --harmonic S:K:AMP[:PHASE]... [--set NAME=VALUE]... [--json] [--out FILE.png]
    gyro unbalance MODEL --force-x NAME --force-y NAME --magnitude ME [--phase PHI] [--spin NAME] --spin-range LO HI [--points N] [--set ...] [--json] [--out FILE.png]
    gyro scene MODEL QUESTION --tol REL [--set NAME=VALUE]... [--modes I,J,...] [--horizon T] [--json]

MODEL is a generated model's name, an emitted folder DIR/<name>, or a model file PATH.py
(derived on first use). A command that needs a declaration the model lacks (a spin angle,
conditions, levels) says so in one line; its --help names the declaration. Bad input prints one line on stderr naming the parameter and exits with code 2; a
numerical failure at valid input one line and exit 1.
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from gyro.cli.common import COMMAND_BUDGET, EXIT_USAGE, Parser
from gyro.errors import ParameterError, Terminated


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
    try:
        args = build_parser().parse_args(argv)
    except KeyboardInterrupt:
        return _interrupted()
    import numpy as np  # after parsing: `gyro --help` and usage errors import no NumPy

    from gyro import executor
    from gyro.equilibrium import EquilibriumError

    try:
        with np.errstate(all="ignore"), _stdout_for_results_only(), _quiet_libraries(), \
                executor.budget(COMMAND_BUDGET):
            return args.run(args)  # failures: one line each
    except Terminated:
        print("gyro: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        return _interrupted()
    except ParameterError as exc:
        print(f"gyro: error: {_plain(str(exc))}", file=sys.stderr)
        return EXIT_USAGE
    except EquilibriumError as exc:
        print(f"gyro: error: no equilibrium found: {_plain(str(exc))}", file=sys.stderr)
        return 1
    except (np.linalg.LinAlgError, ArithmeticError, ValueError, RuntimeError) as exc:
        # valid input whose numbers the solvers cannot handle (e.g. 1e300), an integrator
        # that gives up, mpmath without convergence
        msg = _plain(str(exc).splitlines()[0]) if str(exc) else type(exc).__name__
        print(f"gyro: error: numerical failure at these parameters ({msg})", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output closed early (e.g. piped into head)
        sys.stderr.close()
        return 0
    except MemoryError:
        print("gyro: error: out of memory: fewer points or sets", file=sys.stderr)
        return 1
    except OSError as exc:  # writing a result (disk full, a folder gone meanwhile)
        print(f"gyro: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), file=sys.stderr)
        return 1
    except Exception as exc:  # a numerical library's own failure (mpmath's NoConvergence, ...)
        if type(exc).__module__.split(".")[0] in ("mpmath", "scipy", "casadi", "numpy"):
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            print(f"gyro: error: numerical failure at these parameters ({msg})", file=sys.stderr)
            return 1
        raise


def _interrupted() -> int:
    print("gyro: interrupted", file=sys.stderr)
    return 130


EXIT_TERMINATED = 143  # 128 + SIGTERM, as a shell reports a process the signal ended


class _quiet_libraries:
    """While a command runs, no library's warning reaches stderr (matplotlib's layout and
    log-axis notices, Dask's port and memory notices, as warnings or as log records): gyro
    issues no warning of its own, a command says what went wrong in its own one line, and a
    result it cannot stand behind is refused, not printed beside a warning."""

    LIBRARIES = ("matplotlib", "dask", "distributed", "tornado", "bokeh")

    def __enter__(self):
        import logging
        import warnings

        self.catch = warnings.catch_warnings()
        self.catch.__enter__()
        warnings.simplefilter("ignore")
        self.levels = {}
        for lib in self.LIBRARIES:
            log = logging.getLogger(lib)
            self.levels[lib] = log.level
            log.setLevel(logging.CRITICAL + 1)
        return self

    def __exit__(self, *exc):
        import logging

        for lib, level in self.levels.items():
            logging.getLogger(lib).setLevel(level)
        self.catch.__exit__(*exc)
        return False


def _plain(message: str) -> str:
    """A message with NumPy's scalar reprs (np.float64(0.5), numpy 2) as plain numbers."""
    import re

    return re.sub(r"np\.(?:float|int|uint|complex|bool_?)\d*\(([^()]*)\)", r"\1", message)


class _stdout_for_results_only:
    """While a command runs, whatever C or Fortran code writes to file descriptor 1 (LAPACK's
    `** On entry to DLASCL ...`) goes to stderr; Python's prints still reach the real
    stdout, so that stdout carries the result alone (one JSON object with --json). Only
    where sys.stdout is the process's own descriptor 1 (not under a capture)."""

    def __enter__(self):
        import os

        self.saved = None
        try:
            if sys.stdout.fileno() != 1:
                return self
        except (AttributeError, ValueError, OSError):
            return self
        sys.stdout.flush()
        self.saved = os.dup(1)
        self.stdout = sys.stdout
        os.dup2(2, 1)
        sys.stdout = open(self.saved, "w", closefd=False, encoding=self.stdout.encoding, errors="replace")
        return self

    def __exit__(self, *exc):
        import os

        if self.saved is not None:
            try:
                sys.stdout.flush()
            finally:
                sys.stdout = self.stdout
                os.dup2(self.saved, 1)
                os.close(self.saved)
        return False
