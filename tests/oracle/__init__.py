"""A plain-Python reference of smafinger's model, written apart from it: the test oracle.

Written from the paper (Gilardi et al., Robotica 28(5), 2010), ``shared/MODEL-NOTES.md`` and
``docs/hysteresis.md`` with ``math``, NumPy and SciPy only; it reads a parameter set's fields
and named options but none of smafinger's model functions.

- :func:`build`: a parameter set into an :class:`OracleModel` (both mechanisms).
- :func:`derivative`: the right-hand side at a :class:`Vars` state with :class:`Held` inputs
  (each wire's kinetics branch a legacy :class:`Kinetics` or a memory-rule :class:`MemoryBranch`).
- :func:`simulate`: an open-loop program integrated with ``scipy.integrate.solve_ivp``
  (stick/slip, end stops and the kinetics' reversals and wiped-out loops as events);
  :func:`simulate_baseline`: the joint case the benchmarks time.
"""

from .build import build
from .hysteresis import Affine, Kinetics, MemoryBranch, Phase
from .model import Derivative, Held, OracleModel, Vars, WireHeld, WireVars
from .rhs import derivative
from .simulate import simulate, simulate_baseline
from .trajectory import Trajectory

__all__ = ["build", "derivative", "simulate", "simulate_baseline", "Affine", "Derivative", "Held", "Kinetics",
           "MemoryBranch", "OracleModel", "Phase", "Trajectory", "Vars", "WireHeld", "WireVars"]
