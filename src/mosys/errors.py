"""Errors a user can cause with a bad input file (not a spec: those raise SpecError)."""


class InputError(ValueError):
    """An input file that exists but cannot be used (wrong shape, missing group, ...). The CLI
    prints the message and exits 2."""
