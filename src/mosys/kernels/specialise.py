"""Kernels specialised to one dynamics model, so that numba inlines the model's equations.

A kernel that takes the model as a first-class function (``integrate.DERIVATIVE_INTO``) is
compiled once for every model but calls the equations through a pointer, and one that takes the
model's dispatcher as an argument would be compiled again in every process (numba cannot key its
cache on a dispatcher argument). So a kernel that is specialised is written as a plain Python
*template* whose body calls the global name ``model_derivative``; ``specialise`` makes a copy of
the template's function with that global bound to the model's ``derivative_into`` and a name of
its own that carries a digest of the model's module name and source, and compiles it with
``cache=True``: numba caches it beside the template's source under that name, once per model and
machine, like the model itself (``dynamics.load``). (The name counts too: the cached code imports
the model by it when it is loaded.)
"""

from __future__ import annotations

import hashlib
import inspect
import types
from collections.abc import Callable
from functools import cache
from pathlib import Path

from numba import njit


def model_derivative(state, inputs, out):
    """Stands for a model's ``derivative_into(state, inputs, out)`` in templates; ``specialise``
    binds the real one."""
    raise NotImplementedError("a template runs only as specialised to a model")


def model_digest(model: types.ModuleType) -> str:
    """The first 16 hex digits of the SHA-256 of the model module's name and source file."""
    source = Path(inspect.getfile(model)).read_bytes()
    return hashlib.sha256(model.__name__.encode() + b"\0" + source).hexdigest()[:16]


@cache
def specialise(template: Callable, model: types.ModuleType, parallel: bool = False) -> Callable:
    """``template`` compiled (numba, ``cache=True``) with ``model_derivative`` bound to
    ``model.derivative_into``; one dispatcher per template and model in a process."""
    bound = dict(template.__globals__, model_derivative=model.derivative_into)
    function = types.FunctionType(
        template.__code__, bound, template.__name__, template.__defaults__
    )
    function.__qualname__ = f"{template.__qualname__}_{model_digest(model)}"
    function.__module__ = template.__module__
    function.__doc__ = template.__doc__
    return njit(cache=True, parallel=parallel)(function)
