"""One dispatch between the compiled generated C and its NumPy twin, and one chunker.

Every analysis calls a generated function through `function(model, name)`: the model's C
over the whole batch (gyro.cbackend compiles it once per machine) when a compiler is there,
the generated NumPy otherwise, with the same shapes. The C kernels that have no NumPy twin
of the same name (the QEP refinement, the Hermitian block forms, the formulas' selection)
come through `compiled(builder, model)`, None where there is no compiler, so that the
caller takes its own NumPy path. `chunks` cuts a large batch into pieces, with a progress
bar where asked."""
from __future__ import annotations

from gyro import cbackend
from gyro.models import Model


def function(model: Model, name: str):
    """A generated function over a batch: returns a list of outputs, (sets,) + shape each."""
    try:
        return cbackend.batch_function(model.name, name)
    except cbackend.CompilerUnavailable:
        g = getattr(model.numpy, name)

        def f(*args):
            out = g(*args)
            return list(out) if isinstance(out, tuple) else [out]
        return f


def compiled(builder, model: Model):
    """builder(model.name) (one of gyro.cbackend's kernels), or None without a compiler."""
    try:
        return builder(model.name)
    except cbackend.CompilerUnavailable:
        return None


def chunks(n: int, size: int, progress: bool = False, desc: str = ""):
    """Slices of range(n), `size` at a time; a tqdm bar on stderr when `progress`."""
    if not progress:
        for s in range(0, n, size):
            yield slice(s, min(s + size, n))
        return
    from tqdm import tqdm

    with tqdm(total=n, desc=desc, unit="set", leave=False) as bar:
        for s in range(0, n, size):
            yield slice(s, min(s + size, n))
            bar.update(min(size, n - s))
