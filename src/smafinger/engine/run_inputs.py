"""A run's arguments checked at the API edge (:func:`.run.make_spec`, :func:`.run.kernel_args`):
their types, and settings that would be silently ignored or misread together."""

from __future__ import annotations

from pathlib import PurePath

import numpy as np

from ..control.strategies import STRATEGIES
from ..parameters import ParameterSet
from ..profiles import DRIVE_KINDS, TargetProfile, VoltageProgram
from . import integrators, pwm as pwm_models
from .clock import TICK_S
from .defaults import DEFAULT_TOL_DEG, DEFAULT_TOL_M
from ..values import is_real

#: make_spec arguments -> (accepted types, what to give)
_NUMBER = "a number"
_ARG_TYPES = {
    "params": ((str, PurePath, ParameterSet), "a set's name, a .toml path or a ParameterSet"),
    "strategy": ((str,), f"one of {', '.join(STRATEGIES)}"),
    "profile": ((str, TargetProfile, type(None)), 'a profile text such as "0:-25,reach:-55" or a TargetProfile'),
    "voltage": ((str, VoltageProgram, type(None)), 'a program text such as "0:8:0,6:0:0" or a VoltageProgram'),
    "method": ((str,), f"one of {', '.join(integrators.INTEGRATORS)}"),
    "drive": ((str,), f"one of {', '.join(DRIVE_KINDS)}"),
    "pwm": ((str,), f"one of {', '.join(pwm_models.PWM_MODELS)}"),
    "independent_wait": ((bool, np.bool_), "True or False"),
}


def check_types(**args) -> None:
    """``TypeError`` naming the first argument of the wrong type (numbers: not bool, not text)."""
    for name, value in args.items():
        if name in _ARG_TYPES:
            types, want = _ARG_TYPES[name]
            ok = isinstance(value, types)
        else:
            want = _NUMBER
            ok = is_real(value)
        if not ok:
            raise TypeError(f"{name} = {value!r} is not {want}")
    if args["drive"] not in DRIVE_KINDS:
        raise ValueError(f"drive = {args['drive']!r} is not one of {', '.join(DRIVE_KINDS)}")


def check_tolerance_unit(p: ParameterSet, tol_deg: float, tol_m: float) -> None:
    """A tolerance in the other mechanism's unit would be ignored (``tol_deg`` on a slider)."""
    unused, value, default = (("tol_m", tol_m, DEFAULT_TOL_M) if p.coordinate.unit == "deg"
                              else ("tol_deg", tol_deg, DEFAULT_TOL_DEG))
    if value != default:
        used = "tol_deg" if unused == "tol_m" else "tol_m"
        raise ValueError(f"{unused} = {value!r} does not apply to {p.name}, whose targets are in {p.coordinate.unit}: "
                         f"give {used}")


def check_output_grid(spec, run) -> None:
    """The output grid of ``spec`` (``run``: its RunSettings) must end at t_end: the totals and the last segment's metrics are read at the
    last sample (with 3 s over 10 s the run's energy was the energy at 9 s)."""
    if run.t_end_ticks % run.out_ticks:
        below = run.t_end_ticks // run.out_ticks * run.out_ticks * TICK_S
        raise ValueError(f"t_end_s = {spec.t_end_s!r} is not a whole multiple of output_interval_s = "
                         f"{spec.output_interval_s!r}: the last sample would be at {below:.9g} s, not at the end "
                         f"(t_end_s = {below:.9g} or {below + run.out_ticks * TICK_S:.9g} would do)")
