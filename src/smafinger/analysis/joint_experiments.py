"""The joint-level experiments of :mod:`.joint_fit`: their voltage programs and the model's angle.

Open-loop experiments on the upper (extensor) wire, the lower wire passive, each starting at rest
at the parameter set's ``theta0_deg`` with the wires at ambient; t = 0 in each file is the moment
the upper wire is switched on. A *heating* curve is driven from t = 0; a *cooling* curve is
driven for a while, then switched off (see :mod:`.joint_fit` for which coefficients each sees).
"""

from __future__ import annotations

import math

import numpy as np

from ..engine.run import DEFAULT_DT_S, make_spec, run_spec
from ..parameters import ParameterSet
from ..profiles import VoltageProgram
from ..values import is_real
from .data import AngleCurve, DataError

OUTPUT_INTERVAL_S = 0.01
OFF_BELOW_V = 0.05  # a measured voltage below this counts as off


def program_from_voltage(curve: AngleCurve) -> VoltageProgram:
    """Piecewise-constant upper-wire program from a curve's voltage column.

    Each row's voltage holds from its time to the next row's; the first row's voltage also
    holds from t = 0. Values are rounded to 1 mV, values below :data:`OFF_BELOW_V` count as
    off (0 V), and consecutive equal values merge.
    """
    if curve.voltage_V is None:
        raise ValueError(f"{curve.path}: no voltage column")
    steps: list[tuple[float, float, float]] = []
    for k, (t, v) in enumerate(zip(curve.t_s, curve.voltage_V)):
        v = round(float(v), 3) if v >= OFF_BELOW_V else 0.0
        t0 = 0.0 if k == 0 else round(float(t), 9)
        if not steps or v != steps[-1][1]:
            steps.append((t0, v, 0.0))
    return VoltageProgram(tuple(steps))


def heating_program(curve: AngleCurve, voltage_V: float) -> VoltageProgram:
    """The heating experiment's program: the voltage column, else ``voltage_V`` from t = 0.
    Raises DataError if the column switches the voltage off: the curve's end is then a cooling,
    which the heating phase's coefficients do not describe."""
    if curve.voltage_V is not None:
        prog = program_from_voltage(curve)
        off = next((t for t, v, _ in prog.steps if v == 0.0 and t > 0.0), None)
        if off is not None:
            raise DataError(f"{curve.path}: the voltage column switches off at t = {off:g} s, so the curve "
                            "ends in a cooling: give it as a cooling curve (--cooling), or cut it there")
        return prog
    return VoltageProgram(((0.0, float(voltage_V), 0.0),))


def cooling_program(curve: AngleCurve, voltage_V: float, heat_s: float | None) -> VoltageProgram:
    """The cooling experiment's program: ``heat_s`` if given (``voltage_V`` from 0 to
    ``heat_s``, then 0 V), else the file's voltage column. Raises ValueError if neither."""
    if heat_s is not None:
        if not (math.isfinite(heat_s) and heat_s > 0):
            raise ValueError(f"heat_s = {heat_s!r}: the heating time must be a positive number of seconds")
        if heat_s >= curve.t_s[-1]:
            raise ValueError(f"heat_s = {heat_s:g} s is not before the end of the cooling curve "
                             f"{curve.path} ({curve.t_s[-1]:g} s)")
        given = VoltageProgram(((0.0, float(voltage_V), 0.0), (round(float(heat_s), 9), 0.0, 0.0)))
        if curve.voltage_V is not None and program_from_voltage(curve).steps != given.steps:
            raise ValueError(f"heat_s = {heat_s:g} s at {voltage_V:g} V ({program_text(given)}) contradicts the "
                             f"voltage column of {curve.path} ({program_text(program_from_voltage(curve))}): give "
                             "--heat-s only for cooling curves without a voltage column, or matching it")
        return given
    if curve.voltage_V is not None:
        prog = program_from_voltage(curve)
        if prog.steps[-1][1] != 0.0:
            raise DataError(f"{curve.path}: row {len(curve.t_s)}: the voltage column never returns to 0 V, "
                            f"so this is not a cooling curve")
        return prog
    raise ValueError(f"{curve.path} has no voltage column: give the heating time before the voltage "
                     f"was switched off (--heat-s)")


def _t_end(t_last: float) -> float:
    n = math.ceil(t_last / OUTPUT_INTERVAL_S - 1e-9) + 1
    return round(n * OUTPUT_INTERVAL_S, 9)


#: the joint fit's numerics: RK4 (the reference's) at 1 ms for every candidate, whatever its
#: damping (a step per candidate would make the objective jump where the step changes); a fitted
#: damping near RK4's limit there is warned about (joint_phase._stability_warnings)
FIT_DT_S = DEFAULT_DT_S
FIT_METHOD = "rk4"


def joint_set(params: ParameterSet) -> None:
    """ValueError unless ``params`` is a finger-joint set: the joint fit reads its angle and its
    heating and cooling damping (a linear set was an internal error; found by an API fuzz)."""
    if params.mechanism != "joint":
        raise ValueError(f"identify joint fits a finger-joint set; {params.name!r} is a {params.mechanism} set "
                         "(fit it with identify actuator)")


def simulate_angle(params: ParameterSet, program: VoltageProgram, t_s: np.ndarray) -> np.ndarray:
    """Model joint angle [deg] at the times ``t_s`` (at least one) under an open-loop program."""
    joint_set(params)
    if len(t_s) == 0:
        raise ValueError("t_s has no samples: the model's angle is read at one time at least")
    spec = make_spec(params, strategy="open-loop", voltage=program, t_end_s=_t_end(float(t_s[-1])),
                     output_interval_s=OUTPUT_INTERVAL_S, dt_s=FIT_DT_S, method=FIT_METHOD)
    r = run_spec(spec, engine="compiled", record="metrics")  # the angle is one of the metrics' signals
    return np.interp(t_s, r.t, r.theta_deg)


def synthesize(params: ParameterSet, program: VoltageProgram | str, t_end_s: float,
               sample_s: float = 0.05, noise_deg: float = 0.0, seed: int = 0,
               path: str = "<synthetic>") -> AngleCurve:
    """A synthetic measured curve: the model's angle every ``sample_s`` plus Gaussian noise."""
    if isinstance(program, str):
        program = VoltageProgram.parse(program)
    for name, v in (("t_end_s", t_end_s), ("sample_s", sample_s)):
        if not (is_real(v) and math.isfinite(v) and v > 0):
            raise ValueError(f"{name} = {v!r} must be a finite number > 0")
    n = int(round(t_end_s / sample_s))
    t = np.round(np.arange(n + 1) * sample_s, 9)
    th = simulate_angle(params, program, t)
    rng = np.random.default_rng(seed)
    th = th + noise_deg * rng.standard_normal(th.shape)
    # the voltage each row sees (upper wire)
    starts = np.array([s[0] for s in program.steps])
    vu = np.array([s[1] for s in program.steps])
    v = vu[np.searchsorted(starts, t, side="right") - 1]
    return AngleCurve(path, t, th, v)


def program_text(p: VoltageProgram) -> str:
    """A program as ``start:upper:lower`` steps joined by commas (the CLI's ``--voltage`` syntax)."""
    return ",".join(f"{t:g}:{u:g}:{l:g}" for t, u, l in p.steps)
