"""What the commands share: the one-line usage errors (exit 2), the argument helpers for
`--set`, `--out`, `--json` and `--points`, and the checks of a model and an output file."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from gyro.errors import ParameterError

EXIT_USAGE = 2
SET_HELP = "parameter value in SI units (phi in degrees); repeat as needed"


class Parser(argparse.ArgumentParser):
    """argparse that reports a usage error in one line and exits with 2, and reads a value
    such as -1e-4 as a number, not as an option."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        import re

        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message):
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def add_model(p, models=None, help="the model (gyro params MODEL lists its parameters)") -> None:
    """The positional MODEL, its choices the generated models (or `models`)."""
    from gyro.catalog import available, model_source

    known = list(models or available())

    def model_name(text: str) -> str:
        if text in known:
            return text
        if models is None:  # any model: a generated one, an emitted folder or a model file
            if model_source(text) is not None:
                return text
            raise argparse.ArgumentTypeError(f"unknown model {text!r}: not one of {', '.join(known)}, nor a "
                                             "model file PATH.py, nor an emitted folder DIR/<name>")
        raise argparse.ArgumentTypeError(f"unknown model {text!r}; known: {', '.join(known)}")

    more = ", or a model file PATH.py (derived on first use), or an emitted folder DIR/<name>" if models is None else ""
    p.add_argument("model", type=model_name, metavar="MODEL", help=f"{help}; one of: {', '.join(known)}{more}")


def add_set(p, help: str | None = SET_HELP) -> None:
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=help)


def add_json(p) -> None:
    p.add_argument("--json", action="store_true", help="print one JSON object")


def add_out(p, required: bool = True, help: str | None = "image to write") -> None:
    p.add_argument("--out", required=required, metavar="FILE.png", help=help)


def add_points(p, default, help: str | None = None, type=int) -> None:
    p.add_argument("--points", type=type, default=default, help=help)


def add_quiet(p) -> None:
    p.add_argument("--quiet", action="store_true", help="no progress bar (none either when stderr is not a terminal)")


def add_scheduler(p) -> None:
    p.add_argument("--scheduler", default=None, metavar="local|ADDRESS",
                   help="run the chunks on Dask: 'local' starts a local cluster of one worker per core; "
                        "an address (tcp://host:8786) uses a running scheduler (default: this process)")


def parse_sets(items: list[str]) -> dict[str, str]:
    """NAME=VALUE items into a dict (values still text: the model checks them)."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError(f"--set {item!r}: expected NAME=VALUE")
        out[name.strip()] = value.strip()
    return out


def model_with_equilibrium(name):
    from gyro.models import load

    model = load(name)
    if model.meta.get("momenta"):
        raise ParameterError(f"{model.name}: its operator depends on the momenta "
                             f"{', '.join(model.meta['momenta'])} of a stationary motion; "
                             "this command covers models with a relative equilibrium")
    return model


def check_png_out(path) -> Path:
    """A figure's --out: a .png in a folder that exists and is writable."""
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise ParameterError(f"--out {path!r}: the figure is written as PNG; name it *.png")
    if out.is_dir():
        raise ParameterError(f"--out {path!r}: is a folder; name the file")
    if len(out.name.encode()) > 200:  # the temporary beside it adds its own tag to the name
        raise ParameterError(f"--out: the file name is too long ({len(out.name.encode())} bytes; at most 200)")
    parent = out.resolve().parent
    if not parent.is_dir():
        raise ParameterError(f"--out {path!r}: folder {parent} does not exist")
    if not os.access(parent, os.W_OK):
        raise ParameterError(f"--out {path!r}: folder {parent} is not writable")
    return out
