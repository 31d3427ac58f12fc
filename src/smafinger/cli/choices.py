"""The choices and defaults the commands' options show in ``--help``, without loading the engine.

The defaults come from :mod:`smafinger.engine.defaults` (plain values, one copy). The names of
the choices are declared by the modules that implement them (``control.strategies.STRATEGIES``,
``engine.integrators.INTEGRATORS``, ``engine.pwm.PWM_MODELS``), which load numba: about a second
before ``smafinger --help`` could print. They are listed here as plain names;
``tests/test_cli_startup.py`` checks that they equal the engine's.
"""

from __future__ import annotations

# the engine's defaults and identification's: one copy, in a module that loads no numba
from ..engine.defaults import (DEFAULT_DT_S, DEFAULT_METHOD, DEFAULT_OUTPUT_S, DEFAULT_PWM, LONG_STEP_DT_S,  # noqa: F401
                               LONG_STEP_METHOD, LONG_STEP_PWM, LONG_STEP_STIFF_METHOD,
                               DEFAULT_TOL_DEG, DEFAULT_TOL_M, ENGINE_ENV, ENGINES, FIT_BUDGET, FIT_MAX_NFEV, FIT_SEED)

#: control strategies (``control.strategies.STRATEGIES``)
STRATEGY_NAMES = ("open-loop", "independent", "cooperative")
#: integrators (``engine.integrators.INTEGRATORS``)
METHOD_NAMES = ("euler", "rk4", "semi-implicit", "exponential", "authors-ode4")
#: PWM models a user chooses (``engine.pwm.PWM_MODELS``)
PWM_NAMES = ("exact", "averaged")
