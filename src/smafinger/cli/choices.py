"""The choices and defaults the commands' options show in ``--help``, without loading the engine.

The engine defines these (``control.strategies.STRATEGIES``, ``engine.integrators.INTEGRATORS``,
``engine.pwm.PWM_MODELS``, ``engine.run.DEFAULT_*``, ``analysis.actuator_fit.FitSettings``), but
importing it loads numba and the compiled kernel: about a second before ``smafinger --help``
could print. They are repeated here as plain values; ``tests/test_cli_startup.py`` checks that
they equal the engine's, so a change there fails the tests instead of drifting.
"""

from __future__ import annotations

#: control strategies (``control.strategies.STRATEGIES``)
STRATEGY_NAMES = ("open-loop", "independent", "cooperative")
#: integrators (``engine.integrators.INTEGRATORS``)
METHOD_NAMES = ("euler", "rk4", "semi-implicit", "exponential", "authors-ode4")
#: PWM models a user chooses (``engine.pwm.PWM_MODELS``)
PWM_NAMES = ("exact", "averaged")

#: ``engine.run``'s defaults: step [s], integrator, output sampling [s], PWM model, linear tolerance [m]
DEFAULT_DT_S = 1e-3
DEFAULT_METHOD = "rk4"
DEFAULT_OUTPUT_S = 1e-3
DEFAULT_PWM = "exact"
DEFAULT_TOL_M = 5e-4

#: ``analysis.actuator_fit.FitSettings()``: global-stage budget, least-squares iterations, seed
FIT_BUDGET = 1500
FIT_MAX_NFEV = 40
FIT_SEED = 1
