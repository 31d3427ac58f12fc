"""smafinger: simulate, control and identify SMA tendon-driven finger joints.

Implements Gilardi, Haslam, Bundhoo & Park, "A shape memory alloy based tendon-driven
actuation system for biomimetic artificial fingers, part II: modelling and control",
Robotica 28(5):675-687 (2010).
"""

from .engine.run import SimulationError, simulate
from .parameters import ParameterError, ParameterSet
from .profiles import ProfileError, TargetProfile, VoltageProgram

__version__ = "0.1.0"
__all__ = ["simulate", "SimulationError", "ParameterSet", "ParameterError", "ProfileError",
           "TargetProfile", "VoltageProgram", "__version__"]
