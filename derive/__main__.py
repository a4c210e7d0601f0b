"""`python -m derive [--out DIR] [MODEL ...]`: derive and emit models, step by step."""
from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

from derive import emit, pipeline
from derive.models import MODELS


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m derive", description=__doc__)
    ap.add_argument("models", nargs="*", help=f"models to derive (default: all of {', '.join(MODELS)})")
    ap.add_argument("--out", default="generated", help="output folder (default: generated)")
    args = ap.parse_args(argv)
    names = args.models or list(MODELS)
    for name in names:
        if name not in MODELS:
            print(f"derive: unknown model {name!r}; known: {', '.join(MODELS)}", file=sys.stderr)
            return 2
    t_all = time.perf_counter()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "__init__.py").write_text(emit.environment().get_template("generated_init.py.j2").render())
    for name in names:
        steps = pipeline.Steps(prefix=f"[{name}] ")
        with steps("model: energies and parameters"):
            model = importlib.import_module(MODELS[name]).build()
        deriv = pipeline.derive(model, steps)
        with steps("functions to emit"):
            fns = pipeline.functions(deriv)
        with steps("emit: CSE, CasADi, NumPy, C through the templates"):
            files = emit.emit(model, fns, pipeline.metadata(deriv), Path(args.out) / name)
        print(f"[{name}] {len(files)} files in {Path(args.out) / name}; {steps.total:.1f} s", file=sys.stderr)
    print(f"derive: done in {time.perf_counter() - t_all:.1f} s", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
