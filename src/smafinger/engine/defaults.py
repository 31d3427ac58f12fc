"""The engine's defaults, as plain values (importing this loads no numba: ``--help`` shows them).

:mod:`.run` and the commands (:mod:`smafinger.cli`) both read them from here.
"""

# The reference numerics: what a run gets when it sets any of dt_s, method, pwm (the unset ones
# come from here), and what the paper's scenarios use (the golden record holds their bits).
#: integration step [s]; on a stiff slider shorter (engine.numerics.reference_dt)
DEFAULT_DT_S = 1e-3
#: classical RK4. Forward Euler at 1 ms is about 3x faster on the co-operative full cycle and
#: 0.01 deg RMS from a 1 us reference there (benchmarks/bench_core.py), but it blows up on
#: the open-loop Table II runs of Figs. 7-8 (a stiff joint-tendon mode): not a safe default.
DEFAULT_METHOD = "rk4"
#: output sampling [s]
DEFAULT_OUTPUT_S = 1e-3
#: the PWM resolved at its edges (engine.pwm); "averaged" allows long steps (docs/speed.md)
DEFAULT_PWM = "exact"

# The long-step numerics: what a run that sets none of dt_s, method, pwm gets where they were
# validated (engine.numerics.long_step_refusal): the full co-operative cycle 14x faster than the
# reference, 0.0056 deg RMS from a 1 us run (benchmarks/bench_speed.py, docs/speed.md).
LONG_STEP_DT_S = 5e-3
LONG_STEP_METHOD = "exponential"
LONG_STEP_PWM = "averaged"
#: the slider's long step (engine.numerics.LONG_STEP_STIFF: the wire's stiffness implicit too), a
#: setting to give, no run's default (engine.numerics.long_step_refusal: the slider's momentum)
LONG_STEP_STIFF_METHOD = "semi-implicit"

#: the engines a single run may use (engine.interpreted); the default comes from ENGINE_ENV, else "auto"
ENGINES = ("auto", "compiled", "interpreted")
ENGINE_ENV = "SMAFINGER_ENGINE"

#: default target tolerance of the linear actuator [m]
DEFAULT_TOL_M = 5e-4
#: default target tolerance of the finger joint [deg]
DEFAULT_TOL_DEG = 0.5

#: identification's two stages (analysis.actuator_fit.FitSettings): the global stage's budget
#: of candidate sets, the least-squares stage's iterations, CMA-ES's seed
FIT_BUDGET = 1500
FIT_MAX_NFEV = 40
FIT_SEED = 1
