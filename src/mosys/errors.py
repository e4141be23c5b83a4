"""Errors a user can cause with a bad input file (not a spec: those raise SpecError), and the
stop signals a command has received."""

import signal


class InputError(ValueError):
    """A file a command cannot use: an input that is missing, unreadable or not what it should
    be (wrong shape, missing group or attribute, ...), or an output that cannot be written there.
    The message names the file. The CLI prints it and exits 2."""


class SimulationError(InputError):
    """A simulation the inputs make impossible to go on with. The message comes complete, led by
    the file and line it was asked for when there is one (``script.anim:3:1: ...``, as a
    SpecError); the CLI prints it as it is and exits 2."""


class NonFiniteStateError(SimulationError):
    """The model's state became non-finite (NaN, inf, or beyond ``kernels.soundness.STATE_LIMIT``,
    where the next step would overflow) at ``t`` seconds into a run; ``state`` (S,) SI is the
    state there. The message names the source that was driving and the state."""

    def __init__(self, message: str, t: float, state):
        super().__init__(message)
        self.t = t
        self.state = state


class Stopped(BaseException):
    """A stop signal (SIGTERM, SIGHUP) received while a command ran, raised where it arrived as
    Ctrl-C raises KeyboardInterrupt, so that the command's partial outputs are removed on the
    way out (``cli.stop_signals_raise``); ``code`` is the exit code, 128 + the signal's number. Not
    an Exception: nothing on the way catches it as an error."""

    def __init__(self, number: int):
        super().__init__(f"stopped by signal {number}")
        self.code = 128 + number


_stops: list[int] = []  # the stop signals received by the running command, in order


def note_stop(number: int) -> None:
    """Record that the running command was sent stop signal ``number`` (``cli`` does, as the
    signal arrives): a library that swallows the exception the signal raised (numba compiling
    through a ctypes callback prints 'Exception ignored' and goes on) cannot make the command
    finish as if nothing had happened (``raise_if_stopped``)."""
    _stops.append(number)


def forget_stops() -> None:
    """A new command starts with no stop received."""
    _stops.clear()


def stop_received() -> int | None:
    """The first stop signal the running command received, or None."""
    return _stops[0] if _stops else None


def raise_if_stopped() -> None:
    """Raise what the first stop signal received raises (KeyboardInterrupt for SIGINT, else
    Stopped), if one was: before a command's outputs are renamed into place."""
    number = stop_received()
    if number == signal.SIGINT:
        raise KeyboardInterrupt
    if number is not None:
        raise Stopped(number)
