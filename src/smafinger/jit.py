"""The package's numba decorator: :func:`numba.njit` with ``error_model="numpy"``.

Under numba's default ``error_model="python"`` every floating-point division and modulo is
compiled with a test of its divisor and a branch that raises ``ZeroDivisionError``; the wire
rates (Eqs. 7b-8), the kinetics (Eqs. 9-10) and the heat balance (Eq. 11) are chains of
divisions. With ``"numpy"`` a division follows IEEE 754 as numpy does (x / 0 is inf or NaN),
so the branches go: the same bits wherever no divisor is zero (the golden record is
bit-identical), and the kernel takes 0.85-0.89 of its time on the 60 s full cycle, at the long
step and the reference alike (docs/speed.md). A zero divisor inside a run, which parameter
validation is there to prevent, now gives inf or NaN instead of a bare ``ZeroDivisionError``:
in the state's rates it makes the state non-finite, and the run stops with the blow-up error
that gives the time and the state (:func:`smafinger.engine.run.run_spec`). The output-only
signals divide by parameters validated > 0 (the wire's length and area), and the integer
divisors inside the kernel are tick counts validated > 0.

Every compiled function of the package is made with this decorator (a test checks).
"""

import numba


def njit(*args, **options):
    """:func:`numba.njit` with ``error_model="numpy"`` unless given (``cache`` as given)."""
    options.setdefault("error_model", "numpy")
    return numba.njit(*args, **options)
