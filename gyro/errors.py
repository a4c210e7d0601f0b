"""The runtime's error for bad user input, importable without NumPy (the command line's
help and its one-line errors start fast)."""


class ParameterError(ValueError):
    """Bad user input; the message is one line naming the parameter."""
