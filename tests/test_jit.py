"""Every compiled function of the package is made by :func:`smafinger.jit.njit`: numba's
``error_model="numpy"`` (IEEE division, no ZeroDivisionError branch on every division).

A module that imported ``numba.njit`` directly would compile its functions with the
divisor tests again, and their callers inline them: the check walks every module."""

import importlib
import math
import pkgutil

from numba.core.dispatcher import Dispatcher

import smafinger
from smafinger.jit import njit


def _dispatchers():
    found = {}
    for info in pkgutil.walk_packages(smafinger.__path__, "smafinger."):
        if info.name.endswith("__main__"):  # runs the CLI
            continue
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if isinstance(obj, Dispatcher) and obj.py_func.__module__ == info.name:
                found[f"{info.name}.{name}"] = obj
    return found


def test_every_compiled_function_uses_the_numpy_error_model():
    found = _dispatchers()
    assert len(found) > 150  # the model, engine and controllers (179 decorated functions)
    other = sorted(n for n, d in found.items() if d.targetoptions.get("error_model") != "numpy")
    assert other == []


def test_a_zero_divisor_gives_ieee_values_not_an_exception():
    @njit
    def ratio(a, b):
        return a / b

    assert ratio(1.0, 0.0) == math.inf
    assert math.isnan(ratio(0.0, 0.0))
    assert ratio(1.0, 4.0) == 0.25
