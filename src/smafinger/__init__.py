"""smafinger: simulate, control and identify SMA tendon-driven finger joints.

Implements Gilardi, Haslam, Bundhoo & Park, "A shape memory alloy based tendon-driven
actuation system for biomimetic artificial fingers, part II: modelling and control",
Robotica 28(5):675-687 (2010).

The public names are imported on first use (PEP 562 ``__getattr__``): ``import smafinger``
alone, as ``smafinger --help`` does, does not load the numba-compiled engine;
``from smafinger import simulate`` works as before.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

__version__ = "0.1.0"
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
