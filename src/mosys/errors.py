"""Errors a user can cause with a bad input file (not a spec: those raise SpecError)."""


class InputError(ValueError):
    """An input file that exists but cannot be used (wrong shape, missing group, ...). The CLI
    prints the message and exits 2."""


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
    way out (``cli.stops_as_exit``); ``code`` is the exit code, 128 + the signal's number. Not
    an Exception: nothing on the way catches it as an error."""

    def __init__(self, number: int):
        super().__init__(f"stopped by signal {number}")
        self.code = 128 + number
