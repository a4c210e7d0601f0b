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


def grid_axis(flag: str, text: str, names, most: int, what: str = "axis") -> tuple[str, float, float, int]:
    """A map's axis NAME=LO:HI:N -> (name, lo, hi, n): NAME one of `names` (an unknown one is
    called an unknown `what`), LO < HI finite, 2 <= N <= `most`; otherwise ParameterError
    naming the flag."""
    name, sep, rng = str(text).partition("=")
    parts = rng.split(":")
    if not sep or len(parts) != 3:
        raise ParameterError(f"{flag} {text!r}: expected NAME=LO:HI:N")
    name = name.strip()
    if name not in names:
        raise ParameterError(f"{flag} {name!r}: unknown {what}; known: {' '.join(names)}")
    lo, hi = (finite_number(f"{flag} {name}", p) for p in parts[:2])
    try:
        n = int(parts[2])
    except ValueError:
        raise ParameterError(f"{flag} {name}: N not an integer: {parts[2]!r}") from None
    if not lo < hi:
        raise ParameterError(f"{flag} {name}: need LO < HI, got {lo!r}:{hi!r}")
    if not 2 <= n <= most:
        raise ParameterError(f"{flag} {name}: N must lie in [2, {most}], got {n}")
    return name, lo, hi, n


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the code is (inside `terminable()`), so that its `finally`
    blocks run: the command line stops as on Ctrl-C, says so and exits 143."""


class terminable:
    """`with terminable():` SIGTERM raises Terminated in the main thread while the block
    runs, the handler before is restored after. Only around work that leaves something to
    clean up (a temporary folder) and that returns to Python often (chunks): a handler
    runs between bytecodes, so around one long compiled call it would hold the signal off
    until the call returns, where the default ends the process at once."""

    def __enter__(self):
        import signal
        import threading

        self.saved = None
        if threading.current_thread() is threading.main_thread():
            def stop(signum, frame):
                raise Terminated()

            self.saved = signal.signal(signal.SIGTERM, stop)
        return self

    def __exit__(self, *exc):
        import signal

        if self.saved is not None:
            signal.signal(signal.SIGTERM, self.saved)
        return False
