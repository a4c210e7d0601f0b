"""Runtime analysis of the generated gyroscope models: parameters, equilibria, natural
frequencies, and the `gyro` command line. Reads the generated models only; never imports
SymPy. `gyro.load(name)` gives a model; `gyro.ladder.spectrum` its frequencies (docs/api.md)."""

__all__ = ["ParameterError", "load"]


def __getattr__(name):  # lazy: `gyro --help` imports no NumPy
    if name == "load":
        from gyro.models import load

        return load
    if name == "ParameterError":
        from gyro.errors import ParameterError

        return ParameterError
    raise AttributeError(f"module 'gyro' has no attribute {name!r}")
