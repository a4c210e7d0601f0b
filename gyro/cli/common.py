"""What the commands share: the one-line usage errors (exit 2), the argument helpers for
`--set`, `--out`, `--json` and `--points`, and the checks of a model and an output file."""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from gyro.errors import ParameterError
from gyro.models import has_operator  # noqa: F401  (the commands import it from here)

EXIT_USAGE = 2
COMMAND_BUDGET = 60.0  # s: a command's batch in this process (gyro.executor.budget), refused beyond
MAX_NAME = 200  # bytes of an output's file name: the temporary beside it adds its own tag
MAX_PATH = 4000  # bytes of a path (PATH_MAX is 4096 on Linux)
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




def has_levels(meta: dict) -> bool:
    """Declared levels, or the implicit exact one (gyro.levels.declarations): what
    `scene` and `level-map` need."""
    from gyro.levels import declarations

    return bool(declarations(meta))


def has_spin(meta: dict) -> bool:
    """An operator and a spin: a declared one (Model.spin) or a parameter in rad/s."""
    return has_operator(meta) and bool(meta.get("spin") or any(p["unit"] == "rad/s" for p in meta["parameters"]))


def add_model(p, models=None, help="the model (gyro params MODEL lists its parameters)", declares=None) -> None:
    """The positional MODEL, its choices the generated models (or `models`). With `declares`
    (a predicate on a model's metadata) the help lists the generated models that declare what
    the command needs; any model is still taken, and one that lacks it is refused when run."""
    from gyro.catalog import available, declaring, model_source

    known = list(models or available())
    listed = declaring(declares) if declares is not None else known

    def model_name(text: str) -> str:
        if text in known:
            return text
        if models is None:  # any model: a generated one, an emitted folder or a model file
            try:
                found = model_source(text)
            except ParameterError as exc:  # a path the system cannot take (too long a name)
                raise argparse.ArgumentTypeError(str(exc)) from None
            if found is not None:
                return text
            raise argparse.ArgumentTypeError(f"unknown model {text!r}: not one of {', '.join(known)}, nor a "
                                             "model file PATH.py, nor an emitted folder DIR/<name>")
        raise argparse.ArgumentTypeError(f"unknown model {text!r}; known: {', '.join(known)}")

    more = ", or a model file PATH.py (derived on first use), or an emitted folder DIR/<name>" if models is None else ""
    p.add_argument("model", type=model_name, metavar="MODEL",
                   help=f"{help}; one of: {', '.join(listed) or '(no generated model declares it)'}{more}")


def add_set(p, help: str | None = SET_HELP) -> None:
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", help=help)


def add_json(p) -> None:
    p.add_argument("--json", action="store_true", help="print one JSON object")


def out_name(text: str) -> str:
    """An output file's name as argparse's type: refused in the parse when empty (an empty
    --out would be taken for no --out) or longer than a file name can be."""
    if not text.strip():
        raise argparse.ArgumentTypeError("empty: name the file to write")
    name = Path(text).name
    if len(name.encode(errors="surrogateescape")) > MAX_NAME or len(os.fsencode(text)) > MAX_PATH:
        raise argparse.ArgumentTypeError(f"the file name is too long ({len(name.encode(errors='surrogateescape'))} "
                                         f"bytes; at most {MAX_NAME}, the path at most {MAX_PATH})")
    return text


def add_out(p, required: bool = True, help: str | None = "image to write", flag: str = "--out") -> None:
    p.add_argument(flag, required=required, type=out_name, metavar="FILE.png", help=help)


def add_points(p, default, help: str | None = None, type=int) -> None:
    p.add_argument("--points", type=type, default=default, help=help)


def add_quiet(p) -> None:
    p.add_argument("--quiet", action="store_true", help="no progress bar (none either when stderr is not a terminal)")


def add_scheduler(p) -> None:
    p.add_argument("--scheduler", default=None, metavar="local|ADDRESS",
                   help="run the chunks on Dask: 'local' starts a local cluster of one worker per core; "
                        "an address (tcp://host:8786) uses a running scheduler (default: this process)")


