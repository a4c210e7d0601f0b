"""The runtime's error for bad user input, importable without NumPy (the command line's
help and its one-line errors start fast)."""


class ParameterError(ValueError):
    """Bad user input; the message is one line naming the parameter."""


def finite_number(label: str, raw) -> float:
    """A finite float from user input, or ParameterError naming `label`."""
    import math

    try:
        value = float(raw)
    except (TypeError, ValueError):
        raise ParameterError(f"{label}: not a number: {raw!r}") from None
    if not math.isfinite(value):
        raise ParameterError(f"{label}: must be a finite number, got {raw!r}")
    return value
