"""smafinger: simulate, control and identify shape-memory-alloy (SMA) wire actuators.

One engine drives two mechanisms: the tendon-driven finger joint of Gilardi, Haslam, Bundhoo &
Park, "A shape memory alloy based tendon-driven actuation system for biomimetic artificial
fingers, part II: modelling and control", Robotica 28(5):675-687 (2010), moved by two opposing
SMA wires (``paper2010`` and the other joint sets), and a single SMA wire pulling a slider
against a bias spring (``linear-bias-spring``).

Public names: :func:`simulate` (one run of either mechanism), :class:`ParameterSet` (the base
type of every parameter set; each field range-checked), :class:`TargetProfile` (a closed-loop
target schedule such as ``"0:-25,reach:-55"``: degrees for the joint, metres for the linear
rig), :class:`VoltageProgram` (an open-loop drive program: voltages, duties or currents per
wire), and the errors :class:`SimulationError`, :class:`ParameterError` and
:class:`ProfileError`.

The public names are imported on first use (PEP 562 ``__getattr__``): ``import smafinger``
alone, as ``smafinger --help`` does, does not load the numba-compiled engine;
``from smafinger import simulate`` works as before.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

__version__ = "0.2.0.dev0"
__all__ = ["simulate", "SimulationError", "ParameterSet", "ParameterError", "ProfileError",
           "TargetProfile", "VoltageProgram", "__version__"]

if TYPE_CHECKING:  # what type checkers and IDEs see: the same names, imported eagerly
    from .engine.run import SimulationError, simulate
    from .parameters import ParameterError, ParameterSet
    from .profiles import ProfileError, TargetProfile, VoltageProgram


def __getattr__(name: str):
    """A public name of :data:`__all__`, imported from its module now and kept."""
    if name in ("simulate", "SimulationError"):
        from .engine import run as module
    elif name in ("ParameterSet", "ParameterError"):
        from . import parameters as module
    elif name in ("ProfileError", "TargetProfile", "VoltageProgram"):
        from . import profiles as module
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