def axis(args, flag: str):
    """One axis of a sweep or a map, in the grammar of `gyro map` and `gyro level-map`,
    `--x NAME=LO:HI[:N]`, or as `--x NAME --x-range LO HI` (kept): (name, (lo, hi), N or
    None). Either form, not both; ParameterError naming the flag otherwise."""
    from gyro.errors import finite_number

    text, rng = getattr(args, flag), getattr(args, f"{flag}_range")
    if "=" not in text:
        if rng is None:
            raise ParameterError(f"--{flag}-range: required with --{flag} NAME (or give the axis as "
                                 f"--{flag} NAME=LO:HI[:N])")
        return text, tuple(rng), None
    if rng is not None:
        raise ParameterError(f"--{flag}-range: the axis is given twice (--{flag} {text} has its range)")
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    if not name.strip() or len(parts) not in (2, 3):
        raise ParameterError(f"--{flag} {text!r}: expected NAME=LO:HI[:N]")
    lo, hi = (finite_number(f"--{flag} {name.strip()}", v) for v in parts[:2])
    n = None
    if len(parts) == 3:
        try:
            n = int(parts[2])
        except ValueError:
            raise ParameterError(f"--{flag} {text!r}: N is not an integer: {parts[2]!r}") from None
    return name.strip(), (lo, hi), n


def axis_points(args, default: int, *ns) -> int:
    """The points of an axis (or of both axes of a map): --points, or the N of the axes'
    NAME=LO:HI:N, which must agree with each other and with --points where both are given."""
    given = {n for n in ns if n is not None} | ({args.points} if args.points is not None else set())
    if len(given) > 1:
        raise ParameterError(f"--points: the axes and --points give different counts ({', '.join(map(str, sorted(given)))}); "
                             "this command takes one")
    return given.pop() if given else default


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


def check_png_out(path, flag: str = "--out") -> Path:
    """A figure's --out: a .png in a folder that exists and where a file can be created,
    checked before anything is computed (by creating and removing a probe file there: a
    permission bit says nothing for root, nor for a read-only or pseudo file system)."""
    try:
        out_name(str(path))
    except argparse.ArgumentTypeError as exc:
        raise ParameterError(f"{flag}: {exc}") from None
    out = Path(path)
    if out.suffix.lower() != ".png":
        raise ParameterError(f"{flag} {path!r}: the figure is written as PNG; name it *.png")
    try:
        if out.is_dir():
            raise ParameterError(f"{flag} {path!r}: is a folder; name the file")
        parent = out.resolve().parent
        if not parent.is_dir():
            raise ParameterError(f"{flag} {path!r}: folder {parent} does not exist")
    except OSError as exc:
        raise ParameterError(f"{flag} {path!r}: {exc.strerror or exc}") from None
    writable_folder(flag, path, parent)
    return out


def writable_folder(flag: str, path, folder: Path) -> None:
    """ParameterError naming `flag` unless a file can be created in `folder` (tried: a probe
    file created and removed at once, nothing left)."""
    import tempfile

    try:
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".gyro-probe-"):
            pass
    except OSError as exc:
        raise ParameterError(f"{flag} {str(path)!r}: cannot write in {folder} ({exc.strerror or exc})") from None


def refuse_over_budget(flag: str, count: int, each: float, scheduler=None, what: str = "sets",
                       cluster: bool = True) -> None:
    """Before anything runs: ParameterError naming `flag` when `count` items at `each`
    seconds apiece (measured: a method's COST, compiled) cannot fit the command line's
    budget in this process. On a --scheduler the cluster is the user's, and nothing is
    refused here."""
    if scheduler is None and count * each > COMMAND_BUDGET:
        raise ParameterError(f"{flag}: {count} {what} take about {count * each:.0f} s in this process "
                             f"({f'{each:.3g} s' if each >= 0.01 else f'{each * 1e6:.3g} us'} each), over the "
                             "command line's budget of "
                             f"{COMMAND_BUDGET:.0f} s: ask for fewer" + (", or use --scheduler" if cluster else ""))


def method_cost(name: str) -> float:
    """A frequency method's COST (s per set, compiled, measured), read from its source
    without importing it."""
    from gyro.catalog import module_constants
    from gyro.methods import __path__ as folder

    return float(module_constants(folder[0], ("COST",))[name]["COST"])
