"""A plain-Python reference of smafinger's model, written apart from it: the test oracle.

Written from the paper (Gilardi et al., Robotica 28(5), 2010) and ``shared/MODEL-NOTES.md``
with ``math``, NumPy and SciPy only; it reads a parameter set's fields and named options but
none of smafinger's compiled model functions.

- :func:`build`: a parameter set into an :class:`OracleModel` (both mechanisms).
- :func:`derivative`: the right-hand side at a :class:`Vars` state with :class:`Held` inputs.
- :func:`simulate`: an open-loop program integrated with ``scipy.integrate.solve_ivp``
  (stick/slip and end stops as events); :func:`simulate_baseline`: the joint case the
  benchmarks time.
"""

from .build import build
from .material import Kinetics, Phase
from .model import Derivative, Held, OracleModel, Vars, WireHeld, WireVars
from .rhs import derivative
from .simulate import simulate, simulate_baseline
from .trajectory import Trajectory

__all__ = ["build", "derivative", "simulate", "simulate_baseline", "Derivative", "Held", "Kinetics", "OracleModel",
           "Phase", "Trajectory", "Vars", "WireHeld", "WireVars"]
