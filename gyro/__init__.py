"""Runtime analysis of the generated gyroscope models: parameters, equilibria, natural
frequencies, and the `gyro` command line. Reads `generated/` only; never imports SymPy."""
from gyro.models import ParameterError, load

__all__ = ["ParameterError", "load"]
